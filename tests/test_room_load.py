"""Rooms as data (catalog.room.load): the built-in rooms load as the room format says, bad
rooms are refused in one line naming the node and the rule, and the transport cache follows
the room file's content."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.core.errors import InputError
from catalog.render import scene as scene_lib
from catalog.room.load import load_room, room_path

trimesh = pytest.importorskip("trimesh")


@pytest.mark.slow
def test_box_is_todays_room():
    room = load_room("box")
    x0, x1, y0, y1 = scene_lib.WINDOW_RECT
    assert np.allclose(np.sort(room.window.corners[:, 0]), [x0, x0, x1, x1], atol=1e-6)
    assert np.allclose(np.sort(room.window.corners[:, 1]), [y0, y0, y1, y1], atol=1e-6)
    assert np.allclose(room.window.corners[:, 2], scene_lib.WINDOW_Z, atol=1e-6)
    assert np.allclose(room.window.normal, [0, 0, 1])
    # the shell of catalog.render.scene (the rod is the curtain's, not the room's)
    ours = np.sort(np.round(room.triangles().reshape(-1, 3), 5), axis=0)
    theirs = np.concatenate(scene_lib._room_parts()[:-1]).reshape(-1, 3)
    assert np.allclose(ours, np.sort(np.round(theirs, 5), axis=0), atol=1e-5)
    assert np.allclose(room.mean_albedo(), scene_lib.ROOM_ALBEDO)
    assert room.camera is not None and room.camera.fov_y_deg == pytest.approx(50.0)


@pytest.mark.slow
def test_living_has_a_textured_floor_and_furniture():
    room = load_room("living")
    names = {s.name for s in room.surfaces}
    assert {"floor", "sofa_seat", "table_top", "rug", "shelf_back", "window_sill"} <= names
    floor = next(s for s in room.surfaces if s.name == "floor")
    assert floor.texture is not None and floor.uvs is not None
    albedo = room.mean_albedo()[np.concatenate([[s.name == "floor"] * len(s.triangles) for s in room.surfaces])]
    assert 0.1 < albedo.mean() < 0.5 and albedo.std() > 0


@pytest.mark.slow
def test_bedroom_is_another_furnished_room():
    room = load_room("bedroom")
    names = {s.name for s in room.surfaces}
    assert {"floor", "bed_mattress", "desk_top", "chair_post", "rug", "wall_shelf_0", "window_sill"} <= names
    for textured in ("floor", "rug"):
        s = next(s for s in room.surfaces if s.name == textured)
        assert s.texture is not None and s.uvs is not None
    # its window is not the box's: wider, lower, off-centre
    box = load_room("box")
    assert room.window.area_m2 == pytest.approx(2.1 * 1.45, rel=1e-6)
    assert not np.allclose(room.window.centre, box.window.centre, atol=0.1)
    assert np.allclose(room.window.normal, [0, 0, 1])
    lo, hi = room.bounds()
    assert hi[1] - lo[1] < box.bounds()[1][1] - box.bounds()[0][1]     # a lower ceiling
    assert room.camera is not None


def test_unknown_name_is_refused():
    with pytest.raises(InputError, match="--room.*unknown room 'attic'"):
        room_path("attic")


def _write(tmp_path, parts, window, name="r.glb"):
    scene = trimesh.Scene()
    for i, tris in enumerate(parts):
        scene.add_geometry(trimesh.Trimesh(tris.reshape(-1, 3), np.arange(tris.size // 3).reshape(-1, 3),
                                           process=False), node_name=f"part{i}", geom_name=f"part{i}")
    if window is not None:
        scene.add_geometry(trimesh.Trimesh(window.reshape(-1, 3), np.arange(window.size // 3).reshape(-1, 3),
                                           process=False), node_name="window", geom_name="window")
    path = tmp_path / name
    path.write_bytes(scene.export(file_type="glb"))
    return path


def _cube_room(hole=(0.3, 0.7, 0.3, 0.7), drop_face=None):
    """The unit cube's walls as slabs 0.05 thick, the z = 0 wall with a hole."""
    t = 0.05
    b = scene_lib.box_triangles
    x0, x1, y0, y1 = hole
    parts = [b(-t, 1 + t, -t, 0, -t, 1 + t), b(-t, 1 + t, 1, 1 + t, -t, 1 + t), b(-t, 0, 0, 1, -t, 1 + t),
             b(1, 1 + t, 0, 1, -t, 1 + t), b(0, 1, 0, 1, 1, 1 + t),
             b(0, x0, 0, 1, -t, 0), b(x1, 1, 0, 1, -t, 0), b(x0, x1, 0, y0, -t, 0), b(x0, x1, y1, 1, -t, 0)]
    if drop_face is not None:
        parts.pop(drop_face)
    q = np.array([[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0]], dtype=float)
    return parts, np.array([[q[0], q[1], q[2]], [q[0], q[2], q[3]]])


@pytest.mark.slow
def test_a_good_user_room_loads(tmp_path):
    parts, window = _cube_room()
    room = load_room(_write(tmp_path, parts, window))
    assert np.allclose(room.window.normal, [0, 0, 1]) and room.camera is None
    assert np.allclose(room.mean_albedo(), 0.5)          # no material: albedo 0.5


