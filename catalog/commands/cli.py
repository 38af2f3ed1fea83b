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
shader, an optional package not installed: one line naming the extra to install,
:mod:`catalog.core.extras`); 130 interrupted. With ``--json`` an error is also one JSON object on stdout,
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
from catalog.core.resources import DATA_ENV, use_data, use_fabrics

#: Subcommand name -> module. Order is the order shown by ``catalog --help``.
COMMANDS: dict[str, str] = {
    "fluorescence": "catalog.commands.fluorescence",
    "lights": "catalog.commands.lights",
    "sun": "catalog.commands.sun",
    "bispectral": "catalog.commands.bispectral",
    "fit": "catalog.commands.fit",
    "snapshot": "catalog.commands.snapshot",
    "sheet": "catalog.commands.sheet",
    "render-catalog": "catalog.commands.render_catalog",
    "view": "catalog.commands.view",
    "simulate": "catalog.commands.simulate",
    "bench": "catalog.commands.bench",
    "web": "catalog.commands.web",
    "reference": "catalog.commands.reference",
    "import": "catalog.commands.import_fabric",
    "export": "catalog.commands.export",
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


class CommandLineError(CatalogError):
    """An option argparse refused (unknown, missing, or a value its type refused)."""

    def __init__(self, prog: str, message: str):
        self.prog = prog
        super().__init__(message)


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """--help states every option's default: ``(default: X)`` after the help, unless the
    help already says it or there is none to state (a flag, an option left out)."""

    def _get_help_string(self, action):
        text = action.help or ""
        default = action.default
        if (not action.option_strings or default is None or default is False
                or default is argparse.SUPPRESS or "default" in text.lower()
                or isinstance(action, (argparse._HelpAction, argparse._VersionAction))):
            return text
        return f"{text} (default: {format_default(default)})"


def format_default(value) -> str:
    """An option's default as one would type it: (1280, 720) -> 1280x720, a Path as text."""
    if isinstance(value, tuple) and len(value) == 2 and all(isinstance(v, int) for v in value):
        return f"{value[0]}x{value[1]}"
    if isinstance(value, (list, tuple)):
        return ",".join(str(v) for v in value) if value else "none"
    return str(value).replace("%", "%%")


class _Parser(argparse.ArgumentParser):
    """argparse, but a refused option is one line (no usage block) and, with ``--json``,
    one JSON object like every other refusal: :meth:`error` raises instead of exiting."""

    def error(self, message: str):
        raise CommandLineError(self.prog, message)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="catalog",
        description="Woven-cloth fabric catalog: fit measurements to presets, compute "
                    "fluorescence, simulate and render curtains under any light.")
    parser.add_argument("--version", action="version", version=f"catalog {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True,
                                parser_class=_Parser)
    for name, module in _available_commands().items():
        command_parser = sub.add_parser(name, help=module.HELP, description=module.HELP,
                                        formatter_class=DefaultsHelpFormatter)
        module.add_arguments(command_parser)
        resources = getattr(module, "RESOURCES", ())
        if "fabrics" in resources and "--fabrics" not in command_parser._option_string_actions:
            from catalog.core.fabricargs import add_fabric_folders  # noqa: PLC0415

            add_fabric_folders(command_parser)
        if "data" in resources:
            command_parser.add_argument(
                "--data", metavar="DIR", type=Path,
                help="the validation data folder (measured brightener spectra, bispectral "
                     f"matrices; not shipped). Default ${DATA_ENV}, else shared/data beside "
                     "a checkout")
        command_parser.set_defaults(_run=module.run, _module=module)
    return parser


def check_outputs(module, args) -> None:
    """Refuse, before any work, the outputs a command declares that cannot be written.

    A command module may declare ``OUTPUT_FILES`` and ``OUTPUT_FOLDERS`` (option names whose
    values are written) and ``INPUT_FILES`` (option names whose values are read): an output
    that is a folder, sits under a file, is not writable, is on a read-only file system or
    names one of the inputs is refused in one line naming the option
    (:func:`catalog.core.atomic.check_target`).
    """
    from catalog.core.atomic import OutputError, check_target, register_input  # noqa: PLC0415
    from catalog.core.inputs import register_preset_inputs  # noqa: PLC0415

    inputs = [value for name in getattr(module, "INPUT_FILES", ())
              for value in _values(getattr(args, name, None))]
    for value in inputs:
        register_input(value)
    if "fabric" in getattr(module, "INPUT_FILES", ()) and getattr(args, "fabric", None):
        from catalog.presets import find_preset  # noqa: PLC0415

        try:
            register_preset_inputs(find_preset(args.fabric))  # the preset and its files
        except (CatalogError, OSError, ValueError):
            pass  # the command refuses it with its own line
    for names, folder in ((getattr(module, "OUTPUT_FILES", ()), False),
                          (getattr(module, "OUTPUT_FOLDERS", ()), True)):
        for name in names:
            for value in _values(getattr(args, name, None)):
                if name == "plot":  # every command's --plot: an image the plotter writes
                    from catalog.core.validate import check_plot_path  # noqa: PLC0415

                    check_plot_path(value, "--plot")
                try:
                    check_target(value, inputs=inputs, folder=folder)
                except OutputError as exc:
                    raise CatalogError(f"--{name.replace('_', '-')} {exc}") from None


