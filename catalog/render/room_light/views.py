"""Where the room's maps look from: the key light's frame, the captures' eyes and projections, the curtain's room-side grid, the occlusion directions."""

from __future__ import annotations

import functools
import math

import numpy as np

from catalog.render import scene as scene_lib
from catalog.render.room_light.geometry import (BACK_LUMINAIRE_EYE, BOUNCE_LEVEL, CAPTURE_SIDE_EYES,
                                                FACE_NAMES, FACE_TEXELS, LUMINAIRE_EYE, LUMINAIRE_LEVEL,
                                                LUMINAIRE_TEXELS, SHADOW_TEXELS)
from catalog.render.room_light.radiosity import (coarse_patches, patch_reflectance,
                                                 rectangle_irradiance_factor)


#: The curtain's room side (issue 11, fourth round): the room's irradiance on it is gathered at
#: this many points across and down the window opening, in the window wall's plane (every
#: other face lies wholly in front of that plane, as Lambert's formula needs; the closed
#: curtain hangs 12 cm in front of it), and read bilinearly per vertex (curtain.vert
#: ROOM_SIDE). The room's light varies over metres: 12 x 12 points are 16 x 19 cm apart.
CURTAIN_SIDE_TEXELS = (12, 12)


def curtain_side_rect() -> tuple[float, float, float, float]:
    """The room-side grid's extent (x from, y from, width, height; metres): the opening."""
    x0, x1, y0, y1 = scene_lib.WINDOW_RECT
    return (x0, y0, x1 - x0, y1 - y0)


def curtain_side_points(texels: tuple[int, int] = CURTAIN_SIDE_TEXELS) -> np.ndarray:
    """(H, W, 3) the grid's points (texel centres, row 0 = the opening's bottom), in the window
    wall's plane."""
    x0, y0, w, h = curtain_side_rect()
    tw, th = texels
    xs = x0 + (np.arange(tw) + 0.5) / tw * w
    ys = y0 + (np.arange(th) + 0.5) / th * h
    gx, gy = np.meshgrid(xs, ys)
    return np.stack([gx, gy, np.full_like(gx, scene_lib.ROOM_BOX[2][0])], axis=-1)


def curtain_side_irradiance(total_rgb: np.ndarray, albedo: float, window_albedo_rgb,
                            texels: tuple[int, int] = CURTAIN_SIDE_TEXELS) -> np.ndarray:
    """The float64 twin of room_bounce.frag's CURTAIN_SIDE gather, (H, W, 3): at each grid point
    (facing the room), E = sum_j (rho_j / pi) T_j G_j over the coarse patches of every face but
    the window wall, with ``total_rgb`` (RC, 6 RC, 3) the patches' total irradiance (the
    radiosity pass's texture, row = v) and G_j from :func:`rectangle_irradiance_factor`."""
    patches = coarse_patches()
    rc = FACE_TEXELS >> BOUNCE_LEVEL
    total = np.asarray(total_rgb, dtype=np.float64)
    # patch (f, v, u), index (f rc + v) rc + u, is atlas texel (f rc + u, v)
    t_patch = total.reshape(rc, len(FACE_NAMES), rc, 3).transpose(1, 0, 2, 3).reshape(-1, 3)
    keep = patches["face"] != FACE_NAMES.index("window_wall")
    points = curtain_side_points(texels).reshape(-1, 3)
    normals = np.broadcast_to(np.array([0.0, 0.0, 1.0]), points.shape)
    geometry = rectangle_irradiance_factor(points, normals, patches["corner"][keep],
                                           patches["s"][keep], patches["t"][keep])
    out = np.zeros((points.shape[0], 3))
    for c in range(3):
        rho = patch_reflectance(albedo, float(np.asarray(window_albedo_rgb)[c]), patches["wall"][keep])
        out[:, c] = geometry @ (rho * t_patch[keep, c]) / math.pi
    return out.reshape(texels[1], texels[0], 3)


