"""The path-traced reference of the curtain scene (issue 11): Mitsuba 3 on the CPU.

- :mod:`catalog.pathtrace.backend`: finds the LLVM library Dr.Jit needs and imports Mitsuba
  (only here, only when a reference is asked for: the frame path never imports this package);
- :mod:`catalog.pathtrace.woven`: eq. 7 as a Mitsuba BSDF (two HG lobes, importance-sampled,
  LD as null transmission through the gaps, two-sided, dye per channel);
- :mod:`catalog.pathtrace.scene`: the scene of ``catalog snapshot`` exported from the same
  description (catalog.render.scene): room, window, curtain, key light, sky and ground;
- :mod:`catalog.pathtrace.render`: ``catalog reference``, an EXR of radiance;
- :mod:`catalog.pathtrace.metrics`: the real-time frame's error against it (FLIP, Delta E 2000).

docs/pathtrace.md describes the model, its validation and the measured error.
"""
