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
    return {"bispectral-summary": "\n".join(lines), "bispectral-goal": goal_line}