@pytest.mark.slow
@pytest.mark.parametrize("case, message", [
    ("no_window", "no node named 'window'"),
    ("triangle", "node 'window': must be one planar quad.*1 triangles"),
    ("bent", "node 'window': not planar"),
    ("outwards", "node 'window': its normal must point into the room"),
    ("leak", "the room leaks"),
])
def test_bad_rooms_are_refused_in_one_line(tmp_path, case, message):
    parts, window = _cube_room(drop_face=1 if case == "leak" else None)
    if case == "no_window":
        window = None
    elif case == "triangle":
        window = window[:1]
    elif case == "bent":
        window = window.copy()
        window[0, 2, 2] = window[1, 1, 2] = 0.05     # the shared corner (x1, y1) moved off the plane
    elif case == "outwards":
        window = window[:, ::-1]
    with pytest.raises(InputError, match=message) as info:
        load_room(_write(tmp_path, parts, window))
    assert "\n" not in str(info.value) and "r.glb" in str(info.value)


def test_too_many_triangles_are_refused_before_decoding(tmp_path, monkeypatch):
    import catalog.room.load as load_mod

    parts, window = _cube_room()
    path = _write(tmp_path, parts, window)
    monkeypatch.setattr(load_mod, "MAX_TRIANGLES", 50)
    monkeypatch.setattr(load_mod, "_decoded", lambda *a: pytest.fail("decoded a room over the bound"))
    with pytest.raises(InputError, match="110 triangles: a room holds at most 50"):
        load_room(path)


def test_an_oversized_texture_is_refused_before_decoding(tmp_path, monkeypatch):
    import catalog.room.load as load_mod
    from PIL import Image

    parts, window = _cube_room()
    path = _write(tmp_path, parts, window)
    scene = trimesh.load(path, force="scene", process=False)
    floor = scene.geometry["part0"]
    floor.visual = trimesh.visual.TextureVisuals(
        uv=np.zeros((len(floor.vertices), 2)),
        material=trimesh.visual.material.PBRMaterial(baseColorTexture=Image.new("RGB", (4097, 4))))
    path.write_bytes(scene.export(file_type="glb"))
    monkeypatch.setattr(load_mod, "_decoded", lambda *a: pytest.fail("decoded a room over the bound"))
    with pytest.raises(InputError, match="a 4097x4 texture: at most 4096 texels a side") as info:
        load_room(path)
    assert "\n" not in str(info.value) and "r.glb" in str(info.value)


@pytest.mark.slow
def test_transport_cache_follows_the_room_file(tmp_path, monkeypatch):
    from catalog.room.cache import cache_path, room_transport
    from catalog.room.transport import TransportParams

    monkeypatch.setenv("CATALOG_CACHE", str(tmp_path / "cache"))
    params = TransportParams(element_m=0.3, max_receivers=500, patches=(1, 1), order=1, gather_rays=16,
                             window_samples=2)
    parts, window = _cube_room()
    path = _write(tmp_path, parts, window)
    room = load_room(path)
    first = room_transport(room, params, backend="numpy")
    assert first.timings_s["from_cache"] is False and cache_path(room, params).is_file()
    again = room_transport(load_room(path), params, backend="numpy")
    assert again.timings_s["from_cache"] is True
    assert np.array_equal(again.window_operator, first.window_operator)
    # the refined receivers' tree comes back: a point maps to the same receiver
    assert again.receivers.children is not None and np.array_equal(again.receivers.leaf, first.receivers.leaf)
    rng = np.random.default_rng(0)
    pick = rng.integers(0, first.receivers.count, 64)
    pts = first.receivers.sample_points(pick, rng)
    tri = first.receivers.triangle[pick]
    assert np.array_equal(again.receiver_at(tri, pts), first.receiver_at(tri, pts))
    assert np.array_equal(first.receiver_at(tri, pts), pick)
    # the same room with a deeper back wall: another file, another entry, recomputed
    parts[4] = scene_lib.box_triangles(0, 1, 0, 1, 1, 1.05)
    parts[4][:, :, 2] += 0.2
    parts[2] = scene_lib.box_triangles(-0.05, 0, 0, 1, -0.05, 1.25)
    parts[3] = scene_lib.box_triangles(1, 1.05, 0, 1, -0.05, 1.25)
    parts[0] = scene_lib.box_triangles(-0.05, 1.05, -0.05, 0, -0.05, 1.25)
    parts[1] = scene_lib.box_triangles(-0.05, 1.05, 1, 1.05, -0.05, 1.25)
    _write(tmp_path, parts, window)
    changed = load_room(path)
    assert changed.content_sha256 != room.content_sha256
    third = room_transport(changed, params, backend="numpy")
    assert third.timings_s["from_cache"] is False
    assert (third.receivers.count != first.receivers.count                    # the deeper room
            or not np.allclose(third.receivers.centre, first.receivers.centre))
    def back_wall_mean(t):                                 # the far wall's mean direct light (unit DC patch)
        rec = t.receivers
        back = (rec.normal[:, 2] < -0.99) & (rec.centre[:, 2] > 0.5)      # the only inside face towards -z
        return np.average(t.direct[back, 0], weights=rec.area_m2[back])

    assert back_wall_mean(third) < 0.8 * back_wall_mean(first)      # its far wall sees less of the window


@pytest.mark.slow
def test_built_in_rooms_are_what_the_tool_makes(tmp_path):
    import subprocess
    import sys

    from catalog.core.resources import PROJECT_ROOT
    from catalog.room.load import DATA_DIR

    subprocess.run([sys.executable, str(PROJECT_ROOT / "tools" / "make_rooms.py"), "--out", str(tmp_path)],
                   check=True, capture_output=True, timeout=120)
    for name in ("box", "living", "bedroom"):
        assert (tmp_path / f"{name}.glb").read_bytes() == (DATA_DIR / f"{name}.glb").read_bytes(), name
