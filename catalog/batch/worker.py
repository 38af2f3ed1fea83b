"""The worker side: one GL context and one renderer per process, and one fabric per task.

:func:`render_fabric` simulates the fabric's cloth once (frame by frame, as far as the last
frame asked for), and at each frame asked for renders every light and yaw from the one
renderer. Every piece of renderer state an image depends on is set before it is drawn, so
an image does not depend on what the process rendered before (the determinism test checks
it across worker counts).

Images are written durably: a temporary file beside the target, ``fsync``, rename, and an
``fsync`` of the folder, so a crash leaves either the whole image or none under its name.
Each image carries its inputs' key in its metadata (``catalog:inputs``), so an image whose
manifest record was lost in a crash is recognised and kept, not rendered again.

A preset that cannot be loaded, or any other :class:`CatalogError`, fails the fabric
without a retry (it would fail again); other exceptions propagate, and Dask retries them.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import threading
import time
from pathlib import Path

import numpy as np

from catalog.core.errors import CatalogError

#: Metadata attribute holding the image's input key.
KEY_ATTRIBUTE = "catalog:inputs"
#: Temporary image files are called ``.<name>.part-XXXX.<ext>`` (removed on the next run).


class RendererPool:
    """The process's GL context and renderer, made on first use and kept.

    ``device_index``: the EGL device for this process (None: the default one); ``ctx``: use
    this context instead of making one (it stays the caller's). A lock lets a worker with
    several threads share the one context safely (tasks take turns).
    """

    def __init__(self, device_index: int | None = None, ctx=None):
        self.device_index = device_index
        self.lock = threading.Lock()
        self.ctx = ctx
        self._own_ctx = ctx is None
        self._thread = threading.get_ident() if ctx is not None else None
        self.renderer = None
        self.contexts_created = 0

    def renderer_for(self, size: tuple[int, int]):
        from catalog.gl.context import create_headless_context  # noqa: PLC0415
    
        if self.ctx is None:
            self.ctx = create_headless_context(self.device_index)  # current in this thread
            self._thread = threading.get_ident()
            self.contexts_created += 1
        self.make_current()
        if self.renderer is None or tuple(self.renderer.size) != tuple(size):
            if self.renderer is not None:
                self.renderer.release()
                self.renderer = None
            from catalog.render.snapshot import new_renderer  # noqa: PLC0415

            self.renderer = new_renderer(self.ctx, tuple(size))  # size checked first
        return self.renderer

    def make_current(self) -> None:
        """Make the context current in the calling thread if another thread had it (a
        worker's task threads take turns under :attr:`lock`). Never undone: moderngl's
        ``with ctx`` would leave no context current when it exits."""
        if self._thread != threading.get_ident():
            self.ctx.__enter__()
            self._thread = threading.get_ident()

    def describe(self) -> dict:
        from catalog.gl.context import describe  # noqa: PLC0415

        info = {"device_index": self.device_index, "pid": os.getpid(),
                "lp_num_threads": os.environ.get("LP_NUM_THREADS"),
                "contexts_created": self.contexts_created}
        if self.ctx is not None:
            info.update(describe(self.ctx))
        return info

    def close(self) -> None:
        if self.ctx is None:
            return
        with contextlib.suppress(Exception):
            self.make_current()
            if self.renderer is not None:
                self.renderer.release()
        self.renderer = None
        if self._own_ctx:
            with contextlib.suppress(Exception):
                self.ctx.release()
        self.ctx = None


_POOL: RendererPool | None = None
_POOL_LOCK = threading.Lock()


def process_pool(device_index: int | None = None, replace: bool = False) -> RendererPool:
    """This process's renderer pool (the Dask worker plugin makes it with its device)."""
    global _POOL
    with _POOL_LOCK:
        if replace and _POOL is not None:
            _POOL.close()
            _POOL = None
        if _POOL is None:
            _POOL = RendererPool(device_index)
        return _POOL


def close_process_pool() -> None:
    global _POOL
    with _POOL_LOCK:
        if _POOL is not None:
            _POOL.close()
        _POOL = None


def file_sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for chunk in iter(lambda: handle.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def write_durable(target: Path, pixels: np.ndarray, metadata: dict[str, str]) -> tuple[str, int]:
    """Write an image through the project's output layer (catalog.render.imagefile: a
    temporary file beside ``target``, read back, ``fsync``, rename, the folder ``fsync``ed),
    so a crash leaves the whole image or none under its name. Returns (sha256 of the file,
    its size in bytes)."""
    from catalog.render.imagefile import write_image  # noqa: PLC0415

    write_image(target, pixels, metadata)
    return file_sha256(target), target.stat().st_size


def existing_key(path: Path) -> str | None:
    """The input key recorded in an image already on disk, or None."""
    if not path.is_file():
        return None
    from catalog.render.snapshot import read_metadata  # noqa: PLC0415

    try:
        return read_metadata(path).get(KEY_ATTRIBUTE)
    except CatalogError:
        return None


def thread_sched() -> tuple[float, float] | None:
    """The calling thread's (seconds on a CPU, seconds runnable but waiting for one) since it
    started, from the kernel's /proc/thread-self/schedstat; None where there is none. Over a
    task, its wall time less these two is the time the thread slept (a lock, llvmpipe's
    threads, I/O): the wait that is not the cores being busy."""
    try:
        with open("/proc/thread-self/schedstat") as handle:
            on_cpu_ns, waiting_ns = handle.read().split()[:2]
    except (OSError, ValueError):
        return None
    return int(on_cpu_ns) * 1e-9, int(waiting_ns) * 1e-9


def _sched_split(before, wall_s: float) -> dict:
    after = thread_sched()
    if before is None or after is None:
        return {}
    thread_cpu, run_wait = after[0] - before[0], after[1] - before[1]
    return {"thread_cpu_s": round(thread_cpu, 4), "run_wait_s": round(run_wait, 4),
            "sleep_s": round(max(wall_s - thread_cpu - run_wait, 0.0), 4)}


def _record(image, status: str, digest: str, size: int, render_s: float) -> dict:
    return {"path": image.path, "fabric": image.fabric, "light": image.light,
            "frame": image.frame, "yaw_deg": image.yaw_deg, "key": image.key,
            "sha256": digest, "bytes": size, "status": status, "render_s": round(render_s, 5)}


def render_fabric(task, pool: RendererPool | None = None, on_image=None) -> dict:
    """Render the images of one fabric task; returns ``{"fabric", "ok", "records", ...}``.

    ``on_image(record)`` is called after each image is on disk (progress). A CatalogError
    (bad preset, non-finite render) returns ``ok: False`` with the error; anything else
    is raised (an engine may retry it)."""
    start, cpu_start = time.perf_counter(), time.process_time()
    sched_start = thread_sched()
    pool = pool or process_pool()
    out_dir = Path(task.out_dir)
    records: list[dict] = []
    # simulate_s includes settle_s (settling the drape, once per fabric)
    timings = {"load_s": 0.0, "settle_s": 0.0, "simulate_s": 0.0, "render_s": 0.0,
               "write_s": 0.0}
    try:
        todo = []
        for image in task.images:  # kept from a run whose manifest record was lost
            target = out_dir / image.path
            if existing_key(target) == image.key:
                record = _record(image, "kept", file_sha256(target), target.stat().st_size, 0.0)
                records.append(record)
                if on_image:
                    on_image(record)
            else:
                todo.append(image)
        if todo:
            with pool.lock:
                _render_images(task, todo, pool, out_dir, records, timings, on_image)
    except CatalogError as exc:
        return {"fabric": task.fabric, "ok": False, "error": str(exc), "records": records,
                "wall_s": round(time.perf_counter() - start, 4), **timings,
                "worker": pool.describe()}
    wall_s = time.perf_counter() - start
    return {"fabric": task.fabric, "ok": True, "error": None, "records": records,
            "wall_s": round(wall_s, 4),
            # CPU seconds of this process in the task, llvmpipe's and numba's threads included
            "cpu_s": round(time.process_time() - cpu_start, 4),
            # the task's thread: on a CPU, runnable but waiting for one, asleep
            **_sched_split(sched_start, wall_s),
            **{k: round(v, 4) for k, v in timings.items()}, "worker": pool.describe()}


def _render_images(task, todo, pool, out_dir, records, timings, on_image) -> None:
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.presets import load_preset  # noqa: PLC0415
    from catalog.render.settings import FrameSettings  # noqa: PLC0415
    from catalog.render.snapshot import (FRAME_DT_S, SnapshotRequest,  # noqa: PLC0415
                                         curtain_on_rod, curtain_simulation, image_metadata,
                                         ring_xs_m, snapshot_settings)

    t0 = time.perf_counter()
    preset = load_preset(task.preset_path)
    # the task's scene value, resolved once here (the edge): the fabric's tables read, its
    # choices checked; each image draws it with its own light and camera
    task_scene = FrameSettings(fabric=preset, fluorescence=task.fluorescence, bands=task.bands,
                               exposure=task.exposure, room=task.room)
    lights = {name: get_light(name) for name in sorted({image.light for image in todo})}
    from catalog.render.placement import room_placement  # noqa: PLC0415

    placement = room_placement(task.room)   # the curtain on the rod of the room's own window
    rings = ring_xs_m(preset, placement)
    timings["load_s"] += time.perf_counter() - t0

    renderer = pool.renderer_for(task.size)
    linear = task.image_format == "exr"
    by_frame: dict[int, list] = {}
    for image in todo:
        by_frame.setdefault(image.frame, []).append(image)
    simulation, stepped = None, 0
    for frame in sorted(by_frame):  # one simulation, stepped through the frames asked for
        t0 = time.perf_counter()
        if simulation is None:
            simulation = curtain_simulation(preset, placement)  # frame 0: the settled drape
            timings["settle_s"] += time.perf_counter() - t0
        while stepped < frame:  # (its own frame counter includes the settling)
            simulation.step(FRAME_DT_S)
            stepped += 1
        if not simulation.finite:
            raise CatalogError(f"{task.fabric}: the cloth simulation diverged by frame {frame}")
        *mesh, fabric_size = curtain_on_rod(simulation, placement)
        timings["simulate_s"] += time.perf_counter() - t0
        for image in by_frame[frame]:
            t0 = time.perf_counter()
            # every setting an image depends on, as `catalog snapshot` sets it
            request = SnapshotRequest(fabric=task.fabric, light=image.light, size=task.size,
                                      out=out_dir / image.path, frame=frame,
                                      fluorescence=task.fluorescence, bands=task.bands,
                                      yaw_deg=image.yaw_deg, pitch_deg=task.pitch_deg,
                                      distance_m=task.distance_m, exposure=task.exposure,
                                      room=task.room)
            renderer.update(snapshot_settings(request, preset, lights[image.light], base=task_scene))
            renderer.display.forget_white()   # each image adapts to its own view, as a snapshot
            if image is by_frame[frame][0]:
                # once a frame: a new mesh makes the room's light be drawn again, which the
                # frame's other lights and yaws need not pay (its key holds the light; the
                # camera is no part of it)
                renderer.set_mesh(*mesh, fabric_size_m=fabric_size)
                renderer.set_rings(rings)
            renderer.render()
            pixels = renderer.read_linear() if linear else renderer.read_srgb8()
            render_s = time.perf_counter() - t0
            if not np.all(np.isfinite(pixels)):
                raise CatalogError(f"{image.path}: the render has NaN or infinite pixels")
            metadata = image_metadata(renderer.info(), frame, linear)
            metadata.update({
                "ImageDescription": f"catalog render-catalog: {task.fabric} under "
                                    f"{image.light}, frame {frame}, yaw {image.yaw_deg:g} deg",
                "catalog:yaw_deg": f"{image.yaw_deg:g}",
                KEY_ATTRIBUTE: image.key,
                "DateTime": "",  # OpenEXR would stamp the time: the bytes must not vary
            })
            t1 = time.perf_counter()
            digest, size = write_durable(out_dir / image.path, pixels, metadata)
            timings["write_s"] += time.perf_counter() - t1
            timings["render_s"] += render_s
            record = _record(image, "rendered", digest, size, render_s)
            records.append(record)
            if on_image:
                on_image(record)
