"""The room's receivers: its triangles cut into small elements (a regular barycentric grid
of n x n sub-triangles per triangle, n from the element size), each with a centre, a normal,
an area and an albedo, then refined where the light changes fast (:func:`refine`: an
element split into its four midpoint sub-triangles, recursively: a quadtree on each base
element). A ray's hit (triangle, point) maps to its element in closed form on the base grid
and a descent of the tree (:meth:`Receivers.element_at`). Float64 numpy."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Receivers:
    """``corners`` (E, 3, 3) m; ``normal`` (E, 3); ``area_m2`` (E,); ``albedo`` (E, 3) linear;
    ``triangle`` (E,) the room triangle each lies in; ``divisions`` (T,) n per triangle and
    ``first`` (T,) its first base element. After :func:`refine`, the tree: ``node_corners``
    (N, 3, 3) every node's corners (the base elements are nodes 0..B-1), ``children`` (N,)
    a node's first of four children (-1: a leaf) and ``leaf`` (N,) a leaf's receiver index
    (-1: split); None when nothing is refined (the base elements are the receivers).
    ``exposed`` (E,) the share of each receiver's area not buried inside other geometry (a
    rug's or a sofa's base standing on the floor, a shelf against a wall: catalog.room.
    transport.exposed_fraction), None before it is measured (all exposed)."""

    corners: np.ndarray
    normal: np.ndarray
    area_m2: np.ndarray
    albedo: np.ndarray
    triangle: np.ndarray
    divisions: np.ndarray
    first: np.ndarray
    triangles: np.ndarray
    node_corners: np.ndarray | None = None
    children: np.ndarray | None = None
    leaf: np.ndarray | None = None
    exposed: np.ndarray | None = None

    @property
    def weld_weight_m2(self) -> np.ndarray:
        """(E,) a receiver's weight in the light map's weld: its exposed area (m^2; a floor
        at least 1e-6 of the area, so a vertex only buried receivers meet stays defined).
        A buried part of a receiver is seen by no one: it must not darken its neighbours'
        shared corners."""
        if self.exposed is None:
            return self.area_m2
        return self.area_m2 * np.maximum(self.exposed, 1e-6)

    @property
    def count(self) -> int:
        return int(self.corners.shape[0])

    @property
    def centre(self) -> np.ndarray:
        return self.corners.mean(axis=1)

    def sample_points(self, index: np.ndarray, rng) -> np.ndarray:
        """(N, 3) uniform random points in elements ``index`` (N,)."""
        r1, r2 = rng.random((2, index.shape[0]))
        s = np.sqrt(r1)
        b = np.stack([1 - s, s * (1 - r2), s * r2], axis=1)
        return np.einsum("nk,nkj->nj", b, self.corners[index])

    def element_at(self, triangle: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(N,) element index of ``points`` lying on room triangles ``triangle`` (N,)."""
        t = self.triangles[triangle]
        e1, e2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
        p = points - t[:, 0]
        d11, d12, d22 = (np.einsum("ni,ni->n", e1, e1), np.einsum("ni,ni->n", e1, e2),
                         np.einsum("ni,ni->n", e2, e2))
        p1, p2 = np.einsum("ni,ni->n", p, e1), np.einsum("ni,ni->n", p, e2)
        det = d11 * d22 - d12 * d12
        b1 = np.clip((d22 * p1 - d12 * p2) / det, 0.0, 1.0)
        b2 = np.clip((d11 * p2 - d12 * p1) / det, 0.0, 1.0)
        n = self.divisions[triangle]
        node = self.first[triangle] + grid_index(b1, b2, n)
        if self.children is None:
            return node
        inner = np.flatnonzero(self.children[node] >= 0)
        while inner.size:
            c = self.node_corners[node[inner]]
            bary = barycentric(c, points[inner])
            # midpoint children: 0, 1, 2 at the corners (barycentric >= 1/2), 3 the middle one
            k = np.where(bary[:, 0] >= 0.5, 0, np.where(bary[:, 1] >= 0.5, 1, np.where(bary[:, 2] >= 0.5, 2, 3)))
            node[inner] = self.children[node[inner]] + k
            inner = inner[self.children[node[inner]] >= 0]
        return self.leaf[node]


