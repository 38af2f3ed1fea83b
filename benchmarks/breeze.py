"""The viewer's default breeze on the hung curtain: how far the hem moves and rises
(docs/pattern.md, "The breeze").

    .venv/bin/python -m benchmarks.breeze [--grid 96x56] [--seconds 5] [--json OUT.json]

From the settled drape (catalog.cloth.drape), each case runs ``seconds`` of 1/60 s frames
with the preset's wind (gusts 0.6, the default) and samples the hem every 10 frames
(catalog.cloth.drape.hem_displacement_m against the settled hem): the mean over samples of
the hem's mean and largest horizontal displacement, the largest displacement of any sample,
and the largest rise. tests/test_drape.py holds the bounds (the voile's rise under 10 cm at
the default wind, over 30 cm at 2 m/s).
"""

from __future__ import annotations

import sys

from catalog.core.constants import FRAME_DT_S
from catalog.core.resources import FABRIC_DIR

RESULT_JSON = "benchmarks/breeze.json"
#: (fabric preset, wind m/s): the lightest catalog cloth at the default and at the old
#: 1.5 m/s, a heavier one at the default.
CASES = (("voile-white", None), ("jacquard-white", None), ("voile-white", 1.5))


def run(grid=(96, 56), seconds: float = 5.0, backend: str = "numpy") -> dict:
    from catalog.cloth.drape import (drape_params, fullness_of, hem_displacement_m,
                                     settled_simulation, settled_state)
    from catalog.presets import load_preset
    from catalog.viewer.settings import DEFAULT_WIND_M_S

    rows = []
    frames = int(round(seconds / FRAME_DT_S))
    for name, wind in CASES:
        wind = DEFAULT_WIND_M_S if wind is None else wind
        preset = load_preset(FABRIC_DIR / f"{name}.toml")
        params = drape_params(preset, grid=tuple(grid), wind_speed_m_s=wind)
        rest = settled_state(params).positions_m.copy()
        simulation = settled_simulation(params, backend=backend)
        samples = []
        for _ in range(frames // 10):
            simulation.run(10, FRAME_DT_S)
            samples.append(hem_displacement_m(rest, simulation.positions()))
        rows.append({"fabric": name, "wind_m_s": wind, "fullness": fullness_of(preset),
                     "areal_density_kg_m2": float(params.areal_density_kg_m2),
                     "mean_m": sum(s["mean_m"] for s in samples) / len(samples),
                     "mean_of_max_m": sum(s["max_m"] for s in samples) / len(samples),
                     "max_m": max(s["max_m"] for s in samples),
                     "rise_m": max(s["rise_m"] for s in samples)})
    return {"grid": list(grid), "seconds": seconds, "frame_s": FRAME_DT_S, "backend": backend,
            "rows": rows}


def markdown_tables(result: dict) -> dict[str, str]:
    """``breeze``: per case the hem's mean, mean largest and largest displacement and rise."""
    lines = ["| fabric (kg/m^2, fullness) | wind m/s | hem moves, mean (m) | largest across the hem, mean (m) | "
             "largest (m) | largest rise (m) |", "|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['fabric']} ({r['areal_density_kg_m2']:.2g}, {r['fullness']:g}) | "
                     f"{r['wind_m_s']:g} | {r['mean_m']:.2f} | "
                     f"{r['mean_of_max_m']:.2f} | {r['max_m']:.2f} | {r['rise_m']:.3f} |")
    w, h = result["grid"]
    lines.append(f"\n({w}x{h} particles, {result['seconds']:g} s of 1/60 s frames from the settled "
                 f"drape, {result['backend']} backend, hem sampled every 10 frames.)")
    return {"breeze": "\n".join(lines)}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415

    def options(parser) -> None:
        parser.add_argument("--grid", default="96x56")
        parser.add_argument("--seconds", type=float, default=5.0)
        parser.add_argument("--backend", default="numpy")

    def result(args) -> dict:
        from catalog.render.snapshot import parse_size  # noqa: PLC0415

        return run(parse_size(args.grid), args.seconds, args.backend)

    return study_main(sys.modules[__name__], argv, result, options)


if __name__ == "__main__":
    sys.exit(main())
