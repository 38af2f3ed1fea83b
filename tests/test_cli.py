"""The console script: fast help, no heavy imports at start, errors as one line."""

from __future__ import annotations

import json
import subprocess
import sys

from catalog.commands.cli import COMMANDS

HEAVY = ("numpy", "scipy", "colour", "matplotlib", "moderngl", "OpenImageIO", "numba",
         "trimesh", "pvlib", "glfw", "imgui_bundle")


def _python(code: str) -> str:
    return subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                          text=True).stdout


def test_help_builds_every_command_parser_without_heavy_imports():
    out = _python(
        "import sys\n"
        "from catalog.commands.cli import build_parser\n"
        "parser = build_parser()\n"
        "parser.format_help()\n"
        "import json\n"
        f"heavy = {HEAVY!r}\n"
        "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules} & set(heavy))))\n")
    assert json.loads(out) == []


def test_every_registered_command_module_imports_light():
    """Each command module that exists is importable and declares HELP, add_arguments, run."""
    out = _python(
        "import importlib, importlib.util, json, sys\n"
        f"commands = {COMMANDS!r}\n"
        "found = {}\n"
        "for name, mod in commands.items():\n"
        "    if importlib.util.find_spec(mod) is None: continue\n"
        "    m = importlib.import_module(mod)\n"
        "    found[name] = [hasattr(m, a) for a in ('HELP', 'add_arguments', 'run')]\n"
        f"heavy = set({HEAVY!r})\n"
        "print(json.dumps({'found': found,"
        " 'heavy': sorted({m.split('.')[0] for m in sys.modules} & heavy)}))\n")
    result = json.loads(out)
    assert result["heavy"] == []
    for name, has in result["found"].items():
        assert all(has), f"catalog.commands.{name} lacks HELP/add_arguments/run"


def test_unknown_command_is_refused():
    proc = subprocess.run([sys.executable, "-m", "catalog", "no-such-command"],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert "no-such-command" in proc.stderr


def test_wxh_values_are_parsed_and_refused_by_one_rule():
    import pytest

    from catalog.core.cliargs import parse_wxh
    from catalog.core.errors import InputError

    assert parse_wxh(" 64X48 ", "--size", 1, 100) == (64, 48)
    assert parse_wxh("2x100000", "--grid", 2) == (2, 100000)  # no upper bound given
    for text, low, high in (("40x", 1, 100), ("axb", 1, 100), ("0x4", 1, 100),
                            ("101x4", 1, 100), ("1x4", 2, None), ("-3x4", 1, 100)):
        with pytest.raises(InputError) as err:
            parse_wxh(text, "--opt", low, high)
        assert str(err.value).startswith("--opt: ")