def sample_bilinear(texture: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """GL's LINEAR filter with clamp to edge: ``texture`` (H, W, C) read at ``uv`` (P, 2) in
    [0, 1] (texel centres at (i + 0.5) / W), float64 (P, C)."""
    tex = np.asarray(texture, dtype=np.float64)
    h, w = tex.shape[:2]
    uv = np.asarray(uv, dtype=np.float64)
    x = np.clip(uv[:, 0] * w - 0.5, 0.0, w - 1.0)
    y = np.clip(uv[:, 1] * h - 0.5, 0.0, h - 1.0)
    x0 = np.minimum(np.floor(x).astype(int), w - 2) if w > 1 else np.zeros(len(x), int)
    y0 = np.minimum(np.floor(y).astype(int), h - 2) if h > 1 else np.zeros(len(y), int)
    fx = (x - x0)[:, None]
    fy = (y - y0)[:, None]
    x1 = np.minimum(x0 + 1, w - 1)
    y1 = np.minimum(y0 + 1, h - 1)
    return ((1 - fy) * ((1 - fx) * tex[y0, x0] + fx * tex[y0, x1])
            + fy * ((1 - fx) * tex[y1, x0] + fx * tex[y1, x1]))


def curtain_side_uv(positions: np.ndarray) -> np.ndarray:
    """(P, 2) where fragments at ``positions`` (P, 3) read the room-side grid: their x, y over
    the opening (curtain.frag ROOM_SIDE; outside it, clamped to the edge)."""
    x0, y0, w, h = curtain_side_rect()
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    return np.stack([(p[:, 0] - x0) / w, (p[:, 1] - y0) / h], axis=-1)


# --------------------------------------------------------------------------- the key's shadow map

def light_view_projection(to_light: np.ndarray, margin_m: float = 0.05, placement=None) -> np.ndarray:
    """Orthographic view-projection looking along the key light's travel (-to_light), framing
    the window opening and the curtain's space in front of it (what can cast a shadow): the
    room's window and curtain (``placement``, catalog.render.placement; None: the box's)."""
    to_light = np.asarray(to_light, dtype=np.float64)
    to_light = to_light / np.linalg.norm(to_light)
    forward = -to_light
    helper = np.array([0.0, 1.0, 0.0]) if abs(forward[1]) < 0.95 else np.array([1.0, 0.0, 0.0])
    right = np.cross(forward, helper)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    if placement is None:
        from catalog.render.placement import BOX as placement  # noqa: PLC0415
    wx0, wx1, wy0, wy1 = placement.window_rect
    z0 = placement.window_z
    cx, half_w = placement.window_centre_x, placement.rod_span_m / 2 + 0.15
    corners = np.array([[x, y, z] for x in (min(wx0, cx - half_w), max(wx1, cx + half_w))
                        for y in (wy0, max(wy1, placement.curtain_top_y + 0.1))
                        for z in (z0 - 0.1, placement.curtain_z + 0.35)])
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, up, -forward
    local = corners @ view[:3, :3].T
    lo, hi = local.min(axis=0) - margin_m, local.max(axis=0) + margin_m
    proj = np.eye(4)
    proj[0, 0], proj[0, 3] = 2 / (hi[0] - lo[0]), -(hi[0] + lo[0]) / (hi[0] - lo[0])
    proj[1, 1], proj[1, 3] = 2 / (hi[1] - lo[1]), -(hi[1] + lo[1]) / (hi[1] - lo[1])
    # view space looks down -z: depth from -hi.z (near) to -lo.z (far)
    near, far = -hi[2], -lo[2]
    proj[2, 2], proj[2, 3] = -2 / (far - near), -(far + near) / (far - near)
    return proj @ view


#: The cloth's own occlusion of the outside (issue 11, curtain.frag SKY_OCCLUSION): directions,
#: one front-layer depth map each (tiles of OCCLUSION_TEXELS, a square grid).
OCCLUSION_DIRECTIONS = 16
OCCLUSION_TEXELS = 128


@functools.lru_cache(maxsize=4)
def occlusion_directions(count: int = OCCLUSION_DIRECTIONS) -> np.ndarray:
    """(count, 3) unit directions towards the outside (-z), cosine-weighted about -z: the
    strata u = (j + 1/2) / count of a Fibonacci spiral, sin(theta) = sqrt(u), phi = j times
    the golden angle (their mean visibility estimates the cosine-weighted visible fraction)."""
    j = np.arange(count)
    u = (j + 0.5) / count
    r = np.sqrt(u)
    phi = j * math.pi * (3.0 - math.sqrt(5.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), -np.sqrt(1.0 - u)], -1)


def shadow_texel_m(to_light: np.ndarray, texels: int = SHADOW_TEXELS, placement=None) -> float:
    """World size (m) of one texel of a ``texels``-wide shadow map (the larger of the two axes)."""
    m = light_view_projection(to_light, placement=placement)
    return float(2.0 / min(m[0, :3] @ m[0, :3], m[1, :3] @ m[1, :3]) ** 0.5 / texels)


# --------------------------------------------------------------------------- the luminaire capture

