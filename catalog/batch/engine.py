"""Running a job: plan what is left, send one task per fabric to an engine, record results.

Engines:

- ``process`` (default, and whenever Dask is not asked for): this process renders every
  fabric in turn with one GL context and one renderer.
- ``dask``: Dask distributed. ``workers=N`` starts a ``LocalCluster`` of N worker processes
  (one thread each) on the loopback address, no dashboard; ``scheduler=ADDRESS`` uses an
  existing cluster (dask-jobqueue, dask-kubernetes, a cloud provider: docs/batch.md). A
  worker plugin (:class:`RendererPlugin`) sets ``LP_NUM_THREADS`` for software GL, picks
  the worker's EGL device, and keeps one context and renderer per worker process.

A task that raises is retried (``retries``); a fabric that still fails, or fails with a
user-fixable error (a broken preset), is recorded under ``failed`` in the manifest and the
report, and the other fabrics go on.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

from catalog.batch.manifest import Manifest
from catalog.batch.spec import JobSpec
from catalog.core.errors import CatalogError, EnvironmentFailure, InputError

#: Seconds between manifest rewrites during a run (the journal holds what comes between).
MANIFEST_EVERY_S = 60.0
_TEXT_PORT = "tcp://HOST:PORT"


def dask_available() -> bool:
    try:
        import distributed  # noqa: F401, PLC0415
    except ImportError:
        return False
    return True


def check_engine(workers: int | None, scheduler: str | None) -> None:
    """Refuse impossible engine options (one line naming the option)."""
    if workers is not None and scheduler is not None:
        raise InputError("give --workers (a local cluster) or --scheduler (an existing one), "
                         "not both", field="--workers")
    if workers is not None and not (1 <= int(workers) <= 1024):
        raise InputError(f"{workers} must be a whole number in 1..1024", field="--workers")
    if scheduler is not None:
        address = str(scheduler).strip()
        rest = address.split("://", 1)[-1]
        host, _, port = rest.rpartition(":")
        if not address or not host or not port.isdigit():
            raise InputError(f"{scheduler!r} is not a scheduler address ({_TEXT_PORT})",
                             field="--scheduler")
    if (workers is not None or scheduler is not None) and not dask_available():
        option = "--workers" if workers is not None else "--scheduler"
        from catalog.core.extras import missing_message  # noqa: PLC0415

        raise EnvironmentFailure(missing_message("distributed", option))


def _run_process(tasks, retries, on_image, on_result) -> dict:
    from catalog.batch.worker import process_pool, render_fabric  # noqa: PLC0415

    pool = process_pool()
    for task in tasks:
        for attempt in range(retries + 1):
            try:
                result = render_fabric(task, pool, on_image)
                break
            except Exception as exc:  # noqa: BLE001 - as Dask would: retry, then report
                if attempt == retries:
                    reason = " ".join(str(exc).split()) or type(exc).__name__
                    result = {"fabric": task.fabric, "ok": False, "records": [],
                              "error": f"{type(exc).__name__}: {reason} "
                                       f"(after {retries} retries)"}
        on_result(task, result)
    return {"engine": "process", "workers": 1, "startup_s": 0.0}


# ---------------------------------------------------------------------- the job
def render_catalog(spec: JobSpec, *, workers: int | None = None, scheduler: str | None = None,
                   retries: int = 2, lp_threads: int | None = None,
                   progress: bool = False) -> dict:
    """Render every image of ``spec`` not done yet; returns the run's summary (also stored
    in the manifest). ``workers``/``scheduler`` choose Dask; neither: this process.

    Summary keys: ``images`` (in the job), ``rendered``, ``kept`` (found on disk from a run
    whose record was lost), ``skipped`` (done before), ``failed`` ({fabric: error}),
    ``wall_s``, ``images_per_s`` (rendered / wall), ``engine``, ``workers``, ``manifest``;
    ``processes`` (each worker: its context, and its tasks' seconds summed) and ``tasks``
    (each task in the order it finished: fabric, worker pid, wall, CPU, its thread's time on
    a CPU, waiting for one and asleep)."""
    check_engine(workers, scheduler)
    if retries < 0:
        raise InputError(f"{retries} must be >= 0", field="--retries")
    started = time.perf_counter()
    manifest = Manifest(spec.out_dir).open()
    try:
        tasks, skipped = [], 0
        for index in range(len(spec.fabrics)):
            images = spec.images_of(index)
            todo = [image for image in images if not manifest.is_done(image)]
            skipped += len(images) - len(todo)
            if todo:
                tasks.append(spec.task(index, todo))
            manifest.failed.pop(spec.fabrics[index], None)  # this run says anew
        left = sum(len(task.images) for task in tasks)
        counts = {"rendered": 0, "kept": 0}
        failed: dict[str, str] = {}
        timings = {"settle_s": 0.0, "simulate_s": 0.0, "render_s": 0.0, "write_s": 0.0,
                   "task_cpu_s": 0.0}
        #: per task, summed for the job and for each worker process: its wall and CPU, and
        #: its thread's time on a CPU, waiting for one (run_wait) and asleep (worker.py)
        per_task = ("wall_s", "cpu_s", "thread_cpu_s", "run_wait_s", "sleep_s")
        seen: dict[str, int] = {}
        processes: dict[int, dict] = {}
        task_times: list[dict] = []
        lock = threading.Lock()
        last_write = [time.perf_counter()]
        use_dask = workers is not None or scheduler is not None
        from catalog.core.progress import progress as progress_bar  # noqa: PLC0415

        with progress_bar("catalog render-catalog", total=left, unit="images",
                          enabled=progress) as bar:

            def on_image(event):
                with lock:
                    seen[event["fabric"]] = seen.get(event["fabric"], 0) + 1
                bar.advance()
                if "sha256" in event and not use_dask:  # in process: journal every image
                    manifest.add([event])

            def on_result(task, result):
                records = result.get("records", [])
                if use_dask:
                    manifest.add(records)
                for record in records:
                    counts[record.get("status", "rendered")] += 1
                    timings["render_s"] += record.get("render_s", 0.0)
                if "worker" in result:
                    pid = result["worker"]["pid"]
                    tasks = processes.get(pid, {}).get("tasks", {k: 0.0 for k in per_task})
                    for key in per_task:
                        tasks[key] = round(tasks[key] + result.get(key, 0.0), 4)
                    tasks["count"] = tasks.get("count", 0) + 1
                    processes[pid] = {**result["worker"], "tasks": tasks}
                    task_times.append({"fabric": task.fabric, "pid": pid, "images": len(records),
                                       **{k: result[k] for k in per_task if k in result}})
                for key in ("settle_s", "simulate_s", "write_s"):
                    timings[key] += result.get(key, 0.0)
                timings["task_cpu_s"] += result.get("cpu_s", 0.0)
                if not result["ok"]:
                    failed[task.fabric] = result["error"]
                    manifest.failed[task.fabric] = result["error"]
                with lock:  # the bar reaches the end even when events were lost or failed
                    missing = len(task.images) - seen.get(task.fabric, 0)
                    seen[task.fabric] = len(task.images)
                if missing > 0:
                    bar.advance(missing)
                if time.perf_counter() - last_write[0] > MANIFEST_EVERY_S:
                    manifest.write(spec.describe())
                    last_write[0] = time.perf_counter()

            if not tasks:
                engine = {"engine": "dask" if use_dask else "process",
                          "workers": workers or 0, "startup_s": 0.0}
            elif use_dask:
                from catalog.batch.dask_engine import run_dask  # noqa: PLC0415

                engine = run_dask(tasks, workers, scheduler, retries, lp_threads, on_image,
                                   on_result)
            else:
                engine = _run_process(tasks, retries, on_image, on_result)
        wall_s = time.perf_counter() - started
        summary = {"images": spec.image_count, "rendered": counts["rendered"],
                   "kept": counts["kept"], "skipped": skipped, "failed": failed,
                   "wall_s": round(wall_s, 3),
                   "images_per_s": round(counts["rendered"] / wall_s, 3) if wall_s > 0 else None,
                   **{k: round(v, 3) for k, v in timings.items()}, **engine,
                   "processes": [processes[pid] for pid in sorted(processes)],
                   "tasks": task_times,
                   "manifest": str(Path(spec.out_dir) / "manifest.json")}
        manifest.write(spec.describe(), summary)
    finally:
        manifest.close()
    return summary
