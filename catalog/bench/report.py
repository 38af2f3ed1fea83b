"""The benchmark report: a markdown table per section, one JSON file, the plots.

:func:`write_report` writes into a folder ``bench.md``, ``bench.json`` and the PNG plots
(matplotlib, Agg) of the sections that have one; all three are written atomically.
"""

from __future__ import annotations

import json
import math
from pathlib import Path


def fmt(value, digits: int = 3) -> str:
    """A number for a table: 3 significant digits, small and large values in e-notation."""
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return str(value)
        if value == 0:
            return "0"
        if abs(value) < 1e-3 or abs(value) >= 1e5:
            return f"{value:.{digits - 1}e}"
        return f"{value:.{digits}g}"
    return str(value)


def table(rows: list[dict], columns: list[str], headers: list[str] | None = None) -> str:
    headers = headers or columns
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(columns)]
    for row in rows:
        lines.append("| " + " | ".join(fmt(row.get(c, "")) for c in columns) + " |")
    return "\n".join(lines)


def colour_md(result: dict) -> str:
    s = result["summary"]
    st = result["settings"]
    rows = [{"variant": k, **v} for k, v in s["per_variant"].items()]
    text = [f"Fabrics: {', '.join(st['fabrics'])}; lights: {', '.join(st['lights'])}. "
            f"Delta E 2000 over the lit cloth at {st['error_size'][0]}x{st['error_size'][1]} px "
            f"against the float64 spectral reference of the physical model; whole frame at "
            f"{st['time_size'][0]}x{st['time_size'][1]} px, median of {st['repeats']} "
            f"({st['device']['renderer']}).", "",
            table(rows, ["variant", "mean_delta_e", "worst_case_mean_delta_e", "mean_p95_delta_e",
                         "worst_p95_delta_e", "median_frame_ms", "median_time_ratio",
                         "median_cpu_time_ratio", "cases_mean_below_goal", "cases"],
                  ["variant", "mean dE", "worst case mean dE", "mean p95 dE", "worst p95 dE",
                   "frame ms (median)", "x RGB frame, wall (median)", "x RGB frame, CPU (median)",
                   "cases mean < 0.5", "cases"]),
            "", "Mean Delta E per light (over the fabrics):", "",
            table([{"light": light, **values} for light, values in s["per_light_mean_delta_e"].items()],
                  ["light"] + list(s["per_variant"])),
            "",
            f"Pareto front: {', '.join(s['pareto_front'])}. Default chosen: "
            f"**{s['default'] or 'none'}** (goal: mean Delta E < {s['goal']['mean_delta_e_below']} "
            f"in every case at <= {s['goal']['time_ratio_at_most']}x the RGB frame time: "
            f"{'met' if s['goal_met'] else 'NOT met'})."]
    return "\n".join(text)


def fluorescence_md(result: dict) -> str:
    from catalog.bench.fluorescence_rgb import markdown_tables  # noqa: PLC0415

    blocks = markdown_tables(result)
    return blocks["fluorescence_representations"] + "\n\n" + blocks["fluorescence_findings"]


def fit_md(result: dict) -> str:
    rows = [{"method": k, **v} for k, v in result["summary"]["per_method"].items()]
    return "\n".join([
        table(rows, ["method", "median_seconds", "median_weighted_rms_over_best",
                     "worst_weighted_rms_over_best", "synthetic_max_rel_param_error"],
              ["method", "median time s", "weighted RMS / best (median)", "worst",
               "synthetic: max rel. parameter error"]),
        "", "Per case:", "",
        table(result["rows"], ["case", "method", "seconds", "rmse_4800", "weighted_rms_4800",
                               "direct", "a_diff", "a_spec", "g_diff", "g_spec"])])


def cloth_md(result: dict) -> str:
    st = result["settings"]
    return "\n".join([
        f"Grid {st['grid'][0]}x{st['grid'][1]}, {st['frames']} frames of {fmt(st['frame_dt_s'])} s, "
        f"wind {st['wind_m_s']} m/s; reference: {st['reference_substeps']} substeps on "
        f"{st['reference_backend']}; the simulator's default: {st['default_substeps']} substeps. "
        f"Backends available: {', '.join(k for k, v in st['backends_available'].items() if v)}.", "",
        table(result["rows"], ["backend", "substeps", "rms_deviation_m", "max_deviation_m",
                               "frames_per_second", "finite"],
              ["backend", "substeps", "RMS deviation m", "max deviation m", "frames/s", "finite"])])


