"""Frame time and its parts: simulation, shading, UI (and the rest: swap, events, waits).

Each part is wall time on the CPU around a ``ctx.finish()``-terminated block, so GL work
queued in a part is charged to that part (on llvmpipe the "GPU" is the CPU anyway).
The panel shows the medians over the last frames; ``--stats`` logs every frame.
"""

from __future__ import annotations

import statistics
import time
from collections import deque
from contextlib import contextmanager
from dataclasses import dataclass, field

PARTS = ("simulation", "shading", "ui")


@dataclass
class FrameTimes:
    """One frame's times, milliseconds."""

    frame: int
    total_ms: float
    parts_ms: dict[str, float] = field(default_factory=dict)

    @property
    def other_ms(self) -> float:
        """Swap, event polling and bookkeeping: the total less the measured parts."""
        return max(0.0, self.total_ms - sum(self.parts_ms.values()))


class FrameTimer:
    """Measures parts of the current frame and keeps the last ``history`` frames."""

    def __init__(self, history: int = 120, clock=time.perf_counter):
        self._clock = clock
        self.history: deque[FrameTimes] = deque(maxlen=history)
        self._frame = 0
        self._start: float | None = None
        self._parts: dict[str, float] = {}

    def begin_frame(self) -> None:
        self._start = self._clock()
        self._parts = {part: 0.0 for part in PARTS}

    @contextmanager
    def part(self, name: str):
        start = self._clock()
        try:
            yield
        finally:
            self._parts[name] = self._parts.get(name, 0.0) + (self._clock() - start) * 1e3

    def end_frame(self) -> FrameTimes:
        if self._start is None:
            raise RuntimeError("end_frame() without begin_frame()")
        self._frame += 1
        times = FrameTimes(self._frame, (self._clock() - self._start) * 1e3, dict(self._parts))
        self.history.append(times)
        self._start = None
        return times

    def median_ms(self) -> dict[str, float]:
        """Median of the kept frames: 'total', each part and 'other' (ms); {} before any."""
        if not self.history:
            return {}
        out = {"total": statistics.median(t.total_ms for t in self.history)}
        for part in PARTS:
            out[part] = statistics.median(t.parts_ms.get(part, 0.0) for t in self.history)
        out["other"] = statistics.median(t.other_ms for t in self.history)
        return out

    def totals_ms(self) -> list[float]:
        return [t.total_ms for t in self.history]
