"""Progress of long work on stderr: items done, the rate and the time left.

On a terminal, a rich progress bar (``12/64 images  0.8 images/s  0:00:15  left 0:01:05``);
elsewhere (a log, CI, a pipe), a plain line now and then: at the first item, each tenth of
the work, at least every :data:`PLAIN_EVERY_S` seconds, and at the end. Off with ``--json``
(stdout carries one JSON object; stderr stays free for errors) or ``enabled=False``.

    with progress("catalog sheet", total=64, unit="images", enabled=not args.json) as bar:
        for ...:
            bar.advance()

Thread-safe: workers' callbacks may advance the same bar. Light: rich is imported only when
a terminal shows the bar.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from typing import Iterator

#: The longest silence of the plain lines (s).
PLAIN_EVERY_S = 30.0


def _clock(seconds: float | None) -> str:
    if seconds is None or seconds != seconds or seconds == float("inf"):
        return "?"
    seconds = int(round(seconds))
    hours, rest = divmod(seconds, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"


class _Silent:
    total = 0
    done = 0

    def advance(self, count: int = 1) -> None:
        self.done += count

    def set_total(self, total: int) -> None:
        self.total = total


class PlainProgress:
    """The sparse plain lines (no terminal)."""

    def __init__(self, label: str, total: int, unit: str, stream=None, clock=time.monotonic):
        self.label, self.total, self.unit = label, int(total), unit
        self.stream = stream if stream is not None else sys.stderr
        self._clock = clock
        self.started = clock()
        self.done = 0
        self._last_line_at = None
        self._last_tenth = -1
        self._lock = threading.Lock()

    def set_total(self, total: int) -> None:
        with self._lock:
            self.total = int(total)

    def line(self) -> str:
        elapsed = self._clock() - self.started
        rate = self.done / elapsed if elapsed > 0 else None
        left = (self.total - self.done) / rate if rate else None
        share = f" ({100 * self.done / self.total:.0f} %)" if self.total else ""
        speed = f"{rate:.2f} {self.unit}/s" if rate else f"? {self.unit}/s"
        return (f"{self.label}: {self.done}/{self.total} {self.unit}{share}, {speed}, "
                f"{_clock(elapsed)} elapsed, {_clock(left)} left")

    def advance(self, count: int = 1) -> None:
        with self._lock:
            self.done += count
            now = self._clock()
            tenth = int(10 * self.done / self.total) if self.total else 0
            due = (self._last_line_at is None or tenth > self._last_tenth
                   or now - self._last_line_at >= PLAIN_EVERY_S or self.done >= self.total)
            if not due:
                return
            self._last_line_at, self._last_tenth = now, tenth
            try:
                print(self.line(), file=self.stream, flush=True)
            except (OSError, ValueError):
                pass  # a closed stderr must not stop the work


class _RichProgress:
    def __init__(self, bar, task):
        self._bar, self._task = bar, task
        self.done = 0

    def advance(self, count: int = 1) -> None:
        self.done += count
        self._bar.advance(self._task, count)

    def set_total(self, total: int) -> None:
        self._bar.update(self._task, total=total)


def _rich_bar(unit: str):
    from rich.console import Console  # noqa: PLC0415
    from rich.progress import (BarColumn, MofNCompleteColumn, Progress, ProgressColumn,  # noqa: PLC0415
                               TextColumn, TimeElapsedColumn, TimeRemainingColumn)
    from rich.text import Text  # noqa: PLC0415

    class RateColumn(ProgressColumn):
        def render(self, task):
            speed = task.finished_speed or task.speed
            return Text(f"  ? {unit}/s" if speed is None else f"{speed:5.2f} {unit}/s")

    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                    RateColumn(), TimeElapsedColumn(), TextColumn("left"),
                    TimeRemainingColumn(), console=Console(stderr=True), transient=False)


def _is_terminal(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


class _Delayed:
    """A reporter that shows nothing until the work has taken ``delay_s``: then the plain
    lines or the rich bar (from what is done so far). For work that is usually quick."""

    def __init__(self, start_reporter, total: int, delay_s: float, clock=time.monotonic):
        self._start, self.total, self._delay_s, self._clock = start_reporter, int(total), delay_s, clock
        self._started_at = clock()
        self.done = 0
        self.shown = None   # the real reporter, once the work is slow
        self._lock = threading.Lock()

    def set_total(self, total: int) -> None:
        with self._lock:
            self.total = int(total)
            if self.shown is not None:
                self.shown.set_total(total)

    def advance(self, count: int = 1) -> None:
        with self._lock:
            self.done += count
            if self.shown is None and self._clock() - self._started_at >= self._delay_s:
                self.shown = self._start(self.total)
                self.shown.advance(self.done)
            elif self.shown is not None:
                self.shown.advance(count)


@contextlib.contextmanager
def progress(label: str, total: int, unit: str = "items", *, enabled: bool = True,
             stream=None, delay_s: float = 0.0) -> Iterator[object]:
    """A progress reporter for ``total`` items (see the module's docstring). ``delay_s``:
    shown only once the work has taken that long (an item done after it), for work that is
    usually quick (the fit's starts)."""
    stream = stream if stream is not None else sys.stderr
    if not enabled or stream is None:
        yield _Silent()
        return
    if delay_s > 0:
        with contextlib.ExitStack() as stack:
            def start(total_now: int):
                return stack.enter_context(progress(label, total_now, unit, stream=stream))
            yield _Delayed(start, total, delay_s)
        return
    if not _is_terminal(stream):
        yield PlainProgress(label, total, unit, stream)
        return
    bar = _rich_bar(unit)
    with bar:
        yield _RichProgress(bar, bar.add_task(label, total=total))
