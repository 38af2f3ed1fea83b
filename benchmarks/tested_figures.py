"""Figures the tests measure, as the docs quote them.

Some tests measure a figure and hold it to a bound (the bound stated in the test before the
figure was seen). The docs quote those figures; instead of copying them from a test's
output, the tests record them (the ``record_figure`` fixture of tests/conftest.py), and a
run with ``CATALOG_RECORD_FIGURES`` set merges them into benchmarks/tested_figures.json:

    CATALOG_RECORD_FIGURES=$PWD/benchmarks/tested_figures.json .venv/bin/python -m pytest \\
        tests/test_display_gl.py tests/test_render_frame.py tests/test_render_pattern.py \\
        tests/test_uv_fluorescence.py

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


def _short(name: str) -> str:
    return name.split("-")[0]


def _pattern_checks(f: dict) -> tuple[str, str]:
    far = _select(f, "pattern.far_limit|")
    pairs = _select(f, "pattern.pairwise|")
    lo_far, hi_far = min(far, key=far.get), max(far, key=far.get)
    lo_pair, hi_pair = min(pairs, key=pairs.get), max(pairs, key=pairs.get)

    def pair(key: str) -> str:
        return "/".join(_short(n) for n in key.split("|"))
    oit = _select(f, "pattern.oit_over_bound|")
    oit_text = f"{oit['auto']:.2f} of the bound" + (f" (MSAA path: {oit['msaa']:.2f})" if "msaa" in oit else "")
    peak = f["pattern.spectrum_peak"]
    dolly = f["pattern.dolly_levels"]
    edges = _select(f, "pattern.edges_levels|")

    def edge(mode: str) -> str:
        e = edges.get(mode)
        return f"{e['with']:.1f} vs {e['without']:.1f} levels" if e else "not run"
    rows = [
        ("open area of every preset's coverage vs LD", "1 %", "by construction < 1e-5"),
        ("mip chain's last level vs 1 - LD, every preset", "1 %, normal tilt < 1 deg", "pass"),
        ("OIT vs sorted, two layers", "see above", oit_text),
        ("a known pattern read back", "thread exactly in the quarter the uvs name", "pass"),
        ("far limit (48x36 at 4.3 m: a pixel > the 0.1 m repeat) vs the flat cloth, "
         f"{len(far)} fabrics", "Delta E 2000 <= 0.5",
         f"{far[lo_far]:.3f} ({_short(lo_far)}) .. {far[hi_far]:.2f} ({_short(hi_far)})"),
        ("white fabrics pairwise, default view, D65, settled drapes, 256x144",
         "mean per-pixel Delta E 2000 >= 3",
         f"{pairs[lo_pair]:.1f} ({pair(lo_pair)}) .. {pairs[hi_pair]:.1f} ({pair(hi_pair)})"),
        ("the lace at 0.3 m, luminance spectrum", "off-axis peak at the rosette lattice (+-1 bin)",
         f"({peak['peak'][0]:g}, {peak['peak'][1]:g}) cycles/image, expected "
         f"({peak['expected'][0]:.1f}, {peak['expected'][1]:.1f})"),
        ("dolly 3 m -> 0.2 m, 40 frames, 128x96, one exposure",
         "filtered <= 0.6 x unfiltered, < 8 levels (6 under the old Reinhard display)",
         f"{dolly['filtered']:.1f} vs {dolly['unfiltered']:.1f} levels"),
        ("the pattern's LOD bias (log2 1/sqrt 3) vs the hardware's level, lace at 0.8 m, 96x72, "
         "against its 4x4 box (hardware level)", "mean relative luminance error <= 0.85 x",
         (f"{lod['box variance']:.4f} vs {lod['hardware level']:.4f}"
          if (lod := f.get("pattern.lod_bias_box_error")) else "not run")),
        ("FXAA vs a 4x4 supersampled frame, edge pixels", "<= 0.8 x no AA", edge("fxaa")),
        ("MSAA 4x vs the same reference, edge pixels", "<= 0.8 x no AA", edge("msaa")),
        ("MSAA vs one sample, curtain interior (HDR)", "mean relative difference < 2 %",
         f"{100 * f['pattern.msaa_interior_relative']:.1f} %"),
        ("MSAA at fold silhouettes (settled lace, 320x180)", "< one-sample 3x3 max + 10 levels",
         f"{f['pattern.msaa_silhouette_excess_levels']:+.1f}"),
        ("the panel's zoom (imgui, no window: clicks at the slider's ends, reset)",
         "within 5 % of 0.2 m / the room limit; home exactly", "pass (tests/test_viewer_zoom.py)"),
    ]
    table = "\n".join(["| check | bound (stated before measuring) | measured |", "|---|---|---|"]
                      + [f"| {a} | {b} | {c} |" for a, b, c in rows])
    brief = (f"The white fabrics differ pairwise by a mean Delta E 2000 of "
             f"{pairs[lo_pair]:.1f}-{pairs[hi_pair]:.1f} at the default view (bound 3).")
    return table, brief


def markdown_tables(result: dict) -> dict[str, str]:
    """``display_checks`` (docs/display.md), ``display_checks_brief`` (README),
    ``render_reference_error`` (docs/render.md), ``render_reference_brief`` (README),
    ``pattern_checks`` (docs/pattern.md), ``pattern_pairwise_brief`` (README) and
    ``render_led405_brief`` (docs/render.md)."""
    f = result["figures"]
    display, display_brief = _display_checks(f)
    reference, reference_brief = _render_reference(f)
    out = {"display_checks": display, "display_checks_brief": display_brief,
           "render_reference_error": reference, "render_reference_brief": reference_brief}
    blue = f.get("render.led405_blue")
    if blue:
        out["render_led405_brief"] = (
            f"its mean blue channel is {blue['lace'] / blue['voile']:.1f}x the plain voile's "
            f"({blue['lace']:.0f} against {blue['voile']:.0f} of 255; the test holds >= 1.2x and the "
            "voile unclipped)")
    if "pattern.spectrum_peak" in f:
        out["pattern_checks"], out["pattern_pairwise_brief"] = _pattern_checks(f)
    return out
