"""The console script: fast help, no heavy imports at start, errors as one line."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

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


# ---- exit codes: 2 the input, 3 the environment; with --json the error is one object ---

@pytest.mark.slow
def test_missing_shader_is_an_environment_failure_with_a_json_error(gl, tmp_path, monkeypatch,
                                                                    capsys, fabric_dir):
    """A shader file missing from the installation: exit 3, one line on stderr, and with
    --json one JSON object on stdout; no image written."""
    from catalog.commands.cli import main
    from catalog.gl import shaderlib

    monkeypatch.setattr(shaderlib, "SEARCH_PATH", [tmp_path])  # an installation without shaders
    out = tmp_path / "x.png"
    code = main(["snapshot", "--fabric", "voile-white", "--light", "D65", "--size", "32x24",
                 "--out", str(out), "--json"])
    captured = capsys.readouterr()
    assert code == 3
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and "not found" in err[0]
    report = json.loads(captured.out)
    assert report["exit_code"] == 3 and "not found" in report["error"]
    assert not out.exists()


def test_bad_input_with_json_is_one_json_object(tmp_path, capsys):
    from catalog.commands.cli import main

    code = main(["snapshot", "--fabric", "no-such-fabric", "--light", "D65",
                 "--out", str(tmp_path / "x.png"), "--json"])
    captured = capsys.readouterr()
    assert code == 2
    report = json.loads(captured.out)  # exactly one object: json.loads refuses anything more
    assert report["exit_code"] == 2 and "no-such-fabric" in report["error"]
    assert len(captured.err.strip().splitlines()) == 1


def test_a_lamp_outside_the_room_is_refused_naming_the_option(tmp_path, capsys):
    """The lamp's position is checked against the loaded room's interior (a frame setting),
    but the user typed --lamp: the one line names the option, exit 2, nothing written."""
    from catalog.commands.cli import main

    out = tmp_path / "x.png"
    code = main(["snapshot", "--fabric", "voile-white", "--size", "32x18",
                 "--lamp", "A@0.5,0.3,9", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "--lamp: room lamp position (0.5, 0.3, 9.0) must lie inside the room" in err[0]
    assert not out.exists()


def test_user_fabric_folder_is_searched_before_the_built_in_catalog(tmp_path, monkeypatch,
                                                                    fabric_dir):
    """--fabrics DIR (and $CATALOG_FABRICS): a name found there wins over the built-in one;
    other names still come from the built-in catalog; a missing folder is refused."""
    import pytest

    from catalog.core import resources
    from catalog.core.errors import InputError
    from catalog.presets import find_preset, list_presets

    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "voile-white.toml").write_text((fabric_dir / "voile-white.toml").read_text())
    (mine / "my-own.toml").write_text((fabric_dir / "voile-white.toml").read_text())
    monkeypatch.setattr(resources, "_user_fabrics", None)
    monkeypatch.setenv(resources.FABRICS_ENV, str(mine))
    assert find_preset("voile-white") == mine / "voile-white.toml"
    assert find_preset("lace-fwa") == fabric_dir / "lace-fwa.toml"
    names = [p.stem for p in list_presets()]
    assert "my-own" in names and names.count("voile-white") == 1
    monkeypatch.delenv(resources.FABRICS_ENV)
    assert find_preset("voile-white") == fabric_dir / "voile-white.toml"
    resources.use_fabrics([mine])  # what --fabrics DIR does
    assert find_preset("my-own") == mine / "my-own.toml"
    with pytest.raises(InputError, match="--fabrics"):
        resources.use_fabrics([tmp_path / "nowhere"])
    resources.use_fabrics(None)


@pytest.mark.slow
def test_missing_validation_data_is_one_line_exit_2(tmp_path):
    """Without the validation data, commands that need it say so in one line (exit 2)."""
    import os

    env = {**os.environ, "CATALOG_DATA": str(tmp_path / "no-data")}
    for argv in (["bispectral", "CIBA12"], ["bench", "--sections", "fluorescence", "--out",
                                            str(tmp_path / "b")]):
        proc = subprocess.run([sys.executable, "-m", "catalog", *argv], env=env,
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and "validation data not found" in lines[0], proc.stderr
    proc = subprocess.run([sys.executable, "-m", "catalog", "bispectral", "CIBA12", "--data",
                           str(tmp_path / "elsewhere")], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 2 and str(tmp_path / "elsewhere") in proc.stderr
