"""The renderer: band pre-integration, scene, frames, snapshots and contact sheets. The
GL context and shader loading it uses are in :mod:`catalog.gl` (shared with the cloth).

Nothing heavy is imported here; import the submodule you need:

- :mod:`catalog.render.bands`: light, dye and fluorescence spectra -> per-band uniforms;
- :mod:`catalog.render.scene`, :mod:`catalog.render.camera`: curtain, window, room, sun, camera;
- :mod:`catalog.render.frame`: :class:`~catalog.render.frame.FrameRenderer`, used by the viewer:
  it orders the passes of :mod:`catalog.render.passes` and owns the targets;
- :mod:`catalog.render.curtain_frames`: where the curtain's maps look from (the key's frame,
  the occlusion directions, the room-side grid); :mod:`catalog.render.room_operators`: the
  room's transport as the frame loads it;
- :mod:`catalog.render.snapshot`: headless EXR/PNG images with metadata.
"""
