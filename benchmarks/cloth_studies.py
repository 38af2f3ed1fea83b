"""Two studies of the cloth solver that docs/cloth.md quotes: numba's compile and cache-load
time, and the resting strain of stiff XPBD springs.

    .venv/bin/python -m benchmarks.cloth_studies [--seconds 6] [--grid 64x64] [--json OUT.json]

1. ``catalog.cloth.simulation.warm_up_numba()`` in two fresh processes sharing one empty
   numba cache folder (NUMBA_CACHE_DIR): the first compiles the cpu backend's kernels, the
   second loads them from the cache (wall seconds each, as warm_up_numba reports them).
2. A curtain at 1e6 N/m hangs without wind for ``seconds`` of 1/60 s frames from its rest
   pose, closed, 80 % closed and half open (the rings' span over the rest width); the largest
   spring strain at the end (catalog.cloth.simulation.max_spring_strain), cpu backend.
3. A gale that flies the curtain like a flag: 128x128, 3 m/s mean wind with gusts to 5 m/s
   (gust strength 2/3), 1/60 s frames for ``gale_seconds``: the largest spring strain seen
   at the end of any frame (the final strain-limit sweeps do not converge in a fluttering hem).
4. How the backends agree after 1 s (60 frames of 1/60 s, 12x16): cpu against numpy, gpu
   (GLSL compute, float32) against cpu, on a flat curtain without wind and with gusts and
   pleats (opening 0.7, 1.5 m/s); and how far the float64 run itself moves when its start is
   nudged by 1e-7 m (the cloth's own sensitivity), largest and RMS distance.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

from catalog.core.constants import FRAME_DT_S

RESULT_JSON = "benchmarks/cloth_studies.json"
OPENINGS = (1.0, 0.8, 0.5)
STIFFNESS_N_M = 1e6


def numba_times() -> dict:
    code = "from catalog.cloth.simulation import warm_up_numba; print(warm_up_numba())"
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        seconds = [float(subprocess.run([sys.executable, "-c", code], env=env, check=True,
                                        capture_output=True, text=True).stdout.split()[-1])
                   for _ in range(2)]
    return {"compile_s": seconds[0], "cache_load_s": seconds[1]}


def strain_rows(grid=(64, 64), seconds: float = 6.0, backend: str = "cpu") -> list[dict]:
    from catalog.cloth.params import ClothParams
    from catalog.cloth.simulation import ClothSimulation, max_spring_strain

    rows = []
    for opening in OPENINGS:
        params = ClothParams(grid_w=grid[0], grid_h=grid[1], stretch_stiffness_n_m=STIFFNESS_N_M,
                             opening=opening)
        simulation = ClothSimulation(params, backend)
        simulation.run(int(round(seconds / FRAME_DT_S)), FRAME_DT_S)
        rows.append({"opening": opening, "max_strain": max_spring_strain(simulation.positions(), params),
                     "final_strain_limit": params.max_stretch})
    return rows


GALE = {"grid": (128, 128), "wind_speed_m_s": 3.0, "gust_strength": 2.0 / 3.0}


def gale_strain(seconds: float = 5.0, backend: str = "cpu") -> dict:
    from catalog.cloth.params import ClothParams
    from catalog.cloth.simulation import ClothSimulation

    params = ClothParams(grid_w=GALE["grid"][0], grid_h=GALE["grid"][1],
                         wind_speed_m_s=GALE["wind_speed_m_s"], gust_strength=GALE["gust_strength"])
    simulation = ClothSimulation(params, backend)
    simulation.monitor_every = 1
    simulation.run(int(round(seconds / FRAME_DT_S)), FRAME_DT_S)
    return {"grid": list(GALE["grid"]), "wind_speed_m_s": GALE["wind_speed_m_s"],
            "gust_strength": GALE["gust_strength"], "seconds": seconds, "backend": backend,
            "max_strain_seen": simulation.state.max_stretch_seen,
            "strain_limit": params.max_stretch}


AGREEMENT_CASES = {"flat": {"opening": 1.0}, "gusts and pleats": {"opening": 0.7, "wind_speed_m_s": 1.5}}


def agreement_rows(frames: int = 60) -> list[dict]:
    import numpy as np

    from catalog.cloth.params import ClothParams
    from catalog.cloth.simulation import ClothSimulation

    def distance(a, b) -> dict:
        d = np.linalg.norm(a.positions() - b.positions(), axis=-1)
        return {"max_m": float(np.abs(a.positions() - b.positions()).max()),
                "rms_m": float(np.sqrt(np.mean(d ** 2)))}

    try:
        from catalog.gl.context import create_headless_context
        ctx = create_headless_context()
    except Exception as exc:  # noqa: BLE001 - no GL: the gpu rows say why
        ctx, why = None, str(exc)
    rows = []
    for case, changes in AGREEMENT_CASES.items():
        params = ClothParams(grid_w=12, grid_h=16, **changes)
        sims = {b: ClothSimulation(params, b) for b in ("numpy", "cpu")}
        nudged = ClothSimulation(params, "numpy")
        nudged.state.positions_m[1:] += 1e-7
        if ctx is not None:
            sims["gpu"] = ClothSimulation(params, "gpu", ctx=ctx)
        for sim in [*sims.values(), nudged]:
            sim.run(frames, FRAME_DT_S)
        rows.append({"case": case, **changes, "frames": frames,
                     "cpu_vs_numpy": distance(sims["cpu"], sims["numpy"]),
                     "gpu_vs_cpu": distance(sims["gpu"], sims["cpu"]) if "gpu" in sims else why,
                     "nudged_1e-7_vs_numpy": distance(nudged, sims["numpy"])})
    return rows


def markdown_tables(result: dict) -> dict[str, str]:
    """``cloth_numba_times``, ``cloth_resting_strain``, ``cloth_gale_strain`` and
    ``cloth_backend_agreement``."""
    n = result["numba"]
    times = ("| numba, cpu backend kernels | seconds |\n|---|---|\n"
             f"| first run on a machine (compile, empty cache) | {n['compile_s']:.1f} |\n"
             f"| later runs (load from the cache) | {n['cache_load_s']:.1f} |")
    s = result["strain"]
    w, h = s["grid"]
    lines = [f"| rings' span / rest width | largest spring strain after {s['seconds']:g} s |",
             "|---|---|"]
    for r in s["rows"]:
        lines.append(f"| {r['opening']:g} | {100 * r['max_strain']:.2g} % |")
    lines.append(f"\n({w}x{h}, {s['stiffness_n_m']:.0e} N/m, no wind, 1/60 s frames, "
                 f"{s['backend']} backend.)")
    g = result["gale"]
    gale = (f"In a gale that flies the curtain like a flag ({g['wind_speed_m_s']:g} m/s mean, gusts to "
            f"{g['wind_speed_m_s'] * (1 + g['gust_strength']):.0f} m/s, {g['grid'][0]}x{g['grid'][1]}, "
            f"1/60 s frames, {g['seconds']:g} s, {g['backend']} backend) the largest strain seen was "
            f"{100 * g['max_strain_seen']:.1f} % (strain limit {100 * g['strain_limit']:g} %).")
    agree = ["| after 1 s, 12x16 | cpu vs numpy, max | gpu vs cpu, max / RMS | "
             "numpy nudged by 1e-7 m vs numpy, max / RMS |", "|---|---|---|---|"]
    for r in result["agreement"]:
        g = r["gpu_vs_cpu"]
        gpu = f"{g['max_m']:.2g} m / {g['rms_m']:.2g} m" if isinstance(g, dict) else f"unavailable ({g})"
        n = r["nudged_1e-7_vs_numpy"]
        agree.append(f"| {r['case']} | {r['cpu_vs_numpy']['max_m']:.2g} m | {gpu} | "
                     f"{n['max_m']:.2g} m / {n['rms_m']:.2g} m |")
    return {"cloth_numba_times": times, "cloth_resting_strain": "\n".join(lines),
            "cloth_gale_strain": gale, "cloth_backend_agreement": "\n".join(agree)}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415

    def options(parser) -> None:
        parser.add_argument("--grid", default="64x64")
        parser.add_argument("--seconds", type=float, default=6.0)
        parser.add_argument("--gale-seconds", type=float, default=5.0)
        parser.add_argument("--backend", default="cpu")

    def result(args) -> dict:
        from catalog.render.snapshot import parse_size  # noqa: PLC0415

        grid = parse_size(args.grid)
        return {"numba": numba_times(),
                "strain": {"grid": list(grid), "seconds": args.seconds, "backend": args.backend,
                           "stiffness_n_m": STIFFNESS_N_M,
                           "rows": strain_rows(grid, args.seconds, args.backend)},
                "gale": gale_strain(args.gale_seconds, args.backend),
                "agreement": agreement_rows()}

    return study_main(sys.modules[__name__], argv, result, options)


if __name__ == "__main__":
    sys.exit(main())
