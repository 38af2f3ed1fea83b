"""What every benchmark module shares, and nothing else (so that a module may import it
without a cycle): the number format of the tables, the machine a result was measured on, and
``python -m benchmarks.<module>`` for the sections of ``catalog bench``."""

from __future__ import annotations

import json
import math
import sys
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


#: Sections that draw, and so need an OpenGL context (catalog bench makes one for them).
GL_SECTIONS = ("colour", "stability", "display", "image", "accuracy")


def machine_info(ctx=None) -> dict:
    """The machine a result was measured on: cores, platform, Python, the GL renderer."""
    import os  # noqa: PLC0415
    import platform  # noqa: PLC0415

    machine = {"cpu_count": os.cpu_count(), "platform": platform.platform(),
               "python": platform.python_version(),
               "load_average_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None,
               "commit": source_commit()}
    if ctx is not None:
        from catalog.gl.context import describe  # noqa: PLC0415

        machine["gl_renderer"] = describe(ctx)["renderer"]
    return machine


def source_commit() -> str | None:
    """The checkout's commit the measurement runs on (``+dirty`` when files differ from it;
    None outside a git checkout): the tables name it (tools/docs_figures.py)."""
    import subprocess  # noqa: PLC0415

    from catalog.core.resources import PROJECT_ROOT as root  # noqa: PLC0415
    try:
        head = subprocess.run(["git", "rev-parse", "--short=10", "HEAD"], cwd=root,
                              capture_output=True, text=True, timeout=10)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=root, capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return head.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")


def section_main(name: str, argv: list[str] | None = None) -> int:
    """``python -m benchmarks.<module>`` for a section of ``catalog bench``: run it at full
    size (``--quick``: the CI size), write its result with the machine to the module's
    committed JSON (``RESULT_JSON`` under the checkout; ``--json-out FILE`` elsewhere) and
    print the tables the docs are generated from (tools/docs_figures.py)."""
    import argparse  # noqa: PLC0415
    import importlib  # noqa: PLC0415

    from benchmarks import SECTIONS  # noqa: PLC0415
    from catalog.core.resources import PROJECT_ROOT  # noqa: PLC0415

    module = importlib.import_module(SECTIONS[name])
    parser = argparse.ArgumentParser(description=(module.__doc__ or name).splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the CI size (fewer cases, repeats)")
    parser.add_argument("--json-out", type=Path, default=PROJECT_ROOT / module.RESULT_JSON,
                        metavar="FILE", help=f"write the result here (default {module.RESULT_JSON})")
    args = parser.parse_args(argv)
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    try:
        return _run_section(name, module, args)
    except CatalogError as exc:  # missing data, no EGL: one line, the documented exit code
        print(f"{module.__name__}: error: {exc}", file=sys.stderr)
        return exc.exit_code


def _run_section(name: str, module, args) -> int:
    import time  # noqa: PLC0415

    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415
    from catalog.core.jsonout import _plain  # noqa: PLC0415

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


def study_main(module, argv: list[str] | None = None, make_result=None,
               add_arguments=None) -> int:
    """``python -m benchmarks.<study>`` for a study module that is not a section of
    ``catalog bench``: its options (``add_arguments(parser)``), ``--json-out FILE`` (default
    the module's committed ``RESULT_JSON``), the result (``make_result(args)``, default
    ``module.run()``) written atomically, and the blocks the docs are generated from printed.
    Missing data or no EGL: one line and the documented exit code, nothing written."""
    import argparse  # noqa: PLC0415

    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415
    from catalog.core.errors import CatalogError  # noqa: PLC0415
    from catalog.core.resources import PROJECT_ROOT  # noqa: PLC0415

    name = module.__spec__.name if getattr(module, "__spec__", None) else module.__name__
    short = name.rsplit(".", 1)[-1]
    parser = argparse.ArgumentParser(prog=f"python -m {name}",
                                     description=(module.__doc__ or short).splitlines()[0])
    if add_arguments is not None:
        add_arguments(parser)
    parser.add_argument("--json-out", type=Path, default=PROJECT_ROOT / module.RESULT_JSON,
                        metavar="FILE", help=f"write the result here (default {module.RESULT_JSON})")
    args = parser.parse_args(argv)
    try:
        result = make_result(args) if make_result is not None else module.run()
    except CatalogError as exc:
        print(f"{short}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    if isinstance(result, dict) and "machine" not in result:
        # every published result names the commit and machine it was measured on
        # (tools/figures_age.py dates it by that commit, tools/docs_figures.py prints it)
        result["machine"] = machine_info()
    write_text_atomic(args.json_out, json.dumps(result, indent=1, default=float) + "\n")
    for name, text in module.markdown_tables(result).items():
        print(f"<!-- generated:{name} -->\n{text}\n<!-- /generated:{name} -->\n")
    print(f"wrote {args.json_out}")
    return 0


def sized_study_main(module, argv: list[str] | None = None) -> int:
    """:func:`study_main` for a study run at frame sizes: ``--quick`` and ``--sizes WxH[,WxH..]``
    (default the module's DEFAULT_SIZES), then ``module.run(quick=, sizes=)``."""
    def add_arguments(parser) -> None:
        parser.add_argument("--quick", action="store_true", help="fewer cases and repeats")
        parser.add_argument("--sizes", default=",".join(f"{w}x{h}" for w, h in module.DEFAULT_SIZES),
                            help="frame sizes, WxH[,WxH..]")

    def make_result(args) -> dict:
        from catalog.core.errors import InputError  # noqa: PLC0415

        try:
            sizes = [tuple(int(v) for v in s.lower().split("x")) for s in args.sizes.split(",")]
        except ValueError:
            raise InputError(f"{args.sizes!r} is not WxH[,WxH...]", field="--sizes") from None
        if not all(len(size) == 2 for size in sizes):
            raise InputError(f"{args.sizes!r} is not WxH[,WxH...]", field="--sizes")
        return module.run(quick=args.quick, sizes=sizes)

    return study_main(module, argv, make_result=make_result, add_arguments=add_arguments)
