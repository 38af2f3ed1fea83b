"""benchmarks.preset_table: docs/fit.md's preset table comes from the presets themselves."""

from __future__ import annotations

import json

from benchmarks import preset_table
from catalog.core.resources import PROJECT_ROOT


def test_committed_json_is_what_the_presets_say_today():
    """A preset refitted (make presets) without re-running the table leaves the docs stale."""
    committed = json.loads((PROJECT_ROOT / preset_table.RESULT_JSON).read_text())
    assert committed == json.loads(json.dumps(preset_table.run()))


def test_the_direct_sentence_names_the_dense_fabrics_and_the_worst_open_one():
    result = preset_table.run()
    blocks = preset_table.markdown_tables(result)
    sentence = blocks["fit-presets-direct"]
    rows = [r for r in result["rows"] if r["open_area_model"] is not None]
    dense = [r["preset"] for r in rows if r["open_area_model"] < result["open_area_at_least"]]
    open_ = [r for r in rows if r["open_area_model"] >= result["open_area_at_least"]]
    worst = max(open_, key=lambda r: abs(r["direct"] - r["open_area_model"]))["preset"]
    assert dense and all(name in sentence for name in dense)
    assert f"{worst} is off by" in sentence
    assert len(blocks["fit-presets"].splitlines()[2:]) == len(result["rows"])


def test_gonio_header_reads_key_value_comments(tmp_path):
    path = tmp_path / "g.csv"
    path.write_text("# made by hand\n# weave: lace\n# open_area_normal: 0.25\na,b\n1,2\n# weave: not read\n")
    assert preset_table.gonio_header(path) == {"weave": "lace", "open_area_normal": "0.25"}
