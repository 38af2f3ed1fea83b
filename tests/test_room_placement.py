"""The curtain, its rod and the camera placed from the room's own window
(catalog.render.placement): the box's rules reproduce the scene's constants, any window
gets the same margins, and in every built-in room the drawn curtain is centred on its
window (read-back pixels)."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.core.errors import InputError
from catalog.render import placement as placement_lib
from catalog.render.placement import BOX, interior_box, placement_of
from catalog.render.views import VIEWS

BUILT_IN = ("box", "living", "bedroom")


def _window(x0, x1, y0, y1, z):
    return np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], dtype=np.float64)


def _box_triangles(x0, x1, y0, y1, z0, z1):
    from catalog.render.scene import box_triangles

    return box_triangles(x0, x1, y0, y1, z0, z1)


def test_the_box_rules_give_the_scene_constants_and_views():
    """The box's window through the rules: CURTAIN_Z, CURTAIN_TOP_Y, ROD_Y, the drape's
    ROD_SPAN_M and LENGTH_M exactly, and the named views unchanged."""
    assert placement_lib.check_box_constants() == []
    assert BOX.views() == VIEWS
    assert BOX.rod_length_m == pytest.approx(2.1)


def test_a_window_elsewhere_gets_the_same_margins():
    """A 2.1 x 1.45 m window 0.2 m left of the middle and 0.35 m lower (the bedroom's), in a
    wall 0.3 m farther out: the rod is centred on it, spans it less 0.1 m a side, the curtain
    hangs 0.1 m below its top, 0.12 m in front of it and ends 0.05 m below its sill."""
    corners = _window(-1.25, 0.85, -0.45, 1.0, -0.5)
    room = _box_triangles(-1.9, 2.4, -1.4, 1.35, -0.6, 3.7)
    p = placement_of(corners, (0.0, 0.0, 1.0), room)
    assert p.window_centre_x == pytest.approx(-0.2)
    assert p.rod_centre == pytest.approx((-0.2, 1.0 - 0.1 + 0.03, -0.5 + 0.12))
    assert p.rod_span_m == pytest.approx(2.1 - 0.2)
    assert p.length_m == pytest.approx(1.0 - 0.1 - (-0.45 - 0.05))
    assert p.curtain_middle == pytest.approx((-0.2, 0.9 - 0.5 * p.length_m, -0.38))
    # each view's target moves with the curtain's middle
    for name in VIEWS:
        shift = np.subtract(p.view(name).target, VIEWS[name].target)
        assert shift == pytest.approx(np.subtract(p.curtain_middle, BOX.curtain_middle)), name
    # the corners' order does not matter
    assert placement_of(corners[::-1], (0.0, 0.0, 1.0), room) == p


def test_the_interior_is_bounded_by_the_faces_looking_into_the_room():
    """A closed box seen from inside (its faces turned inwards) with a thick floor slab and a
    table: the interior is the box's inside, not the slab's outer faces nor the table's."""
    inner = (-2.0, 2.0, -1.0, 1.5, -0.2, 3.0)
    outward = _box_triangles(*inner)
    inward = outward[:, ::-1]                       # the walls' inner faces look into the room
    slab = _box_triangles(-2.1, 2.1, -1.1, -1.0, -0.3, 3.1)      # its top is the floor
    table = _box_triangles(-0.5, 0.5, -1.0, -0.3, 1.0, 1.8)
    triangles = np.concatenate([inward, slab, table])
    box = interior_box(triangles, -0.2)
    assert np.allclose(box, ((-2.0, 2.0), (-1.0, 1.5), (-0.2, 3.0)))
    # faces wound the wrong way give no box on that axis: the surfaces' bounds instead
    flipped = interior_box(outward, -0.2)
    assert flipped[0] == pytest.approx((-2.0, 2.0)) and flipped[2][0] == pytest.approx(-0.2)


def test_a_window_not_facing_the_room_axis_is_refused_in_one_line():
    corners = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, 0.0]])
    with pytest.raises(InputError, match="node 'window': faces .* only in a window facing \\+z") as info:
        placement_of(corners, (-1.0, 0.0, 0.0), _box_triangles(-2, 2, -1, 1, 0, 3), "attic.glb")
    assert "\n" not in str(info.value) and "attic.glb" in str(info.value)
    with pytest.raises(InputError, match="too small"):
        placement_of(_window(0.0, 0.15, 0.0, 1.0, 0.0), (0.0, 0.0, 1.0), _box_triangles(-2, 2, -1, 1, 0, 3))


