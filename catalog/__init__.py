"""Fabric catalog: woven-cloth transmission with fluorescence, rendered in real time.

Importing the package is cheap on purpose: no numpy-heavy or GL module is
imported here, so ``catalog --help`` answers at once. One sub-package per room
(docs/architecture.md):

- :mod:`catalog.core`: errors, atomic writes, JSON/CSV helpers, option parsers, resources;
- :mod:`catalog.optics`: spectra, colorimetry, lights, fluorescence, BTDF, the float64
  shading reference, the sun (:mod:`catalog.optics.sun`) and bispectral matrices
  (:mod:`catalog.optics.bispectral`) (float64 numpy, no GL);
- :mod:`catalog.presets`: preset TOML <-> typed object;
- :mod:`catalog.fit`: gonio measurements and the eq. 7 fit;
- :mod:`catalog.gl`: the GL context and shader loading (used by cloth and render);
- :mod:`catalog.cloth`, :mod:`catalog.render`, :mod:`catalog.viewer`;
- :mod:`catalog.commands`: the ``catalog`` command (parse, call, print);
- ``benchmarks`` (top level, outside the package and the wheel): every benchmark and study.
"""

__version__ = "0.1.0"
