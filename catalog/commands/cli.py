"""The ``catalog`` command.

Each subcommand lives in ``catalog/commands/<name>.py`` and defines

- ``HELP``: a one-line summary,
- ``add_arguments(parser)``: its options (argparse), and
- ``run(args) -> int``: the work; it imports what it needs (numpy, scipy, GL) inside.

Command modules import nothing heavy at module level, so ``catalog --help`` stays fast.
A :class:`catalog.core.errors.CatalogError` becomes one line on stderr and exit status 2
(3 for :class:`catalog.core.errors.EnvironmentFailure`: a library the machine lacks).
"""

from __future__ import annotations

import argparse
import importlib
import sys

from catalog import __version__
from catalog.core.errors import CatalogError

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
    "reference": "catalog.commands.reference",
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
        command_parser.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except CatalogError as exc:
        print(f"catalog {args.command}: error: {exc}", file=sys.stderr)
        return int(getattr(exc, "exit_code", 2))  # 2: the input; 3: the environment
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
