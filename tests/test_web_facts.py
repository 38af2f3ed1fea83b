"""The web page's fabric facts are the desktop panel's: one function (catalog.presets.facts)
gives both, the site's data carries its values, summary line and rows, and the page's facts
list and cards show them as given (tests/test_web_links.py reads the page)."""

from __future__ import annotations

import pytest

from catalog.presets import find_preset, load_preset
from catalog.presets.facts import fabric_facts
from catalog.viewer.catalog_state import FabricCatalog
from catalog.web.facts import page_facts


def test_page_facts_are_the_panels_for_every_fabric():
    catalog = FabricCatalog()
    catalog.load_all()
    assert len(catalog) >= 8
    for entry in catalog.entries:
        page = page_facts(entry.preset)
        assert page["line"] == entry.facts.lines()[0]
        assert [tuple(r) for r in page["rows"]] == entry.facts.rows()
        assert page["kind"] == entry.facts.kind and page["openness_pct"] == entry.facts.openness_pct


def test_fact_words_for_a_brightened_lace_and_a_fluorescent_dye():
    lace = page_facts(load_preset(find_preset("lace-fwa")))
    assert lace["line"] == "open 38 %, optical brightener, 60 g/m2, lace"
    rows = dict(lace["rows"])
    assert rows["Openness"] == "38 % see-through" and "quantum yield" in rows["Colour"]
    pink = fabric_facts(load_preset(find_preset("fluoro-pink")))
    assert pink.kind == "fluorescent dye"   # the page once called it an optical brightener
    grey = fabric_facts(load_preset(find_preset("net-grey")))
    assert grey.kind == "dye" and grey.quantum_yield is None
    assert "quantum yield" not in dict(grey.rows())["Colour"]


@pytest.mark.slow
def test_the_sites_data_carries_the_desktops_facts(web_site):
    from catalog.web.browser import site_data

    out, _ = web_site
    for fabric in site_data(out)["fabrics"]:
        assert fabric["facts"] == page_facts(load_preset(find_preset(fabric["name"])))
