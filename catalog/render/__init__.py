"""The renderer: band pre-integration, scene, frames, snapshots and contact sheets. The
GL context and shader loading it uses are in :mod:`catalog.gl` (shared with the cloth).

Nothing heavy is imported here; import the submodule you need:

- :mod:`catalog.render.bands`: light, dye and fluorescence spectra -> per-band uniforms;
- :mod:`catalog.render.scene`, :mod:`catalog.render.camera`: curtain, window, room, sun, camera;
- :mod:`catalog.render.frame`: :class:`~catalog.render.frame.FrameRenderer`, used by the viewer;
- :mod:`catalog.render.snapshot`: headless EXR/PNG images with metadata.
"""
