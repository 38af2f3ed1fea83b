"""Shape of issue 12's cost benchmarks (not their timings): the pattern benchmark's quick run
has every case, per-round ratios and the anti-aliasing choice, and its tables; the viewer
benchmark's before/after table from a JSON of the form `--before` writes."""

from __future__ import annotations

import math

import pytest

from benchmarks import alpha_to_coverage, pattern, viewer_frames
from catalog.render.passes.targets import choose_antialiasing


@pytest.mark.slow
def test_pattern_benchmark_quick_run(gl):
    result = pattern.run(quick=True, ctx=gl, repeats=2)
    cases = [row["case"] for row in result["rows"]]
    assert cases[0].startswith("before") and "patterned + OIT + FXAA (settled drape)" in cases
    if int(gl.info.get("GL_MAX_SAMPLES", 0) or 0) >= 4:
        assert "patterned + OIT + MSAA 4x (settled drape)" in cases
    for row in result["rows"]:
        assert row["median_ms"] > 0 and row["best_ms"] <= row["median_ms"]
        assert math.isfinite(row["round_ratio"]) and row["round_ratio"] > 0
    assert result["rows"][0]["round_ratio"] == 1.0
    assert result["summary"]["choice"] == choose_antialiasing(dict(gl.info))
    tables = pattern.markdown_tables(result)
    assert set(tables) == {"pattern_cost", "pattern_msaa"}
    assert len(tables["pattern_cost"].splitlines()) == len(cases) + 4  # header, rule, blank, summary


def test_viewer_before_after_table():
    rows = []
    for version, total in (("before (26f3c74)", 40.0), ("after (this tree)", 60.0)):
        rows.append({"version": version, "case": "1280x720:default", "size": "1280x720",
                     "render_scale": 0.5, "grid": "96x56 (default)", "total_ms": total,
                     "simulation_ms": 5.0, "shading_ms": 20.0, "ui_ms": 5.0, "other_ms": 10.0})
    table = viewer_frames.before_after_table({"rows": rows})
    lines = table.splitlines()
    assert len(lines) == 4 and lines[2].endswith("| 1.00 |") and lines[3].endswith("| 1.50 |")


def test_alpha_to_coverage_study(gl):
    """The study's shape, and what any 4-sample alpha-to-coverage must give: a layer whose
    coverage is a whole number of quarters covers that fraction of the samples (within 1e-6)."""
    if int(gl.info.get("GL_MAX_SAMPLES", 0) or 0) < 4:
        import pytest
        pytest.skip("the context has fewer than 4 samples (GL_MAX_SAMPLES)")
    result = alpha_to_coverage.run(gl)
    rows = {row["coverage"]: row for row in result["rows"]}
    assert set(rows) == set(alpha_to_coverage.COVERAGES)
    for c in (0.25, 0.5, 0.75):
        assert abs(rows[c]["open_one"] - (1.0 - c)) < 1e-6
    print("two layers at c = 0.5: open", rows[0.5]["open_two"], "(product 0.25)")
    assert alpha_to_coverage.markdown_tables(result)["a2c_layers"].count("\n") == len(rows) + 1