@pytest.mark.slow
@pytest.mark.parametrize("room", BUILT_IN)
def test_the_drape_and_rod_hang_centred_on_each_rooms_window(room):
    """The settled drape (voile-white) on each built-in room's rod: its cloth spans x
    symmetrically about the window's middle (within 1 cm) and within the rod's length, its
    rings centred, its heading between
    2 cm below the curtain's top and the rings' top, its hem within 6 cm of 5 cm below the sill, in the plane
    0.12 m before the aperture (the folds' depth about it); the rod is centred and spans the
    window less 0.1 m plus 0.2 m a side."""
    from catalog.presets import find_preset, load_preset
    from catalog.render.placement import room_placement
    from catalog.render.scene import rod_mesh
    from catalog.render.snapshot import ring_xs_m, simulated_curtain

    p = room_placement(room)
    assert (p == BOX) == (room != "bedroom"), p    # box and living keep the box's window
    preset = load_preset(find_preset("voile-white"))
    positions, *_ = simulated_curtain(preset, 0, p)
    x0, x1, y0, y1 = p.window_rect
    lo, hi = positions.min(axis=0), positions.max(axis=0)
    assert 0.5 * (lo[0] + hi[0]) == pytest.approx(p.window_centre_x, abs=0.01), (lo, hi)
    half_rod = 0.5 * p.rod_length_m
    assert p.window_centre_x - half_rod < lo[0] and hi[0] < p.window_centre_x + half_rod, \
        "the cloth stays within the rod's length"
    from catalog.render.scene import RING_RADIUS_M
    assert p.curtain_top_y - 0.02 <= hi[1] <= p.rod_y + RING_RADIUS_M, (hi[1], p.curtain_top_y)
    assert lo[1] == pytest.approx(y0 - 0.05, abs=0.06)
    assert abs(0.5 * (lo[2] + hi[2]) - p.curtain_z) < 0.1 and lo[2] > p.window_z
    rings = np.asarray(ring_xs_m(preset, p))
    assert 0.5 * (rings.min() + rings.max()) == pytest.approx(p.window_centre_x, abs=1e-6)
    rod, _ = rod_mesh(p)
    assert 0.5 * (rod[:, 0].min() + rod[:, 0].max()) == pytest.approx(p.window_centre_x, abs=1e-5)
    assert rod[:, 0].max() - rod[:, 0].min() == pytest.approx(x1 - x0 - 0.2 + 0.4, abs=1e-5)


def _project(camera, aspect, points):
    clip = np.c_[points, np.ones(len(points))] @ camera.view_projection(aspect).T
    return clip[:, :2] / clip[:, 3:4]


@pytest.mark.gl
@pytest.mark.slow
@pytest.mark.parametrize("room", BUILT_IN)
def test_the_drawn_curtain_is_centred_on_its_window(room):
    """Read-back, 320x180, each room's fabric view (linen-dense under D65): the curtain's
    pixels (where the frame changes by more than a fifth of its largest change when the
    curtain is taken away) are centred on the window's projected middle within 2 px (the
    box's placement in the bedroom would be 22 px off), lie inside the window's projected
    columns widened by the rod's overhang, and reach from below its top to its sill's line."""
    from catalog.gl.context import create_headless_context
    from catalog.presets import find_preset, load_preset
    from catalog.render.settings import orbit
    from catalog.render.snapshot import new_renderer, ring_xs_m, simulated_curtain

    w, h = 320, 180
    preset = load_preset(find_preset("linen-dense"))
    ctx = create_headless_context()
    renderer = new_renderer(ctx, (w, h))
    try:
        renderer.update(fabric=preset, light="D65", room=room)
        p = renderer.placement
        view = p.view("fabric")
        renderer.update(camera=orbit(view.yaw_deg, view.pitch_deg, view.distance_m, target=view.target,
                                     fov_y_deg=view.fov_y_deg, inside=True, placement=p))
        positions, *rest, size = simulated_curtain(preset, 0, p)
        renderer.set_rings(ring_xs_m(preset, p))
        frames = []
        for shift in (0.0, -50.0):     # the curtain, then taken far below the floor
            renderer.set_mesh(positions + np.float32([0.0, shift, 0.0]), *rest, fabric_size_m=size)
            renderer.render()
            frames.append(renderer.read_linear().astype(np.float64))
        camera = renderer.camera
    finally:
        renderer.release()
    change = np.abs(frames[0] - frames[1]).mean(axis=2)
    mask = change > 0.2 * np.percentile(change, 99.5)
    cols = np.flatnonzero(mask.sum(axis=0) >= 3)
    rows = np.flatnonzero(mask.sum(axis=1) >= 3)
    assert cols.size > 0.2 * w, cols.size
    x0, x1, y0, y1 = p.window_rect
    ndc = _project(camera, w / h, np.array([[x0, y0, p.window_z], [x1, y1, p.window_z],
                                            [x0, y0 - 0.05, p.curtain_z]]))
    px = (ndc[:, 0] + 1) * 0.5 * w
    py = (1 - ndc[:, 1]) * 0.5 * h            # rows from the top
    curtain_mid = 0.5 * (cols.min() + cols.max() + 1)
    assert curtain_mid == pytest.approx(0.5 * (px[0] + px[1]), abs=2.0), (cols.min(), cols.max(), px)
    overhang = np.abs(_project(camera, w / h, np.array([[x0 - 0.1, y0, p.curtain_z]]))[0, 0]
                      - _project(camera, w / h, np.array([[x0, y0, p.curtain_z]]))[0, 0]) * 0.5 * w
    assert px[0] - overhang - 1 <= cols.min() and cols.max() + 1 <= px[1] + overhang + 1, \
        (cols.min(), cols.max(), px, overhang)
    assert rows.min() >= max(py[1], 0) - 1, (rows.min(), py)
    if py[2] < h:                               # the hem in view: it ends near the sill's line
        assert abs(rows.max() + 1 - py[2]) < 0.08 * h, (rows.max(), py)


