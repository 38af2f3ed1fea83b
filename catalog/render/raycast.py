"""Rays against a triangle mesh in float64 numpy, for the checks and studies that hold the GPU's
shadow maps to an independent answer (tests/test_cloth_shadows.py,
benchmarks/key_shadow_bias.py). No GL here."""

from __future__ import annotations

import numpy as np


def mesh_triangles(mesh) -> np.ndarray:
    """(T, 3, 3) float64 corner positions of a mesh with ``positions`` and ``indices``."""
    return np.asarray(mesh.positions, dtype=np.float64)[np.asarray(mesh.indices).reshape(-1, 3)]


def first_hit(origins: np.ndarray, direction: np.ndarray, triangles: np.ndarray,
              chunk: int = 64) -> np.ndarray:
    """(P,) distance (m) to the nearest triangle along one direction from each origin (inf:
    none), by the Moller-Trumbore test, in chunks of ``chunk`` origins."""
    v0, v1, v2 = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = v1 - v0, v2 - v0
    pvec = np.cross(np.broadcast_to(direction, e2.shape), e2)
    det = np.einsum("ti,ti->t", e1, pvec)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    out = np.full(origins.shape[0], np.inf)
    for start in range(0, origins.shape[0], chunk):
        o = origins[start:start + chunk]
        tvec = o[:, None, :] - v0[None]
        u = np.einsum("pti,ti->pt", tvec, pvec) * inv
        qvec = np.cross(tvec, e1[None])
        v = np.einsum("pti,i->pt", qvec, direction) * inv
        t = np.einsum("pti,ti->pt", qvec, e2) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
        out[start:start + chunk] = np.where(hit, t, np.inf).min(axis=1)
    return out
