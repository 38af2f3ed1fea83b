"""The curtain's coarse grid, the room's lamps, the view's regions and the light the window wall shows the cloth (the twin of WALL_LIGHT)."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from catalog.render import scene as scene_lib
from catalog.render.room_light.views import occlusion_directions, sample_bilinear
from catalog.render.room_light.geometry import room_faces
from catalog.render.room_light.window import window_beam_mask


#: The room's shadow map and the occlusion maps draw the curtain from a grid with at most this many
#: vertices a side: on a CPU rasteriser a draw costs per triangle, and the beam's pattern
#: needs the folds (5.5 across), not every vertex.
COARSE_GRID_SIDE = 40


def coarse_grid_indices(uvs: np.ndarray, max_side: int = COARSE_GRID_SIDE) -> np.ndarray | None:
    """Triangles (int32, flat) over every k-th row and column of a row-major grid mesh, or
    None when the vertices are not such a grid (u running 0..1 along each row, v constant in
    it) or the grid is small already. The last row and column are always kept."""
    uvs = np.asarray(uvs, dtype=np.float64).reshape(-1, 2)
    n = uvs.shape[0]
    starts = np.flatnonzero(np.abs(uvs[:, 0]) < 1e-9)
    if starts.size < 2:
        return None
    columns = int(starts[1] - starts[0])
    if columns < 2 or n % columns:
        return None
    rows = n // columns
    grid = uvs.reshape(rows, columns, 2)
    if not (np.allclose(grid[:, :, 0], np.linspace(0.0, 1.0, columns)[None, :], atol=1e-6)
            and np.allclose(grid[:, :, 1], grid[:, :1, 1], atol=1e-9)):
        return None
    step = int(math.ceil(max(rows, columns) / max_side))
    if step <= 1:
        return None

    def keep(count):
        picks = list(range(0, count, step))
        return picks if picks[-1] == count - 1 else picks + [count - 1]

    r, c = np.array(keep(rows)), np.array(keep(columns))
    index = r[:, None] * columns + c[None, :]
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    cc, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    return np.concatenate([np.stack([a, cc, b], 1), np.stack([b, cc, d], 1)]).astype(np.int32).ravel()


@dataclass(frozen=True)
class RoomLamp:
    """A lamp in the room: a light of the library at ``position_m``, isotropic, its normal
    irradiance at 1 m equal to the light's spectrum (intensity = E(1 m) x 1 m^2)."""

    light: str
    position_m: tuple[float, float, float]


def check_lamp_position(position_m) -> tuple[float, float, float]:
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    p = tuple(float(v) for v in position_m)
    (x0, x1), (y0, y1), (z0, z1) = scene_lib.ROOM_BOX
    if len(p) != 3 or not (x0 < p[0] < x1 and y0 < p[1] < y1 and z0 < p[2] < z1):
        raise CatalogError(f"room lamp position {position_m!r} must lie inside the room "
                           f"x {x0}..{x1}, y {y0}..{y1}, z {z0}..{z1} m")
    return p


# --------------------------------------------------------------------------- regions of a view

#: Names of the regions :func:`view_regions` returns (the tests and the path-traced
#: comparison of the same scene use the same masks).
REGION_NAMES = ("floor_patch", "floor_away", "window_wall_strips")


