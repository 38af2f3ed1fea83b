"""Figures the tests measure, as the docs quote them.

Some tests measure a figure and hold it to a bound (the bound stated in the test before the
figure was seen). The docs quote those figures; instead of copying them from a test's
output, the tests record them (the ``record_figure`` fixture of tests/conftest.py), and a
run with ``CATALOG_RECORD_FIGURES`` set merges them into benchmarks/tested_figures.json:

    CATALOG_RECORD_FIGURES=$PWD/benchmarks/tested_figures.json .venv/bin/python -m pytest \\
        tests/test_display_gl.py tests/test_render_frame.py

:func:`markdown_tables` makes the docs' tables from that JSON (tools/docs_figures.py).
"""

from __future__ import annotations

RESULT_JSON = "benchmarks/tested_figures.json"

#: The hue cases of tests/test_display_gl.py, in the table's order.
HUE_CASES = (("lace-fwa", "UV-A", "lace UV-A"), ("fluoro-pink", "D65", "pink D65"),
             ("fluoro-pink", "UV-A", "pink UV-A"), ("safety-yellow", "D65", "yellow D65"),
             ("safety-yellow", "UV-A", "yellow UV-A"))


def _select(figures: dict, prefix: str) -> dict:
    return {key[len(prefix):]: value for key, value in figures.items() if key.startswith(prefix)}


def _display_checks(f: dict) -> tuple[str, str]:
    twins = _select(f, "display.twin|")
    identical = sum(1 for t in twins.values() if t["max_levels"] == 0)
    others = "; ".join(f"{k.replace('|', ' ')} {100 * t['equal']:.2f} % equal, max {t['max_levels']:.0f}"
                       for k, t in twins.items() if t["max_levels"] > 0)
    twin = f"{len(twins)} scenes: {identical} bit-identical" + (f"; {others}" if others else "")
    clip = f["display.clipped"]
    hues = "; ".join(f"{label} {h['shown_deg']:.1f} / {h['exact_deg']:.1f}"
                     for fabric, light, label in HUE_CASES
                     if (h := f.get(f"display.hue|{fabric}|{light}")) is not None)
    dr, dg, db = f["display.table2_change_levels"]
    rows = [
        ("shader = numpy twin, per channel value", ">= 99.9 % within 1 level, none > 4", twin),
        ("curtain pixels clipped (255, or 0 in a pixel with a channel >= 32), 10 fabrics x 12 "
         "lights (D65, D50, A, FL2, FL11, HP1, LED-B4, LED-warm, UV-A, sun:22, sun:300, sun:500), "
         "automatic exposure", "<= 1 % each",
         f"{100 * clip['worst_fraction']:.2f} % at most in all {clip['cases']}"),
        ("CIELAB hue, displayed mean vs exact (float64, 1 nm) mean, same white balance",
         "<= 10 deg", hues + " (shown / exact)"),
        ("sun:500, lace vs safety yellow", ">= 10 Delta E 2000",
         f"{f['display.sunset_lace_vs_yellow_delta_e']:.1f}"),
        ("lace under A, chroma (D65 display white)", "C*ab <= 10", f"{f['display.lace_a_chroma']:.1f}"),
        ("Table 2 on the display, noon sun, same fixed EV",
         "B up > 3 levels, > 5x |dG| and |dR|; |dR| <= |dG|", f"R {dr:+.1f}, G {dg:+.1f}, B {db:+.1f}"),
    ]
    table = "\n".join(["| check | bound | measured |", "|---|---|---|"]
                      + [f"| {a} | {b} | {c} |" for a, b, c in rows])
    worst_hue = max(abs((h["shown_deg"] - h["exact_deg"] + 180) % 360 - 180)
                    for h in _select(f, "display.hue|").values())
    brief = (f"Over the 10 fabrics x 12 lights, at most {100 * clip['worst_fraction']:.2f} % of a "
             f"frame's curtain pixels clip a channel at the automatic exposure (bound 1 %); the UV-A "
             f"glow and the two dyes show within {worst_hue:.1f} degrees of CIELAB hue of their exact "
             f"spectral colours (bound 10); at sunset the lace and the safety yellow differ by Delta E "
             f"2000 {f['display.sunset_lace_vs_yellow_delta_e']:.1f} (bound 10); under A the lace shows "
             f"as white (C*ab {f['display.lace_a_chroma']:.1f}, bound 10).")
    return table, brief


def _render_reference(f: dict) -> tuple[str, str]:
    cases = _select(f, "render.rgb_vs_reference|")
    lines = ["| light | fluorescence | options | max relative error per pixel and channel |",
             "|---|---|---|---|"]
    for key, error in cases.items():
        light, mode, options = key.split("|")
        lines.append(f"| {light} | {mode} | {options if options != '-' else ''} | {error:.2g} |")
    brief = (f"Per pixel, the RGB shader's linear radiance is within {max(cases.values()):.2g} "
             "relative of the float64 reference (bound 1e-3) under D65, A, FL11, the sun, UV-A and "
             "1e9 lx, and exactly zero in zero light.")
    return "\n".join(lines), brief


def markdown_tables(result: dict) -> dict[str, str]:
    """``display_checks`` (docs/display.md), ``display_checks_brief`` (README),
    ``render_reference_error`` (docs/render.md) and ``render_reference_brief`` (README)."""
    f = result["figures"]
    display, display_brief = _display_checks(f)
    reference, reference_brief = _render_reference(f)
    return {"display_checks": display, "display_checks_brief": display_brief,
            "render_reference_error": reference, "render_reference_brief": reference_brief}
