"""The suite's pytest-xdist schedule (tests/conftest.py): the modules that share a costly
session fixture are the ones that use it, and run in one worker."""

from __future__ import annotations

import re

import pytest

import conftest
from catalog.core.resources import PROJECT_ROOT


def _loadfile_config(pytestconfig):
    """The suite's config as `-n 2 --dist loadfile` gives it (what the scheduler reads)."""

    class LoadFile:
        option = pytestconfig.option

        def getvalue(self, name):
            return {"dist": "loadfile", "tx": ["popen"] * 2}.get(name)

        def getoption(self, name, default=None):
            return {"dist": "loadfile", "numprocesses": 2, "tx": [],
                    "maxschedchunk": None}.get(name, default)

    return LoadFile()


@pytest.mark.parametrize("fixture", sorted(conftest.SHARED_FIXTURE_MODULES))
def test_the_modules_listed_for_a_shared_fixture_are_the_ones_using_it(fixture):
    uses = re.compile(rf"def \w+\([^)]*\b{fixture}\b", re.S)
    using = sorted(str(path.relative_to(PROJECT_ROOT)) for path in
                   (PROJECT_ROOT / "tests").glob("test_*.py") if uses.search(path.read_text()))
    assert using, f"no test module uses {fixture}: take it out of SHARED_FIXTURE_MODULES"
    assert sorted(conftest.SHARED_FIXTURE_MODULES[fixture]) == using


def test_the_shared_modules_are_one_scope_and_the_others_one_each(pytestconfig):
    pytest.importorskip("xdist")

    loadfile = _loadfile_config(pytestconfig)
    scheduler = conftest.pytest_xdist_make_scheduler(loadfile, None)
    shared = {scheduler._split_scope(f"{m}::test_x")
              for m in conftest.SHARED_FIXTURE_MODULES["web_site"]}
    modules = [f"tests/test_{name}.py" for name in ("a", "b")]   # made-up modules
    others = {scheduler._split_scope(f"{m}::test_x[1]") for m in modules}
    assert len(shared) == 1 and others == set(modules)
    assert conftest.pytest_xdist_make_scheduler(type("Load", (type(loadfile),), {
        "getvalue": lambda self, name: "load"})(), None) is None   # other modes: xdist's own


def test_the_longest_scopes_start_first_and_each_listed_one_is_a_scope(pytestconfig,
                                                                        monkeypatch):
    pytest.importorskip("xdist")
    from xdist.scheduler import LoadFileScheduling

    shared = set(conftest.SHARED_FIXTURE_MODULES)
    for scope in conftest.SCOPE_SECONDS:   # a renamed or deleted module would be a dead entry
        assert scope in shared or (PROJECT_ROOT / scope).is_file(), scope

    scheduler = conftest.pytest_xdist_make_scheduler(_loadfile_config(pytestconfig), None)
    longest = max(conftest.SCOPE_SECONDS, key=conftest.SCOPE_SECONDS.get)
    second = sorted(conftest.SCOPE_SECONDS, key=conftest.SCOPE_SECONDS.get)[-2]
    unlisted = [f"tests/test_unlisted_{name}.py" for name in ("a", "b")]   # made-up modules
    scheduler.workqueue.update((scope, {f"{scope}::test_x": False})
                               for scope in (unlisted[0], second, unlisted[1], longest))
    given = []
    monkeypatch.setattr(LoadFileScheduling, "_assign_work_unit", lambda self, node: given.append(
        self.workqueue.popitem(last=False)[0]))   # xdist's own: sends the unit to a worker
    for _ in range(4):
        scheduler._assign_work_unit(None)
    assert given == [longest, second, *unlisted]
