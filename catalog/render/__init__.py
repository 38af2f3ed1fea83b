"""The renderer: GL context, shader loading, band pre-integration, scene, frames, snapshots.

Nothing heavy is imported here; import the submodule you need:

- :mod:`catalog.gl.context`: the one place a GL context is created (EGL or a window's);
- :mod:`catalog.gl.shaderlib`: shader files with ``#include`` and injected ``#define``s;
- :mod:`catalog.render.bands`: light, dye and fluorescence spectra -> per-band uniforms;
- :mod:`catalog.render.scene`, :mod:`catalog.render.camera`: curtain, window, room, sun, camera;
- :mod:`catalog.render.frame`: :class:`~catalog.render.frame.FrameRenderer`, used by the viewer;
- :mod:`catalog.render.snapshot`: headless EXR/PNG images with metadata.
"""
