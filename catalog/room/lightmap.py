"""The light map as the frame shows it, in numpy: each receiver corner's irradiance welded
with the corners it shares on one plane (mean of the receivers meeting there weighted by
their exposed area, Receivers.weld_weight_m2), interpolated linearly inside each receiver. The GL pass
(catalog.render.passes.room_transport) draws exactly this; the benchmark measures it.

A refined receiver's corner may lie inside a coarser neighbour's edge (a hanging vertex: the
quadtree's midpoints beside an unsplit element, base grids of different sizes meeting): its
value is then the neighbour's edge interpolated there (:func:`hanging_vertices`), as adaptive
finite elements constrain hanging nodes, so the light map is continuous across every edge."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Corner positions closer than this (m) on one plane are one vertex of the light map.
WELD_M = 1e-5


@dataclass(frozen=True)
class Csr:
    """A sparse matrix (rows, cols) as CSR arrays; :meth:`dot` of (cols, C) -> (rows, C)."""

    data: np.ndarray
    indices: np.ndarray
    indptr: np.ndarray
    shape: tuple

    def dot(self, x: np.ndarray) -> np.ndarray:
        rows = np.repeat(np.arange(self.shape[0]), np.diff(self.indptr))
        contrib = self.data[:, None] * x[self.indices]
        return np.stack([np.bincount(rows, weights=contrib[:, c], minlength=self.shape[0])
                         for c in range(x.shape[1])], axis=1)


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


def hanging_vertices(receivers, vertex: np.ndarray | None = None) -> tuple:
    """The light map's hanging vertices and the free vertices their values come from:
    ``(hang, matrix)``, a :class:`Csr` (H, V) whose row i gives vertex ``hang[i]`` as a
    weighted sum of free vertices (``vertex``: :func:`weld_vertices`). A vertex is hanging
    when it lies inside an edge (farther than WELD_M from its ends and within WELD_M of the
    line) of a receiver on its plane; it takes the longest such edge's ends, linearly
    (1 - t, t). An end may hang itself, and where two grids' edges overlap along one line
    two vertices may hang on each other: the constraints are then solved together
    (:func:`_resolve_hanging`), which makes the light map linear along such a run."""
    vertex = weld_vertices(receivers) if vertex is None else np.asarray(vertex)
    count = int(vertex.max()) + 1
    position = np.zeros((count, 3))
    position[vertex] = receivers.corners.reshape(-1, 3)
    normal = np.zeros((count, 3))
    normal[vertex] = np.repeat(receivers.normal, 3, axis=0)
    offset = np.einsum("ni,ni->n", position, normal)
    key = np.concatenate([np.round(normal * 1e4), np.round(offset[:, None] / WELD_M)], axis=1)
    _, plane = np.unique(key.astype(np.int64), axis=0, return_inverse=True)
    plane = plane.ravel()
    ends = vertex.reshape(-1, 3)
    edges = np.unique(np.sort(np.concatenate([ends[:, [0, 1]], ends[:, [1, 2]], ends[:, [2, 0]]]), axis=1),
                      axis=0)
    edge_plane = plane[edges[:, 0]]
    rows: dict[int, dict[int, float]] = {}
    longest: dict[int, float] = {}
    for p in np.unique(edge_plane):
        on_plane = np.flatnonzero(plane == p)
        e = edges[edge_plane == p]
        a, d = position[e[:, 0]], position[e[:, 1]] - position[e[:, 0]]
        length = np.sqrt(np.einsum("ni,ni->n", d, d))
        for start in range(0, on_plane.size, 256):
            v = on_plane[start:start + 256]
            q = position[v][:, None, :] - a[None]
            t = np.einsum("vei,ei->ve", q, d) / length[None] ** 2
            off_line = np.linalg.norm(q - t[..., None] * d[None], axis=2)
            inside = (off_line < WELD_M) & (t * length > WELD_M) & ((1 - t) * length > WELD_M)
            for i, j in zip(*np.nonzero(inside)):
                h = int(v[i])
                if length[j] > longest.get(h, 0.0):
                    longest[h] = float(length[j])
                    rows[h] = {int(e[j, 0]): 1.0 - float(t[i, j]), int(e[j, 1]): float(t[i, j])}
    rows = _resolve_hanging(rows)
    hang = np.array(sorted(rows), dtype=np.int64)
    indptr = np.zeros(hang.size + 1, dtype=np.int64)
    indptr[1:] = np.cumsum([len(rows[h]) for h in hang])
    indices = np.array([k for h in hang for k in sorted(rows[h])], dtype=np.int64)
    data = np.array([rows[h][k] for h in hang for k in sorted(rows[h])], dtype=np.float64)
    return hang, Csr(data, indices, indptr, (hang.size, count))


def _resolve_hanging(rows: dict) -> dict:
    """Each hanging vertex's row in free vertices only: the constraints v_h = sum_k w_hk v_k
    solved by substitution (a vertex's own weight eliminated exactly, v_h (1 - w_hh) = the
    rest), to a weight of at most 1e-15 left on hanging vertices (then dropped and the row
    renormalised: the weights sum to 1, a constant light map stays constant)."""
    rows = {h: dict(row) for h, row in rows.items()}
    for _ in range(200):
        left = 0.0
        for h in rows:
            expanded: dict[int, float] = {}
            for k, w in rows[h].items():
                for k2, w2 in (rows[k].items() if k in rows and k != h else ((k, 1.0),)):
                    expanded[k2] = expanded.get(k2, 0.0) + w * w2
            own = expanded.pop(h, 0.0)
            rows[h] = {k: w / (1.0 - own) for k, w in expanded.items()}
            left = max(left, sum(w for k, w in rows[h].items() if k in rows))
        if left <= 1e-15:
            break
    else:
        raise ValueError("the light map's hanging vertices do not resolve to free ones")
    for h, row in rows.items():
        free = {k: w for k, w in row.items() if k not in rows}
        total = sum(free.values())
        rows[h] = {k: w / total for k, w in free.items()}
    return rows


def weld_values(vertex: np.ndarray, weight: np.ndarray, irradiance: np.ndarray, hanging: tuple) -> np.ndarray:
    """(3E, C) each receiver corner's light-map value: receiver values ``irradiance`` (E, C)
    averaged over each welded vertex by ``weight`` (E,), hanging vertices set from the free
    ones (``hanging``: :func:`hanging_vertices`'s pair)."""
    corner_weight = np.repeat(weight, 3)
    count = int(vertex.max()) + 1
    values = corner_weight[:, None] * np.repeat(irradiance, 3, axis=0)
    total = np.stack([np.bincount(vertex, weights=values[:, c], minlength=count)
                      for c in range(values.shape[1])], axis=1)
    welded = total / np.bincount(vertex, weights=corner_weight, minlength=count)[:, None]
    hang, matrix = hanging
    if hang.size:
        welded[hang] = matrix.dot(welded)   # its rows read free vertices only
    return welded[vertex]


_HANGING: list = []   # (receivers, vertex, hanging) of the last few transports asked


def _weld_of(receivers) -> tuple:
    for rec, vertex, hanging in _HANGING:
        if rec is receivers:
            return vertex, hanging
    vertex = weld_vertices(receivers)
    hanging = hanging_vertices(receivers, vertex)
    _HANGING[:] = [(receivers, vertex, hanging)] + _HANGING[:3]
    return vertex, hanging


def corner_irradiance(transport, irradiance: np.ndarray) -> np.ndarray:
    """(E, 3, C) the irradiance at each receiver's three corners from receiver values (E, C)."""
    rec = transport.receivers
    vertex, hanging = _weld_of(rec)
    corner = weld_values(vertex, rec.weld_weight_m2, np.asarray(irradiance, dtype=np.float64), hanging)
    return corner.reshape(rec.count, 3, -1)


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
