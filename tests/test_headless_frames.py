"""benchmarks.headless_frames: the viewer's frame without its window (EGL), and its tables."""

from __future__ import annotations

import json

import pytest

from benchmarks import headless_frames as bench
from catalog.core.resources import PROJECT_ROOT


def test_parse_case_reads_size_and_grid_and_refuses_bad_text():
    assert bench.parse_case("1920x1080:128x128") == ((1920, 1080), (128, 128))
    for bad in ("1920x1080", "1920:128x128", "axb:2x2", "1x1080:8x8"):
        with pytest.raises(SystemExit, match="--cases"):
            bench.parse_case(bad)


@pytest.mark.gl
@pytest.mark.slow
def test_a_small_run_times_the_cloth_and_the_frame(tmp_path):
    out = tmp_path / "frames.json"
    assert bench.main(["--cases", "64x48:6x8", "--backend", "numpy", "--frames", "2",
                       "--warmup", "1", "--passes", "--json-out", str(out)]) == 0
    result = json.loads(out.read_text())
    (row,) = result["rows"]
    assert row["size"] == [64, 48] and row["grid"] == [6, 8] and row["backend"] == "numpy"
    assert row["simulation_ms"] > 0 and row["shading_ms"] > 0
    # medians of sums need not be sums of medians, but the total cannot be below either part
    assert row["total_ms"] >= max(row["simulation_ms"], row["shading_ms"]) * 0.999
    assert {"curtain", "room", "display"} <= set(row["passes_ms"])
    assert result["settings"]["passes"] is True
    assert not list(tmp_path.glob("*.tmp*"))   # written whole


def test_tables_hold_every_committed_row():
    result = json.loads((PROJECT_ROOT / bench.RESULT_JSON).read_text())
    tables = bench.markdown_tables(result)
    frames = tables["viewer-headless-frames"].splitlines()[2:]
    assert len(frames) == sum(len(result["runs"][k]["rows"]) for k in bench.FRAME_RUNS)
    summary = tables["gpu-frame-summary"].splitlines()[2:]
    assert summary and all("|" in line for line in summary)
    accuracy = tables["viewer-gpu-accuracy"].splitlines()[2:]
    assert len(accuracy) == len(result["accuracy_h200"])
