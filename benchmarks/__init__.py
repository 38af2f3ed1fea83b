"""The benchmark suite behind ``catalog bench``: run time against error, side by side.

Each section is a module with ``run(quick: bool, ctx: Context) -> dict`` returning
``{"rows": [...], "summary": {...}}`` (plain numbers, finite unless said otherwise) and,
optionally, ``plot(result, folder) -> list[Path]``:

- ``colour``: paper-mode RGB, physical-mode RGB and N-band renders of every catalog
  fabric under the study's lights against the float64 spectral reference, beside each
  one's frame time (:mod:`benchmarks.colour`);
- ``fluorescence``: representations of fluorescence in an RGB engine on the measured
  Donaldson matrices (:mod:`benchmarks.fluorescence_rgb`, with the reduced
  re-radiation matrices of :mod:`benchmarks.reduction`);
- ``uv``: fluorescence under UV and violet light: the matrices' noise floor and the
  banded model chosen on selection lights (:mod:`benchmarks.uv_fluorescence`);
- ``fit``: Levenberg-Marquardt on 79 and 4800 gonio points against differential
  evolution (:mod:`benchmarks.fit`);
- ``cloth``: substeps and backends against a small-step reference run
  (:mod:`benchmarks.cloth`);
- ``stability``: every model's parameters swept to their edges
  (:mod:`benchmarks.stability`);
- ``startup``: import time and time to the first frame (:mod:`benchmarks.startup`);
- ``display``: each display transform's cost in the frame (:mod:`benchmarks.display`);
- ``room``: the frame with the room lit through the curtain, the clear sky and the glare
  against the frame without, each pass's share (:mod:`benchmarks.room`);
- ``image``: the real-time frame against the path-traced reference of the same scene, FLIP
  and Delta E per region, both run times (:mod:`benchmarks.image`; needs the
  ``pathtrace`` extra and LLVM 19, docs/pathtrace.md);
- ``accuracy``: the frame against the reference on scenes drawn at random from the whole
  scene space, both through one neutral display (:mod:`benchmarks.accuracy`).

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
    "colour": "benchmarks.colour",
    "fluorescence": "benchmarks.fluorescence_rgb",
    "uv": "benchmarks.uv_fluorescence",
    "fit": "benchmarks.fit",
    "cloth": "benchmarks.cloth",
    "stability": "benchmarks.stability",
    "startup": "benchmarks.startup",
    "display": "benchmarks.display",
    "room": "benchmarks.room",
    "image": "benchmarks.image",
    "accuracy": "benchmarks.accuracy",
}
