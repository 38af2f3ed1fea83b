"""Where the curtain, its rod and the camera go in a room: all from the room's window.

The room format (docs/formats.md, "Rooms") hangs the curtain "on the room side of the
aperture, placed relative to it as it is to the box's window": the box's rules, stated once
here as margins about the aperture and applied to any room's window:

- the rod's flat span lies SIDE_MARGIN_M inside each side of the opening, centred on it; the
  rod itself reaches ROD_OVERHANG_M beyond the span on each side;
- the curtain's top hangs TOP_DROP_M below the opening's top, the rod ROD_ABOVE_M above it;
- its hem hangs HEM_BELOW_M below the opening's bottom (the fabric's length);
- it hangs CURTAIN_OFFSET_M in front of the aperture, into the room.

For the box (catalog.render.scene WINDOW_RECT, WINDOW_Z) these give the scene's constants
(CURTAIN_TOP_Y, CURTAIN_Z, ROD_Y, the drape's ROD_SPAN_M and LENGTH_M); tests hold that.

The camera's named views (catalog.render.views, the box's) are carried over by the same
rule: their targets relative to the curtain's middle, the room view's distance scaled with
the window's size, the fabric view's with the curtain's. The camera is kept inside the
room's interior (:func:`interior_box`) less catalog.render.camera.ROOM_MARGIN_M.

The renderer's passes work in the window's plane z = const with the room on +z; a room whose
window faces another way is refused in one line (:func:`placement_of`). numpy only.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from catalog.core.errors import InputError
from catalog.render.views import VIEWS, CameraView

SIDE_MARGIN_M = 0.10
ROD_OVERHANG_M = 0.20
TOP_DROP_M = 0.10
ROD_ABOVE_M = 0.03
HEM_BELOW_M = 0.05
CURTAIN_OFFSET_M = 0.12
#: The box's window (m): the reference the named views were composed for.
_BOX_WINDOW_W_M, _BOX_WINDOW_H_M = 1.9, 2.25
#: The box curtain's flat span and length (m), for the fabric view's scale.
_BOX_SPAN_M, _BOX_LENGTH_M = 1.7, 2.2
#: A window's normal within this of +z (the renderer's convention) is taken as +z.
NORMAL_TOLERANCE = 1e-3


def _nm(length_m: float) -> float:
    """A derived length rounded to the nanometre: the box's margins then give its constants
    exactly (1.9 - 0.2 is 1.7, not 1.6999999999999997), so its drapes keep their cache keys."""
    return round(float(length_m), 9)


@dataclass(frozen=True)
class Placement:
    """The curtain, rod and camera of one room. ``window_rect`` (x0, x1, y0, y1) and
    ``window_z``: the aperture as the room file states it; ``interior``: the room's inside
    ((x0, x1), (y0, y1), (z0, z1)) m, where the camera may go."""

    window_rect: tuple
    window_z: float
    interior: tuple

    @property
    def window_centre_x(self) -> float:
        return _nm(0.5 * (self.window_rect[0] + self.window_rect[1]))

    @property
    def window_size_m(self) -> tuple[float, float]:
        x0, x1, y0, y1 = self.window_rect
        return _nm(x1 - x0), _nm(y1 - y0)

    @property
    def curtain_z(self) -> float:
        return _nm(self.window_z + CURTAIN_OFFSET_M)

    @property
    def curtain_top_y(self) -> float:
        return _nm(self.window_rect[3] - TOP_DROP_M)

    @property
    def rod_y(self) -> float:
        return _nm(self.curtain_top_y + ROD_ABOVE_M)

    @property
    def rod_span_m(self) -> float:
        """The flat span the rings cover (the drape's rod span)."""
        return _nm(self.window_size_m[0] - 2 * SIDE_MARGIN_M)

    @property
    def rod_length_m(self) -> float:
        return _nm(self.rod_span_m + 2 * ROD_OVERHANG_M)

    @property
    def length_m(self) -> float:
        """The fabric's length below the rings."""
        return _nm(self.curtain_top_y - (self.window_rect[2] - HEM_BELOW_M))

    @property
    def rod_centre(self) -> tuple[float, float, float]:
        return (self.window_centre_x, self.rod_y, self.curtain_z)

    @property
    def curtain_middle(self) -> tuple[float, float, float]:
        """The middle of the hanging curtain: the fabric view's target."""
        return (self.window_centre_x, _nm(self.curtain_top_y - 0.5 * self.length_m), self.curtain_z)

    def curtain_offset(self, params) -> np.ndarray:
        """(3,) float32: what moves a drape of ``params`` (catalog.cloth.params.ClothParams, its
        rings at y = rod_y_m) onto this rod, the rings' span centred on the window."""
        from catalog.cloth.drape import rod_centre_x_m  # noqa: PLC0415

        return np.array([self.window_centre_x - rod_centre_x_m(params),
                         self.curtain_top_y - params.rod_y_m, self.curtain_z], dtype=np.float32)

    def view(self, name: str) -> CameraView:
        """The named view (catalog.render.views.VIEWS, composed for the box) for this window:
        its target moved with the curtain's middle, the room view's distance scaled with the
        window's size, the fabric view's with the curtain's, each no farther than the room's
        inside allows; the close-up keeps its 0.5 m."""
        from catalog.render.views import view_named  # noqa: PLC0415

        box = view_named(name)
        middle = np.asarray(self.curtain_middle)
        target = tuple(_nm(v) for v in middle + (np.asarray(box.target) - BOX_MIDDLE))
        width, height = self.window_size_m
        scale = {"room": max(width / _BOX_WINDOW_W_M, height / _BOX_WINDOW_H_M),
                 "fabric": max(self.rod_span_m / _BOX_SPAN_M, self.length_m / _BOX_LENGTH_M)}.get(name, 1.0)
        from catalog.render.camera import room_limit_m  # noqa: PLC0415

        # no farther than the room allows in that direction (a small room's back wall)
        distance = min(box.distance_m * scale, room_limit_m(target, box.yaw_deg, box.pitch_deg, self.interior))
        return CameraView(target, box.yaw_deg, box.pitch_deg, _nm(distance), box.fov_y_deg, box.about)

    def views(self) -> dict[str, CameraView]:
        return {name: self.view(name) for name in VIEWS}


def placed_drape_params(preset, placement=None, **overrides):
    """The preset's drape parameters (catalog.cloth.drape.drape_params) on the rod of
    ``placement`` (None: the box's): the rod's span and the fabric's length from the window."""
    from catalog.cloth.drape import drape_params  # noqa: PLC0415

    placement = placement or BOX
    return drape_params(preset, span_m=placement.rod_span_m, length_m=placement.length_m, **overrides)


def interior_box(triangles: np.ndarray, window_z: float) -> tuple:
    """The room's inside as an axis-aligned box: on each axis, the innermost of the surfaces
    facing into the room (the walls' inner faces: the least x of the faces looking along +x,
    the greatest of those looking along -x, and so on; the outer faces of the walls look
    outwards, furniture lies within); the near side is the window's plane. A room whose faces
    give no such box (inconsistent winding) falls back to the surfaces' bounds."""
    t = np.asarray(triangles, dtype=np.float64)
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    length = np.linalg.norm(n, axis=1)
    keep = length > 0
    t, n = t[keep], n[keep] / length[keep, None]
    centre = t.mean(axis=1)
    lo_all, hi_all = t.reshape(-1, 3).min(axis=0), t.reshape(-1, 3).max(axis=0)
    box = []
    for axis in range(3):
        facing_up, facing_down = n[:, axis] > 0.99, n[:, axis] < -0.99
        lo = centre[facing_up, axis].min() if facing_up.any() else lo_all[axis]
        hi = centre[facing_down, axis].max() if facing_down.any() else hi_all[axis]
        if not lo < hi:
            lo, hi = lo_all[axis], hi_all[axis]
        box.append((round(float(lo), 6), round(float(hi), 6)))   # the micrometre, as the window
    box[2] = (float(window_z), max(box[2][1], float(window_z) + 0.5))
    return tuple(box)


def placement_of(window_corners, window_normal, triangles, source: str = "room") -> Placement:
    """The placement of a room given its window (corners (4, 3), normal into the room) and its
    surfaces' triangles (T, 3, 3); refused in one line when the window does not face +z."""
    corners = np.asarray(window_corners, dtype=np.float64)
    normal = np.asarray(window_normal, dtype=np.float64)
    if not normal[2] > 1.0 - NORMAL_TOLERANCE:
        raise InputError(f"node 'window': faces ({normal[0]:.3g}, {normal[1]:.3g}, {normal[2]:.3g}); "
                         "the renderer hangs the curtain only in a window facing +z (into the room)",
                         path=source)
    # a file's float32 corners rounded to the micrometre (about their precision at a room's
    # scale), so that the box's file gives the box's placement exactly
    rect = tuple(round(float(v), 6) for v in (corners[:, 0].min(), corners[:, 0].max(),
                                              corners[:, 1].min(), corners[:, 1].max()))
    z = round(float(corners[:, 2].mean()), 6)
    if rect[1] - rect[0] <= 2 * SIDE_MARGIN_M or rect[3] - rect[2] <= TOP_DROP_M:
        raise InputError(f"node 'window': {rect[1] - rect[0]:.3g} x {rect[3] - rect[2]:.3g} m is too "
                         "small to hang a curtain in", path=source)
    return Placement(window_rect=rect, window_z=z, interior=interior_box(triangles, z))


def placement_of_room(room) -> Placement:
    """The placement of a loaded room (catalog.room.model.Room)."""
    return placement_of(room.window.corners, room.window.normal, room.triangles(), room.source)


@functools.lru_cache(maxsize=8)
def _placement_of_bundle(path: str, key: str, spec: str) -> Placement:
    from catalog.render.room_operators import room_operators  # noqa: PLC0415

    ops = room_operators(spec)
    return placement_of(ops.window_corners, ops.window_normal, ops.triangles, path)


def room_placement(spec) -> Placement:
    """The placement of a room given by a built-in name or a .glb path (its window and
    surfaces from the room's frame bundle, built when absent); None: the box."""
    if spec is None:
        return BOX
    from catalog.render.room_operators import bundle_path  # noqa: PLC0415

    path, key, _ = bundle_path(spec)
    return _placement_of_bundle(str(path), key, str(spec))


def _box() -> Placement:
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    return Placement(window_rect=tuple(scene_lib.WINDOW_RECT), window_z=scene_lib.WINDOW_Z,
                     interior=tuple(tuple(a) for a in scene_lib.ROOM_BOX))


#: The box's placement (the scene's constants; the room None of the library).
BOX = _box()
BOX_MIDDLE = np.asarray(BOX.curtain_middle)


def check_box_constants() -> list[str]:
    """The scene constants the box's placement should reproduce, and any that differ."""
    from catalog.cloth import drape  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    pairs = {"CURTAIN_Z": (BOX.curtain_z, scene_lib.CURTAIN_Z),
             "CURTAIN_TOP_Y": (BOX.curtain_top_y, scene_lib.CURTAIN_TOP_Y),
             "ROD_Y": (BOX.rod_y, scene_lib.ROD_Y),
             "ROD_SPAN_M": (BOX.rod_span_m, drape.ROD_SPAN_M),
             "LENGTH_M": (BOX.length_m, drape.LENGTH_M),
             "CURTAIN_WIDTH_M": (BOX.rod_span_m, scene_lib.CURTAIN_WIDTH_M)}
    return [name for name, (a, b) in pairs.items() if not math.isclose(a, b, abs_tol=1e-9)]
