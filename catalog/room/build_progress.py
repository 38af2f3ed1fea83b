"""Progress of a room's precompute (its transport and frame bundle), for a first start that
builds one: the build's loops report (stage, done, total) here; a listener (the child
process the viewer starts, ``python -m catalog.render.room_operators ROOM --progress``)
turns them into lines "room living: 3/6 direct light, 41 % done, 0:24 elapsed, 0:35 left".

The stages in order, with their shares of a build's time (WEIGHTS: measured on one build
of ``bedroom`` here at load 13 on 2 cores, 114 s: loading and receivers 10 s, form factors
8, direct light 4, the solve 66, compression 23, the gathers 3.5); the time left is the
elapsed time scaled by the share left.
No listener: nothing happens (one dictionary look-up a chunk). numpy-free.
"""

from __future__ import annotations

import contextlib
import sys
import time

#: The stages of a build, in order, and their measured shares of its time (sum 1).
STAGES = ("receivers", "form factors", "direct light", "solve", "compress", "gathers")
WEIGHTS = (0.09, 0.07, 0.035, 0.575, 0.20, 0.03)
#: A listener prints at most one line this often (s), and at each new stage.
LINE_EVERY_S = 2.0

_listener = None


def report(stage: str, done: int = 0, total: int = 1) -> None:
    """The build is in ``stage`` (one of STAGES), ``done`` of its ``total`` chunks."""
    if _listener is not None:
        _listener(stage, done, total)


@contextlib.contextmanager
def listening(listener):
    """Send the build's reports to ``listener(stage, done, total)`` inside the block."""
    global _listener
    previous, _listener = _listener, listener
    try:
        yield
    finally:
        _listener = previous


def fraction_done(stage: str, done: int, total: int) -> float:
    """The share of the build done at (stage, done of total), by WEIGHTS."""
    k = STAGES.index(stage)
    within = min(1.0, max(0.0, done / total)) if total > 0 else 0.0
    return sum(WEIGHTS[:k]) + WEIGHTS[k] * within


def clock_text(seconds: float | None) -> str:
    if seconds is None or seconds != seconds or seconds == float("inf"):
        return "?"
    minutes, secs = divmod(int(round(seconds)), 60)
    return f"{minutes}:{secs:02d}"


class LinePrinter:
    """A listener that prints the build's progress as lines (flushed) on ``stream``."""

    def __init__(self, name: str, stream=None, clock=time.monotonic):
        self.name, self.stream, self._clock = name, stream or sys.stdout, clock
        self.started = clock()
        self._last_at, self._last_stage = None, None

    def line(self, stage: str, done: int, total: int) -> str:
        elapsed = self._clock() - self.started
        f = fraction_done(stage, done, total)
        left = elapsed * (1.0 - f) / f if f > 0.02 else None
        return (f"room {self.name}: {STAGES.index(stage) + 1}/{len(STAGES)} {stage}, "
                f"{100 * f:.0f} % done, {clock_text(elapsed)} elapsed, {clock_text(left)} left")

    def __call__(self, stage: str, done: int = 0, total: int = 1) -> None:
        now = self._clock()
        if stage == self._last_stage and self._last_at is not None and now - self._last_at < LINE_EVERY_S:
            return
        self._last_at, self._last_stage = now, stage
        try:
            print(self.line(stage, done, total), file=self.stream, flush=True)
        except (OSError, ValueError):
            pass   # a closed stream must not stop the build