@pytest.mark.slow
def test_export_hangs_the_curtain_in_the_rooms_own_window(tmp_path):
    """``catalog export --room bedroom``: the glTF curtain is centred on the bedroom's window
    (x -0.2 m, within 1 cm) and hangs from its rod; with the box, on the box's (x 0)."""
    import json
    import struct

    from catalog.commands.cli import main

    centres = {}
    for room in ("box", "bedroom"):
        out = tmp_path / f"{room}.glb"
        assert main(["export", "--fabric", "voile-white", "--room", room, "--out", str(out)]) == 0
        data = out.read_bytes()
        length = struct.unpack_from("<I", data, 12)[0]
        doc = json.loads(data[20:20 + length])
        position = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
        lo, hi = np.array(position["min"]), np.array(position["max"])
        centres[room] = (0.5 * (lo[0] + hi[0]), hi[1])
    assert centres["box"][0] == pytest.approx(0.0, abs=0.01)
    assert centres["bedroom"][0] == pytest.approx(-0.2, abs=0.01)
    assert centres["bedroom"][1] < centres["box"][1] - 0.3      # its window's top is 0.35 m lower


@pytest.mark.slow
@pytest.mark.parametrize("room", BUILT_IN)
def test_the_views_frame_each_rooms_window(room):
    """The default (room) view of each built-in room, as the camera stands (kept inside):
    the whole window in the 16:9 frame with a margin (|ndc| <= 0.9), at least a fifth of its
    width; the fabric view: the curtain's span across at least 60 % of the frame's width."""
    from catalog.render.camera import OrbitCamera
    from catalog.render.placement import room_placement

    p = room_placement(room)
    x0, x1, y0, y1 = p.window_rect
    window = np.array([[x, y, p.window_z] for x in (x0, x1) for y in (y0, y1)])
    camera = OrbitCamera.from_view(p.view("room"), bounds=p.interior)
    ndc = _project(camera, 16 / 9, window)
    assert np.abs(ndc).max() <= 0.9, ndc
    assert np.ptp(ndc[:, 0]) >= 0.4, ndc
    fabric = OrbitCamera.from_view(p.view("fabric"), bounds=p.interior)
    cx, half = p.window_centre_x, 0.5 * p.rod_span_m
    span = _project(fabric, 16 / 9, np.array([[cx - half, p.curtain_top_y, p.curtain_z],
                                              [cx + half, p.curtain_top_y, p.curtain_z]]))
    assert np.ptp(span[:, 0]) >= 1.2 and abs(span[:, 0].mean()) < 1e-6, span


@pytest.mark.slow
@pytest.mark.parametrize("room", BUILT_IN)
def test_the_cloth_side_grid_and_key_map_frame_each_rooms_window(room):
    """The cloth's room-side grid (the transport's gather points) spans the room's own window
    opening, and the key's map frames that window and the curtain before it: every corner of
    the opening and of the rod's span projects inside the map (the bedroom's window lies
    0.2 m left of the box's and is 0.45 m shorter)."""
    from catalog.render.curtain_frames import light_view_projection
    from catalog.render.placement import room_placement
    from catalog.render.room_operators import room_operators

    p = room_placement(room)
    x0, x1, y0, y1 = p.window_rect
    _tw, _th, gx, gy, gw, gh = room_operators(room).side_grid
    assert np.allclose((gx, gy, gx + gw, gy + gh), (x0, y0, x1, y1), atol=1e-9)
    cx, half = p.window_centre_x, p.rod_span_m / 2
    points = [(x, y, p.window_z) for x in (x0, x1) for y in (y0, y1)]
    points += [(x, p.curtain_top_y, p.curtain_z) for x in (cx - half, cx + half)]
    for to_light in ((0.3, 0.5, -0.8), (-0.5, 0.2, -0.8), (0.0, 0.0, -1.0)):
        m = light_view_projection(np.array(to_light), placement=p)
        clip = np.c_[np.array(points), np.ones(len(points))] @ m.T
        assert np.all(np.abs(clip[:, :3] / clip[:, 3:]) < 1.0), (room, to_light)
