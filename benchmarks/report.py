"""The benchmark report: a markdown table per section, one JSON file, the plots.

:func:`write_report` writes into a folder ``bench.md``, ``bench.json`` and the PNG plots
(matplotlib, Agg) of the sections that have one; all three are written atomically.
"""

from __future__ import annotations

import json
from pathlib import Path

from benchmarks.results import fmt  # noqa: F401  (the tables' number format, re-exported)


def table(rows: list[dict], columns: list[str], headers: list[str] | None = None) -> str:
    headers = headers or columns
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(columns)]
    for row in rows:
        lines.append("| " + " | ".join(fmt(row.get(c, "")) for c in columns) + " |")
    return "\n".join(lines)


def colour_md(result: dict) -> str:
    from benchmarks.colour import markdown_tables  # noqa: PLC0415

    blocks = markdown_tables(result)
    return blocks["bench_colour"] + "\n\n" + blocks["bench_colour_findings"]


def fluorescence_md(result: dict) -> str:
    from benchmarks.fluorescence_rgb import markdown_tables  # noqa: PLC0415

    blocks = markdown_tables(result)
    return blocks["fluorescence_representations"] + "\n\n" + blocks["fluorescence_findings"]


def fit_md(result: dict) -> str:
    from benchmarks.fit import markdown_tables  # noqa: PLC0415

    return "\n".join([
        markdown_tables(result)["bench_fit"], "", "Per case:", "",
        table(result["rows"], ["case", "method", "seconds", "rmse_4800", "weighted_rms_4800",
                               "direct", "a_diff", "a_spec", "g_diff", "g_spec"])])


def cloth_md(result: dict) -> str:
    from benchmarks.cloth import markdown_tables  # noqa: PLC0415

    return markdown_tables(result)["bench_cloth"]


def stability_md(result: dict) -> str:
    from benchmarks.stability import markdown_tables  # noqa: PLC0415

    return "\n".join([markdown_tables(result)["bench_stability"], "", "All probes:", "",
                      table(result["rows"], ["probe", "parameter", "checked", "worst_rel_error",
                                             "non_finite"])])


def startup_md(result: dict) -> str:
    from benchmarks.startup import markdown_tables  # noqa: PLC0415

    return markdown_tables(result)["startup"]


def room_md(result: dict) -> str:
    from benchmarks.room import markdown_tables  # noqa: PLC0415

    return "\n\n".join(markdown_tables(result).values())


def image_md(result: dict) -> str:
    from benchmarks.image import markdown_tables  # noqa: PLC0415

    blocks = markdown_tables(result)
    return (blocks["image"] + "\n\nReal-time options (image-pareto.png):\n\n"
            + blocks["image-options"] + "\n\n" + blocks["image-options-by-scene"])


def uv_md(section: dict) -> str:
    from benchmarks.uv_fluorescence import markdown_tables  # noqa: PLC0415

    return "\n\n".join(markdown_tables(section).values())


def display_md(result: dict) -> str:
    from benchmarks.display import markdown_tables  # noqa: PLC0415

    return markdown_tables(result)["display_cost"]


def accuracy_md(result: dict) -> str:
    from benchmarks.accuracy import markdown_tables  # noqa: PLC0415

    blocks = markdown_tables(result)
    return blocks["accuracy-summary"] + "\n\n" + blocks["accuracy"]


SECTION_MD = {"colour": ("Colour accuracy against frame time", colour_md),
              "fluorescence": ("Fluorescence in an RGB engine (measured Donaldson matrices)", fluorescence_md),
              "uv": ("Fluorescence under UV and violet light: noise floor and banded model", uv_md),
              "fit": ("Eq. 7 fit: accuracy against time", fit_md),
              "cloth": ("Cloth: substeps and backend against a small-step reference", cloth_md),
              "stability": ("Numerical stability at the parameters' edges", stability_md),
              "startup": ("Start-up", startup_md),
              "room": ("The room lit through the curtain: frame with and without", room_md),
              "display": ("The display step's cost in the frame", display_md),
              "image": ("The real-time frame against the path-traced reference", image_md),
              "accuracy": ("Accuracy over the scene space: frame against reference, neutral display",
                           accuracy_md)}


def markdown(report: dict) -> str:
    m = report["machine"]
    parts = [f"# catalog bench{' --quick' if report['quick'] else ''}", "",
             f"Machine: {m['cpu_count']} CPU cores, {m['platform']}, Python {m['python']}, "
             f"GL: {m.get('gl_renderer', '?')}. Total {fmt(report['total_seconds'])} s.", ""]
    for name, section in report["sections"].items():
        title, render = SECTION_MD[name]
        parts += [f"## {title}", "", f"({fmt(section['seconds'])} s)", "", render(section), ""]
    return "\n".join(parts)


def write_report(report: dict, folder: Path, plotters: dict) -> list[Path]:
    """bench.md, bench.json and each section's plot into ``folder``; returns the paths."""
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415
    from catalog.core.jsonout import _plain  # noqa: PLC0415

    from catalog.core.atomic import staged_folder  # noqa: PLC0415

    written = []
    with staged_folder(folder) as stage:  # the report's files all appear, or none
        for name, plot in plotters.items():
            if name in report["sections"]:
                written += [folder / Path(p).name for p in plot(report["sections"][name], stage)]
        write_text_atomic(stage / "bench.json",
                          json.dumps(_plain(report), indent=1, allow_nan=False) + "\n")
        write_text_atomic(stage / "bench.md", markdown(report) + "\n")
    return [folder / "bench.md", folder / "bench.json"] + written
