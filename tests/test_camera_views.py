"""The named views and the camera kept inside the room (issue 34).

The room's box is catalog.render.scene.ROOM_BOX; a camera's eye must lie inside it less
ROOM_MARGIN_M for any yaw, pitch and distance asked for (the snapshot command, the
renderer, the viewer). The default view's side walls are lit: read-back pixels."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from catalog.render.camera import (DEFAULT_VIEW, ROOM_MARGIN_M, VIEWS, OrbitCamera,
                                   room_limit_m, view_named)
from catalog.render.scene import ROOM_BOX


def _inside(position, margin=ROOM_MARGIN_M - 1e-9):
    return all(lo + margin <= p <= hi - margin for p, (lo, hi) in zip(position, ROOM_BOX))


@pytest.mark.parametrize("name", list(VIEWS))
def test_every_view_starts_inside_the_room(name):
    camera = OrbitCamera.from_view(view_named(name), bounds=ROOM_BOX)
    assert _inside(camera.position), camera.position
    assert camera.distance_m == pytest.approx(VIEWS[name].distance_m)   # not clamped


def test_any_yaw_pitch_distance_is_kept_inside_the_room():
    """A sweep of 24 yaws x 7 pitches x 4 distances up to 50 m, from every view's target:
    the eye stays inside the room (a ray that meets the margin's box nowhere, towards the
    window from the curtain, keeps the camera at twice the near plane); an unclamped camera
    (bounds None) does leave it."""
    left = 0
    for view, yaw, pitch, distance in itertools.product(
            VIEWS.values(), np.arange(-180, 180, 15), np.arange(-80, 81, 25), (0.3, 2.6, 3.5, 50)):
        camera = OrbitCamera(target=view.target, yaw_deg=yaw, pitch_deg=pitch,
                             distance_m=distance, bounds=ROOM_BOX)
        assert _inside(camera.position, 0.0) or camera.distance_m == 2 * camera.near_m, \
            (view, yaw, pitch, distance, camera.position)
        left += not _inside(OrbitCamera(target=view.target, yaw_deg=yaw, pitch_deg=pitch,
                                        distance_m=distance).position)
    assert left > 0
    # the case: --distance 3.5 --yaw 40 from the front target left the box
    camera = OrbitCamera(yaw_deg=40.0, distance_m=3.5, bounds=ROOM_BOX)
    assert _inside(camera.position) and camera.distance_m < 3.5


BUILT_IN = ("box", "living", "bedroom")


def _inside_box(position, box, margin=ROOM_MARGIN_M - 1e-9):
    return all(lo + margin <= p <= hi - margin for p, (lo, hi) in zip(position, box))


@pytest.fixture(scope="module")
def room_boxes():
    """Each built-in room's inside as tools/make_rooms.py builds it (independent of the
    placement's inference from the faces) and its placement."""
    import sys
    from pathlib import Path

    from catalog.render.placement import room_placement

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
    import make_rooms

    boxes = {"box": ROOM_BOX, "living": ROOM_BOX, "bedroom": make_rooms.BEDROOM_BOX}
    return {name: (boxes[name], room_placement(name)) for name in BUILT_IN}


@pytest.mark.slow
@pytest.mark.parametrize("room", BUILT_IN)
def test_every_room_keeps_every_view_and_any_orbit_inside(room_boxes, room):
    """In each built-in room: its interior (inferred from the faces) is the builder's box;
    every named view, composed for the room's window, starts inside it unclamped; a sweep of
    24 yaws x 7 pitches x 4 distances up to 50 m from each view's target stays inside."""
    box, placement = room_boxes[room]
    assert np.allclose(placement.interior, box, atol=1e-6), (placement.interior, box)
    for name in VIEWS:
        view = placement.view(name)
        camera = OrbitCamera.from_view(view, bounds=placement.interior)
        assert _inside_box(camera.position, box), (name, camera.position)
        assert camera.distance_m == pytest.approx(view.distance_m), name
    for view, yaw, pitch, distance in itertools.product(
            placement.views().values(), np.arange(-180, 180, 15), np.arange(-80, 81, 25), (0.3, 2.6, 3.5, 50)):
        camera = OrbitCamera(target=view.target, yaw_deg=yaw, pitch_deg=pitch, distance_m=distance,
                             bounds=placement.interior)
        assert _inside_box(camera.position, box, 0.0) or camera.distance_m == 2 * camera.near_m, \
            (room, view, yaw, pitch, distance, camera.position)


