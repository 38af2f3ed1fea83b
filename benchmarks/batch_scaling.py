"""render-catalog throughput: one process, Dask workers, and a process per image, on one job.

The job: 5 fabrics x 2 lights x frames 0:5 x 4 yaws = 200 PNG images (96x64 by default).
Each engine renders it from scratch into a fresh folder (engines in turn, ``repeats``
rounds, medians), through the command line as a user
runs it (process start, cluster start and all):

- ``process``: ``catalog render-catalog`` in one process (no Dask);
- ``dask-1``, ``dask-2``: ``--workers 1`` and ``--workers 2`` (LocalCluster on 127.0.0.1);
- ``process-per-image``: ``catalog snapshot`` once per image (each process starts Python,
  makes a context, simulates the cloth up to its frame, renders one image). On a shared
  machine this takes minutes per 100 images, so by default it runs one image per fabric
  and frame (25: lights and yaws in turn; ``--per-image-all`` runs all 200) and scales
  the mean time per image to the 200 (the JSON says how many were run).

For each: wall seconds, images/s, CPU seconds per image (user + system of the process and
its children, which a loaded machine changes less than wall time), and from the batch
summaries the split into simulation, render + read-back and encode + write. Speed-up is
images/s against ``dask-1``. A model on paper (:func:`cost_model`) scales the measured
per-image and per-frame costs to 10 000 fabrics x 4 lights x 48 frames on N nodes.

    .venv/bin/python -m benchmarks.batch_scaling [--quick] [--repeats N] [--per-image-all] [--out F.json]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from catalog.core.resources import PROJECT_ROOT

FABRICS = ("lace-fwa", "linen-dense", "net-grey", "sheer-teal", "voile-white")
LIGHTS = ("D65", "A")
FRAMES = "0:5"
YAWS = "0,30,60,90"
CATALOG = [sys.executable, "-m", "catalog"]
#: The committed result (tools/docs_figures.py fills the docs from it).
RESULT_JSON = "benchmarks/bench_batch.json"


def _timed(cmd: list[str]) -> tuple[float, float, subprocess.CompletedProcess]:
    """(wall s, CPU s of the process and its children, result)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run(cmd, capture_output=True, text=True, cwd=PROJECT_ROOT)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {result.stderr.strip()[-400:]}")
    return wall, cpu, result


def _job_args(size: str, out: Path) -> list[str]:
    return ["render-catalog", "--fabric", ",".join(FABRICS), "--lights", ",".join(LIGHTS),
            "--frames", FRAMES, "--yaw", YAWS, "--size", size, "--out", str(out), "--json"]


def _job_images() -> list[tuple[str, str, int, float]]:
    from catalog.batch.spec import parse_frames, parse_yaws  # noqa: PLC0415

    return [(f, light, frame, yaw) for f in FABRICS for frame in parse_frames(FRAMES)
            for light in LIGHTS for yaw in parse_yaws(YAWS)]


def run_once(extra: list[str], size: str) -> tuple[float, float, dict]:
    """One run of the job from scratch: (wall s, CPU s, the command's JSON summary)."""
    with tempfile.TemporaryDirectory(prefix="bench-batch-") as tmp:
        wall, cpu, result = _timed(CATALOG + _job_args(size, Path(tmp) / "out") + extra)
    return wall, cpu, json.loads(result.stdout)


def engine_row(name: str, runs: list[tuple[float, float, dict]]) -> dict:
    """Median over an engine's runs (the summary of the median-wall run for the split)."""
    walls = [w for w, _, _ in runs]
    summary = runs[walls.index(statistics.median_low(walls))][2]
    images = summary["rendered"]
    wall = statistics.median(walls)
    return {"engine": name, "images": images, "runs": len(runs), "wall_s": round(wall, 3),
            "wall_s_runs": [round(w, 3) for w in walls],
            "images_per_s": round(images / wall, 3),
            "cpu_s_per_image": round(statistics.median(c for _, c, _ in runs) / images, 4),
            "startup_s": summary.get("startup_s", 0.0),
            "settle_s": summary.get("settle_s", 0.0),
            "simulate_s": summary["simulate_s"], "render_s": summary["render_s"],
            "write_s": summary["write_s"], "workers": summary["workers"]}