def window_view_projection(eye, plane_z: float, near: float = 0.05, far: float = 60.0) -> np.ndarray:
    """Off-axis perspective from ``eye`` whose frustum is exactly the window opening's
    rectangle in the plane z = ``plane_z``, looking towards that plane from either side: texel
    (i, j) of a capture is the radiance of window patch (i, j) towards the eye, i counting
    along +x and j along +y whichever side the eye is on (the clip space is written out, not
    a camera's view matrix, which would mirror x for an eye looking along +z)."""
    ex, ey, ez = (float(v) for v in eye)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    sign = 1.0 if ez < plane_z else -1.0         # the view axis: +z or -z
    to_plane = sign * (plane_z - ez)             # > 0
    if to_plane <= near:
        raise ValueError(f"eye {eye} is within {near} m of the plane z = {plane_z}")
    # w = sign (z - ez): the distance along the view axis
    w_row = np.array([0.0, 0.0, sign, -sign * ez])

    def lateral(axis, e, lo, hi):
        # clip = w ndc, ndc = 2 (crossing - lo) / (hi - lo) - 1, crossing = e + (q - e) D / w
        row = np.zeros(4)
        row[axis] = 2.0 * to_plane / (hi - lo)
        row[3] = -2.0 * to_plane * e / (hi - lo)
        return row + (2.0 * (e - lo) / (hi - lo) - 1.0) * w_row

    a, b = (far + near) / (far - near), -2.0 * far * near / (far - near)
    z_row = a * w_row + np.array([0.0, 0.0, 0.0, b])
    return np.stack([lateral(0, ex, wx0, wx1), lateral(1, ey, wy0, wy1), z_row, w_row])


#: The front of the box the room sees the closed curtain through (m): the drape's folds reach
#: from the window wall (z = WINDOW_Z) to about this far into the room; the room side's patches
#: lie in this plane and the box's sides join it to the opening's edges (issue 11, ninth round).
WINDOW_FRONT_Z = 0.02

#: room.frag takes the window's direct light on the window wall within this distance of the
#: opening (m; about two light-map texels), where it falls tenfold within one texel, from a
#: finer grid (room_window_near.frag) of this many texels a side.
WINDOW_NEAR_M = 0.6
WINDOW_NEAR_TEXELS = 64
#: ... fading into the light map over this much before WINDOW_NEAR_M (m): no seam there.
WINDOW_NEAR_FADE_M = 0.15


def window_near_rect() -> tuple[float, float, float, float]:
    """The window wall's rectangle round the opening that room_window_near.frag covers (x0, x1,
    y0, y1, m): the opening widened by WINDOW_NEAR_M, within the room's walls."""
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    (bx0, bx1), (by0, by1), _ = scene_lib.ROOM_BOX
    return (max(wx0 - WINDOW_NEAR_M, bx0), min(wx1 + WINDOW_NEAR_M, bx1),
            max(wy0 - WINDOW_NEAR_M, by0), min(wy1 + WINDOW_NEAR_M, by1))


def window_near_points(texels: int = WINDOW_NEAR_TEXELS) -> np.ndarray:
    """(texels, texels, 3): room_window_near.frag's points (row 0 = the rectangle's bottom):
    the texels' centres on the window wall, those inside the opening moved onto its nearest
    edge, 1 mm out on the wall."""
    x0, x1, y0, y1 = window_near_rect()
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    f = (np.arange(texels) + 0.5) / texels
    y, x = np.meshgrid(y0 + f * (y1 - y0), x0 + f * (x1 - x0), indexing="ij")
    q = np.stack([x, y], axis=-1).reshape(-1, 2)
    inside = np.minimum(q - [wx0, wy0], [wx1, wy1] - q)
    moved = inside.min(axis=1) > -1e-3
    along_x = moved & (inside[:, 0] < inside[:, 1])
    along_y = moved & ~along_x
    q[along_x, 0] = np.where(q[along_x, 0] - wx0 < wx1 - q[along_x, 0], wx0 - 1e-3, wx1 + 1e-3)
    q[along_y, 1] = np.where(q[along_y, 1] - wy0 < wy1 - q[along_y, 1], wy0 - 1e-3, wy1 + 1e-3)
    z = np.full((q.shape[0], 1), scene_lib.ROOM_BOX[2][0])
    return np.hstack([q, z]).reshape(texels, texels, 3)


#: Eyes by the window wall that capture the box's sides as the wall beside the opening sees
#: them (left, right; m): from behind the curtain's plane most ways through a side pass in
#: front of the folds into the room, and the side eyes' radiance, seen from the room, lit that
#: strip of wall 2-2.4x the path tracer's (issue 11, ninth round).
WALL_EYES = ((-1.5, 0.2, -0.15), (1.5, 0.2, -0.15))
#: The wall eyes' captures: a box side's 9 patch rows (one column) supersampled by 2^level.
WALL_EYE_LEVEL = 3


def wall_eye_capture_size() -> tuple[int, int]:
    """A wall eye's capture size: one column of the 9 patch rows supersampled by
    2^WALL_EYE_LEVEL."""
    return 1 << WALL_EYE_LEVEL, LUMINAIRE_TEXELS[1] << WALL_EYE_LEVEL


