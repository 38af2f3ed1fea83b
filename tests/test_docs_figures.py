"""Figures in the docs are generated from the benchmarks' committed JSON, never typed."""

from __future__ import annotations

import importlib.util
import json

import pytest

from catalog.core.resources import PROJECT_ROOT


@pytest.fixture(scope="module")
def docs_figures():
    spec = importlib.util.spec_from_file_location("docs_figures",
                                                  PROJECT_ROOT / "tools" / "docs_figures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_committed_docs_equal_the_regenerated_blocks(docs_figures):
    made = docs_figures.tables()
    assert made, "no bench module provides markdown_tables"
    used = set()
    for path in docs_figures.documents():
        text = path.read_text(encoding="utf-8")
        used |= {m.group("name") for m in docs_figures.BLOCK.finditer(text)}
        assert docs_figures.fill(text, made, path.name) == text, \
            f"{path.name}: a generated block differs from its JSON (run tools/docs_figures.py)"
    assert used == set(made), f"blocks made but shown nowhere: {sorted(set(made) - used)}"


def test_a_changed_figure_changes_the_block_and_unknown_names_are_refused(docs_figures):
    from benchmarks import bispectral_figures

    result = json.loads((PROJECT_ROOT / bispectral_figures.RESULT_JSON).read_text())
    result["summary_goal_lights"]["physical"]["mean"] = 0.77
    made = bispectral_figures.markdown_tables(result)
    assert "**0.77**" in made["bispectral-summary"] and "mean 0.77" in made["bispectral-goal"]
    result["summary_goal_lights"]["physical"]["max"] = 1.5
    assert "NOT met" in bispectral_figures.markdown_tables(result)["bispectral-goal"]
    text = "a\n<!-- generated:bispectral-goal -->\nold\n<!-- /generated:bispectral-goal -->\nb\n"
    new = docs_figures.fill(text, made, "x.md")
    assert "old" not in new and made["bispectral-goal"] in new and new.endswith("b\n")
    with pytest.raises(KeyError, match="no-such-table"):
        docs_figures.fill("<!-- generated:no-such-table -->\n<!-- /generated:no-such-table -->",
                          made, "x.md")


def test_a_module_may_make_its_tables_from_several_runs(docs_figures, tmp_path):
    """RESULT_JSONS: markdown_tables receives every run by its key; a missing run, or a
    module giving both RESULT_JSON and RESULT_JSONS, is refused naming it."""
    import types

    (tmp_path / "a.json").write_text(json.dumps({"ms": 2.5}))
    (tmp_path / "b.json").write_text(json.dumps({"ms": 7.0}))
    module = types.SimpleNamespace(
        __name__="fake", RESULT_JSONS={"cpu": "a.json", "gpu": "b.json"},
        markdown_tables=lambda runs: {"t": " / ".join(f"{k} {v['ms']}" for k, v in runs.items()) + "\n"})
    assert docs_figures.module_tables(module, tmp_path) == {"t": "cpu 2.5 / gpu 7.0"}
    module.RESULT_JSONS["h200"] = "c.json"
    with pytest.raises(SystemExit, match="c.json: no such file"):
        docs_figures.module_tables(module, tmp_path)
    del module.RESULT_JSONS["h200"]
    module.RESULT_JSON = "a.json"
    with pytest.raises(SystemExit, match="both RESULT_JSON and RESULT_JSONS"):
        docs_figures.module_tables(module, tmp_path)
    assert docs_figures.module_tables(types.SimpleNamespace(__name__="plain"), tmp_path) is None


def test_the_viewer_tables_take_one_more_run_as_one_more_row_set():
    """The viewer's frame table spans its runs: a run added (e.g. on a GPU) adds its rows."""
    from benchmarks import viewer_frames

    runs = {key: json.loads((PROJECT_ROOT / path).read_text())
            for key, path in viewer_frames.RESULT_JSONS.items()}
    before = viewer_frames.markdown_tables(runs)["viewer_frames"].splitlines()
    extra = json.loads(json.dumps(runs["defaults"]))
    extra["machine"]["gl_renderer"] = "NVIDIA H200/PCIe/SSE2"
    for row in extra["rows"]:
        row["gl_renderer"] = "NVIDIA H200/PCIe/SSE2"
    after = viewer_frames.markdown_tables({**runs, "h200": extra})["viewer_frames"].splitlines()
    assert after[:len(before)] == before and len(after) == len(before) + len(extra["rows"])
    assert all(line.startswith("| NVIDIA H200/PCIe/SSE2 |") for line in after[len(before):])


def test_no_two_bench_modules_claim_the_same_json(docs_figures):
    """One module's run must not overwrite another's committed result (docs_figures refuses
    it too)."""
    import importlib
    import pkgutil

    import benchmarks as bench

    owners: dict[str, list[str]] = {}
    for info in pkgutil.iter_modules(bench.__path__):
        module = importlib.import_module(f"benchmarks.{info.name}")
        for source in docs_figures.result_sources(module):
            owners.setdefault(source, []).append(info.name)
    shared = {k: v for k, v in owners.items() if len(v) > 1}
    assert owners and not shared, f"JSON files claimed by several modules: {shared}"


def test_fit_table_margins_count_the_combinations_hg_loses():
    """The generated sentence counts, it does not assume: a combination where CT is better
    is reported as such."""
    from benchmarks import fit_table

    def row(fabric, points, weighting, hg, ct):
        return {"fabric": fabric, "points": points, "weighting": weighting, "hg_rmse": hg,
                "ct_rmse": ct, "hg_relative_rms": 0.1, "ct_relative_rms": 0.2,
                "hg_anisotropy_rmse": None if points == 79 else hg}

    rows = [row(f, p, w, 1.0, 2.0) for f in ("a", "b") for p in (4800, 79)
            for w in ("relative", "none")]
    rows[1]["ct_rmse"] = 0.5
    tables = fit_table.markdown_tables({"rows": rows})
    assert "lower rmse in 7 of 8 combinations" in tables["fit_table_margins"]
    assert "from 0.5x (a, 4800 points, none weighting)" in tables["fit_table_margins"]
    assert len(tables["fit_table_readme"].splitlines()) == 2 + 2
