"""The window's light on the room in numpy: the beam's mask, the box round the folds, the captured patches' irradiance (the twin of room_lightmap.frag)."""

from __future__ import annotations

import math

import numpy as np

from catalog.render import scene as scene_lib
from catalog.render.room_light.geometry import FACE_TEXELS, LUMINAIRE_TEXELS, room_faces, texel_points
from catalog.render.room_light.views import WALL_EYES, WINDOW_FRONT_Z, capture_eye_weights
from catalog.render.room_light.radiosity import rectangle_irradiance_factor


#: room_lightmap.frag averages the window's light over 2 x 2 points of a texel within this
#: distance of the window's plane (m), its centre alone further away.
WINDOW_SUPERSAMPLE_M = 1.0


def window_patch_rectangles(plane_z: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The luminaire's patches in the plane z = ``plane_z``, in capture order (row j, column
    i: index j * 12 + i): corners (N, 3) and edges s, t (N, 3 each)."""
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    nx, ny = LUMINAIRE_TEXELS
    cx, cy = (wx1 - wx0) / nx, (wy1 - wy0) / ny
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    corners = np.stack([wx0 + i.ravel() * cx, wy0 + j.ravel() * cy,
                        np.full(i.size, float(plane_z))], axis=-1)
    s = np.broadcast_to([cx, 0.0, 0.0], corners.shape)
    t = np.broadcast_to([0.0, cy, 0.0], corners.shape)
    return corners, np.array(s), np.array(t)


def _smoothstep(edge0, edge1, x):
    t = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def window_beam_mask(points: np.ndarray, to_light, tan_radius: float = math.tan(scene_lib.SUN_RADIUS_RAD)) -> np.ndarray:
    """The float64 twin of common.glsl's ``room_window_beam``: the fraction of the key's beam
    that reaches ``points`` (P, 3) through the opening (its inner and outer planes, edges
    softened by the light's angular radius x the distance to each plane)."""
    p = np.asarray(points, dtype=np.float64)
    to_light = np.asarray(to_light, dtype=np.float64)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    z_in = scene_lib.ROOM_BOX[2][0]
    z_out = z_in - scene_lib.WALL_THICKNESS_M

    def soft_rect(q, half):
        lo_x = _smoothstep(wx0 - half, wx0 + half, q[:, 0])
        lo_y = _smoothstep(wy0 - half, wy0 + half, q[:, 1])
        hi_x = 1.0 - _smoothstep(wx1 - half, wx1 + half, q[:, 0])
        hi_y = 1.0 - _smoothstep(wy1 - half, wy1 + half, q[:, 1])
        return lo_x * lo_y * hi_x * hi_y

    s_in = (z_in - p[:, 2]) / to_light[2]
    s_out = (z_out - p[:, 2]) / to_light[2]
    q_in = p[:, :2] + s_in[:, None] * to_light[:2]
    q_out = p[:, :2] + s_out[:, None] * to_light[:2]
    inner = np.where(s_in > 0.0, soft_rect(q_in, s_in * tan_radius + 1e-3), 1.0)
    return (s_out >= 0.0) * inner * soft_rect(q_out, s_out * tan_radius + 1e-3)


def _key_lobe(points: np.ndarray, centres: np.ndarray, alpha: np.ndarray, lobe: dict | None) -> np.ndarray:
    """(P, N, 3): common.glsl ``key_lobe`` from rectangles centred at ``centres`` (N, 3) whose
    cloth the key reaches by ``alpha`` (N,) towards ``points`` (P, 3); 0 without ``lobe``
    (keywords lobe_rgb, g_spec, to_light)."""
    if lobe is None:
        return np.zeros((points.shape[0], centres.shape[0], 3))
    to_light = np.asarray(lobe["to_light"], dtype=np.float64)
    w = points[:, None, :] - centres[None, :, :]
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    chord2 = np.sum((w + to_light) ** 2, axis=-1)
    g = float(lobe["g_spec"])
    d = (1.0 - g) ** 2 + g * chord2
    phase = (1.0 - g) * (1.0 + g) / (4.0 * math.pi) / (d * np.sqrt(d))
    return (np.asarray(alpha, dtype=np.float64)[None, :] * phase)[..., None] \
        * np.asarray(lobe["lobe_rgb"], dtype=np.float64)


def window_box_rectangles(front_z: float = WINDOW_FRONT_Z) -> dict[str, tuple[np.ndarray, ...]]:
    """The box the room sees the closed curtain through (common.glsl ``window_irradiance``),
    each (corners, s, t) (N, 3): "front" the opening's 12 x 9 patches in the plane ``front_z``
    (capture order); "left" and "right" the sides x = x0, x1 from the curtain's plane to the
    front, a rectangle a patch row (9); "bottom" and "top" y = y0, y1, one a patch column
    (12); "left_gap" and "right_gap" the sides between the window wall and the curtain's
    plane (9 each); "back" the window side's patches in the curtain's plane."""
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    nx, ny = LUMINAIRE_TEXELS
    cx, cy = (wx1 - wx0) / nx, (wy1 - wy0) / ny
    wall_z, back_z = scene_lib.ROOM_BOX[2][0], scene_lib.CURTAIN_Z
    rows, cols = np.arange(ny), np.arange(nx)
    depth = np.array([0.0, 0.0, front_z - back_z])
    gap = np.array([0.0, 0.0, back_z - wall_z])

    def rects(corners, s, t):
        corners = np.asarray(corners, dtype=np.float64)
        return corners, np.broadcast_to(s, corners.shape).copy(), np.broadcast_to(t, corners.shape).copy()

    def side(x, z0, edge):
        return rects(np.stack([np.full(ny, x), wy0 + rows * cy, np.full(ny, z0)], -1), edge, [0.0, cy, 0.0])

    def cap(y):
        return rects(np.stack([wx0 + cols * cx, np.full(nx, y), np.full(nx, back_z)], -1), depth, [cx, 0.0, 0.0])

    return {"front": window_patch_rectangles(front_z), "back": window_patch_rectangles(back_z),
            "left": side(wx0, back_z, depth), "right": side(wx1, back_z, depth),
            "left_gap": side(wx0, wall_z, gap), "right_gap": side(wx1, wall_z, gap),
            "bottom": cap(wy0), "top": cap(wy1)}


def box_side_angle(centres: np.ndarray, points: np.ndarray, right: bool) -> np.ndarray:
    """common.glsl ``box_side_angle``: the angle (rad) of the way from ``centres`` on the box's
    side (right: x = x1, else x0) to ``points`` (broadcast), up from the side's outward normal
    towards +z."""
    d = np.asarray(points, dtype=np.float64) - np.asarray(centres, dtype=np.float64)
    return np.arctan2(d[..., 2], d[..., 0] if right else -d[..., 0])


def wall_eye_weight(centres: np.ndarray, points: np.ndarray, right: bool) -> np.ndarray:
    """The share of the box side's radiance (rows centred at ``centres`` (N, 3)) towards
    ``points`` (P, 3) taken from the room's side eye, the rest from the wall eye, (P, N):
    linear in :func:`box_side_angle` from the wall eye's angle (0) to level (1; a way level
    with the side's centre or falling crosses the folds, one rising from below it leaves by
    the box's front), clamped."""
    eye = np.asarray(WALL_EYES[1 if right else 0], dtype=np.float64)
    a_wall = box_side_angle(centres, eye, right)[None, :]
    a = box_side_angle(centres[None, :, :], np.asarray(points, dtype=np.float64)[:, None, :], right)
    return np.clip((a - a_wall) / (0.0 - a_wall), 0.0, 1.0)


def window_irradiance_at(points: np.ndarray, normals: np.ndarray, radiance_front: np.ndarray,
                         radiance_back: np.ndarray, radiance_sides: np.ndarray | None = None,
                         lobe: dict | None = None, alpha=None,
                         front_z: float = WINDOW_FRONT_Z, radiance_walls: np.ndarray | None = None) -> np.ndarray:
    """The float64 twin of common.glsl's ``window_irradiance``, (P, 3), at ``points`` (P, 3)
    of the room outside the opening with ``normals``: the front's patches (plane ``front_z``;
    ``radiance_front`` (9, 12, 3), the middle capture at its patch level, blended per point
    and patch with ``radiance_sides`` (2, 9, 12, 3), the side eyes' captures, by
    :func:`capture_eye_weights`) where the point lies before that plane; with a box
    (``front_z`` before the curtain's plane), its sides (the edge column of the side eye
    towards them), bottom and top (the blended edge row) and, for points before the curtain's
    plane, the sides' gaps (the window side's edge column); behind the curtain's plane, the
    window side's patches (``radiance_back``). ``radiance_walls`` (2, 9, 3): the wall eyes'
    captures of the sides, blended with the side eyes' by :func:`wall_eye_weight`. ``lobe``
    (keywords lobe_rgb, g_spec, to_light) adds the key's directional lobe to the room side's
    rectangles, scaled by ``alpha`` (9, 12), the middle capture's alpha. E = sum L F, F from
    :func:`rectangle_irradiance_factor`."""
    p = np.asarray(points, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    lf = np.asarray(radiance_front, dtype=np.float64).reshape(LUMINAIRE_TEXELS[1], LUMINAIRE_TEXELS[0], 3)
    lb = np.asarray(radiance_back, dtype=np.float64).reshape(-1, 3)
    a = (np.zeros(lf.shape[:2]) if alpha is None else np.asarray(alpha, dtype=np.float64).reshape(lf.shape[:2]))
    sides = None if radiance_sides is None else np.asarray(radiance_sides, dtype=np.float64).reshape((2,) + lf.shape)
    box = window_box_rectangles(front_z)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    back_z = scene_lib.CURTAIN_Z

    def blended(rows, cols, centres, at):   # (A, N, 3): captured_towards
        middle = lf[rows, cols]
        if sides is None:
            return np.broadcast_to(middle, (at.shape[0],) + middle.shape)
        w = capture_eye_weights(at, centres)
        return w[..., 0:1] * sides[0][rows, cols][None] + w[..., 1:2] * middle[None] + w[..., 2:3] * sides[1][rows, cols][None]

    def add(e, mask, rect, radiance, alpha_n):   # radiance (A, N, 3) or (N, 3)
        if not mask.any():
            return
        corners, s, t = rect
        at = p[mask]
        centres = corners + 0.5 * (s + t)
        factors = rectangle_irradiance_factor(at, n[mask], corners, s, t)
        total = np.broadcast_to(radiance, (at.shape[0],) + corners.shape) + _key_lobe(at, centres, alpha_n, lobe)
        e[mask] += np.einsum("pn,pnc->pc", factors, total)

    e = np.zeros(p.shape)
    ny, nx = lf.shape[:2]
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    front = box["front"]
    before_front = p[:, 2] > front_z + 1e-4
    if before_front.any():
        centres = front[0] + 0.5 * (front[1] + front[2])
        add(e, before_front, front, blended(j.ravel(), i.ravel(), centres, p[before_front]), a.ravel())
    if front_z > back_z:
        rows, cols = np.arange(ny), np.arange(nx)
        for name, col, mask in (("left", 0, p[:, 0] < wx0 - 1e-4), ("right", nx - 1, p[:, 0] > wx1 + 1e-4)):
            right = name == "right"
            edge = lf[rows, col] if sides is None else sides[1 if right else 0][rows, col]
            if radiance_walls is not None and mask.any():
                corners, s, t = box[name]
                weight = wall_eye_weight(corners + 0.5 * (s + t), p[mask], right)[..., None]
                walls = np.asarray(radiance_walls, dtype=np.float64).reshape(2, ny, 3)[1 if right else 0]
                edge = weight * edge[None] + (1.0 - weight) * walls[None]
            add(e, mask, box[name], edge, a[rows, col])
            gap_radiance = lb.reshape(ny, nx, 3)[rows, col]
            add(e, mask & (p[:, 2] > back_z), box[name + "_gap"], gap_radiance, np.zeros(ny))
        for name, row, mask in (("bottom", 0, p[:, 1] < wy0 - 1e-4), ("top", ny - 1, p[:, 1] > wy1 + 1e-4)):
            if mask.any():
                corners, s, t = box[name]
                centres = corners + 0.5 * (s + t)
                add(e, mask, box[name], blended(np.full(nx, row), cols, centres, p[mask]), a[row, cols])
    behind = p[:, 2] < back_z
    if behind.any():
        corners, s, t = box["back"]
        e[behind] += rectangle_irradiance_factor(p[behind], n[behind], corners, s, t) @ lb
    return e


def window_irradiance(radiance_front: np.ndarray, radiance_back: np.ndarray,
                      face_texels: int = FACE_TEXELS, lobe: dict | None = None,
                      radiance_sides: np.ndarray | None = None, alpha=None,
                      front_z: float = WINDOW_FRONT_Z, radiance_walls: np.ndarray | None = None) -> np.ndarray:
    """The float64 twin of room_lightmap.frag's window term, (R, 6R, 3): per atlas texel, the
    mean over its sample points on a wall (2 x 2 within WINDOW_SUPERSAMPLE_M of the window's
    plane, else the centre; none inside the opening) of :func:`window_irradiance_at` (its
    arguments)."""
    positions, _normals = texel_points(face_texels)
    wall_z = scene_lib.ROOM_BOX[2][0]
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    out = np.zeros(positions.shape[:2] + (3,))
    for k, face in enumerate(room_faces()):
        cols = slice(k * face_texels, (k + 1) * face_texels)
        centres = positions[:, cols].reshape(-1, 3)
        near = centres[:, 2] < wall_z + WINDOW_SUPERSAMPLE_M
        total = np.zeros((centres.shape[0], 3))
        count = np.zeros(centres.shape[0])
        offsets = [(0.0, 0.0, True)] + [((a - 0.5) * 0.5, (b - 0.5) * 0.5, False)
                                         for b in (0, 1) for a in (0, 1)]
        for ds, dt, is_centre in offsets:
            use = ~near if is_centre else near
            q = centres + (ds * face.axis_s + dt * face.axis_t) / face_texels
            in_opening = ((q[:, 2] < wall_z + 1e-4) & (q[:, 0] > wx0) & (q[:, 0] < wx1)
                          & (q[:, 1] > wy0) & (q[:, 1] < wy1))
            use = use & ~in_opening
            if not use.any():
                continue
            n = np.broadcast_to(face.normal, q[use].shape)
            total[use] += window_irradiance_at(q[use], n, radiance_front, radiance_back, radiance_sides,
                                               lobe=lobe, alpha=alpha, front_z=front_z,
                                               radiance_walls=radiance_walls)
            count[use] += 1
        mean = np.where(count[:, None] > 0, total / np.maximum(count, 1)[:, None], 0.0)
        out[:, cols] = mean.reshape(face_texels, face_texels, 3)
    return out
