"""The benchmark suite behind ``catalog bench``: run time against error, side by side.

Each section is a module with ``run(quick: bool, ctx: Context) -> dict`` returning
``{"rows": [...], "summary": {...}}`` (plain numbers, finite unless said otherwise) and,
optionally, ``plot(result, folder) -> list[Path]``:

- ``colour``: paper-mode RGB, physical-mode RGB and N-band renders of every catalog
  fabric under the study's lights against the float64 spectral reference, beside each
  one's frame time (:mod:`catalog.bench.colour`);
- ``fluorescence``: representations of fluorescence in an RGB engine on the measured
  Donaldson matrices (:mod:`catalog.bench.fluorescence_rgb`, with the reduced
  re-radiation matrices of :mod:`catalog.bench.reduction`);
- ``uv``: fluorescence under UV and violet light: the matrices' noise floor and the
  banded model chosen on selection lights (:mod:`catalog.bench.uv_fluorescence`);
- ``fit``: Levenberg-Marquardt on 79 and 4800 gonio points against differential
  evolution (:mod:`catalog.bench.fit`);
- ``cloth``: substeps and backends against a small-step reference run
  (:mod:`catalog.bench.cloth`);
- ``stability``: every model's parameters swept to their edges
  (:mod:`catalog.bench.stability`);
- ``startup``: import time and time to the first frame (:mod:`catalog.bench.startup`);
- ``display``: each display transform's cost in the frame (:mod:`catalog.bench.display`);
- ``room``: the frame with the room lit through the curtain, the clear sky and the glare
  against the frame without, each pass's share (:mod:`catalog.bench.room`);
- ``image``: the real-time frame against the path-traced reference of the same scene, FLIP
  and Delta E per region, both run times (:mod:`catalog.bench.image`; needs the
  ``pathtrace`` extra and LLVM 19, docs/pathtrace.md);
- ``accuracy``: the frame against the reference on scenes drawn at random from the whole
  scene space, both through one neutral display (:mod:`catalog.bench.accuracy`).

docs/bench.md has the figures and how to reproduce them.
"""

from __future__ import annotations

from pathlib import Path

from catalog.gl.shaderlib import register_folder

#: Shaders only the benchmarks use (trivial floors, the HG probe, springs12), found by name.
SHADER_DIR = Path(__file__).resolve().parent / "shaders"
register_folder(SHADER_DIR)

#: Section name -> module, in report order.
SECTIONS: dict[str, str] = {
    "colour": "catalog.bench.colour",
    "fluorescence": "catalog.bench.fluorescence_rgb",
    "uv": "catalog.bench.uv_fluorescence",
    "fit": "catalog.bench.fit",
    "cloth": "catalog.bench.cloth",
    "stability": "catalog.bench.stability",
    "startup": "catalog.bench.startup",
    "display": "catalog.bench.display",
    "room": "catalog.bench.room",
    "image": "catalog.bench.image",
    "accuracy": "catalog.bench.accuracy",
}
