"""The Dask engine (imported only when Dask is asked for; ``pip install 'fabric-catalog[batch]'``).

``run_dask`` starts a ``LocalCluster`` (N worker processes, one thread each, on 127.0.0.1,
no dashboard) or connects to an existing scheduler, registers :class:`RendererPlugin`, and
submits one task per fabric with retries. Workers report each finished image as a Dask
event (topic :data:`PROGRESS_TOPIC`) for the progress bar; the records come back with the
task's result and the driver journals them.
"""

from __future__ import annotations

import os
import time

from distributed.diagnostics.plugin import WorkerPlugin

from catalog.core.errors import CatalogError

#: Dask event topic for per-image progress.
PROGRESS_TOPIC = "catalog-render-catalog"


class RendererPlugin(WorkerPlugin):
    """Per worker process: ``LP_NUM_THREADS`` (unless already set) and ``NUMBA_NUM_THREADS``
    (the cores / the host's workers), the EGL device, and one
    GL context and renderer kept for every task the worker runs (released at teardown).

    ``host_workers``: worker address -> (its rank among the workers of its host, how many
    workers that host runs), known when the plugin is registered; a worker that joins later
    counts as rank 0 of 1 unless ``CATALOG_EGL_DEVICE`` says which device to use."""

    name = "catalog-renderer"

    def __init__(self, host_workers: dict[str, tuple[int, int]] | None = None,
                 lp_threads: int | None = None):
        self.host_workers = dict(host_workers or {})
        self.lp_threads = lp_threads

    def setup(self, worker) -> None:
        from catalog.batch.worker import process_pool  # noqa: PLC0415
        from catalog.gl.context import egl_device_count  # noqa: PLC0415

        rank, peers = self.host_workers.get(worker.address, (0, 1))
        # read by llvmpipe when the context is made (the first task): set before that
        cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
        share = str(self.lp_threads or max(1, (cpus or 1) // peers))
        if self.lp_threads or "LP_NUM_THREADS" not in os.environ:
            os.environ["LP_NUM_THREADS"] = share
        # the settle's numba threads (read when numba is first imported, in the first task
        # that settles): the worker's share of the cores too, not all of them per worker
        os.environ.setdefault("NUMBA_NUM_THREADS", share)
        device = os.environ.get("CATALOG_EGL_DEVICE")
        if device is not None:
            device_index = int(device)
        else:
            count = egl_device_count() or 1
            device_index = rank % count if count > 1 else None
        process_pool(device_index, replace=True)

    def teardown(self, worker) -> None:
        from catalog.batch.worker import close_process_pool  # noqa: PLC0415

        close_process_pool()


def dask_render_fabric(task) -> dict:
    """The Dask task: render one fabric with the worker's pool, an event per image."""
    from distributed import get_worker  # noqa: PLC0415

    from catalog.batch.worker import process_pool, render_fabric  # noqa: PLC0415

    worker = get_worker()

    def on_image(record):
        worker.log_event(PROGRESS_TOPIC, {"fabric": record["fabric"], "path": record["path"]})

    return render_fabric(task, process_pool(), on_image)


def _host_workers(client) -> dict[str, tuple[int, int]]:
    by_host: dict[str, list[str]] = {}
    for address, info in client.scheduler_info(n_workers=-1)["workers"].items():
        by_host.setdefault(info.get("host", address.rsplit(":", 1)[0]), []).append(address)
    ranks = {}
    for addresses in by_host.values():
        for rank, address in enumerate(sorted(addresses)):
            ranks[address] = (rank, len(addresses))
    return ranks


def run_dask(tasks, workers, scheduler, retries, lp_threads, on_image, on_result) -> dict:
    import logging  # noqa: PLC0415

    from distributed import Client, LocalCluster, as_completed  # noqa: PLC0415

    cluster = None
    started = time.perf_counter()
    try:
        if scheduler is not None:
            try:
                client = Client(scheduler, timeout="20s")
            except (OSError, TimeoutError) as exc:
                raise CatalogError(f"--scheduler: cannot reach {scheduler} ({exc})") from None
        else:
            import os  # noqa: PLC0415

            # the workers' semaphores outlive a Ctrl-C (the workers are terminated at once,
            # catalog.core.atomic.hard_exit); multiprocessing's tracker, a process of its
            # own, cleans them up and need not warn about it on the user's terminal
            os.environ.setdefault("PYTHONWARNINGS", "ignore:resource_tracker:UserWarning")
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None,
                                   silence_logs=logging.ERROR)
            client = Client(cluster)
        with client:
            client.register_plugin(RendererPlugin(_host_workers(client), lp_threads))
            n_workers = len(client.scheduler_info(n_workers=-1)["workers"])
            startup_s = time.perf_counter() - started
            client.subscribe_topic(PROGRESS_TOPIC, lambda event: on_image(event[1]))
            futures = {client.submit(dask_render_fabric, task, retries=retries, pure=False,
                                     key=f"render-catalog-{task.fabric}-{i}"): task
                       for i, task in enumerate(tasks)}
            for future in as_completed(futures):
                task = futures[future]
                try:
                    result = future.result()
                except Exception as exc:  # noqa: BLE001 - reported per fabric, not fatal
                    reason = " ".join(str(exc).split()) or type(exc).__name__
                    result = {"fabric": task.fabric, "ok": False, "records": [],
                              "error": f"{type(exc).__name__}: {reason} "
                                       f"(after {retries} retries)"}
                on_result(task, result)
            client.unsubscribe_topic(PROGRESS_TOPIC)
    finally:
        if cluster is not None:
            cluster.close()
    return {"engine": "dask", "workers": n_workers, "startup_s": round(startup_s, 3),
            "scheduler": scheduler or "LocalCluster (127.0.0.1)"}
