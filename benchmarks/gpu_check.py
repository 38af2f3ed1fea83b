"""The GPU check: the viewer's frame without its window (benchmarks.headless_frames) at
720p, 1080p and 4K, with the compute (gpu) and the numba (cpu) cloth on a 128x128 curtain,
moving (wind 2 m/s) and static (wind 0: the settled drape falls asleep, docs/cloth.md
"Sleep"), in one bounded run writing one JSON. ``tools/gpu_check.sh`` runs it on a machine
with an NVIDIA GPU (docs/gpu.md, "The GPU check"); here it dry-runs on llvmpipe, tiny.

    python -m benchmarks.gpu_check [--json-out FILE] [--budget-s 240] [--tiny]

``--tiny``: the dry run (window sizes divided by 8, a 16x16 curtain, few frames): it checks
that every case runs, not what it costs. Cases run in order until ``--budget-s`` is spent;
those left are listed under ``skipped`` with the reason, never silently dropped.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

#: (label, window size) of the goals: >= 120 fps at 1080p, >= 60 fps at 4K, gpu cloth 128x128
SIZES = (("720p", (1280, 720)), ("1080p", (1920, 1080)), ("4K", (3840, 2160)))
GRID = (128, 128)
BACKENDS = ("gpu", "cpu")
#: (label, wind m/s, warm-up frames): a static curtain sleeps 0.5 s of simulated time after
#: its settled start (the gpu cloth checks every 30 frames: asleep by frame 60), so its
#: warm-up covers that and its timed frames are asleep
MOTIONS = (("moving", 2.0, 10), ("static", 0.0, 70))
GOALS_FPS = {"1080p": 120.0, "4K": 60.0}
RESULT_JSONS = {"dry_run": "benchmarks/gpu_check_dry_run.json"}


def cases(tiny: bool) -> list[dict]:
    out = []
    for label, (w, h) in SIZES:
        size = (max(2, w // 8), max(2, h // 8)) if tiny else (w, h)
        for backend in BACKENDS:
            for motion, wind, warmup in MOTIONS:
                out.append({"label": label, "size": size, "grid": (16, 16) if tiny else GRID,
                            "backend": backend, "motion": motion, "wind_m_s": wind,
                            "warmup": warmup, "frames": 5 if tiny else 40})
    return out


def run(budget_s: float, tiny: bool) -> dict:
    from benchmarks.headless_frames import machine, run_case  # noqa: PLC0415
    from benchmarks.results import source_commit  # noqa: PLC0415
    from catalog.gl.context import create_headless_context  # noqa: PLC0415

    started = time.perf_counter()
    ctx = create_headless_context()
    rows, skipped = [], []
    for case in cases(tiny):
        spent = time.perf_counter() - started
        if spent > budget_s:
            skipped.append({**case, "reason": f"time budget ({budget_s:g} s) spent"})
            continue
        if case["backend"] == "cpu":
            try:
                import numba  # noqa: F401, PLC0415
            except ImportError as exc:
                skipped.append({**case, "reason": f"numba unavailable: {exc}"})
                continue
        t0 = time.perf_counter()
        try:
            row = run_case(ctx, case["size"], case["grid"], case["backend"], case["frames"],
                           case["warmup"], "lace-fwa", "D65", case["wind_m_s"],
                           antialiasing="fxaa")
        except Exception as exc:  # noqa: BLE001 - one failed case is reported, not fatal
            skipped.append({**case, "reason": f"{type(exc).__name__}: {exc}"[:300]})
            continue
        row.update(label=case["label"], motion=case["motion"], wind_m_s=case["wind_m_s"],
                   case_s=round(time.perf_counter() - t0, 2))
        goal = GOALS_FPS.get(case["label"]) if case["backend"] == "gpu" else None
        if goal is not None and not tiny:
            row["goal_fps"] = goal
            row["goal_met"] = bool(row["fps"] and row["fps"] >= goal)
        rows.append(row)
        print(f"{case['label']:>5} {case['backend']} {case['motion']:>7}: {row['total_ms']:8.2f} ms "
              f"({row['fps']} fps; simulation {row['simulation_ms']:.2f}, shading "
              f"{row['shading_ms']:.2f}) in {row['case_s']} s", file=sys.stderr, flush=True)
    return {"benchmark": "gpu_check", "tiny": tiny, "machine": {**machine(ctx),
            "commit": source_commit()}, "budget_s": budget_s,
            "seconds": round(time.perf_counter() - started, 1), "rows": rows,
            "skipped": skipped}


def markdown_table(result: dict) -> str:
    lines = ["| window | cloth | curtain | total ms | fps | simulation ms | shading ms | goal |",
             "|---|---|---|---|---|---|---|---|"]
    for row in result["rows"]:
        w, h = row["size"]
        goal = "" if "goal_fps" not in row else \
            f"{'met' if row['goal_met'] else 'NOT met'} (>= {row['goal_fps']:g} fps)"
        lines.append(f"| {row['label']} ({w}x{h}) | {row['backend']} {row['grid'][0]}x"
                     f"{row['grid'][1]} | {row['motion']} | {row['total_ms']:.2f} | {row['fps']} | "
                     f"{row['simulation_ms']:.2f} | {row['shading_ms']:.2f} | {goal} |")
    for case in result["skipped"]:
        lines.append(f"| {case['label']} | {case['backend']} | {case['motion']} | skipped: "
                     f"{case['reason']} | | | | |")
    m = result["machine"]
    lines.append("")
    kind = ("dry run (tiny sizes: it checks that the cases run, not their cost)"
            if result["tiny"] else "full sizes")
    lines.append(f"{m['renderer']}; {kind}; {len(result['rows'])} cases in "
                 f"{result['seconds']:g} s; medians after warm-up; measured on commit "
                 f"{m.get('commit') or 'unknown'}.")
    return "\n".join(lines)


def markdown_tables(results: dict) -> dict[str, str]:
    """``gpu_check_dry_run``: the llvmpipe dry run; ``gpu_check`` once a GPU run is added."""
    return {f"gpu_check_{key}" if key != "gpu" else "gpu_check": markdown_table(result)
            for key, result in results.items()}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.gpu_check",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--json-out", type=Path, default=Path("gpu_check.json"))
    parser.add_argument("--budget-s", type=float, default=240.0,
                        help="stop starting cases after this many seconds (default 240)")
    parser.add_argument("--tiny", action="store_true", help="the dry run: tiny sizes")
    args = parser.parse_args(argv)
    if not args.budget_s > 0:
        parser.error(f"--budget-s: must be > 0, found {args.budget_s:g}")
    result = run(args.budget_s, args.tiny)
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    write_text_atomic(args.json_out, json.dumps(result, indent=1) + "\n")
    print(markdown_table(result))
    print(f"wrote {args.json_out}")
    return 0 if result["rows"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
