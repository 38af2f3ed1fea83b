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
    from catalog.bench import bispectral_figures

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
