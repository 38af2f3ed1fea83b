"""Timing helpers of the benchmark suite: medians of repeats (the machine is shared)."""

from __future__ import annotations

import statistics
import time
from typing import Callable


def median_seconds(work: Callable[[], object], repeats: int, warmup: int = 1,
                   finish: Callable[[], object] | None = None) -> float:
    """Median wall time (s) of ``work()`` over ``repeats`` calls after ``warmup`` calls.

    ``finish`` (e.g. a GL context's ``finish``) runs inside each timed call, so work
    queued on a device is counted where it is done.
    """
    for _ in range(warmup):
        work()
        if finish is not None:
            finish()
    samples = []
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        work()
        if finish is not None:
            finish()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def median_wall_and_cpu(work: Callable[[], object], repeats: int, warmup: int = 1,
                        finish: Callable[[], object] | None = None) -> tuple[float, float]:
    """(median wall s, median process CPU s) of ``work()``: CPU time counts every thread
    of this process (llvmpipe's rasteriser threads included) and little of what other
    processes on a shared machine take, so its ratios are the steadier ones."""
    for _ in range(warmup):
        work()
        if finish is not None:
            finish()
    walls, cpus = [], []
    for _ in range(max(1, repeats)):
        wall0, cpu0 = time.perf_counter(), time.process_time()
        work()
        if finish is not None:
            finish()
        walls.append(time.perf_counter() - wall0)
        cpus.append(time.process_time() - cpu0)
    return statistics.median(walls), statistics.median(cpus)


def percentile(values, q: float) -> float:
    """The q-th percentile (0..100) of a non-empty sequence, linear interpolation."""
    import numpy as np  # noqa: PLC0415

    return float(np.percentile(np.asarray(values, dtype=np.float64), q))