def test_room_limit_is_where_the_ray_meets_the_shrunk_box():
    """Closed form: straight along +z from z = 0.15 the room ends at 4.5 - margin."""
    target = (0.0, 0.0, 0.15)
    assert room_limit_m(target, 0.0, 0.0, ROOM_BOX) == pytest.approx(4.5 - ROOM_MARGIN_M - 0.15)
    assert room_limit_m((9.0, 0.0, 0.0), 0.0, 0.0, ROOM_BOX) == 0.0   # the ray misses the room
    # from the curtain (nearer the window wall than the margin) the ray enters and leaves
    assert room_limit_m((0.0, 0.0, -0.08), 0.0, 0.0, ROOM_BOX) == pytest.approx(4.35 + 0.08)


def test_unknown_view_is_refused_by_name():
    from catalog.core.errors import CatalogError

    with pytest.raises(CatalogError, match="unknown view 'attic'"):
        view_named("attic")
    assert DEFAULT_VIEW in VIEWS


@pytest.mark.gl
@pytest.mark.slow
def test_default_view_shows_lit_side_walls(tmp_path):
    """The default (room) view in daylight (D65): the frame's outer sixths, left and right,
    each at least a third of the curtain's mean sRGB level (the curtain: the brightest
    column band of the frame's middle third)."""
    from PIL import Image

    from catalog.commands.cli import main

    out = tmp_path / "room.png"
    assert main(["snapshot", "--fabric", "voile-white", "--light", "D65", "--size", "320x180",
                 "--out", str(out)]) == 0
    px = np.asarray(Image.open(out).convert("RGB"), dtype=np.float64)
    w = px.shape[1]
    middle = px[:, w // 3:2 * w // 3].mean(axis=(0, 2))
    curtain = np.sort(middle)[-w // 8:].mean()
    for side in (px[:, :w // 6], px[:, -w // 6:]):
        assert side.mean() >= curtain / 3.0, (side.mean(), curtain)


@pytest.mark.gl
@pytest.mark.slow
def test_snapshot_keeps_the_camera_in_the_room(tmp_path, capsys):
    """The issue's command, ``snapshot --distance 3.5 --yaw 40``: the report's camera lies
    inside the room's box (it left it before: a sky wedge at the frame's edge)."""
    import json

    from catalog.commands.cli import main

    assert main(["snapshot", "--fabric", "voile-white", "--light", "D65", "--size", "64x36",
                 "--distance", "3.5", "--yaw", "40", "--out", str(tmp_path / "a.png"),
                 "--json"]) == 0
    camera = json.loads(capsys.readouterr().out)["camera"]
    assert _inside(camera["position_m"], 0.0) and camera["distance_m"] < 3.5, camera


@pytest.mark.gl
@pytest.mark.slow
@pytest.mark.parametrize("room", ["living", "bedroom"])
def test_snapshot_keeps_the_camera_in_each_room(tmp_path, capsys, room_boxes, room):
    """``snapshot --room R --distance 3.5 --yaw 40`` (and the default view): the camera lies
    inside that room's own box (the bedroom is 0.9 m shallower and 0.45 m lower than the box)."""
    import json

    from catalog.commands.cli import main

    box, _ = room_boxes[room]
    for extra in ([], ["--distance", "3.5", "--yaw", "40"], ["--distance", "9", "--yaw", "-60", "--pitch", "30"]):
        assert main(["snapshot", "--fabric", "voile-white", "--light", "D65", "--size", "32x18",
                     "--room", room, "--out", str(tmp_path / "a.png"), "--json", *extra]) == 0
        camera = json.loads(capsys.readouterr().out)["camera"]
        assert _inside_box(camera["position_m"], box, ROOM_MARGIN_M - 1e-6), (extra, camera)
