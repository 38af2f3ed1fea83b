"""The room as a value: its surfaces (world-space triangles with their albedo), the window
aperture and the optional default camera. Built by :func:`catalog.room.load.load_room`;
numpy only (no trimesh, no GL), so a frame can hold one without importing either."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Surface:
    """One mesh instance (a glTF node) in world space: ``triangles`` (T, 3, 3) metres,
    ``uvs`` (T, 3, 2) or None, the albedo ``factor`` (3,) linear RGB and ``texture``
    (H, W, 3) linear RGB reflectance (decoded from sRGB) or None; the albedo at a point is
    factor x texture(uv) (the room format)."""

    name: str
    triangles: np.ndarray
    uvs: np.ndarray | None
    factor: np.ndarray
    texture: np.ndarray | None

    def albedo_at(self, triangle: np.ndarray, barycentric: np.ndarray) -> np.ndarray:
        """(N, 3) albedo at points given by triangle index (N,) and barycentrics (N, 3)."""
        if self.texture is None or self.uvs is None:
            return np.broadcast_to(self.factor, (len(triangle), 3)).copy()
        uv = np.einsum("nk,nkj->nj", barycentric, self.uvs[triangle])
        return self.factor[None, :] * sample_bilinear(self.texture, uv)


def sample_bilinear(texture: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(N, C) bilinear lookup with repeat wrapping; uv (0, 0) is the image's first row
    (glTF's convention: v runs down the image)."""
    h, w = texture.shape[:2]
    x = (uv[:, 0] % 1.0) * w - 0.5
    y = (uv[:, 1] % 1.0) * h - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    x0, x1 = x0 % w, (x0 + 1) % w
    y0, y1 = y0 % h, (y0 + 1) % h
    return ((1 - fy) * ((1 - fx) * texture[y0, x0] + fx * texture[y0, x1])
            + fy * ((1 - fx) * texture[y1, x0] + fx * texture[y1, x1]))


@dataclass(frozen=True)
class Window:
    """The aperture: a planar quad, ``corners`` (4, 3) in order around it, ``normal`` (3,)
    into the room. ``origin`` is corners[0]; ``u_edge``/``v_edge`` the edges from it
    (corners[1] - corners[0], corners[3] - corners[0]); for a parallelogram a point is
    origin + s u_edge + t v_edge, s, t in [0, 1]."""

    corners: np.ndarray
    normal: np.ndarray

    @property
    def origin(self) -> np.ndarray:
        return self.corners[0]

    @property
    def u_edge(self) -> np.ndarray:
        return self.corners[1] - self.corners[0]

    @property
    def v_edge(self) -> np.ndarray:
        return self.corners[3] - self.corners[0]

    @property
    def centre(self) -> np.ndarray:
        return self.corners.mean(axis=0)

    @property
    def area_m2(self) -> float:
        c = self.corners
        return 0.5 * float(np.linalg.norm(np.cross(c[2] - c[0], c[3] - c[1])))

    def triangles(self) -> np.ndarray:
        c = self.corners
        return np.array([[c[0], c[1], c[2]], [c[0], c[2], c[3]]])


@dataclass(frozen=True)
class Camera:
    """The ``camera`` node: position, unit forward and up (world), vertical field of view."""

    position: np.ndarray
    forward: np.ndarray
    up: np.ndarray
    fov_y_deg: float


@dataclass(frozen=True)
class Room:
    """A loaded, validated room. ``content_sha256`` is the file's hash (the transport
    cache's key)."""

    name: str
    source: str
    content_sha256: str
    surfaces: tuple[Surface, ...]
    window: Window
    camera: Camera | None

    def triangles(self) -> np.ndarray:
        """(T, 3, 3) every surface's triangles (the window excluded), world metres."""
        return np.concatenate([s.triangles for s in self.surfaces])

    def surface_of_triangle(self) -> tuple[np.ndarray, np.ndarray]:
        """(T,) surface index and (T,) triangle index inside it, for :meth:`triangles`."""
        sizes = [len(s.triangles) for s in self.surfaces]
        surface = np.repeat(np.arange(len(sizes)), sizes)
        local = np.concatenate([np.arange(n) for n in sizes])
        return surface, local

    def mean_albedo(self) -> np.ndarray:
        """(T, 3) each triangle's albedo averaged over it (7-point rule on the texture)."""
        bary = np.array([[1 / 3, 1 / 3, 1 / 3], [0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6],
                         [0.1, 0.45, 0.45], [0.45, 0.1, 0.45], [0.45, 0.45, 0.1]])
        out = []
        for s in self.surfaces:
            t = np.repeat(np.arange(len(s.triangles)), len(bary))
            b = np.tile(bary, (len(s.triangles), 1))
            out.append(s.albedo_at(t, b).reshape(len(s.triangles), len(bary), 3).mean(axis=1))
        return np.concatenate(out)

    def bounds(self) -> np.ndarray:
        """(2, 3) the axis-aligned bounds of the surfaces (m)."""
        p = self.triangles().reshape(-1, 3)
        return np.stack([p.min(axis=0), p.max(axis=0)])
