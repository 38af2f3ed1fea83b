"""Simulation accuracy against cost: substeps and backend against a small-step reference.

A curtain in a gusty 1.5 m/s breeze is run for a fixed number of 1/60 s frames with each
number of substeps per frame (``max_substep_s`` = frame / n) and backend; the reference
is the same run with REFERENCE_SUBSTEPS substeps on the float64 ``cpu`` backend (the
numba port of the numpy reference; the two agree to rounding, which the ``numpy`` row at
the default substeps shows), or on ``numpy`` on a smaller grid where numba cannot run. Deviation: particle distance to the reference at the same
frame, RMS over every particle and frame, and the worst one; beside it frames per second
of simulation alone, median of repeated runs (numba's compilation is done before timing;
the numpy reference backend runs once). The ``gpu`` backend is
included when it can be built on this machine.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np

from catalog.core.constants import FRAME_DT_S
REFERENCE_SUBSTEPS = 100
SUBSTEPS = (1, 2, 5, 10, 20, 40)
QUICK_SUBSTEPS = (2, 10, 20)
WIND_M_S = 1.5


def params_for(grid: tuple[int, int], substeps: int):
    from catalog.cloth import ClothParams  # noqa: PLC0415

    return ClothParams(grid_w=grid[0], grid_h=grid[1], wind_speed_m_s=WIND_M_S,
                       max_substep_s=FRAME_DT_S / substeps)


def trajectory(grid, substeps: int, backend: str, frames: int, ctx=None, repeats: int = 1):
    """(positions per frame (F, H, W, 3), seconds of stepping, finite, substeps used).

    The run is repeated ``repeats`` times from rest (the same trajectory each time: the
    gusts are a function of time and position) and the median stepping time is returned.
    """
    times = []
    for _ in range(max(1, repeats)):
        positions, seconds, finite, used = _one_trajectory(grid, substeps, backend, frames, ctx)
        times.append(seconds)
    return positions, statistics.median(times), finite, used


def _one_trajectory(grid, substeps: int, backend: str, frames: int, ctx=None):
    from catalog.cloth import ClothSimulation  # noqa: PLC0415

    options = {"ctx": ctx} if backend == "gpu" else {}
    sim = ClothSimulation(params_for(grid, substeps), backend=backend, **options)
    positions = []
    seconds = 0.0
    for _ in range(frames):
        start = time.perf_counter()
        sim.step(FRAME_DT_S)
        if backend == "gpu":
            sim.positions()  # wait for the GPU (a download) inside the timed part
        seconds += time.perf_counter() - start
        positions.append(np.array(sim.positions(), dtype=np.float64))
    return np.stack(positions), seconds, sim.finite, sim.last_substeps


def deviation(run: np.ndarray, reference: np.ndarray) -> tuple[float, float]:
    distance = np.linalg.norm(run - reference, axis=-1)
    return float(np.sqrt(np.mean(distance ** 2))), float(np.max(distance))


def warm_up(backend: str, ctx=None) -> bool:
    """Compile a backend (numba JIT, shaders) on a tiny grid; False if it cannot be built."""
    try:
        trajectory((4, 4), 2, backend, 2, ctx)
        return True
    except Exception:  # noqa: BLE001 - an unavailable backend is reported, not fatal
        return False


def fastest_backend() -> str:
    """``cpu`` (numba) when it builds and runs here, else the ``numpy`` reference."""
    return "cpu" if warm_up("cpu") else "numpy"


def run(quick: bool = False, ctx=None) -> dict:
    available = {b: warm_up(b, ctx if b == "gpu" else None) for b in ("cpu", "numpy", "gpu")}
    reference_backend = "cpu" if available["cpu"] else "numpy"
    small = quick or reference_backend == "numpy"  # the numpy reference is 50x slower
    grid = (12, 16) if small else (24, 32)
    frames = 20 if small else 60
    substeps_list = QUICK_SUBSTEPS if quick else SUBSTEPS
    repeats = 3 if quick else 5
    reference, ref_seconds, ref_finite, _ = trajectory(grid, REFERENCE_SUBSTEPS,
                                                       reference_backend, frames)
    rows = [{"backend": reference_backend, "substeps": REFERENCE_SUBSTEPS, "reference": True,
             "rms_deviation_m": 0.0, "max_deviation_m": 0.0, "finite": ref_finite,
             "frames_per_second": frames / ref_seconds, "seconds": ref_seconds}]
    cases = [(reference_backend, n) for n in substeps_list]
    if reference_backend == "cpu":
        cases.append(("numpy", 10))
    if available["gpu"]:
        cases += [("gpu", n) for n in substeps_list]
    for backend, n in cases:
        if not available[backend]:
            continue
        positions, seconds, finite, used = trajectory(grid, n, backend, frames, ctx,
                                                      1 if backend == "numpy" else repeats)
        rms, worst = deviation(positions, reference)
        rows.append({"backend": backend, "substeps": used, "reference": False,
                     "rms_deviation_m": rms, "max_deviation_m": worst, "finite": finite,
                     "frames_per_second": frames / seconds, "seconds": seconds})
    from catalog.cloth import ClothParams  # noqa: PLC0415

    default = ClothParams().substeps_for(FRAME_DT_S)  # the simulator's own choice
    return {"rows": rows, "summary": summarise(rows, default),
            "settings": {"grid": list(grid), "frames": frames, "frame_dt_s": FRAME_DT_S,
                         "reference_backend": reference_backend, "timing_repeats": repeats,
                         "wind_m_s": WIND_M_S, "reference_substeps": REFERENCE_SUBSTEPS,
                         "backends_available": available, "default_substeps": default}}


def summarise(rows: list[dict], default_substeps: int) -> dict:
    runs = [r for r in rows if not r["reference"]]
    at_default = [r for r in runs if r["substeps"] == default_substeps]
    return {"all_finite": all(r["finite"] for r in rows),
            "default_substeps": default_substeps,
            "at_default": {r["backend"]: {"rms_deviation_m": r["rms_deviation_m"],
                                          "frames_per_second": r["frames_per_second"]}
                           for r in at_default},
            "worst_rms_deviation_m": max((r["rms_deviation_m"] for r in runs), default=math.nan)}


def plot(result: dict, folder) -> list:
    from pathlib import Path  # noqa: PLC0415

    from benchmarks.plots import pyplot, save_figure  # noqa: PLC0415

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for backend in ("cpu", "numpy", "gpu"):
        mine = [r for r in result["rows"] if r["backend"] == backend and not r["reference"]]
        if not mine:
            continue
        ax.scatter([r["frames_per_second"] for r in mine],
                   [max(r["rms_deviation_m"], 1e-9) for r in mine], label=backend)
        for r in mine:
            ax.annotate(str(r["substeps"]), (r["frames_per_second"], max(r["rms_deviation_m"], 1e-9)),
                        fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("simulated frames per second (1/60 s frames)")
    ax.set_ylabel(f"RMS deviation from {REFERENCE_SUBSTEPS}-substep reference, m")
    g = result["settings"]["grid"]
    ax.set_title(f"Cloth {g[0]}x{g[1]}: substeps (labels) and backend against accuracy")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return [save_figure(fig, Path(folder) / "bench_cloth.png")]


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py);
#: `python -m benchmarks.cloth` writes it (the same section as `catalog bench --sections cloth`).
RESULT_JSON = "benchmarks/bench_cloth_substeps.json"


def markdown_tables(result: dict) -> dict[str, str]:
    """``bench_cloth`` (every backend and substep count, docs/bench.md) and
    ``bench_cloth_brief`` (the default's figures, BENCHMARKS.md)."""
    from benchmarks.results import fmt  # noqa: PLC0415

    st, summary = result["settings"], result["summary"]
    default = st["default_substeps"]
    lines = ["| backend | substeps per frame | RMS deviation cm | max deviation cm | frames/s |",
             "|---|---|---|---|---|"]
    for row in result["rows"]:
        name = row["backend"] + (" (reference)" if row.get("reference") else "")
        cells = [name, str(row["substeps"]), fmt(100 * row["rms_deviation_m"]),
                 fmt(100 * row["max_deviation_m"]), f"{row['frames_per_second']:.0f}"]
        if row["backend"] == st["reference_backend"] and row["substeps"] == default \
                and not row.get("reference"):
            cells = [f"**{c}**" for c in cells]
            cells[0] = f"**{name} (default)**"
        lines.append("| " + " | ".join(cells) + " |")
    ref = st["reference_backend"]
    sweep = [r for r in result["rows"] if r["backend"] == ref and not r.get("reference")
             and r["rms_deviation_m"] > 0]
    slope = float(np.polyfit(np.log([r["substeps"] for r in sweep]),
                             np.log([r["rms_deviation_m"] for r in sweep]), 1)[0])
    by = {(r["backend"], r["substeps"]): r for r in result["rows"] if not r.get("reference")}
    twins = {}
    for (backend, substeps), row in by.items():
        if backend != ref and (ref, substeps) in by:
            diff = abs(row["rms_deviation_m"] - by[(ref, substeps)]["rms_deviation_m"])
            twins[backend] = max(twins.get(backend, 0.0), diff)
    at = summary["at_default"][ref]
    head = (f"A {st['grid'][0]}x{st['grid'][1]} curtain in a gusty {fmt(st['wind_m_s'])} m/s "
            f"breeze for {st['frames']} frames of {fmt(st['frame_dt_s'])} s; deviation from the "
            f"same run with {st['reference_substeps']} substeps on the {ref} backend (float64), "
            f"RMS over particles and frames and the worst; frames per second of simulation "
            f"alone (median of {st['timing_repeats']} runs).")
    text = (f"The error falls as substeps^{slope:.2f} (a fit over the {ref} rows); the default "
            f"({default} substeps) is {fmt(100 * at['rms_deviation_m'])} cm RMS from the converged "
            f"motion at {at['frames_per_second']:.0f} frames/s on the {ref} backend. "
            + " ".join(f"The {b} backend's RMS deviation is the {ref} one's to within "
                       f"{fmt(1e3 * d)} mm at every substep count." for b, d in twins.items())
            + f" All values finite: {summary['all_finite']}.")
    return {"bench_cloth": head + "\n\n" + "\n".join(lines) + "\n\n" + text,
            "bench_cloth_brief": text}


if __name__ == "__main__":
    from benchmarks.results import section_main  # noqa: PLC0415

    raise SystemExit(section_main("cloth"))
