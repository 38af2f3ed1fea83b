"""The benchmark suite behind ``catalog bench``: run time against error, side by side.

Each section is a module with ``run(quick: bool, ctx: Context) -> dict`` returning
``{"rows": [...], "summary": {...}}`` (plain numbers, finite unless said otherwise) and,
optionally, ``plot(result, folder) -> list[Path]``:

- ``colour``: paper-mode RGB, physical-mode RGB and N-band renders of every catalog
  fabric under the study's lights against the float64 spectral reference, beside each
  one's frame time (:mod:`catalog.benchsuite.colour`);
- ``fluorescence``: representations of fluorescence in an RGB engine on the measured
  Donaldson matrices (:mod:`catalog.benchsuite.fluorescence_rgb`, with the reduced
  re-radiation matrices of :mod:`catalog.benchsuite.reduction`);
- ``fit``: Levenberg-Marquardt on 79 and 4800 gonio points against differential
  evolution (:mod:`catalog.benchsuite.fit`);
- ``cloth``: substeps and backends against a small-step reference run
  (:mod:`catalog.benchsuite.cloth`);
- ``stability``: every model's parameters swept to their edges
  (:mod:`catalog.benchsuite.stability`);
- ``startup``: import time and time to the first frame (:mod:`catalog.benchsuite.startup`);
- ``image``: the real-time frame against the path-traced reference of the same scene, FLIP
  and Delta E per region, both run times (:mod:`catalog.benchsuite.image`; needs the
  ``pathtrace`` extra and LLVM 19, docs/pathtrace.md).

docs/bench.md has the figures and how to reproduce them.
"""

from __future__ import annotations

#: Section name -> module, in report order.
SECTIONS: dict[str, str] = {
    "colour": "catalog.benchsuite.colour",
    "fluorescence": "catalog.benchsuite.fluorescence_rgb",
    "fit": "catalog.benchsuite.fit",
    "cloth": "catalog.benchsuite.cloth",
    "stability": "catalog.benchsuite.stability",
    "startup": "catalog.benchsuite.startup",
    "image": "catalog.benchsuite.image",
}
