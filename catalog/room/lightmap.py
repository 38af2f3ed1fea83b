"""The light map as the frame shows it, in numpy: each receiver corner's irradiance welded
with the corners it shares on one plane (mean of the receivers meeting there weighted by
their exposed area, Receivers.weld_weight_m2), interpolated linearly inside each receiver. The GL pass
(catalog.render.passes.room_transport) draws exactly this; the benchmark measures it."""

from __future__ import annotations

import numpy as np

#: Corner positions closer than this (m) on one plane are one vertex of the light map.
WELD_M = 1e-5


def weld_vertices(receivers) -> np.ndarray:
    """(3E,) the light-map vertex of each receiver corner: corners within WELD_M of each
    other on one plane (same normal and offset) share one vertex."""
    corners = receivers.corners.reshape(-1, 3)
    normal = np.repeat(receivers.normal, 3, axis=0)
    offset = np.einsum("ni,ni->n", corners, normal)
    key = np.concatenate([np.round(corners / WELD_M), np.round(normal * 1e4),
                          np.round(offset[:, None] / WELD_M)], axis=1).astype(np.int64)
    _, vertex = np.unique(key, axis=0, return_inverse=True)
    return vertex.ravel()


def corner_irradiance(transport, irradiance: np.ndarray) -> np.ndarray:
    """(E, 3, 3) the irradiance at each receiver's three corners from receiver values (E, 3)."""
    rec = transport.receivers
    vertex = weld_vertices(rec)
    weight = np.repeat(rec.weld_weight_m2, 3)
    total = np.zeros((vertex.max() + 1, irradiance.shape[1]))
    np.add.at(total, vertex, weight[:, None] * np.repeat(irradiance, 3, axis=0))
    norm = np.bincount(vertex, weights=weight)
    return (total / norm[:, None])[vertex].reshape(rec.count, 3, -1)


def irradiance_at(transport, corner: np.ndarray, receiver: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(N, 3) the light map at ``points`` in receivers ``receiver`` (N,) from
    :func:`corner_irradiance` values (barycentric interpolation)."""
    c = transport.receivers.corners[receiver]
    area = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    n2 = np.einsum("ni,ni->n", area, area)
    b0 = np.einsum("ni,ni->n", np.cross(c[:, 2] - c[:, 1], points - c[:, 1]), area) / n2
    b1 = np.einsum("ni,ni->n", np.cross(c[:, 0] - c[:, 2], points - c[:, 2]), area) / n2
    bary = np.stack([b0, b1, 1 - b0 - b1], 1)
    return np.einsum("nk,nkc->nc", bary, corner[receiver])
