"""Irradiance at points of a room by brute-force path tracing (the transport's independent
reference): from each point, cosine-weighted paths bounce off the surfaces (each hit's own
albedo, texture included) until they leave through the window, where they take the
window's radiance L(x, w) (x on the window, w the direction the light travels). No
discretisation: its only error is noise (reported as a standard error)."""

from __future__ import annotations

import math

import numpy as np

from catalog.room.receivers import cosine_directions


def probe_points(room, count: int, rng, backend: str = "mitsuba") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``count`` points on the room's inside surfaces (their normals and triangles): where rays from
    random points of the window land, half of them after one diffuse bounce (so shadowed
    places are among them; a bounce that leaves through the window keeps its first point:
    the window's reveals beyond it are outside the room)."""
    from catalog.room.rays import ray_caster  # noqa: PLC0415

    tris = room.triangles()
    normals = _normals(tris)
    rays = ray_caster(np.concatenate([tris, room.window.triangles()]), backend)
    w = room.window
    s, t = rng.random((2, count))
    o = w.origin + s[:, None] * w.u_edge + t[:, None] * w.v_edge + 1e-4 * w.normal
    d = cosine_directions(np.repeat(w.normal[None], count, axis=0), rng)
    dist, tri = rays.intersect(o, d)
    p = o + dist[:, None] * d
    n = normals[tri]
    second = np.arange(count) % 2 == 1
    d2 = cosine_directions(n[second], rng)
    dist2, tri2 = rays.intersect(p[second] + 1e-5 * n[second], d2)
    inside = (tri2 >= 0) & (tri2 < len(tris))
    ok = inside & (np.einsum("ni,ni->n", d2, normals[np.clip(tri2, 0, len(tris) - 1)]) < 0)
    idx = np.flatnonzero(second)[ok]
    p[idx] = p[idx] + 1e-5 * n[idx] + dist2[ok, None] * d2[ok]
    n[idx] = normals[tri2[ok]]
    tri[idx] = tri2[ok]
    return p, n, tri


def _normals(tris: np.ndarray) -> np.ndarray:
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def irradiance(room, radiance, points: np.ndarray, normals: np.ndarray, paths: int, rng,
               backend: str = "mitsuba", max_bounces: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) irradiance at ``points`` and its standard error (N, 3); ``radiance(x, w)`` ->
    (M, 3) the window's radiance at window points x (M, 3) in directions w (M, 3)."""
    from catalog.room.rays import ray_caster  # noqa: PLC0415

    tris = room.triangles()
    count = len(tris)
    tri_normals = _normals(tris)
    caster = ray_caster(np.concatenate([tris, room.window.triangles()]), backend)
    surface, local = room.surface_of_triangle()
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    n_pts = points.shape[0]
    owner = np.repeat(np.arange(n_pts), paths)
    o = np.repeat(points, paths, axis=0) + 1e-5 * np.repeat(normals, paths, axis=0)
    n = np.repeat(normals, paths, axis=0)
    weight = np.ones((o.shape[0], 3))
    total = np.zeros((o.shape[0], 3))
    alive = np.arange(o.shape[0])
    for _ in range(max_bounces):
        if alive.size == 0:
            break
        d = cosine_directions(n[alive], rng)
        dist, tri = caster.intersect(o[alive], d)
        leave = tri >= count
        x = o[alive[leave]] + dist[leave, None] * d[leave]
        total[alive[leave]] += weight[alive[leave]] * radiance(x, -d[leave])
        hit = (tri >= 0) & ~leave
        front = np.zeros(alive.size, dtype=bool)
        front[hit] = np.einsum("ni,ni->n", d[hit], tri_normals[tri[hit]]) < 0
        keep = alive[front]
        t = tri[front]
        p = o[keep] + dist[front, None] * d[front]
        # barycentrics of the hit, for the albedo (texture) there
        rel = p - tris[t, 0]
        d11, d12, d22 = (np.einsum("ni,ni->n", e1[t], e1[t]), np.einsum("ni,ni->n", e1[t], e2[t]),
                         np.einsum("ni,ni->n", e2[t], e2[t]))
        p1, p2 = np.einsum("ni,ni->n", rel, e1[t]), np.einsum("ni,ni->n", rel, e2[t])
        det = d11 * d22 - d12 * d12
        b1, b2 = (d22 * p1 - d12 * p2) / det, (d11 * p2 - d12 * p1) / det
        bary = np.stack([1 - b1 - b2, b1, b2], axis=1)
        albedo = np.empty((keep.size, 3))
        for s_index, s in enumerate(room.surfaces):
            m = surface[t] == s_index
            if m.any():
                albedo[m] = s.albedo_at(local[t[m]], bary[m])
        weight[keep] *= albedo
        # Russian roulette past a small throughput keeps the estimate unbiased
        survive = np.max(weight[keep], axis=1)
        q = np.minimum(1.0, survive / 0.05)
        lucky = rng.random(keep.size) < q
        weight[keep[lucky]] /= q[lucky, None]
        keep, t = keep[lucky], t[lucky]
        o[keep] = p[lucky] + 1e-5 * tri_normals[t]
        n[keep] = tri_normals[t]
        alive = keep
    e = math.pi * total.reshape(n_pts, paths, 3)
    return e.mean(axis=1), e.std(axis=1) / math.sqrt(paths)