def per_image_sample(all_images: bool = False) -> list[tuple[str, str, int, float]]:
    """The images a process-per-image run renders: all 200, or one per (fabric, frame),
    lights and yaws taken in turn (25 images; every fabric and frame equally often, as in
    the job, so the mean time per image is the job's mean)."""
    from catalog.batch.spec import parse_frames, parse_yaws  # noqa: PLC0415

    if all_images:
        return _job_images()
    yaws = parse_yaws(YAWS)
    return [(fabric, LIGHTS[k % len(LIGHTS)], frame, yaws[k % len(yaws)])
            for k, (fabric, frame) in enumerate((f, n) for f in FABRICS
                                                for n in parse_frames(FRAMES))]


def run_per_image(size: str, all_images: bool = False) -> dict:
    images = _job_images()
    sample = per_image_sample(all_images)
    walls, cpus, by_frame = [], [], {}
    with tempfile.TemporaryDirectory(prefix="bench-batch-") as tmp:
        for i, (fabric, light, frame, yaw) in enumerate(sample):
            cmd = CATALOG + ["snapshot", "--fabric", fabric, "--light", light, "--frame",
                             str(frame), "--yaw", f"{yaw:g}", "--size", size,
                             "--out", str(Path(tmp) / f"{i}.png")]
            wall, cpu, _ = _timed(cmd)
            walls.append(wall)
            cpus.append(cpu)
            by_frame.setdefault(frame, []).append(wall)
    mean_wall = statistics.fmean(walls)
    total = mean_wall * len(images)
    return {"engine": "process-per-image", "images": len(images), "runs": 1,
            "sampled_images": len(sample), "wall_s": round(total, 3),
            "images_per_s": round(len(images) / total, 3),
            "cpu_s_per_image": round(statistics.fmean(cpus), 4),
            "mean_wall_s_per_image": round(mean_wall, 4),
            "wall_s_by_frame": {str(k): round(statistics.fmean(v), 4)
                                for k, v in sorted(by_frame.items())},
            "startup_s": 0.0, "workers": 1}


def cost_model(per_image_s: float, sim_frame_s: float, process_start_s: float,
               cluster_start_s: float, *, settle_s: float = 0.0, fabrics: int = 10_000,
               lights: int = 4, frames: int = 48, yaws: int = 1, nodes=(1, 4, 16, 64),
               workers_per_node: int = 8) -> dict:
    """Hours for ``fabrics x lights x frames x yaws`` images on N nodes of
    ``workers_per_node`` workers (one per GPU), one fabric per task:

    - batch: a worker's fabric costs ``settle_s`` (the settled drape, frame 0) and
      ``sim_frame_s * (frames - 1)`` (the cloth is simulated once) plus ``per_image_s`` per
      image; fabrics are dealt
      to the N*W workers in whole tasks: ceil(fabrics / (N*W)) rounds, plus cluster start;
    - process per image: every image pays a process start and the simulation up to its
      frame, sum over frames f of (process_start_s + sim_frame_s * f + per_image_s), where
      the process start includes settling the drape (measured on frame-0 snapshots).

    Per-image and per-frame costs are the measured ones; nothing else is assumed (no GPU
    speed-up of the render is put in: on GPUs the render term shrinks and the CPU
    simulation and encoding dominate)."""
    images_per_fabric = lights * frames * yaws
    per_fabric = settle_s + sim_frame_s * max(frames - 1, 0) + per_image_s * images_per_fabric
    per_image_process = (process_start_s + per_image_s) * images_per_fabric \
        + sim_frame_s * lights * yaws * frames * (frames - 1) / 2
    rows = []
    for n in nodes:
        workers = n * workers_per_node
        batch_s = cluster_start_s + math.ceil(fabrics / workers) * per_fabric
        process_s = fabrics * per_image_process / workers
        rows.append({"nodes": n, "workers": workers, "batch_s": round(batch_s, 3),
                     "process_per_image_s": round(process_s, 3),
                     "batch_hours": round(batch_s / 3600, 3),
                     "process_per_image_hours": round(process_s / 3600, 3),
                     "ratio": round(process_s / batch_s, 1)})
    return {"fabrics": fabrics, "lights": lights, "frames": frames, "yaws": yaws,
            "images": fabrics * images_per_fabric, "workers_per_node": workers_per_node,
            "per_image_s": round(per_image_s, 5), "sim_frame_s": round(sim_frame_s, 5),
            "process_start_s": round(process_start_s, 4), "settle_s": round(settle_s, 4),
            "cluster_start_s": round(cluster_start_s, 3),
            "batch_s_per_fabric": round(per_fabric, 3), "rows": rows}


