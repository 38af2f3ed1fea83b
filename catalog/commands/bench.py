"""``catalog bench``: run time against error, every benchmark side by side.

    catalog bench [--quick] [--json] [--out DIR] [--sections colour,fluorescence,...]

Runs the sections of the ``benchmarks`` suite (top level, in a checkout) (colour accuracy against frame time,
fluorescence representations on measured matrices, fit, cloth, numerical stability,
start-up) and writes ``bench.md`` (tables), ``bench.json`` and PNG plots into DIR
(default ``bench-out``). ``--json`` prints the same report as one JSON object on stdout;
progress goes to stderr. ``--quick`` runs a reduced set (a few minutes on two cores).
docs/bench.md has the latest figures.
"""

from __future__ import annotations

import sys

RESOURCES = ("data",)
#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
OUTPUT_FOLDERS = ("out",)
HELP = "benchmarks: colour error against frame time, fluorescence, fit, cloth, stability, start-up"

DEFAULT_OUT = "bench-out"


def load_benchmarks():
    """The benchmark suite (top-level ``benchmarks/`` of a checkout; not in the wheel).

    The installed product carries no benchmarks: outside a checkout this is one line and
    the environment exit code."""
    import importlib  # noqa: PLC0415

    from catalog.core.errors import EnvironmentFailure  # noqa: PLC0415
    from catalog.core.resources import IN_CHECKOUT, PROJECT_ROOT  # noqa: PLC0415

    if IN_CHECKOUT and (PROJECT_ROOT / "benchmarks" / "__init__.py").is_file():
        root = str(PROJECT_ROOT)
        if root not in sys.path:
            sys.path.insert(0, root)
    try:
        return importlib.import_module("benchmarks")
    except ModuleNotFoundError as exc:
        if exc.name != "benchmarks":
            raise
        raise EnvironmentFailure("the benchmarks are not part of the installed product: run "
                                 "`catalog bench` (or `python -m benchmarks`) in a checkout of "
                                 "the repository") from None


def add_arguments(parser) -> None:
    parser.add_argument("--quick", action="store_true",
                        help="reduced cases and repeats (a few minutes; for CI)")
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    parser.add_argument("--out", default=DEFAULT_OUT, metavar="DIR",
                        help=f"folder for bench.md, bench.json and the plots (default {DEFAULT_OUT})")
    parser.add_argument("--sections", metavar="NAME,NAME",
                        help="run only these sections (default: all): colour, fluorescence, uv, "
                             "fit, cloth, stability, startup, display, image, accuracy")
    parser.add_argument("--scenes", type=int, default=None, metavar="N",
                        help="accuracy: scenes drawn at random (default 48; --quick 2)")
    parser.add_argument("--seed", type=int, default=None, metavar="S",
                        help="accuracy: the draw's seed (default the report seed)")
    parser.add_argument("--room", default=None, metavar="NAME",
                        help="accuracy: only this built-in room (default: all drawn)")


def parse_sections(text: str | None) -> list[str]:
    from catalog.core.errors import InputError  # noqa: PLC0415

    SECTIONS = load_benchmarks().SECTIONS

    if text is None:
        return list(SECTIONS)
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in SECTIONS]
    if unknown or not names:
        raise InputError(f"unknown section {', '.join(unknown) or '(none given)'}; choose from "
                         f"{', '.join(SECTIONS)}", field="--sections")
    return [n for n in SECTIONS if n in names]


def run(args) -> int:
    import contextlib  # noqa: PLC0415
    import sys  # noqa: PLC0415
    from pathlib import Path  # noqa: PLC0415

    load_benchmarks()   # the suite (a checkout's benchmarks/), or one line saying it is absent
    from benchmarks.results import GL_SECTIONS  # noqa: PLC0415
    from catalog.core.errors import InputError  # noqa: PLC0415
    from catalog.core.jsonout import print_json  # noqa: PLC0415
    from catalog.gl.context import headless_context  # noqa: PLC0415

    names = parse_sections(args.sections)
    if args.scenes is not None and not 1 <= args.scenes <= 1000:
        raise InputError(f"{args.scenes}: give 1 to 1000 scenes", field="--scenes")
    if args.room is not None:
        from benchmarks.accuracy import check_room  # noqa: PLC0415

        check_room(args.room)
    if "fluorescence" in names:  # the measured matrices are not shipped: say so, run nothing
        from catalog.core.resources import data_missing_reason  # noqa: PLC0415

        reason = data_missing_reason("bispectral")
        if reason is not None:
            raise InputError(f"section fluorescence needs the measured matrices: {reason}; "
                             "or leave it out with --sections", field="--data")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"{str(out)!r} exists and is not a folder", field="--out")

    def say(text: str) -> None:
        print(f"catalog bench: {text}", file=sys.stderr, flush=True)

    # the GL sections' context, released at the end (the caller's current context current again)
    with (headless_context() if any(n in GL_SECTIONS for n in names)
          else contextlib.nullcontext()) as ctx:
        report = _run_sections(names, args, out, ctx, say)
    say(f"wrote {', '.join(report['written'])}")
    if args.json:
        print_json(report)
    else:
        print((out / "bench.md").read_text(encoding="utf-8"))
    return 1 if report["failed"] else 0


def _run_sections(names, args, out, ctx, say) -> dict:
    """The report of the named sections, run in ``ctx`` (None: no GL section) and written to
    the folder ``out`` (the files in its ``written``)."""
    import time  # noqa: PLC0415

    from benchmarks.report import write_report  # noqa: PLC0415
    from benchmarks.results import machine_info  # noqa: PLC0415

    machine = machine_info(ctx)
    report = {"benchmark": "catalog bench", "quick": bool(args.quick), "machine": machine,
              "sections": {}, "failed": {}}
    start_all = time.perf_counter()
    plotters = {}
    from catalog.core.progress import progress  # noqa: PLC0415

    with progress("catalog bench", total=len(names), unit="sections",
                  enabled=not args.json) as bar:
        for name in names:
            _run_section(name, args, ctx, report, plotters, say)
            bar.advance()
    report["total_seconds"] = time.perf_counter() - start_all
    report["written"] = [str(p) for p in write_report(report, out, plotters)]
    return report


def _run_section(name, args, ctx, report, plotters, say) -> None:
    """One section into ``report`` (a failure is recorded; the others still run)."""
    import importlib  # noqa: PLC0415
    import sys  # noqa: PLC0415
    import time  # noqa: PLC0415
    import traceback  # noqa: PLC0415

    from benchmarks import SECTIONS  # noqa: PLC0415

    module = importlib.import_module(SECTIONS[name])
    say(f"{name} ...")
    start = time.perf_counter()
    try:
        options = module.section_options(args) if hasattr(module, "section_options") else {}
        if hasattr(module, "section_options"):
            options["progress"] = say
        result = module.run(quick=bool(args.quick), ctx=ctx, **options)
    except Exception as exc:  # noqa: BLE001 - one broken section must not lose the others
        report["failed"][name] = f"{type(exc).__name__}: {exc}"
        say(f"{name} FAILED: {type(exc).__name__}: {exc}")
        traceback.print_exc(file=sys.stderr)
        return
    result["seconds"] = time.perf_counter() - start
    report["sections"][name] = result
    if hasattr(module, "plot"):
        plotters[name] = module.plot
    say(f"{name} done in {result['seconds']:.1f} s")
