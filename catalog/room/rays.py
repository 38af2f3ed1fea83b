"""Nearest-hit ray queries against a room's triangles, in wavefronts.

:class:`MitsubaRays` casts through Mitsuba 3's ``scene.ray_intersect`` (the reference's own
BVH, LLVM on the CPU; float32 geometry); :class:`NumpyRays` is the brute-force float64
Moller-Trumbore test over every triangle, the independent answer the tests compare with
(and the fallback for a handful of rays where Mitsuba is absent). Both return, per ray, the
hit distance (inf: none) and the triangle index (-1: none).
"""

from __future__ import annotations

import numpy as np

#: Rays per Mitsuba wavefront (bounds the JIT's memory).
WAVEFRONT = 1 << 20


class NumpyRays:
    """Brute force over all triangles, float64: O(rays x triangles)."""

    def __init__(self, triangles: np.ndarray, chunk: int = 256):
        t = np.asarray(triangles, dtype=np.float64)
        self.v0 = t[:, 0]
        self.e1 = t[:, 1] - t[:, 0]
        self.e2 = t[:, 2] - t[:, 0]
        self.chunk = chunk

    def intersect(self, origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = origins.shape[0]
        dist = np.full(n, np.inf)
        index = np.full(n, -1, dtype=np.int64)
        for start in range(0, n, self.chunk):
            o = origins[start:start + self.chunk, None, :]
            d = directions[start:start + self.chunk, None, :]
            pvec = np.cross(d, self.e2[None])
            det = np.einsum("rti,ti->rt", pvec, self.e1)
            ok = np.abs(det) > 1e-14
            inv = 1.0 / np.where(ok, det, 1.0)
            tvec = o - self.v0[None]
            u = np.einsum("rti,rti->rt", tvec, pvec) * inv
            qvec = np.cross(tvec, self.e1[None])
            v = np.einsum("rti,rti->rt", qvec, d) * inv
            t = np.einsum("rti,ti->rt", qvec, self.e2) * inv
            hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-9)
            t = np.where(hit, t, np.inf)
            best = np.argmin(t, axis=1)
            dist[start:start + self.chunk] = t[np.arange(t.shape[0]), best]
            index[start:start + self.chunk] = np.where(np.isfinite(dist[start:start + self.chunk]), best, -1)
        return dist, index


class MitsubaRays:
    """One Mitsuba mesh of all triangles; ``prim_index`` is the triangle's index."""

    def __init__(self, triangles: np.ndarray):
        from catalog.pathtrace.backend import load_mitsuba  # noqa: PLC0415

        self.mi = mi = load_mitsuba()
        t = np.asarray(triangles, dtype=np.float64)
        mesh = mi.Mesh("room_rays", t.shape[0] * 3, t.shape[0])
        params = mi.traverse(mesh)
        params["vertex_positions"] = np.ascontiguousarray(t.reshape(-1), dtype=np.float32)
        params["faces"] = np.arange(t.shape[0] * 3, dtype=np.uint32)
        params.update()
        self.scene = mi.load_dict({"type": "scene", "mesh": mesh})

    def intersect(self, origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        mi = self.mi
        n = origins.shape[0]
        dist = np.full(n, np.inf)
        index = np.full(n, -1, dtype=np.int64)
        for start in range(0, n, WAVEFRONT):
            o = np.ascontiguousarray(origins[start:start + WAVEFRONT].T, dtype=np.float32)
            d = np.ascontiguousarray(directions[start:start + WAVEFRONT].T, dtype=np.float32)
            ray = mi.Ray3f(mi.Point3f(o), mi.Vector3f(d))
            si = self.scene.ray_intersect_preliminary(ray)
            valid = np.asarray(si.is_valid(), dtype=bool)
            t = np.asarray(si.t, dtype=np.float64)
            prim = np.asarray(si.prim_index, dtype=np.int64)
            dist[start:start + WAVEFRONT] = np.where(valid, t, np.inf)
            index[start:start + WAVEFRONT] = np.where(valid, prim, -1)
        return dist, index


def ray_caster(triangles: np.ndarray, backend: str = "mitsuba"):
    """``mitsuba`` (default) or ``numpy`` (brute force)."""
    if backend == "numpy":
        return NumpyRays(triangles)
    return MitsubaRays(triangles)