def run(quick: bool = False, size: str = "96x64", repeats: int | None = None,
        per_image_all: bool = False) -> dict:
    repeats = repeats or (1 if quick else 3)
    engines = {"process": [], "dask-1": ["--workers", "1"], "dask-2": ["--workers", "2"]}
    runs: dict[str, list] = {name: [] for name in engines}
    for _ in range(repeats):  # round robin: a change of the machine's load hits every engine
        for name, extra in engines.items():
            runs[name].append(run_once(extra, size))
    rows = [engine_row(name, runs[name]) for name in engines]
    rows.append(run_per_image(size, per_image_all))
    base = next(r for r in rows if r["engine"] == "dask-1")["images_per_s"]
    for row in rows:
        row["speedup_vs_dask_1"] = round(row["images_per_s"] / base, 3)
    process = rows[0]
    sim_frames = len(FABRICS) * (max(range(*map(int, FRAMES.split(":")))))
    per_image_s = (process["render_s"] + process["write_s"]) / process["images"]
    settle_s = process["settle_s"] / len(FABRICS)
    sim_frame_s = (process["simulate_s"] - process["settle_s"]) / sim_frames
    per_image = rows[-1]
    frame0 = per_image["wall_s_by_frame"].get("0", per_image["mean_wall_s_per_image"])
    model = cost_model(per_image_s, sim_frame_s, max(frame0 - per_image_s, 0.0),
                       rows[2]["startup_s"], settle_s=settle_s)
    return {"job": {"fabrics": list(FABRICS), "lights": list(LIGHTS), "frames": FRAMES,
                    "yaw_deg": YAWS, "size": size, "format": "png", "images": 200},
            "machine": {"cpus": len(os.sched_getaffinity(0)),
                        "load_average_1min": round(os.getloadavg()[0], 2),
                        "note": "shared by several engineers' jobs; run with nice"},
            "rows": rows, "model": model}


def markdown_tables(result: dict) -> dict[str, str]:
    job = result["job"]
    lines = [f"{job['images']} images ({len(job['fabrics'])} fabrics x {len(job['lights'])} "
             f"lights x frames {job['frames']} x yaws {job['yaw_deg']}, {job['size']} PNG), "
             f"{result['machine']['cpus']} CPUs shared (load {result['machine']['load_average_1min']}):",
             "", "| engine | wall s | images/s | speed-up vs 1 Dask worker | CPU s/image "
             "| settle s | simulate s | render s | write s | start s |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in result["rows"]:
        name = row["engine"]
        if name == "process-per-image" and row["sampled_images"] < row["images"]:
            name += f" ({row['sampled_images']} run, scaled)"
        lines.append(f"| {name} | {row['wall_s']:.1f} | {row['images_per_s']:.2f} | "
                     f"{row['speedup_vs_dask_1']:.2f} | {row['cpu_s_per_image']:.3f} | "
                     f"{row.get('settle_s', float('nan')):.2f} | "
                     f"{row.get('simulate_s', float('nan')):.2f} | "
                     f"{row.get('render_s', float('nan')):.2f} | "
                     f"{row.get('write_s', float('nan')):.2f} | {row['startup_s']:.1f} |")
    model = result["model"]
    mlines = [f"{model['images']:,} images ({model['fabrics']:,} fabrics x {model['lights']} "
              f"lights x {model['frames']} frames), {model['workers_per_node']} workers per node, "
              f"from the measured {model['per_image_s'] * 1000:.1f} ms per image, "
              f"{model['sim_frame_s'] * 1000:.0f} ms per simulated frame, "
              f"{model.get('settle_s', 0.0):.2f} s to settle a fabric's drape, "
              f"{model['process_start_s']:.2f} s per process start:",
              "", "| nodes | workers | batch (h) | process per image (h) | ratio |",
              "|---:|---:|---:|---:|---:|"]
    for row in model["rows"]:
        mlines.append(f"| {row['nodes']} | {row['workers']} | {row['batch_hours']:.2f} | "
                      f"{row['process_per_image_hours']:.1f} | {row['ratio']:.0f} |")
    return {"batch_engines": "\n".join(lines), "batch_model": "\n".join(mlines)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one run per engine")
    parser.add_argument("--size", default="96x64")
    parser.add_argument("--repeats", type=int, default=None,
                        help="runs per engine, median (default 3; --quick 1)")
    parser.add_argument("--per-image-all", action="store_true",
                        help="a process for each of the 200 images, not one per fabric and frame")
    parser.add_argument("--out", default=str(PROJECT_ROOT / "benchmarks" / "bench_batch.json"))
    args = parser.parse_args(argv)
    result = run(args.quick, args.size, args.repeats, args.per_image_all)
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    write_text_atomic(args.out, json.dumps(result, indent=1) + "\n")
    for table in markdown_tables(result).values():
        print(table + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
