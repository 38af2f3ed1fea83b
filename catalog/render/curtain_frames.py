"""Where the curtain's own maps look from, in any room: the key light's parallel frame of the
cloth (its transmittance and front-layer maps), the directions of the cloth's occlusion maps,
the coarse grid those maps draw, the cloth's room-side grid (the transport's gather points,
curtain.vert ROOM_SIDE) and the room's lamps. Numpy only; the frame's passes upload them."""

from __future__ import annotations

import functools
import math

import numpy as np

from catalog.render import scene as scene_lib

#: The key's transmittance map's side (texels): 1024, about 2.5 mm a texel over the curtain's
#: space. At 256 (1 cm) the folds' shadows on the floor stepped in one-texel stairs (issue 34:
#: the hem's light patches at 1280x720); the room's lookups take the mip level of the sun's
#: penumbra, whose texels a finer map has box-filtered (antialiased) instead of point-sampled.
SHADOW_TEXELS = 1024
#: Lamps in the room at most (uniform arrays in curtain.frag N_ROOM_LAMPS).
MAX_ROOM_LAMPS = 4
#: The cloth's own occlusion of the outside (curtain.frag SKY_OCCLUSION): directions, one
#: front-layer depth map each (tiles of OCCLUSION_TEXELS, a square grid).
OCCLUSION_DIRECTIONS = 16
OCCLUSION_TEXELS = 128
#: The cloth's room-side grid: the room's light on the cloth's room side gathered at this many
#: points across and down the curtain's rectangle (the transport's gather, read bilinearly
#: per vertex by curtain.vert ROOM_SIDE); the room's light varies over metres.
CURTAIN_SIDE_TEXELS = (12, 12)
#: The key's and the occlusion maps draw the curtain from a grid with at most this many
#: vertices a side: on a CPU rasteriser a draw costs per triangle, and the beam's pattern
#: needs the folds (5.5 across), not every vertex.
COARSE_GRID_SIDE = 40


def curtain_side_rect(placement=None) -> tuple[float, float, float, float]:
    """The room-side grid's extent (x from, y from, width, height; metres): the window's opening
    (of ``placement``, catalog.render.placement; None: the box's)."""
    if placement is None:
        from catalog.render.placement import BOX as placement  # noqa: PLC0415
    x0, x1, y0, y1 = placement.window_rect
    return (x0, y0, x1 - x0, y1 - y0)


def light_view_projection(to_light: np.ndarray, margin_m: float = 0.05, placement=None) -> np.ndarray:
    """Orthographic view-projection looking along the key light's travel (-to_light), framing
    the window opening and the curtain's space in front of it (what can cast a shadow): the
    room's window and curtain (``placement``, catalog.render.placement; None: the box's).
    A frame asks for it some 80 times with one light and room (every shadow and bake pass):
    the matrix is kept per (direction, margin, placement) and a copy returned."""
    direction = tuple(float(v) for v in np.asarray(to_light, dtype=np.float64).ravel())
    return _light_view_projection(direction, float(margin_m), placement).copy()


@functools.lru_cache(maxsize=64)
def _light_view_projection(to_light: tuple, margin_m: float, placement) -> np.ndarray:
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


def shadow_texel_m(to_light: np.ndarray, texels: int = SHADOW_TEXELS, placement=None) -> float:
    """World size (m) of one texel of a ``texels``-wide key map (the larger of the two axes)."""
    m = light_view_projection(to_light, placement=placement)
    return float(2.0 / min(m[0, :3] @ m[0, :3], m[1, :3] @ m[1, :3]) ** 0.5 / texels)


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


def check_lamp_position(position_m, interior=None) -> tuple[float, float, float]:
    """A lamp's position (m) as a finite float triple, refused in one line outside the
    room's ``interior`` ((x0, x1), (y0, y1), (z0, z1)) m: catalog.render.placement's, the
    drawn room's inside). ``interior`` None checks the triple alone (the room not yet
    resolved: the frame checks it against its room's interior when it draws it)."""
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    try:
        p = tuple(float(v) for v in position_m)
    except (TypeError, ValueError):
        raise CatalogError(f"room lamp position {position_m!r}: give (x, y, z) in m") from None
    if len(p) != 3 or not all(math.isfinite(v) for v in p):
        raise CatalogError(f"room lamp position {position_m!r}: give (x, y, z) in m, finite")
    if interior is not None:
        (x0, x1), (y0, y1), (z0, z1) = interior
        if not (x0 < p[0] < x1 and y0 < p[1] < y1 and z0 < p[2] < z1):
            raise CatalogError(f"room lamp position {position_m!r} must lie inside the room "
                               f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}, z {z0:g}..{z1:g} m")
    return p


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
