"""Progress on long work (catalog/core/progress.py): sparse plain lines with the count, the
rate and the time left when stderr is not a terminal, nothing with --json."""

from __future__ import annotations

import io
import json

import pytest

from catalog.core import progress as progress_lib
from catalog.core.progress import PlainProgress, progress


class _Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def test_plain_lines_at_the_start_each_tenth_and_the_end_with_rate_and_time_left():
    stream, clock = io.StringIO(), _Clock()
    bar = PlainProgress("catalog sheet", 40, "images", stream, clock)
    for _ in range(40):
        clock.now += 0.5  # 2 images/s
        bar.advance()
    lines = stream.getvalue().splitlines()
    assert len(lines) == 11, lines  # the first, each tenth (4 images), the last
    assert lines[0] == "catalog sheet: 1/40 images (2 %), 2.00 images/s, 0:00 elapsed, 0:20 left"
    assert lines[5].startswith("catalog sheet: 20/40 images (50 %), 2.00 images/s, 0:10 elapsed")
    assert lines[5].endswith("0:10 left")
    assert lines[-1].startswith("catalog sheet: 40/40 images (100 %)") and lines[-1].endswith("0:00 left")


def test_a_slow_item_still_gets_a_line_every_30_s():
    stream, clock = io.StringIO(), _Clock()
    bar = PlainProgress("catalog web: record", 1000, "scenes", stream, clock)
    bar.advance()
    clock.now += progress_lib.PLAIN_EVERY_S + 1
    bar.advance()
    clock.now += 1
    bar.advance()
    assert len(stream.getvalue().splitlines()) == 2


def test_disabled_or_json_prints_nothing():
    stream = io.StringIO()
    with progress("x", 3, enabled=False, stream=stream) as bar:
        for _ in range(3):
            bar.advance()
    assert stream.getvalue() == "" and bar.done == 3


def test_not_a_terminal_gets_the_plain_lines():
    stream = io.StringIO()
    with progress("catalog bench", 2, unit="sections", stream=stream) as bar:
        bar.advance()
        bar.advance()
    assert isinstance(bar, PlainProgress)
    assert stream.getvalue().splitlines()[-1].startswith("catalog bench: 2/2 sections (100 %)")


@pytest.mark.slow
def test_sheet_reports_progress_on_stderr_and_none_with_json(tmp_path, capsys):
    from catalog.commands.cli import main

    base = ["sheet", "--fabric", "voile-white", "--lights", "D65,A", "--size", "32x24"]
    assert main([*base, "--out", str(tmp_path / "a")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert [line.split(",")[0] for line in err if line.startswith("catalog sheet:")] == [
        "catalog sheet: 1/2 images (50 %)", "catalog sheet: 2/2 images (100 %)"]
    assert main([*base, "--out", str(tmp_path / "b"), "--json"]) == 0
    captured = capsys.readouterr()
    assert captured.err == "" and len(json.loads(captured.out)["images"]) == 2


def test_a_delayed_reporter_is_silent_while_quick_and_shows_all_done_once_slow():
    """progress(delay_s=..): nothing for work done within the delay; after it, the real
    reporter starts from what is already done (the fit's starts)."""
    clock, shown = _Clock(), []

    def start(total):
        bar = PlainProgress("catalog fit", total, "starts", io.StringIO(), clock)
        shown.append(bar)
        return bar

    quick = progress_lib._Delayed(start, 6, 2.0, clock)
    for _ in range(6):
        clock.now += 0.01
        quick.advance()
    assert shown == [] and quick.done == 6
    slow = progress_lib._Delayed(start, 6, 2.0, clock)
    clock.now += 1.0
    slow.advance()
    clock.now += 1.5
    slow.advance()
    assert len(shown) == 1 and shown[0].done == 2
    slow.advance(4)
    lines = shown[0].stream.getvalue().splitlines()
    assert lines[0].startswith("catalog fit: 2/6 starts") and lines[-1].startswith("catalog fit: 6/6")


@pytest.mark.slow
def test_the_fit_counts_its_starts_when_slow(monkeypatch, capsys):
    from pathlib import Path

    from catalog.fit import preset_build
    from catalog.fit.fitting import SCAN_STARTS
    from catalog.fit.gonio import read_gonio

    data = read_gonio(Path(__file__).parents[1] / "fabrics/measurements/voile-white/gonio.csv")
    monkeypatch.setattr(preset_build, "FIT_PROGRESS_DELAY_S", 1e9)  # never slow: silent
    preset_build.fit_measurement(data, "relative", progress=True)
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(preset_build, "FIT_PROGRESS_DELAY_S", 1e-9)
    preset_build.fit_measurement(data, "relative", progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert lines[-1].startswith(f"catalog fit: {2 * SCAN_STARTS}/{2 * SCAN_STARTS} starts (100 %)")
