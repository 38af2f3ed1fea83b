"""The ``catalog`` command.

Each subcommand lives in ``catalog/commands/<name>.py`` and defines

- ``HELP``: a one-line summary,
- ``add_arguments(parser)``: its options (argparse), and
- ``run(args) -> int``: the work; it imports what it needs (numpy, scipy, GL) inside.

and, optionally, ``RESOURCES``: which of ``"fabrics"`` (``--fabrics DIR``, searched before
the built-in catalog) and ``"data"`` (``--data DIR``, the validation data) it reads.

Command modules import nothing heavy at module level, so ``catalog --help`` stays fast.

Exit status: 0 done; 2 a refused input (:class:`catalog.core.errors.CatalogError`: one line
on stderr naming the file, field or option); 3 an environment failure
(:class:`catalog.core.errors.EnvironmentFailure`: no EGL device or display, a missing
shader); 130 interrupted. With ``--json`` an error is also one JSON object on stdout,
``{"error": MESSAGE, "exit_code": N}``.
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
from pathlib import Path

from catalog import __version__
from catalog.core.errors import CatalogError
from catalog.core.resources import DATA_ENV, FABRICS_ENV, use_data, use_fabrics

#: Subcommand name -> module. Order is the order shown by ``catalog --help``.
COMMANDS: dict[str, str] = {
    "fluorescence": "catalog.commands.fluorescence",
    "lights": "catalog.commands.lights",
    "sun": "catalog.commands.sun",
    "bispectral": "catalog.commands.bispectral",
    "fit": "catalog.commands.fit",
    "snapshot": "catalog.commands.snapshot",
    "sheet": "catalog.commands.sheet",
    "view": "catalog.commands.view",
    "simulate": "catalog.commands.simulate",
    "bench": "catalog.commands.bench",
    "web": "catalog.commands.web",
}


def _available_commands() -> dict[str, object]:
    """Import the command modules that exist (each is light: no heavy imports at top)."""
    modules = {}
    for name, module_name in COMMANDS.items():
        try:
            modules[name] = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name != module_name:  # a real missing dependency inside the module
                raise
    return modules


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="catalog",
        description="Woven-cloth fabric catalog: fit measurements to presets, compute "
                    "fluorescence, simulate and render curtains under any light.")
    parser.add_argument("--version", action="version", version=f"catalog {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, module in _available_commands().items():
        command_parser = sub.add_parser(name, help=module.HELP, description=module.HELP)
        module.add_arguments(command_parser)
        resources = getattr(module, "RESOURCES", ())
        if "fabrics" in resources and "--fabrics" not in command_parser._option_string_actions:
            command_parser.add_argument(
                "--fabrics", metavar="DIR", action="append", type=Path,
                help="a folder of your own fabric presets, searched before the built-in "
                     f"catalog (repeatable; default ${FABRICS_ENV})")
        if "data" in resources:
            command_parser.add_argument(
                "--data", metavar="DIR", type=Path,
                help="the validation data folder (measured brightener spectra, bispectral "
                     f"matrices; not shipped). Default ${DATA_ENV}, else shared/data beside "
                     "a checkout")
        command_parser.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        if getattr(args, "fabrics", None) and isinstance(args.fabrics, list):
            use_fabrics(args.fabrics)  # a command's own --fabrics (sheet's list) handles itself
        if getattr(args, "data", None) is not None:
            use_data(args.data)
        return int(args._run(args) or 0)
    except CatalogError as exc:
        message = " ".join(str(exc).split())  # one line, whatever the message held
        print(f"catalog {args.command}: error: {message}", file=sys.stderr)
        if getattr(args, "json", False):
            print(json.dumps({"error": message, "exit_code": exc.exit_code}), flush=True)
        return exc.exit_code
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
