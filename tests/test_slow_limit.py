"""The CI guard of the fast loop: with $CATALOG_UNMARKED_LIMIT_S set, an unmarked test over
the limit fails, a marked one passes; without it nothing is timed."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from catalog.core.resources import PROJECT_ROOT

PROBE = '''
import time
import pytest

def test_unmarked_sleeps():
    time.sleep(0.4)

@pytest.mark.slow
def test_marked_sleeps():
    time.sleep(0.4)

def test_quick():
    pass
'''


def _run(tmp_path: Path, limit: str | None) -> subprocess.CompletedProcess:
    shutil.copy(Path(__file__).with_name("conftest.py"), tmp_path / "conftest.py")
    (tmp_path / "test_probe.py").write_text(PROBE)
    env = {k: v for k, v in os.environ.items() if k != "CATALOG_UNMARKED_LIMIT_S"}
    env["PYTHONPATH"] = str(PROJECT_ROOT)
    if limit is not None:
        env["CATALOG_UNMARKED_LIMIT_S"] = limit
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-o", "addopts=", "-m", "slow or not slow", "--rootdir",
                           str(tmp_path), str(tmp_path / "test_probe.py")],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_an_unmarked_test_over_the_limit_fails_only_when_the_limit_is_set(tmp_path):
    timed = _run(tmp_path, "0.2")
    assert timed.returncode == 1, timed.stdout
    assert "1 failed, 2 passed" in timed.stdout, timed.stdout
    assert "test_unmarked_sleeps took" in timed.stdout and "without @pytest.mark.slow" in timed.stdout
    untimed = _run(tmp_path, None)
    assert untimed.returncode == 0 and "3 passed" in untimed.stdout, untimed.stdout
