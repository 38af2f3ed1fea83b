"""Figures of the bispectral study for the docs, from its committed JSON.

``tools/bispectral_table.py --json benchmarks/bispectral.json`` runs the study (the eight
measured Donaldson matrices x the study's lights, catalog.optics.bispectral.study) and
writes the rows and summaries; :func:`markdown_tables` turns that JSON into the tables
that README.md and the docs show between ``<!-- generated:NAME -->`` markers
(tools/docs_figures.py fills them; a test checks the committed docs equal the result).
"""

from __future__ import annotations

#: The committed result this module's tables are made from (relative to the repository).
RESULT_JSON = "benchmarks/bispectral.json"

#: The goal set's lights (catalog.optics.bispectral.study.GOAL_LIGHTS, repeated so that the
#: docs' figures need no import of the study).
GOAL_LIGHTS = ("D65", "A", "FL2", "FL11", "LED-B4")

#: README's rows: (study method, label).
SUMMARY_ROWS = [
    ("ignore", "ignoring fluorescence"),
    ("paper", "paper mode (eq. 8), scale per material"),
    ("reduced_3x3", "reduced 3x3 after Fichet, Belcour and Barla 2024 (ours)"),
    ("reduced_3x3_uv", "the same with a UV band"),
    ("physical_lsq", "physical mode, separable fit by least squares on the matrix entries"),
    ("physical", "**physical mode, separable fit refined for colour (default)**"),
]


def _cell(value: float, bold: bool) -> str:
    text = f"{value:.2f}"
    return f"**{text}**" if bold else text


def markdown_tables(result: dict) -> dict[str, str]:
    """NAME -> markdown: ``bispectral-summary`` (mean / max Delta E 2000 over 8 matrices x
    D65, A, FL2, FL11, LED-B4 per method) and ``bispectral-goal`` (the default model
    against the goal)."""
    summary = result["summary_goal_lights"]
    lines = ["| method | mean | max |", "|---|---|---|"]
    for method, label in SUMMARY_ROWS:
        bold = label.startswith("**")
        lines.append(f"| {label} | {_cell(summary[method]['mean'], bold)} | "
                     f"{_cell(summary[method]['max'], bold)} |")
    physical, goal = summary["physical"], result["goal"]
    met = physical["mean"] <= goal["mean"] and physical["max"] <= goal["max"]
    goal_line = (f"Physical mode (the default) on the 8 matrices x D65, A, FL2, FL11, LED-B4: "
                 f"Delta E 2000 mean {physical['mean']:.2f}, max {physical['max']:.2f}; "
                 f"goal mean <= {goal['mean']:g}, max <= {goal['max']:g}: "
                 f"{'met' if met else 'NOT met'}.")
    tables = {"bispectral-summary": "\n".join(lines), "bispectral-goal": goal_line}
    tables.update(prose_figures(result))
    return tables


def _pair(summary: dict, method: str, digits: int = 2) -> str:
    return f"{summary[method]['mean']:.{digits}f} / {summary[method]['max']:.{digits}f}"


def prose_figures(result: dict) -> dict[str, str]:
    """The sentences of docs/bispectral.md that quote the study (NAME -> markdown)."""
    summary, sota, goal = result["summary_goal_lights"], result["state_of_the_art"], result["goal"]
    goal_lights = {r["light"] for r in result["rows"] if r["light"] in GOAL_LIGHTS}
    goal_rows = [r for r in result["rows"] if r["light"] in goal_lights]
    physical = summary["physical"]
    separable = sota["separable (exact per light)"]
    largest = sorted(goal_rows, key=lambda r: -r["physical"])[:5]
    above = [r for r in goal_rows if r["physical_lsq"] > goal["max"]]
    out = {}
    out["bispectral-ignore"] = (
        f"Ignoring fluorescence: {_pair(summary, 'ignore')} here against "
        f"{sota['ignoring fluorescence'][0]} / {sota['ignoring fluorescence'][1]} in model.md "
        "section 8 (mean / max Delta E 2000, 8 matrices x D65, A, FL2, FL11, LED-B4).")
    out["bispectral-reduced"] = (
        f"Reduced 3x3: {_pair(summary, 'reduced_3x3')} against their "
        f"{sota['Fichet et al. reduced 3x3'][0]} / {sota['Fichet et al. reduced 3x3'][1]}; "
        f"with our UV box {_pair(summary, 'reduced_3x3_uv')} against their "
        f"{sota['Fichet et al. 3x3 + UV band'][0]} / {sota['Fichet et al. 3x3 + UV band'][1]} "
        "(mean / max, the goal set).")
    out["bispectral-10nm"] = (
        f"Everything sampled every 10 nm against the 1 nm evaluation: "
        f"{summary['data_10nm']['mean']:.2f} mean, {summary['data_10nm']['max']:.2f} max over "
        "the goal set.")
    rgb_gap = max(abs(r["physical_rgb"] - r["physical"]) for r in result["rows"])
    out["bispectral-rgb"] = (
        f"(d) against (c): at most {rgb_gap:.1e} Delta E 2000 over every matrix and light of "
        f"the study; (d') RGB albedo x light: {_pair(summary, 'rgb_product')} on the goal set, "
        f"{summary['rgb_product']['mean'] / physical['mean']:.0f} times (c) in the mean.")
    out["bispectral-goal-detail"] = (
        f"Against the state of the art's separable model ({separable[0]} / {separable[1]}): "
        f"{physical['mean'] - separable[0]:+.2f} on the mean, {physical['max'] - separable[1]:+.2f} "
        "on the max. The largest cases: "
        + ", ".join(f"{r['material']} under {r['light']} {r['physical']:.2f}" for r in largest)
        + f". The least-squares fit alone: {_pair(summary, 'physical_lsq')}; above "
        f"{goal['max']:g}: "
        + (", ".join(f"{r['material']} under {r['light']} {r['physical_lsq']:.2f} (the "
                     f"matrix's anti-Stokes part alone moves the exact colour "
                     f"{r['data_antistokes']:.2f})" for r in above) or "none") + ".")
    out["bispectral-islands"] = (
        f"With absorption islands (least squares): {_pair(summary, 'physical_islands')} on the "
        "goal set.")
    out["bispectral-paper"] = (
        f"Paper mode on the goal set: {_pair(summary, 'paper', 1)} with k per material, "
        f"{_pair(summary, 'paper_global', 1)} with one k.")
    rows = result["rows"]
    calibration = [r for r in rows if r["light"] == "D65"]
    exceptions = [r for r in rows if r["light"] != "D65" and r["physical"] >= r["paper"]]
    out["bispectral-paper-exceptions"] = (
        f"Under D65 (c) and (b) differ by at most "
        f"{max(abs(r['physical'] - r['paper']) for r in calibration):.2f}; away from D65 (c) is "
        f"below (b) in {sum(1 for r in rows if r['light'] != 'D65') - len(exceptions)} of "
        f"{sum(1 for r in rows if r['light'] != 'D65')} cases; not in: "
        + (", ".join(f"{r['material']} under {r['light']} ({r['physical']:.2f} against "
                     f"{r['paper']:.2f}; the matrix's anti-Stokes part alone "
                     f"{r['data_antistokes']:.2f})" for r in exceptions) or "none") + ".")
    uv = sorted((r for r in result["rows"] if r["light"] == "UV-A"), key=lambda r: r["physical"])
    out["bispectral-uv-a"] = ("Physical mode under UV-A: "
                              + ", ".join(f"{r['material']} {r['physical']:.1f}" for r in uv) + ".")
    return out