def _values(value) -> list:
    if value is None or value is False:
        return []
    return list(value) if isinstance(value, (list, tuple)) else [value]


def _report(args, exc: CatalogError) -> int:
    from catalog.core.atomic import silence_stdout  # noqa: PLC0415

    if getattr(exc, "path", None) == "stdout":
        silence_stdout()  # the interpreter's last flush must not fail a second time
    message = " ".join(str(exc).split())  # one line, whatever the message held
    prog = "catalog" if args.command == "catalog" else f"catalog {args.command}"
    print(f"{prog}: error: {message}", file=sys.stderr)
    if getattr(args, "json", False):
        from catalog.core.atomic import OutputError, write_stdout  # noqa: PLC0415

        try:
            write_stdout(json.dumps({"error": message, "exit_code": exc.exit_code}) + "\n")
        except OutputError:
            pass  # stdout itself is what failed: the line on stderr says so
    return exc.exit_code


def main(argv: list[str] | None = None) -> int:
    from catalog.core.atomic import install_signal_handlers  # noqa: PLC0415

    install_signal_handlers()  # first: building the parser imports every command module
    status = _main(argv)
    if argv is None:
        # the command line (not a caller in process): end without the interpreter's
        # teardown. It resets the signal handlers to the default action first, so a SIGTERM
        # during a long teardown (scipy, matplotlib, llvmpipe loaded) killed the process
        # with status -15 after its work was done (6 of 40 fit kill trials); an EGL context
        # torn down after a signal has crashed. Every output is committed by now.
        import contextlib  # noqa: PLC0415
        import os  # noqa: PLC0415

        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                if stream is not None:
                    stream.flush()
        if status in (130, 143):
            from catalog.core.atomic import hard_exit  # noqa: PLC0415

            hard_exit(status)
        os._exit(status)
    return status


def _main(argv: list[str] | None) -> int:
    from catalog.core.atomic import track_inputs  # noqa: PLC0415

    track_inputs(True)
    try:
        return _run_command(argv)
    finally:
        track_inputs(False)


def _guard_standard_descriptors() -> None:
    """A process started with stdin, stdout or stderr closed (``cmd >&-``) would hand that
    descriptor number to the next file it opens, and anything printed (by Python or a
    native library) would land inside an output or over an input: park /dev/null there."""
    import os  # noqa: PLC0415

    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            try:
                devnull = os.open(os.devnull, os.O_RDWR)
            except OSError:
                continue
            if devnull != fd:
                os.dup2(devnull, fd)
                os.close(devnull)


def _run_command(argv: list[str] | None) -> int:
    from catalog.core.atomic import (OutputError, Terminated,  # noqa: PLC0415
                                     install_signal_handlers, os_cause)

    _guard_standard_descriptors()
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except CommandLineError as exc:
        words = sys.argv[1:] if argv is None else argv
        command = exc.prog.split(" ", 1)[1] if " " in exc.prog else "catalog"
        return _report(argparse.Namespace(command=command, json="--json" in words), exc)
    install_signal_handlers()
    try:
        if getattr(args, "fabrics", None) and isinstance(args.fabrics, list):
            use_fabrics(args.fabrics)  # --fabrics DIR, every command (catalog.core.fabricargs)
        if getattr(args, "data", None) is not None:
            use_data(args.data)
        check_outputs(args._module, args)
        if sys.stdout is None and getattr(args, "json", False):
            # refused before any work: --json prints the result there
            raise OutputError("stdout", "closed (--json prints its result on stdout; "
                                        "nothing was done)")
        status = int(args._run(args) or 0)
        try:
            if sys.stdout is not None:
                sys.stdout.flush()
        except (BrokenPipeError, OSError) as exc:
            raise OutputError("stdout", "closed" if isinstance(exc, BrokenPipeError)
                              else os_cause(exc)) from None
        return status
    except CatalogError as exc:
        return _report(args, exc)
    except BrokenPipeError:
        return _report(args, OutputError("stdout", "closed"))
    except ModuleNotFoundError as exc:
        # an optional package (or a broken installation): one line naming the extra, exit 3
        from catalog.core.extras import failure_for  # noqa: PLC0415

        return _report(args, failure_for(exc, f"catalog {args.command}"))
    except OSError as exc:
        # an OS error no writer turned into a message (the output layer does for its own
        # files): still one line, naming the path where the OS gave one
        return _report(args, CatalogError(f"{exc.filename or 'a file'}: {os_cause(exc)}"))
    except KeyboardInterrupt:
        return 130
    except Terminated as exc:
        return int(exc.code)
    except RecursionError:
        return _report(args, CatalogError("the input is nested too deeply to read"))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
