"""A room's first build shows its progress (catalog.room.build_progress), and the viewer's
start-up passes it on (catalog.viewer.room_start)."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from catalog.core.errors import InputError
from catalog.room import build_progress as bp


def test_weights_cover_the_build_and_the_share_done_rises():
    assert len(bp.WEIGHTS) == len(bp.STAGES) and sum(bp.WEIGHTS) == pytest.approx(1.0)
    shares = [bp.fraction_done(stage, done, 4) for stage in bp.STAGES for done in range(5)]
    assert all(b >= a for a, b in zip(shares, shares[1:])) and shares[0] == 0 and shares[-1] == pytest.approx(1)
    assert bp.fraction_done("solve", 1, 3) == pytest.approx(sum(bp.WEIGHTS[:3]) + bp.WEIGHTS[3] / 3)


def test_the_line_says_the_stage_the_share_and_the_time_left():
    """A fake clock: 30 s into the build with half of it done, 30 s are left."""
    now = [100.0]
    out = io.StringIO()
    printer = bp.LinePrinter("bedroom", out, clock=lambda: now[0])
    now[0] = 130.0
    # find a point of the solve that is half the build
    k = bp.STAGES.index("solve")
    within = (0.5 - sum(bp.WEIGHTS[:k])) / bp.WEIGHTS[k]
    printer("solve", round(1000 * within), 1000)
    line = out.getvalue().strip()
    assert line == "room bedroom: 4/6 solve, 50 % done, 0:30 elapsed, 0:30 left", line
    printer("solve", 600, 1000)                 # within LINE_EVERY_S of the last: quiet
    assert out.getvalue().count("\n") == 1
    printer("compress")                         # a new stage always prints
    assert out.getvalue().count("\n") == 2


@pytest.mark.slow
def test_a_small_rooms_precompute_reports_every_stage_in_order():
    """The transport's precompute of a small open cube (numpy rays) under a listener: the
    stages come in STAGES' order (the gathers are the frame bundle's), chunks counted up."""
    sys.path.insert(0, "tests")
    from test_room_transport import constant_albedo, open_cube

    from catalog.room.transport import TransportParams, precompute_geometry

    tris, window = open_cube((0.3, 0.7, 0.3, 0.7))
    params = TransportParams(element_m=0.25, refine_levels=0, patches=(2, 2), order=1, gather_rays=8,
                             window_samples=4, max_rank=8)
    seen = []
    with bp.listening(lambda stage, done, total: seen.append((stage, done, total))):
        precompute_geometry(tris, constant_albedo(0.5), window, params, backend="numpy")
    stages = list(dict.fromkeys(s for s, _, _ in seen))
    assert stages == list(bp.STAGES[:-1]), stages
    shares = [bp.fraction_done(*item) for item in seen]
    assert all(b >= a for a, b in zip(shares, shares[1:])), seen
    assert bp._listener is None                  # the block put the listener back


def test_the_viewer_start_builds_with_progress_only_when_not_cached(monkeypatch, capsys):
    """start_room: a cached room returns its placement without a build; an uncached one runs
    the child, whose lines reach stdout prefixed; a child's refusal is one --room line."""
    from catalog.render.placement import BOX
    from catalog.viewer import room_start

    calls = []
    monkeypatch.setattr(room_start, "bundle_cached", lambda spec: True)
    monkeypatch.setattr(room_start, "build_with_progress", lambda spec, stream=None: calls.append(spec))
    assert room_start.start_room("box") == BOX and calls == []
    assert room_start.start_room(None) == BOX
    monkeypatch.setattr(room_start, "bundle_cached", lambda spec: False)
    assert room_start.start_room("box") == BOX and calls == ["box"]
    with pytest.raises(InputError, match="unknown room 'attic'"):
        room_start.start_room("attic")


def test_the_childs_lines_are_passed_on_and_its_refusal_is_one_line(monkeypatch, capsys):
    from catalog.viewer import room_start

    real = subprocess.Popen

    def fake(argv, **kw):
        assert argv[1:] == ["-m", "catalog.render.room_operators", "bedroom", "--progress"]
        script = ("import sys; print('room bedroom: 1/6 receivers, 0 % done, 0:01 elapsed, ? left'); "
                  "print('room bedroom: 4/6 solve, 40 % done, 0:40 elapsed, 1:00 left'); "
                  + ("sys.exit(0)" if fake.ok else "print('bad.glb: node window: not planar', file=sys.stderr); sys.exit(2)"))
        return real([sys.executable, "-c", script], **kw)

    monkeypatch.setattr(room_start.subprocess, "Popen", fake)
    fake.ok = True
    room_start.build_with_progress("bedroom")
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("catalog view: first use of the room bedroom")
    assert lines[2] == "catalog view: room bedroom: 4/6 solve, 40 % done, 0:40 elapsed, 1:00 left"
    fake.ok = False
    with pytest.raises(InputError, match="not planar") as info:
        room_start.build_with_progress("bedroom")
    assert "--room" in str(info.value) and "\n" not in str(info.value)
