"""``catalog simulate``: the JSON contract of formats.md and clear refusals."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from catalog.commands.cli import main

KEYS = {"steps", "dt", "substeps", "finite", "max_stretch", "kinetic_energy",
        "steps_per_second"}


@pytest.mark.slow
def test_simulate_json_contract(tmp_path):
    out = tmp_path / "curtain.ply"
    proc = subprocess.run(
        [sys.executable, "-m", "catalog", "simulate", "--grid", "8x10", "--steps", "20",
         "--dt", str(1 / 30), "--stiffness", "1e6", "--wind", "1.0", "--out", str(out),
         "--json"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.strip().splitlines()
    assert len(lines) == 1  # one JSON object and nothing else on stdout
    result = json.loads(lines[0])
    assert KEYS <= set(result)
    assert result["steps"] == 20 and result["dt"] == pytest.approx(1 / 30)
    assert result["substeps"] == 20  # 1/30 s cut into steps of at most 1/600 s
    assert result["finite"] is True
    assert 0.0 <= result["max_stretch"] <= 0.101
    assert result["kinetic_energy"] > 0.0 and result["steps_per_second"] > 0.0
    assert out.is_file() and out.stat().st_size > 0


def test_simulate_numpy_backend_and_sequence(tmp_path, capsys):
    pattern = str(tmp_path / "f_{frame:02d}.obj")
    assert main(["simulate", "--grid", "5x5", "--steps", "3", "--backend", "numpy",
                 "--out", pattern, "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["backend"] == "numpy" and result["finite"] is True
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f_00.obj", "f_01.obj", "f_02.obj"]


@pytest.mark.parametrize("argv, option", [
    (["--grid", "0x4"], "--grid"),
    (["--grid", "axb"], "--grid"),
    (["--grid", "4x4", "--wind", "nan"], "--wind"),
    (["--grid", "4x4", "--stiffness", "-5"], "--stiffness"),
    (["--grid", "4x4", "--dt", "0"], "--dt"),
    (["--grid", "4x4", "--opening", "0"], "--opening"),
    pytest.param(["--grid", "4x4", "--out", "x.stl"], "x.stl", marks=pytest.mark.slow),  # 0.8 s: a run
])
def test_simulate_refuses_bad_options(argv, option, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = main(["simulate", "--steps", "2", "--json", *argv])
    captured = capsys.readouterr()
    assert code == 2
    assert json.loads(captured.out) == {"error": captured.err.strip().split("error: ", 1)[1],
                                        "exit_code": 2}  # --json: the error as one object
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and option in err[0]
    assert list(tmp_path.iterdir()) == []  # nothing half-written