def barycentric(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(N, 3) barycentrics of ``points`` (N, 3) projected onto triangles ``corners`` (N, 3, 3)."""
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    p = points - corners[:, 0]
    d11, d12, d22 = (np.einsum("ni,ni->n", e1, e1), np.einsum("ni,ni->n", e1, e2),
                     np.einsum("ni,ni->n", e2, e2))
    p1, p2 = np.einsum("ni,ni->n", p, e1), np.einsum("ni,ni->n", p, e2)
    det = d11 * d22 - d12 * d12
    b1 = (d22 * p1 - d12 * p2) / det
    b2 = (d11 * p2 - d12 * p1) / det
    return np.stack([1 - b1 - b2, b1, b2], axis=1)


def midpoint_children(corners: np.ndarray) -> np.ndarray:
    """(N, 4, 3, 3) the four midpoint sub-triangles of triangles (N, 3, 3), in the order
    :meth:`Receivers.element_at` descends: the three at corners 0, 1, 2, then the middle
    one (same winding as the parent)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
    return np.stack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1),
                     np.stack([ab, bc, ca], 1)], axis=1)


def grid_index(b1: np.ndarray, b2: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Local index of the sub-triangle holding barycentrics (b1, b2) in an n x n grid:
    'up' triangles (i, j) first, row by row (j), then the 'down' ones."""
    x, y = b1 * n, b2 * n
    j = np.clip(np.floor(y).astype(np.int64), 0, n - 1)
    i = np.clip(np.floor(x).astype(np.int64), 0, n - 1 - j)
    up = ((x - i) + (y - j) <= 1.0) | (i + j >= n - 1)
    up_index = j * n - j * (j - 1) // 2 + i
    down_index = n * (n + 1) // 2 + j * (n - 1) - j * (j - 1) // 2 + i
    return np.where(up, up_index, down_index)


def _grid(n: int) -> np.ndarray:
    """(n*n, 3, 2) barycentric (b1, b2) corners of the grid's sub-triangles, in grid_index order."""
    cells = []
    for j in range(n):
        for i in range(n - j):
            cells.append(((i, j), (i + 1, j), (i, j + 1)))
    for j in range(n - 1):
        for i in range(n - 1 - j):
            cells.append(((i + 1, j), (i + 1, j + 1), (i, j + 1)))
    return np.array(cells, dtype=np.float64) / n


def divisions_for(triangles: np.ndarray, size_m: float) -> np.ndarray:
    """n per triangle: elements of about size_m (their area ~ size_m^2 / 2, their longest
    edge at most 3 size_m)."""
    e = np.stack([triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 1],
                  triangles[:, 0] - triangles[:, 2]], axis=1)
    longest = np.linalg.norm(e, axis=2).max(axis=1)
    area = 0.5 * np.linalg.norm(np.cross(e[:, 0], -e[:, 2]), axis=1)
    return np.maximum(1, np.ceil(np.maximum(np.sqrt(2 * area) / size_m, longest / (3 * size_m)))).astype(np.int64)


