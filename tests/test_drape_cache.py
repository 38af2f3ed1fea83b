"""The settled drape's disk cache (catalog/cloth/drape_cache.py): the cached state is the
settle's own, bit for bit; a second process reads it instead of settling; a change of any
parameter, the grid, the frames or the solver's code is another key; a torn or foreign file
is ignored and replaced; two processes writing one key at once leave one whole file."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from catalog.cloth import drape, drape_cache
from catalog.cloth.drape import drape_params, settle
from catalog.core.resources import PROJECT_ROOT

GRID = (12, 8)  # tiny: the cache's logic, not the cloth
FRAMES = 3


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(drape_cache.CACHE_ENV, str(tmp_path))
    drape._settled.cache_clear()
    yield tmp_path / "drape"
    drape._settled.cache_clear()


def _params(**changes):
    return drape_params({"weave": "voile"}, grid=GRID, **changes)


def _same(a, b) -> bool:
    return (np.array_equal(a.positions_m, b.positions_m)
            and np.array_equal(a.velocities_m_s, b.velocities_m_s)
            and np.array_equal(a.ring_positions_m, b.ring_positions_m)
            and (a.time_s, a.frames, a.calm_s) == (b.time_s, b.frames, b.calm_s))


def test_the_key_follows_every_parameter_the_grid_the_frames_and_the_solver(monkeypatch):
    params = _params()
    key = drape_cache.drape_key(params, FRAMES, 1 / 60)
    assert key == drape_cache.drape_key(_params(), FRAMES, 1 / 60)  # content, not identity
    others = {drape_cache.drape_key(_params(stretch_stiffness_n_m=123.0), FRAMES, 1 / 60),
              drape_cache.drape_key(drape_params({"weave": "voile"}, grid=(12, 9)), FRAMES, 1 / 60),
              drape_cache.drape_key(params, FRAMES + 1, 1 / 60),
              drape_cache.drape_key(params, FRAMES, 1 / 30)}
    monkeypatch.setattr(drape_cache, "_SOLVER_HASH", "another solver")
    others.add(drape_cache.drape_key(params, FRAMES, 1 / 60))
    assert key not in others and len(others) == 5


@pytest.mark.slow
def test_the_wind_is_no_part_of_the_key_because_the_settle_is_in_still_air(cache):
    """A curtain at wind 0 and one at 2 m/s with other gusts share one settled rest: the
    settle of the windy parameters is the windless settle bit for bit (so sharing is right),
    and one file serves both."""
    still, windy = _params(), _params(wind_speed_m_s=2.0, gust_strength=0.2,
                                      wind_direction=(0.3, 0.0, 1.0), gust_period_s=1.0)
    assert drape_cache.drape_key(windy, FRAMES, 1 / 60) == drape_cache.drape_key(still, FRAMES, 1 / 60)
    assert _same(settle(windy, FRAMES), settle(still, FRAMES))
    drape.settled_state(windy, FRAMES)
    drape.settled_state(still, FRAMES)
    assert len(list(cache.glob("*.npz"))) == 1
    assert drape_cache.windless(windy) == drape_cache.windless(still)


def test_the_cached_state_is_the_settles_and_a_second_read_does_not_settle(cache, monkeypatch):
    params = _params()
    fresh = settle(params, FRAMES)
    first = drape.settled_state(params, FRAMES)
    assert _same(first, fresh)
    (entry,) = cache.glob("*.npz")
    assert entry.stem == drape_cache.drape_key(params, FRAMES, drape.FRAME_DT_S)
    drape._settled.cache_clear()  # a new process, as far as the cache can tell

    def no_settle(*_args):
        raise AssertionError("settled again although the cache holds the drape")

    monkeypatch.setattr(drape, "settle", no_settle)
    assert _same(drape.settled_state(params, FRAMES), fresh)


def test_a_torn_or_foreign_file_is_ignored_and_written_again(cache):
    params = _params()
    key = drape_cache.drape_key(params, FRAMES, drape.FRAME_DT_S)
    cache.mkdir(parents=True)
    path = cache / f"{key}.npz"
    path.write_bytes(b"PK\x03\x04 torn")
    assert drape_cache.load(key, params) is None
    state = drape.settled_state(params, FRAMES)
    assert _same(drape_cache.load(key, params), state)
    # another key's file under this name is not this key's state
    other = _params(stretch_stiffness_n_m=321.0)
    drape_cache.store(key, settle(other, FRAMES))
    os.replace(cache / f"{key}.npz", cache / "moved.npz")
    other_key = drape_cache.drape_key(other, FRAMES, drape.FRAME_DT_S)
    os.replace(cache / "moved.npz", cache / f"{other_key}.npz")
    assert drape_cache.load(other_key, other) is None  # it records the key it was written for


def test_an_unwritable_cache_or_off_costs_only_the_settle(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(drape_cache.CACHE_ENV, str(blocker))
    params = _params()
    assert drape_cache.store("k", settle(params, FRAMES)) is None
    monkeypatch.setenv(drape_cache.CACHE_ENV, "off")
    assert drape_cache.cache_dir() is None and drape_cache.store("k", settle(params, 1)) is None


WRITER = """
import sys
from catalog.cloth import drape_cache
from catalog.cloth.drape import drape_params, settle
params = drape_params({"weave": "voile"}, grid=(12, 8))
key = drape_cache.drape_key(params, 3, 1 / 60)
state = settle(params, 3)
print("ready", flush=True)
sys.stdin.readline()  # both start writing at the same moment
for _ in range(int(sys.argv[1])):
    assert drape_cache.store(key, state) is not None
"""


@pytest.mark.slow
def test_two_processes_writing_one_key_leave_one_whole_file(cache):
    """Two writers publish the same key 40 times each while this process reads it: every
    read is None (not yet there) or the whole state; no temporary is left behind."""
    env = dict(os.environ, PYTHONPATH=str(PROJECT_ROOT))
    writers = [subprocess.Popen([sys.executable, "-c", WRITER, "40"], env=env, text=True,
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE)
               for _ in range(2)]
    for writer in writers:
        assert writer.stdout.readline().strip() == "ready"
    for writer in writers:
        writer.stdin.write("go\n")
        writer.stdin.flush()
    params = _params()
    key = drape_cache.drape_key(params, FRAMES, drape.FRAME_DT_S)
    expected = settle(params, FRAMES)
    seen = 0
    while any(w.poll() is None for w in writers):
        state = drape_cache.load(key, params)
        if state is not None:
            assert _same(state, expected)
            seen += 1
    assert [w.wait(timeout=60) for w in writers] == [0, 0]
    assert seen > 0
    assert _same(drape_cache.load(key, params), expected)
    assert [p.name for p in cache.iterdir()] == [f"{key}.npz"]


def test_every_cloth_module_is_keyed_or_excluded_for_a_reason():
    """A solver module left out of the key would let a changed kernel reuse a stale drape."""
    from pathlib import Path

    from catalog.cloth import drape_cache

    here = Path(drape_cache.__file__).parent
    modules = {p.stem for p in here.glob("*.py")} - {"__init__"}
    # Not on the settle's path: the cache itself, the GPU backend (settle runs numba or
    # numpy), the mesh export.
    excluded = {"drape_cache", "backend_gpu", "mesh"}
    assert modules - excluded == set(drape_cache.SOLVER_MODULES)