def rectangle_view_projection(eye, corner, s, t, near: float = 0.05, far: float = 60.0) -> np.ndarray:
    """Off-axis perspective from ``eye`` whose frustum is exactly the rectangle
    ``corner + [0,1] s + [0,1] t``: normalised device x runs along s and y along t, -1 to 1
    across it (a capture's texel (i, j) is the radiance of the rectangle's cell (i, j) towards
    the eye); the view axis is the rectangle's normal, away from the eye."""
    e, c = np.asarray(eye, dtype=np.float64), np.asarray(corner, dtype=np.float64)
    s, t = np.asarray(s, dtype=np.float64), np.asarray(t, dtype=np.float64)
    axis = np.cross(s, t)
    axis /= np.linalg.norm(axis)
    if (c - e) @ axis < 0.0:
        axis = -axis
    to_plane = float((c - e) @ axis)
    if to_plane <= near:
        raise ValueError(f"eye {tuple(e)} is within {near} m of the rectangle's plane")
    w_row = np.append(axis, -axis @ e)   # the distance along the view axis

    def lateral(edge):   # clip = w ndc, ndc = 2 (crossing - corner).edge / |edge|^2 - 1
        n2 = edge @ edge
        return (2.0 * ((e - c) @ edge) / n2 - 1.0) * w_row + (2.0 * to_plane / n2) * np.append(edge, -edge @ e)

    a, b = (far + near) / (far - near), -2.0 * far * near / (far - near)
    return np.stack([lateral(s), lateral(t), a * w_row + np.array([0.0, 0.0, 0.0, b]), w_row])


def wall_eye_view_projection(right: bool, front_z: float = None) -> np.ndarray:
    """The capture of the box's left (or right) side from its wall eye (:data:`WALL_EYES`):
    the side's rectangle (x = the opening's edge, y over the opening, z from the curtain's
    plane to the box's front ``front_z``), x along +z, y along +y."""
    front_z = WINDOW_FRONT_Z if front_z is None else front_z
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    corner = (wx1 if right else wx0, wy0, scene_lib.CURTAIN_Z)
    return rectangle_view_projection(WALL_EYES[1 if right else 0], corner, (0.0, 0.0, front_z - scene_lib.CURTAIN_Z),
                                     (0.0, wy1 - wy0, 0.0))


def luminaire_view_projection(eye=LUMINAIRE_EYE, plane_z: float | None = None) -> np.ndarray:
    """The room side's capture: the opening's rectangle in the plane ``plane_z`` (default the
    box's front, :data:`WINDOW_FRONT_Z`) seen from ``eye`` in the room, texel (i, j) the
    radiance of window patch (i, j) towards the room."""
    return window_view_projection(eye, WINDOW_FRONT_Z if plane_z is None else plane_z)


def back_luminaire_view_projection(eye=BACK_LUMINAIRE_EYE) -> np.ndarray:
    """The curtain's window side, captured from outside through the rod's plane
    (scene.CURTAIN_Z): texel (i, j) the radiance that patch (i, j) of that plane sends back
    towards the window wall."""
    return window_view_projection(eye, scene_lib.CURTAIN_Z)


def capture_eye_weights(points: np.ndarray, centres: np.ndarray,
                        side_eyes=CAPTURE_SIDE_EYES, middle_eye=LUMINAIRE_EYE) -> np.ndarray:
    """(P, N, 3): the weights of the left, middle and right captures for the radiance that
    window patch n (centre ``centres[n]``, in the opening) sends to point p: piecewise linear
    in the horizontal angle atan2(dx, dz) of the way from the patch to the point, between the
    angles at which the patch sees the three eyes, clamped beyond the side eyes (the float64
    twin of room_lightmap.frag's ``captured_towards``)."""
    points = np.asarray(points, dtype=np.float64)
    centres = np.asarray(centres, dtype=np.float64)

    def angle(at):   # of the way from every patch's centre to ``at`` ((3,) or (P, 1, 3))
        d = np.asarray(at, dtype=np.float64) - centres
        return np.arctan2(d[..., 0], np.maximum(d[..., 2], 1e-6))

    a = angle(points[:, None, :])
    a_left, a_mid, a_right = angle(side_eyes[0]), angle(middle_eye), angle(side_eyes[1])
    to_left = np.clip((a_mid - a) / (a_mid - a_left), 0.0, 1.0)
    to_right = np.clip((a - a_mid) / (a_right - a_mid), 0.0, 1.0)
    left = np.where(a <= a_mid, to_left, 0.0)
    right = np.where(a > a_mid, to_right, 0.0)
    return np.stack([left, 1.0 - left - right, right], axis=-1)


def luminaire_capture_size(level: int = LUMINAIRE_LEVEL) -> tuple[int, int]:
    """A capture's render size: LUMINAIRE_TEXELS supersampled by 2^level."""
    return LUMINAIRE_TEXELS[0] << level, LUMINAIRE_TEXELS[1] << level
