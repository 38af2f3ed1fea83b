"""The renderer: band pre-integration, scene, frames, snapshots and contact sheets. The
GL context and shader loading it uses are in :mod:`catalog.gl` (shared with the cloth).

Nothing heavy is imported here; import the submodule you need:

- :mod:`catalog.render.bands`: light, dye and fluorescence spectra -> per-band uniforms;
- :mod:`catalog.render.scene`, :mod:`catalog.render.camera`: curtain, window, room, sun, camera;
- :mod:`catalog.render.frame`: :class:`~catalog.render.frame.FrameRenderer`, used by the viewer:
  it orders the passes of :mod:`catalog.render.passes` and owns the targets;
- :mod:`catalog.render.room_light`: the room light's numpy side (geometry, radiosity, the
  maps' frames, the float64 twins of the window's and the wall's light);
- :mod:`catalog.render.snapshot`: headless EXR/PNG images with metadata.
"""