def build_receivers(triangles: np.ndarray, albedo_of, size_m: float) -> Receivers:
    """Cut ``triangles`` (T, 3, 3) into elements of about ``size_m``; ``albedo_of(tri, bary)``
    gives (N, 3) albedo at barycentrics (N, 3) of room triangles tri (N,) (the element's
    albedo is its mean at four points)."""
    triangles = np.asarray(triangles, dtype=np.float64)
    n = divisions_for(triangles, size_m)
    first = np.concatenate([[0], np.cumsum(n * n)[:-1]])
    corners, tri_index, bary_corners = [], [], []
    grids = {}
    for t, k in enumerate(n):
        g = grids.setdefault(int(k), _grid(int(k)))
        b = np.concatenate([1 - g.sum(axis=2, keepdims=True), g], axis=2)    # (k*k, 3, 3)
        corners.append(np.einsum("ecv,vj->ecj", b, triangles[t]))
        bary_corners.append(b)
        tri_index.append(np.full(g.shape[0], t))
    corners = np.concatenate(corners)
    bary_corners = np.concatenate(bary_corners)
    tri_index = np.concatenate(tri_index)
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    normal = cross / np.maximum(2 * area, 1e-300)[:, None]
    rule = np.array([[1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
    points = np.einsum("qc,ecv->eqv", rule, bary_corners)                      # (E, 4, 3) bary
    albedo = albedo_of(np.repeat(tri_index, 4), points.reshape(-1, 3)).reshape(-1, 4, 3).mean(axis=1)
    return Receivers(corners, normal, area, albedo, tri_index, n, first, triangles)


def subset(r: Receivers, keep: np.ndarray) -> tuple[Receivers, np.ndarray]:
    """The receivers ``keep`` (bool (E,)) and the map old index -> new (-1: dropped); the
    result's :meth:`Receivers.element_at` still answers old indices (map them with it)."""
    new = np.full(r.count, -1, dtype=np.int64)
    new[keep] = np.arange(int(keep.sum()))
    return Receivers(r.corners[keep], r.normal[keep], r.area_m2[keep], r.albedo[keep],
                     r.triangle[keep], r.divisions, r.first, r.triangles,
                     r.node_corners, r.children, r.leaf,
                     None if r.exposed is None else r.exposed[keep]), new


def _element_albedo(albedo_of, triangles: np.ndarray, tri_index: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(E, 3) the mean albedo at four points of each element (corners (E, 3, 3) on room
    triangles tri_index (E,))."""
    rule = np.array([[1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
    points = np.einsum("qc,ecj->eqj", rule, corners).reshape(-1, 3)
    tri = np.repeat(tri_index, 4)
    bary = barycentric(triangles[tri], points)
    return albedo_of(tri, bary).reshape(-1, 4, 3).mean(axis=1)


def refine(r: Receivers, split: np.ndarray, albedo_of) -> tuple[Receivers, np.ndarray]:
    """Split receivers ``split`` (bool (E,)) into their four midpoint sub-triangles. Returns
    the refined receivers (leaves in node order) and, per new receiver, the old receiver it
    came from (its parent, or itself)."""
    if r.children is None:
        base = r.count
        node_corners, children, leaf = r.corners, np.full(base, -1, dtype=np.int64), np.arange(base)
    else:
        node_corners, children, leaf = r.node_corners, r.children.copy(), r.leaf
    split_nodes = np.flatnonzero((leaf >= 0) & np.isin(leaf, np.flatnonzero(split)))
    split_nodes = split_nodes[np.argsort(leaf[split_nodes])]
    n0 = node_corners.shape[0]
    kids = midpoint_children(node_corners[split_nodes]).reshape(-1, 3, 3)
    children[split_nodes] = n0 + 4 * np.arange(split_nodes.size)
    children = np.concatenate([children, np.full(kids.shape[0], -1, dtype=np.int64)])
    node_corners = np.concatenate([node_corners, kids])
    # the receiver each node's leaf came from: a kept leaf itself, a child its parent's
    origin = np.concatenate([leaf, np.repeat(leaf[split_nodes], 4)])
    is_leaf = children < 0
    new_leaf = np.full(children.size, -1, dtype=np.int64)
    new_leaf[is_leaf] = np.arange(int(is_leaf.sum()))
    parent = origin[is_leaf]
    corners = node_corners[is_leaf]
    fresh = np.arange(children.size)[is_leaf] >= n0
    area = r.area_m2[parent] * np.where(fresh, 0.25, 1.0)
    albedo = r.albedo[parent].copy()
    if fresh.any():
        albedo[fresh] = _element_albedo(albedo_of, r.triangles, r.triangle[parent[fresh]], corners[fresh])
    return Receivers(corners, r.normal[parent], area, albedo, r.triangle[parent], r.divisions, r.first,
                     r.triangles, node_corners, children, new_leaf), parent


def room_albedo_of(room):
    """``albedo_of`` for :func:`build_receivers` over ``room.triangles()`` (texture x factor)."""
    surface, local = room.surface_of_triangle()

    def albedo_of(tri: np.ndarray, bary: np.ndarray) -> np.ndarray:
        out = np.empty((tri.shape[0], 3))
        for s_index, s in enumerate(room.surfaces):
            mask = surface[tri] == s_index
            if mask.any():
                out[mask] = s.albedo_at(local[tri[mask]], bary[mask])
        return out

    return albedo_of


def cosine_directions(normals: np.ndarray, rng) -> np.ndarray:
    """(N, 3) cosine-distributed unit directions around unit ``normals`` (N, 3)."""
    r1, r2 = rng.random((2, normals.shape[0]))
    phi = 2 * math.pi * r1
    s = np.sqrt(r2)
    local = np.stack([s * np.cos(phi), s * np.sin(phi), np.sqrt(1 - r2)], axis=1)
    helper = np.where(np.abs(normals[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    t = np.cross(normals, helper)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(normals, t)
    return local[:, :1] * t + local[:, 1:2] * b + local[:, 2:] * normals
