"""Each published table names the commit and machine it was measured on, and the age check
finds a result older than the code it measures (tools/figures_age.py, a CI warning)."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys

import pytest

from catalog.core.resources import PROJECT_ROOT


def _load(name):
    sys.path.insert(0, str(PROJECT_ROOT / "tools"))
    spec = importlib.util.spec_from_file_location(name, PROJECT_ROOT / "tools" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def age():
    return _load("figures_age")


def test_the_provenance_line_names_commit_and_machine_or_says_they_are_unknown():
    docs_figures = _load("docs_figures")
    line = docs_figures.provenance({"results/a.json": {"machine": {
        "commit": "abc1234", "cpu_count": 2, "gl_renderer": "llvmpipe (LLVM 15)"}}})
    assert "`results/a.json`: commit `abc1234`, 2 cores, llvmpipe (LLVM 15)" in line
    old = docs_figures.provenance({"results/b.json": {"rows": []}})
    assert "commit not recorded, machine not recorded" in old


def test_a_measurement_records_the_commit_it_ran_on():
    from benchmarks.results import machine_info

    head = subprocess.run(["git", "rev-parse", "--short=10", "HEAD"], cwd=PROJECT_ROOT,
                          capture_output=True, text=True).stdout.strip()
    assert machine_info()["commit"].split("+")[0] == head


def test_the_measured_code_is_the_module_its_imports_and_the_shaders(age):
    import benchmarks.render_shaders as module

    code = age.measured_code(module)
    assert "benchmarks/render_shaders.py" in code and "shaders" in code
    assert any(p.startswith("catalog/render") or p.startswith("catalog/gl") for p in code)
    assert not any(p.endswith("atomic.py") for p in code)


def _git(repo, *args):
    subprocess.run(["git", *args], cwd=repo, check=True, capture_output=True,
                   env={"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t",
                        "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t",
                        "PATH": "/usr/bin:/bin", "HOME": str(repo)})


def test_a_result_is_stale_once_its_code_changes_after_it(age, tmp_path, monkeypatch):
    repo = tmp_path / "repo"
    (repo / "results").mkdir(parents=True)
    (repo / "code.py").write_text("x = 1\n")
    (repo / "results" / "r.json").write_text(json.dumps({"rows": []}))
    _git(repo, "init", "-q")
    _git(repo, "add", ".")
    _git(repo, "commit", "-qm", "measured")
    monkeypatch.setattr(age, "ROOT", repo)
    commit, how = age.measured_at("results/r.json")
    assert how == "the JSON's last commit" and commit
    assert age._git("log", "--format=%h", f"{commit}..HEAD", "--", "code.py") == ""
    (repo / "code.py").write_text("x = 2\n")
    _git(repo, "commit", "-qam", "the code changed")
    assert len(age._git("log", "--format=%h", f"{commit}..HEAD", "--", "code.py").split()) == 1
    # a commit recorded in the result wins over the file's
    (repo / "results" / "r.json").write_text(json.dumps({"machine": {"commit": commit}}))
    _git(repo, "commit", "-qam", "re-committed, same measurement")
    assert age.measured_at("results/r.json") == (commit, "recorded")
