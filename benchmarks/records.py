"""Measurements recorded from earlier states of the code, rendered for the docs.

Some figures in the docs were measured on code that no longer exists (a shader before an
optimisation, a scratch copy with a term removed); today's code cannot re-run them. They
live in benchmarks/recorded_figures.json, each record with its provenance (the commit, date
and command or document it came from), and :func:`markdown_tables` renders each record as a
table ending in that provenance, so the docs quote the record instead of typing the figures.
A figure that today's code can measure belongs to the benchmark that measures it, not here.

Record format: ``{"records": {NAME: {"doc": str, "provenance": str, "columns": [str, ...],
"rows": [[cell, ...], ...]}}}``; a cell is a string, a number or null (shown empty).
"""

from __future__ import annotations

RESULT_JSON = "benchmarks/recorded_figures.json"


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.2f}" if abs(value) < 10 else f"{value:.1f}"
    return str(value)


def render_record(record: dict) -> str:
    """One record as a markdown table followed by its provenance."""
    columns = record["columns"]
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for row in record["rows"]:
        if len(row) != len(columns):
            raise ValueError(f"a row of {len(row)} cells under {len(columns)} columns: {row}")
        lines.append("| " + " | ".join(_cell(v) for v in row) + " |")
    lines.append(f"\n*Historical record, not re-runnable on today's code; from {record['provenance']} "
                 f"({RESULT_JSON}).*")
    return "\n".join(lines)


def markdown_tables(result: dict) -> dict[str, str]:
    """NAME -> markdown for every record."""
    return {name: render_record(record) for name, record in result["records"].items()}