def pixel_rays(view_projection: np.ndarray, eye, size) -> np.ndarray:
    """(H, W, 3) unit directions from ``eye`` through each pixel's centre (row 0 = top) of a
    view ``size`` = (W, H) pixels: the far plane's points unprojected."""
    w, h = size
    inv = np.linalg.inv(np.asarray(view_projection, dtype=np.float64))
    ys, xs = np.mgrid[0:h, 0:w]
    ndc = np.stack([(xs + 0.5) / w * 2 - 1, 1 - (ys + 0.5) / h * 2, np.ones((h, w)),
                    np.ones((h, w))], -1)
    far = ndc @ inv.T
    d = far[..., :3] / far[..., 3:] - np.asarray(eye, dtype=np.float64)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def view_regions(view_projection: np.ndarray, eye, size, to_light) -> dict[str, np.ndarray]:
    """Boolean (H, W) masks of a view (row 0 = top), found by geometry, not by shading:

    - ``floor_patch``: floor pixels the key's beam reaches through the hanging curtain
      (margins of 0.08 m inside the opening and 0.1-0.15 m inside the curtain);
    - ``floor_away``: floor pixels whose beam would cross the wall 0.3 m or more outside
      the opening;
    - ``window_wall_strips``: the outer fifths of the frame (the wall beside the window in
      the default view).
    """
    w, h = size
    eye = np.asarray(eye, dtype=np.float64)
    d = pixel_rays(view_projection, eye, size)
    (x0, x1), (y0, _), (z0, z1) = scene_lib.ROOM_BOX
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (y0 - eye[1]) / d[..., 1]
    p = eye + t[..., None] * d
    floor = (t > 0) & (p[..., 0] > x0 + 0.2) & (p[..., 0] < x1 - 0.2) & (p[..., 2] > z0 + 0.4) & (p[..., 2] < z1 - 0.2)
    to_light = np.asarray(to_light, dtype=np.float64)

    def crossing(z):
        s = (z - p[..., 2]) / to_light[2]
        return p[..., :2] + s[..., None] * to_light[:2]

    q = crossing(z0)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    m = 0.08
    in_window = (q[..., 0] > wx0 + m) & (q[..., 0] < wx1 - m) & (q[..., 1] > wy0 + m) & (q[..., 1] < wy1 - m)
    qc = crossing(scene_lib.CURTAIN_Z)
    half = scene_lib.CURTAIN_WIDTH_M / 2
    through = ((np.abs(qc[..., 0]) < half - 0.1) & (qc[..., 1] < scene_lib.CURTAIN_TOP_Y - 0.1)
               & (qc[..., 1] > scene_lib.CURTAIN_TOP_Y - scene_lib.CURTAIN_HEIGHT_M + 0.15))
    away = ((q[..., 0] < wx0 - 0.3) | (q[..., 0] > wx1 + 0.3) | (q[..., 1] < wy0 - 0.3)
            | (q[..., 1] > wy1 + 0.3))
    strips = np.zeros((h, w), dtype=bool)
    strips[:, : w // 5] = True
    strips[:, w - w // 5:] = True
    return {"floor_patch": floor & in_window & through, "floor_away": floor & away,
            "window_wall_strips": strips}



# --------------------------------------------------------------------------- the wall beside the cloth

@dataclass(frozen=True)
class WallLightSources:
    """What the window wall and its reveals show the cloth's window side (walled_radiance):
    the light map (irradiance, linear sRGB, (R, 6R, 3), row 0 = t = 0), the window-side
    capture at the reveals' level ((H, W, 3), row 0 = the opening's bottom), 0.5 pi x the
    sky's and the ground's radiance, the key's normal irradiance (linear sRGB) and its
    direction towards the light, the walls' albedo."""

    lightmap: np.ndarray
    back: np.ndarray
    reveal_sky: np.ndarray
    reveal_ground: np.ndarray
    key_rgb: np.ndarray
    to_light: np.ndarray
    albedo: float = scene_lib.ROOM_ALBEDO


def reveal_irradiance(points: np.ndarray, normals: np.ndarray, back: np.ndarray,
                      reveal_sky, reveal_ground) -> np.ndarray:
    """The float64 twin of common.glsl's ``reveal_irradiance`` (issue 11, fourth round): on a
    reveal (or the wall's outer face) the outside over the half of its hemisphere facing it
    (the sky above the horizon, the ground below) and the curtain's window side (``back``'s
    texel at the point's place in the opening) over the half facing the room, (P, 3)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    up = (0.5 + 0.5 * n[:, 1])[:, None]
    outside = (1.0 + np.maximum(-n[:, 2], 0.0))[:, None] * (
        up * np.asarray(reveal_sky, dtype=np.float64) + (1.0 - up) * np.asarray(reveal_ground, dtype=np.float64))
    fx = np.clip((p[:, 0] - wx0) / (wx1 - wx0), 0.0, 0.999)
    fy = np.clip((p[:, 1] - wy0) / (wy1 - wy0), 0.0, 0.999)
    h, w = back.shape[:2]
    seen = np.asarray(back, dtype=np.float64)[(fy * h).astype(int), (fx * w).astype(int)]
    return outside + (0.5 * math.pi * (1.0 - np.abs(n[:, 2])))[:, None] * seen


def wall_radiance_along(points: np.ndarray, directions: np.ndarray, sources: WallLightSources,
                        with_walled: bool = False):
    """(P, 3) the radiance met from ``points`` (P, 3) along ``directions`` (P, 3) (towards the
    window, d.z < 0) where they miss the opening, 0 where they pass it (``with_walled``: and
    the (P,) mask of the directions that miss it): the room's face where
    the ray leaves the room box (albedo / pi x the light map, bilinear), or, through the wall's
    inner plane inside the opening but not its outer one, the reveal it meets (albedo / pi x
    (:func:`reveal_irradiance` + the key, cos x the window's mask, undimmed: the reveals lie
    before the cloth)). The float64 twin of common.glsl's ``wall_radiance_along``."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    (x0, x1), (y0, y1), (z0, _) = scene_lib.ROOM_BOX
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    z_out = z0 - scene_lib.WALL_THICKNESS_M
    faces = room_faces()
    lightmap = np.asarray(sources.lightmap, dtype=np.float64)
    texels = lightmap.shape[0]
    to_light = np.asarray(sources.to_light, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        def plane_t(lo, hi, axis):
            t = (np.where(d[:, axis] > 0, hi, lo) - p[:, axis]) / d[:, axis]
            return np.where(np.abs(d[:, axis]) > 1e-12, t, np.inf)

        t_x, t_y = plane_t(x0, x1, 0), plane_t(y0, y1, 1)
        t_z = (z0 - p[:, 2]) / d[:, 2]
        q_in = p + t_z[:, None] * d
        q_out = p + ((z_out - p[:, 2]) / d[:, 2])[:, None] * d

        def inside(q):
            return (q[:, 0] >= wx0) & (q[:, 0] <= wx1) & (q[:, 1] >= wy0) & (q[:, 1] <= wy1)

        through_inner = (t_z <= np.minimum(t_x, t_y)) & inside(q_in)
        opening = through_inner & inside(q_out)
        reveal = through_inner & ~opening
        # the room's faces
        t_exit = np.minimum(np.minimum(t_x, t_y), t_z)
        q = p + t_exit[:, None] * d
        face = np.where(t_exit == t_z, 5, np.where(t_x <= t_y, np.where(d[:, 0] > 0, 3, 2),
                                                   np.where(d[:, 1] > 0, 1, 0)))
        out = np.zeros((p.shape[0], 3))
        edge = 0.5 / texels
        for k, f in enumerate(faces):
            on = (face == k) & ~through_inner
            if on.any():
                rel = q[on] - f.origin
                s = np.clip(rel @ f.axis_s / (f.axis_s @ f.axis_s), edge, 1 - edge)
                t = np.clip(rel @ f.axis_t / (f.axis_t @ f.axis_t), edge, 1 - edge)
                out[on] = sample_bilinear(lightmap, np.stack([(k + s) / len(faces), t], -1))
        # the reveals: where the ray leaves the opening's tunnel, between the wall's planes
        if reveal.any():
            pr, dr = p[reveal], d[reveal]
            tx_r = np.where(np.abs(dr[:, 0]) > 1e-12, (np.where(dr[:, 0] > 0, wx1, wx0) - pr[:, 0]) / dr[:, 0], np.inf)
            ty_r = np.where(np.abs(dr[:, 1]) > 1e-12, (np.where(dr[:, 1] > 0, wy1, wy0) - pr[:, 1]) / dr[:, 1], np.inf)
            side_x = (tx_r <= ty_r)[:, None]
            hit = pr + np.minimum(tx_r, ty_r)[:, None] * dr
            zero = np.zeros(len(pr))
            normal = np.where(side_x, np.stack([-np.sign(dr[:, 0]), zero, zero], -1),
                              np.stack([zero, -np.sign(dr[:, 1]), zero], -1))
            e = reveal_irradiance(hit, normal, sources.back, sources.reveal_sky, sources.reveal_ground)
            if to_light[2] < 0.0:
                cos_key = np.maximum(normal @ to_light, 0.0)
                e = e + (cos_key * window_beam_mask(hit, to_light))[:, None] * np.asarray(sources.key_rgb, dtype=np.float64)
            out[reveal] = e
        out[opening] = 0.0
    radiance = sources.albedo / math.pi * out
    return (radiance, ~opening) if with_walled else radiance


def walled_radiance(points: np.ndarray, sources: WallLightSources,
                    directions: np.ndarray | None = None) -> np.ndarray:
    """(P, 3) the float64 twin of common.glsl's ``walled_radiance``: over the occlusion's
    directions (cosine-weighted about -z, :func:`occlusion_directions`), the mean of
    :func:`wall_radiance_along` (0 where a direction passes the opening). The cloth's own folds
    along a walled direction are not looked for."""
    d_all = occlusion_directions() if directions is None else np.asarray(directions, dtype=np.float64)
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    total = np.zeros((p.shape[0], 3))
    for d in d_all:
        total += wall_radiance_along(p, np.broadcast_to(d, p.shape), sources)
    return total / len(d_all)


#: The directional lobe's samples about the view's continuation (curtain.vert WALL_LIGHT).
WALL_LOBE_SAMPLES = 16


@functools.lru_cache(maxsize=8)
def wall_lobe_directions(g: float, count: int = WALL_LOBE_SAMPLES) -> np.ndarray:
    """(count, 3) directions about +z drawn from Henyey-Greenstein's phase function with
    asymmetry ``g`` (model.md eq. 6) by its closed-form inverse at stratified u = (k + 1/2) /
    count, the azimuth k times the golden ratio's fraction of a turn (|g| < 1e-3: uniform
    over the sphere)."""
    u = (np.arange(count) + 0.5) / count
    phi = 2.0 * math.pi * ((np.arange(count) * 0.6180339887498949) % 1.0)
    if abs(g) < 1e-3:
        cos = 1.0 - 2.0 * u
    else:
        s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u)
        cos = np.clip((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0)
    sin = np.sqrt(np.maximum(0.0, 1.0 - cos * cos))
    return np.stack([sin * np.cos(phi), sin * np.sin(phi), cos], -1)


def wall_lobe_radiance(points: np.ndarray, views: np.ndarray, sources: WallLightSources,
                       lobe: np.ndarray) -> np.ndarray:
    """(P, 3) the float64 twin of curtain.vert WALL_LIGHT's directional sum: over ``lobe``'s
    directions (:func:`wall_lobe_directions`) turned about each unit view continuation
    ``views`` (P, 3) (the shader's frame: across = normalize(cross(x or y, view)), up = cross(
    view, across)), the mean over all of them of the wall's radiance less the outside's (sky
    above the horizon, ground below) where one towards the window meets the wall."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    v = np.asarray(views, dtype=np.float64).reshape(-1, 3)
    axis = np.where((np.abs(v[:, 0]) < 0.9)[:, None], np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    across = np.cross(axis, v)
    across /= np.linalg.norm(across, axis=-1, keepdims=True)
    up = np.cross(v, across)
    sky = np.asarray(sources.reveal_sky, dtype=np.float64) / (0.5 * math.pi)
    ground = np.asarray(sources.reveal_ground, dtype=np.float64) / (0.5 * math.pi)
    total = np.zeros((p.shape[0], 3))
    for local in np.asarray(lobe, dtype=np.float64):
        d = local[0] * across + local[1] * up + local[2] * v
        towards = d[:, 2] < -1e-6
        safe = np.where(towards[:, None], d, np.array([0.0, 0.0, -1.0]))
        radiance, walled = wall_radiance_along(p, safe, sources, with_walled=True)
        outside = np.where(safe[:, 1:2] > 0.0, sky, ground)
        total += np.where((towards & walled)[:, None], radiance - outside, 0.0)
    return total / len(lobe)
