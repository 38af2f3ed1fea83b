"""Figures the docs quote from records, studies and test runs (issue 10): each has a source
that says where it came from, and the quick studies reproduce their committed JSON."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest

from benchmarks import records, sun_spectrl2, tested_figures
from catalog.core.resources import PROJECT_ROOT


def _load(path: str) -> dict:
    return json.loads((PROJECT_ROOT / path).read_text(encoding="utf-8"))


def test_every_record_names_its_provenance_and_a_commit():
    """A record is history: it must say where it came from (a commit of this repository and
    how it was measured), and its rows must fit its columns."""
    result = _load(records.RESULT_JSON)
    assert result["records"]
    for name, record in result["records"].items():
        assert re.search(r"\b[0-9a-f]{7,40}\b", record["provenance"]), name
        assert (PROJECT_ROOT / record["doc"]).is_file(), name
        assert f"<!-- generated:{name} -->" in (PROJECT_ROOT / record["doc"]).read_text(), name
        text = records.render_record(record)
        assert "Historical record, not re-runnable" in text and record["provenance"] in text


def test_a_record_row_that_does_not_fit_its_columns_is_refused():
    with pytest.raises(ValueError, match="2 cells under 3 columns"):
        records.render_record({"columns": ["a", "b", "c"], "rows": [[1, 2]], "provenance": "x"})


def test_the_sun_study_reproduces_its_committed_json():
    committed = _load(sun_spectrl2.RESULT_JSON)["rows"]
    fresh = sun_spectrl2.run()["rows"]
    assert len(fresh) == len(committed)
    for a, b in zip(fresh, committed):
        for key, value in b.items():
            assert a[key] == pytest.approx(value, rel=1e-9, abs=1e-12), key


def test_tested_figures_make_every_block_the_docs_use():
    made = tested_figures.markdown_tables(_load(tested_figures.RESULT_JSON))
    assert {"display_checks", "display_checks_brief", "render_reference_error",
            "render_reference_brief", "pattern_checks", "pattern_pairwise_brief",
            "render_led405_brief"} <= set(made)


@pytest.mark.slow
def test_record_figure_merges_into_the_named_json_only_when_asked(tmp_path):
    """The conftest hook: with CATALOG_RECORD_FIGURES set, a session's figures are merged
    into the file (earlier figures kept); without it nothing is written."""
    test = tmp_path / "test_probe.py"
    test.write_text("def test_one(record_figure):\n    record_figure('probe.value', 1.5)\n")
    target = tmp_path / "figures.json"
    target.write_text(json.dumps({"figures": {"earlier": 2}}))
    conftest = PROJECT_ROOT / "tests" / "conftest.py"
    (tmp_path / "conftest.py").write_text(conftest.read_text())

    def run(env_value):
        env = {"PATH": "/usr/bin:/bin", "CATALOG_RECORD_FIGURES": env_value} if env_value else \
            {"PATH": "/usr/bin:/bin"}
        proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                               str(test)], cwd=tmp_path, env=env, capture_output=True, text=True)
        assert proc.returncode == 0, proc.stdout + proc.stderr

    run(None)
    assert json.loads(target.read_text()) == {"figures": {"earlier": 2}}
    run(str(target))
    assert json.loads(target.read_text()) == {"figures": {"earlier": 2, "probe.value": 1.5}}


@pytest.mark.slow
def test_record_figure_keeps_every_xdist_workers_figures(tmp_path):
    """Under pytest-xdist each worker merges its own figures into the file, one at a time:
    two modules in two workers, both figures and the earlier one are there."""
    conftest = PROJECT_ROOT / "tests" / "conftest.py"
    (tmp_path / "conftest.py").write_text(conftest.read_text())
    for name in ("a", "b"):
        (tmp_path / f"test_{name}.py").write_text(
            f"def test_{name}(record_figure):\n    record_figure('probe.{name}', 1.0)\n")
    target = tmp_path / "figures.json"
    target.write_text(json.dumps({"figures": {"earlier": 2}}))
    env = {"PATH": "/usr/bin:/bin", "CATALOG_RECORD_FIGURES": str(target)}
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-n", "2", "--dist", "loadfile", "test_a.py", "test_b.py"],
                          cwd=tmp_path, env=env, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "2 passed" in proc.stdout
    assert json.loads(target.read_text()) == {"figures": {"earlier": 2, "probe.a": 1.0,
                                                          "probe.b": 1.0}}


def test_the_refinement_study_folds_hold_every_training_light_once():
    """The cross-validation of docs/bispectral.md holds out every training light exactly
    once, and never a goal light."""
    from benchmarks import bispectral_refinement as br
    from catalog.optics.bispectral.matrix import COLOUR_TRAINING_LIGHTS
    from catalog.optics.bispectral.study import GOAL_LIGHTS

    held = [light for group in br.FOLDS.values() for light in group]
    assert sorted(held) == sorted(COLOUR_TRAINING_LIGHTS)
    assert not set(held) & set(GOAL_LIGHTS)


def test_the_refinement_tables_mark_the_default_and_the_lowest():
    from benchmarks import bispectral_refinement as br

    result = _load(br.RESULT_JSON)
    made = br.markdown_tables(result)
    assert {"bispectral-data", "bispectral-refinement-cv", "bispectral-refinement-moves",
            "bispectral-refinement-variants", "bispectral-refinement-study-lights",
            "bispectral-refinement-whites"} <= set(made)
    lowest = min(result["cross_validation"], key=lambda r: r["held_out_mean"])
    assert f"**{lowest['held_out_mean']:.3f}**" in made["bispectral-refinement-cv"]
    assert "(default)" in made["bispectral-refinement-cv"]
    assert made["bispectral-data"].count("\n") == 1 + len(result["data"])


@pytest.mark.slow
def test_the_refinement_study_reproduces_its_committed_json(shared_data):
    """About 20 s: the study re-run gives the committed figures (the same code and data)."""
    from benchmarks import bispectral_refinement as br

    committed = _load(br.RESULT_JSON)
    fresh = json.loads(json.dumps(br.run()))
    for a, b in zip(fresh["cross_validation"], committed["cross_validation"]):
        assert a["held_out_mean"] == pytest.approx(b["held_out_mean"], rel=1e-6)
    for a, b in zip(fresh["variants"], committed["variants"]):
        assert (a["goal_mean"], a["goal_max"]) == pytest.approx((b["goal_mean"], b["goal_max"]),
                                                                 rel=1e-6)
    assert [d["noise_sigma"] for d in fresh["data"]] == pytest.approx(
        [d["noise_sigma"] for d in committed["data"]], rel=1e-9)
