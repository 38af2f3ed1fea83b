"""Does a second Dask worker pay? 48 images on one worker and on two, where the time goes.

The job: 4 fabrics x 2 lights x frames 0:3 x yaws 0,90 = 48 PNG images (96x64), through the
command line (`catalog render-catalog --workers N`, cluster start included), fresh folder
each run, the two engines interleaved for ``--rounds`` rounds (medians), so both see the same
load on the shared machine. Tasks are whole fabrics (4: two per worker, an even deal).
Each worker sets LP_NUM_THREADS and NUMBA_NUM_THREADS to the cores / the workers
(catalog.batch.dask_engine). The drape cache is the bench's own folder, filled by one
untimed run first, so every timed run finds each fabric's settled drape on disk (a worker
keeps its context, shaders and drapes across tasks; a catalog run again settles nothing),
whatever other checkouts left in the user's cache.

The split comes from the job's summary: per phase, the seconds summed over the tasks
(settle = hanging the drape; simulate = the simulation including that settle; render =
draw + read-back; write = encode + write) and the workers' start; ``busy`` = the tasks' seconds / (workers x
wall), how much of the workers' time went into tasks.

Where a task's wall time went, from the kernel (/proc/thread-self/schedstat of the task's
thread, catalog.batch.worker): on a CPU, runnable but waiting for a core (``run_wait``: the
cores were busy, with the other worker or other jobs) and asleep (a lock, llvmpipe's own
threads, I/O). Per run, the load before it and the CPU seconds the rest of the machine used
meanwhile (/proc/stat less the job's own: ``others_cpu_s``; ``free_cores`` = cores - that /
wall); per worker, its tasks' CPU. From each one-worker run, ``bound_2_over_1``: the most two
workers could gain on free cores with the same tasks dealt whole (the best deal's longer
worker, every second outside the tasks unchanged).

    .venv/bin/python -m benchmarks.batch_workers [--rounds 2] [--out F.json]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys
import tempfile
from pathlib import Path

from benchmarks.batch_scaling import _timed
from catalog.core.resources import PROJECT_ROOT

FABRICS = ("lace-fwa", "linen-dense", "net-grey", "voile-white")
LIGHTS = ("D65", "A")
FRAMES = "0:3"
YAWS = "0,90"
IMAGES = len(FABRICS) * len(LIGHTS) * 3 * 2
PHASES = ("load_s", "settle_s", "simulate_s", "render_s", "write_s")
#: The phases that add up to a task's time (the summary's simulate_s includes settle_s).
TASK_PHASES = ("load_s", "simulate_s", "render_s", "write_s")
GOAL = 1.7
RESULT_JSON = "benchmarks/bench_batch_workers.json"


def machine_busy_s() -> float | None:
    """CPU seconds every process on the machine has used since boot (all cores, /proc/stat:
    user, nice, system, irq, softirq, steal); None where there is no /proc/stat."""
    try:
        with open("/proc/stat") as handle:
            fields = handle.readline().split()[1:]
    except OSError:
        return None
    user, nice, system, _idle, _iowait, irq, softirq, steal = (int(v) for v in fields[:8])
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def per_worker(summary: dict) -> list[dict]:
    """Each worker process's tasks: count, wall, CPU (all its threads), and its task thread's
    seconds on a CPU, runnable but waiting for a core (run_wait) and asleep."""
    return [{"pid": p["pid"], "lp_num_threads": p.get("lp_num_threads"), **p["tasks"]}
            for p in summary.get("processes", []) if "tasks" in p]


def best_makespan(costs: list[float], workers: int = 2) -> float:
    """The shortest time ``workers`` take for tasks of ``costs`` seconds dealt whole (every
    deal tried for up to 12 tasks; above, the longest first to the least loaded)."""
    import itertools  # noqa: PLC0415

    costs = sorted(costs, reverse=True)
    if len(costs) > 12:
        loads = [0.0] * workers
        for cost in costs:
            loads[loads.index(min(loads))] += cost
        return max(loads)
    best = math.inf
    for deal in itertools.product(range(workers), repeat=len(costs)):
        loads = [0.0] * workers
        for cost, worker in zip(costs, deal):
            loads[worker] += cost
        best = min(best, max(loads))
    return best


def two_worker_bound(run: dict) -> float | None:
    """From a one-worker run: the most two workers could gain on two free cores with the
    same tasks dealt whole, if every second outside the tasks (start, scheduler, driver)
    stayed as it was and the second worker's first task cost no more than a later one:
    wall / (wall - the tasks' seconds + the best deal's longer worker)."""
    costs = [t["wall_s"] for t in run.get("tasks", [])]
    if not costs:
        return None
    outside = run["wall_s"] - sum(costs)
    return round(run["wall_s"] / (outside + best_makespan(costs, 2)), 3)


def run_once(workers: int, size: str) -> dict:
    """One run of the job; the drape cache is $CATALOG_CACHE_DIR (run() sets the bench's own)."""
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench-batch-workers-") as tmp:
        cmd = [sys.executable, "-m", "catalog", "render-catalog", "--fabrics", ",".join(FABRICS),
               "--lights", ",".join(LIGHTS), "--frames", FRAMES, "--yaw", YAWS, "--size", size,
               "--out", str(Path(tmp) / "out"), "--json", "--workers", str(workers)]
        busy_before = machine_busy_s()
        wall, cpu, result = _timed(cmd)
        busy_after = machine_busy_s()
    summary = json.loads(result.stdout)
    tasks_s = sum(summary.get(k, 0.0) for k in TASK_PHASES)
    workers_split = per_worker(summary)
    # the CPU the rest of the machine took while the job ran (other engineers' jobs): the
    # cores' busy seconds less the job's own
    others = None if busy_before is None else round(busy_after - busy_before - cpu, 3)
    return {"wall_s": round(wall, 3), "cpu_s": round(cpu, 3), "rendered": summary["rendered"],
            "load_average_1min_before": round(load, 2), "others_cpu_s": others,
            "free_cores": None if others is None else
            round(len(os.sched_getaffinity(0)) - others / wall, 2),
            "run_wait_s": round(sum(w["run_wait_s"] for w in workers_split), 3),
            "sleep_s": round(sum(w["sleep_s"] for w in workers_split), 3),
            "workers_split": workers_split,
            "tasks": [{k: t.get(k) for k in ("fabric", "pid", "wall_s", "cpu_s", "run_wait_s",
                                             "sleep_s")} for t in summary.get("tasks", [])],
            "startup_s": summary.get("startup_s", 0.0), "tasks_s": round(tasks_s, 3),
            "busy": round(tasks_s / (workers * wall), 3),
            **{k: summary.get(k, 0.0) for k in PHASES},
            # CPU seconds inside the tasks (the workers' processes, their GL and numba threads
            # included); the rest of cpu_s is start-up, the scheduler and the driver
            "task_cpu_s": summary.get("task_cpu_s", 0.0)}


def run(rounds: int, size: str) -> dict:
    from benchmarks.results import machine_info  # noqa: PLC0415

    runs: dict[int, list[dict]] = {1: [], 2: []}
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench-batch-drapes-") as drapes:
        previous = os.environ.get("CATALOG_CACHE_DIR")
        os.environ["CATALOG_CACHE_DIR"] = drapes
        try:
            warm = run_once(1, size)   # untimed: settles each fabric into the bench's cache
            for _ in range(rounds):
                for workers in runs:
                    runs[workers].append(run_once(workers, size))
        finally:
            if previous is None:
                os.environ.pop("CATALOG_CACHE_DIR", None)
            else:
                os.environ["CATALOG_CACHE_DIR"] = previous
    rows = []
    for workers, worker_runs in runs.items():
        row = {"workers": workers, "runs": worker_runs}
        for key in ("wall_s", "cpu_s", "startup_s", "tasks_s", "busy", "task_cpu_s",
                    "run_wait_s", "sleep_s", "others_cpu_s", "free_cores", *PHASES):
            values = [r[key] for r in worker_runs if r.get(key) is not None]
            row[key] = round(statistics.median(values), 3) if values else None
        median_run = min(worker_runs, key=lambda r: abs(r["wall_s"] - row["wall_s"]))
        row["workers_split"] = median_run["workers_split"]
        row["tasks_split"] = median_run.get("tasks", [])
        row["images_per_s"] = round(IMAGES / row["wall_s"], 3)
        rows.append(row)
    speedup = rows[0]["wall_s"] / rows[1]["wall_s"]   # medians of the interleaved rounds
    bounds = [b for b in map(two_worker_bound, runs[1]) if b is not None]
    return {"job": {"fabrics": list(FABRICS), "lights": list(LIGHTS), "frames": FRAMES,
                    "yaw_deg": YAWS, "size": size, "images": IMAGES},
            "machine": {**machine_info(), "load_average_1min_before": load_before},
            "rounds": rounds, "rows": rows, "cold_cache_run": warm,
            "speedup_2_over_1": round(speedup, 3),
            # two_worker_bound of each one-worker run, median
            "bound_2_over_1": round(statistics.median(bounds), 3) if bounds else None,
            "goal": GOAL,
            "goal_met": speedup >= GOAL}


def markdown_tables(result: dict) -> dict[str, str]:
    job, m = result["job"], result["machine"]
    lines = [f"{job['images']} images ({len(job['fabrics'])} fabrics x {len(job['lights'])} lights "
             f"x frames {job['frames']} x yaws {job['yaw_deg']}, {job['size']} PNG), "
             f"{result['rounds']} interleaved rounds, medians:", "",
             "| workers | wall s | images/s | start s | settle s | simulate s | render s | "
             "write s | tasks s | busy | CPU s | CPU s in tasks | CPU s outside tasks "
             "| task CPU s per worker | run-queue wait s | asleep s | other jobs' CPU s "
             "| free cores |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:"
             "|---:|---:|"]

    def number(value, digits=1):
        return "?" if value is None else f"{value:.{digits}f}"

    for r in result["rows"]:
        split = " / ".join(f"{w['cpu_s']:.1f}" for w in r.get("workers_split", [])) or "?"
        lines.append(f"| {r['workers']} | {r['wall_s']:.1f} | {r['images_per_s']:.2f} | "
                     f"{r['startup_s']:.1f} | {r['settle_s']:.1f} | {r['simulate_s']:.1f} | "
                     f"{r['render_s']:.1f} | {r['write_s']:.1f} | {r['tasks_s']:.1f} | "
                     f"{r['busy']:.2f} | {r['cpu_s']:.1f} | {r.get('task_cpu_s', 0.0):.1f} | "
                     f"{r['cpu_s'] - r.get('task_cpu_s', 0.0):.1f} | {split} | "
                     f"{number(r.get('run_wait_s'))} | {number(r.get('sleep_s'))} | "
                     f"{number(r.get('others_cpu_s'))} | {number(r.get('free_cores'), 2)} |")
    lines += ["", f"Two workers against one: **{result['speedup_2_over_1']:.2f}x** (goal "
              f">= {result['goal']:g}x: {'met' if result['goal_met'] else 'NOT met'}); "
              f"{m['cpu_count']} cores shared with other engineers' jobs, load average "
              f"{m.get('load_average_1min_before', m['load_average_1min']):.1f} before the run and "
              f"{m['load_average_1min']:.1f} after; measured on commit {m.get('commit') or 'unknown'}."]
    one = next((r for r in result["rows"] if r["workers"] == 1), None)
    if one is not None and one.get("tasks_split"):
        tasks = ", ".join(f"{t['fabric']} {t['wall_s']:.1f}" for t in one["tasks_split"])
        lines += ["", f"The one worker's tasks (s, the median run; the first pays the context and "
                      f"the first draws): {tasks}. Dealt whole to two workers on free cores, with "
                      f"the seconds outside the tasks as they are, the best deal gives at most "
                      f"**{number(result.get('bound_2_over_1'), 2)}x**."]
    if "cold_cache_run" in result:
        cold = result["cold_cache_run"]
        lines += ["", f"The untimed first run (one worker, empty drape cache): {cold['wall_s']:.1f} s wall, "
                      f"settle {cold['settle_s']:.1f} s, render {cold['render_s']:.1f} s."]
    return {"batch_workers": "\n".join(lines)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--size", default="96x64")
    parser.add_argument("--out", default=str(PROJECT_ROOT / RESULT_JSON))
    args = parser.parse_args(argv)
    if args.rounds < 1:
        parser.error(f"--rounds: must be at least 1, found {args.rounds}")
    result = run(args.rounds, args.size)
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    write_text_atomic(args.out, json.dumps(result, indent=1) + "\n")
    print(markdown_tables(result)["batch_workers"])
    return 0


if __name__ == "__main__":
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    sys.exit(main())