def stability_md(result: dict) -> str:
    s = result["summary"]
    rows = [{"probe": k, **v} for k, v in s["per_probe"].items()]
    bad = [r for r in result["rows"] if r["non_finite"]]
    lines = [table(rows, ["probe", "checked", "worst_rel_error", "non_finite"],
                   ["probe", "values checked", "worst relative error", "non-finite"]), "",
             f"Non-finite values: {s['non_finite']} (bar: zero, {'met' if s['bar_met'] else 'NOT met'})."]
    if bad:
        lines += ["", "Where:", ""] + [f"- {r['probe']}: {r['parameter']}: {r['non_finite']}"
                                       for r in bad]
    lines += ["", "All probes:", "", table(result["rows"], ["probe", "parameter", "checked",
                                                            "worst_rel_error", "non_finite"])]
    return "\n".join(lines)


def startup_md(result: dict) -> str:
    from catalog.bench.startup import markdown_tables  # noqa: PLC0415

    return markdown_tables(result)["startup"]


def room_md(result: dict) -> str:
    from catalog.bench.room import markdown_tables  # noqa: PLC0415

    return "\n\n".join(markdown_tables(result).values())


def image_md(result: dict) -> str:
    from catalog.bench.image import markdown_tables  # noqa: PLC0415

    blocks = markdown_tables(result)
    return blocks["image"] + "\n\nReal-time options (image-pareto.png):\n\n" + blocks["image-options"]


def uv_md(section: dict) -> str:
    from catalog.bench.uv_fluorescence import markdown_tables  # noqa: PLC0415

    return "\n\n".join(markdown_tables(section).values())


def display_md(result: dict) -> str:
    from catalog.bench.display import markdown_tables  # noqa: PLC0415

    return markdown_tables(result)["display_cost"]


SECTION_MD = {"colour": ("Colour accuracy against frame time", colour_md),
              "fluorescence": ("Fluorescence in an RGB engine (measured Donaldson matrices)", fluorescence_md),
              "uv": ("Fluorescence under UV and violet light: noise floor and banded model", uv_md),
              "fit": ("Eq. 7 fit: accuracy against time", fit_md),
              "cloth": ("Cloth: substeps and backend against a small-step reference", cloth_md),
              "stability": ("Numerical stability at the parameters' edges", stability_md),
              "startup": ("Start-up", startup_md),
              "room": ("The room lit through the curtain: frame with and without", room_md),
              "display": ("The display step's cost in the frame", display_md),
              "image": ("The real-time frame against the path-traced reference", image_md)}


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


#: Sections that draw, and so need an OpenGL context (catalog bench makes one for them).
GL_SECTIONS = ("colour", "stability", "display", "image")


def machine_info(ctx=None) -> dict:
    """The machine a result was measured on: cores, platform, Python, the GL renderer."""
    import os  # noqa: PLC0415
    import platform  # noqa: PLC0415

    machine = {"cpu_count": os.cpu_count(), "platform": platform.platform(),
               "python": platform.python_version(),
               "load_average_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None}
    if ctx is not None:
        from catalog.gl.context import describe  # noqa: PLC0415

        machine["gl_renderer"] = describe(ctx)["renderer"]
    return machine


def section_main(name: str, argv: list[str] | None = None) -> int:
    """``python -m catalog.bench.<module>`` for a section of ``catalog bench``: run it at full
    size (``--quick``: the CI size), write its result with the machine to the module's
    committed JSON (``RESULT_JSON`` under the checkout; ``--json-out FILE`` elsewhere) and
    print the tables the docs are generated from (tools/docs_figures.py)."""
    import argparse  # noqa: PLC0415
    import importlib  # noqa: PLC0415
    import time  # noqa: PLC0415

    from catalog.bench import SECTIONS  # noqa: PLC0415
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415
    from catalog.core.jsonout import _plain  # noqa: PLC0415
    from catalog.core.resources import PROJECT_ROOT  # noqa: PLC0415

    module = importlib.import_module(SECTIONS[name])
    parser = argparse.ArgumentParser(description=(module.__doc__ or name).splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the CI size (fewer cases, repeats)")
    parser.add_argument("--json-out", type=Path, default=PROJECT_ROOT / module.RESULT_JSON,
                        metavar="FILE", help=f"write the result here (default {module.RESULT_JSON})")
    args = parser.parse_args(argv)
    ctx = None
    if name in GL_SECTIONS:
        from catalog.gl.context import create_headless_context  # noqa: PLC0415

        ctx = create_headless_context()
    try:
        start = time.perf_counter()
        result = module.run(quick=args.quick, ctx=ctx)
        result["seconds"] = time.perf_counter() - start
        result["quick"] = bool(args.quick)
        result["machine"] = machine_info(ctx)
    finally:
        if ctx is not None:
            ctx.release()
    write_text_atomic(args.json_out, json.dumps(_plain(result), indent=1, allow_nan=False) + "\n")
    for table_name, text in module.markdown_tables(result).items():
        print(f"<!-- generated:{table_name} -->\n{text}\n<!-- /generated:{table_name} -->\n")
    print(f"wrote {args.json_out}")
    return 0
