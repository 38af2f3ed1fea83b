"""The room's light transport (catalog.room.transport) against independent answers: the SH
basis against closed forms and quadrature, the window's direct light against the closed-form
view factor of a rectangle, a closed room against the albedo series 1/(1 - a), the full
operator against brute-force path tracing (numpy rays) on a small furnished room, and the
cache's invalidation when the room file changes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.render.scene import box_triangles
from catalog.room import sh
from catalog.room.model import Window
from catalog.room.rays import NumpyRays
from catalog.room.receivers import _grid, build_receivers, grid_index, refine
from catalog.room.transport import TransportParams, form_factors, gather, precompute_geometry


# --------------------------------------------------------------------------- basis

def test_sh_is_orthonormal_under_quadrature():
    dirs, w = sh.hemisphere_quadrature(12, 24)
    full = np.concatenate([dirs, dirs * [1, 1, -1]])
    y = sh.real_sh(full, 4)
    gram = (y * np.concatenate([w, w])[:, None]).T @ y
    assert np.abs(gram - np.eye(16)).max() < 1e-10
    h = sh.hemi_basis(dirs, 5)                   # the window's basis: orthonormal on the hemisphere
    assert h.shape[1] == sh.basis_count(5) == 15
    assert np.abs((h * w[:, None]).T @ h - np.eye(15)).max() < 1e-10


def test_projection_of_clamped_cosine_matches_closed_form():
    # cos theta on the hemisphere: the SH zonal integrals sqrt(pi)/2 (l = 0) and sqrt(5 pi)/8
    # (l = 2) times sqrt(2); l = 1, m = 0 is odd in z, not in the basis
    dirs, w = sh.hemisphere_quadrature(8, 16)
    c = sh.project(dirs, w, dirs[:, 2], 3)          # basis (0,0), (1,-1), (1,1), (2,-2), (2,0), (2,2)
    assert c[0] == pytest.approx(math.sqrt(2) * math.sqrt(math.pi) / 2, rel=1e-12)
    assert c[4] == pytest.approx(math.sqrt(2) * math.sqrt(5 * math.pi) / 8, rel=1e-12)
    assert np.abs(np.delete(c, [0, 4])).max() < 1e-12


def test_uniform_radiance_is_exact_at_order_one():
    # the full SH would hold half of it at order 1 (the zero behind the window); the even basis all
    dirs, w = sh.hemisphere_quadrature(6, 12)
    c = sh.project(dirs, w, np.ones(dirs.shape[0]), 1)
    assert np.allclose(c[0] * sh.hemi_basis(dirs, 1)[:, 0], 1.0, rtol=1e-12)


@pytest.mark.slow
def test_projection_of_a_tilted_lobe_matches_dense_quadrature():
    axis = np.array([0.5, -0.3, 0.8]) / np.linalg.norm([0.5, -0.3, 0.8])

    def lobe(d):
        return np.exp(4.0 * (d @ axis - 1.0))

    coarse = sh.project(*sh.hemisphere_quadrature(10, 20), lobe(sh.hemisphere_quadrature(10, 20)[0]), 3)
    rng = np.random.default_rng(3)
    d = rng.normal(size=(400_000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d[:, 2] = np.abs(d[:, 2])
    mc = sh.hemi_basis(d, 3).T @ lobe(d) * (2 * math.pi / d.shape[0])
    assert np.abs(coarse - mc).max() < 5e-3 * np.abs(mc).max() + 3e-3


def test_grid_index_finds_each_sub_triangle():
    rng = np.random.default_rng(0)
    for n in (1, 2, 5):
        cells = _grid(n)
        r1, r2 = rng.random((2, cells.shape[0]))
        s = np.sqrt(r1)
        w = np.stack([1 - s, s * (1 - r2), s * r2], axis=1)
        points = np.einsum("ek,ekj->ej", w, cells)
        assert np.array_equal(grid_index(points[:, 0], points[:, 1], np.full(cells.shape[0], n)),
                              np.arange(cells.shape[0]))


def test_refined_receivers_tile_their_parents_and_are_found_by_element_at():
    tris = box_triangles(0, 1, 0, 0.5, 0, 2)
    albedo_of = lambda tri, bary: np.stack([bary[:, 0], bary[:, 1], 0.5 + 0 * tri], axis=1)   # noqa: E731
    rec = build_receivers(tris, albedo_of, 0.4)
    rng = np.random.default_rng(2)
    for _ in range(3):                       # three levels, a random third split each time
        rec, parent = refine(rec, rng.random(rec.count) < 0.33, albedo_of)
    assert rec.children is not None and (rec.leaf >= 0).sum() == rec.count
    assert rec.area_m2.sum() == pytest.approx(build_receivers(tris, albedo_of, 0.4).area_m2.sum(), rel=1e-12)
    assert np.allclose(rec.area_m2, 0.5 * np.linalg.norm(np.cross(rec.corners[:, 1] - rec.corners[:, 0],
                                                                  rec.corners[:, 2] - rec.corners[:, 0]), axis=1))
    assert rec.area_m2.max() / rec.area_m2.min() > 60           # sizes over three levels (4^3 = 64)
    index = np.repeat(np.arange(rec.count), 5)
    points = rec.sample_points(index, rng)
    assert np.array_equal(rec.element_at(rec.triangle[index], points), index)
    # each child's albedo is its own (the texture's gradient), not its parent's
    centre_bary = np.full((rec.count, 3), 1 / 3)
    assert not np.allclose(rec.albedo[:, 0], albedo_of(rec.triangle, centre_bary)[:, 0][0])


# --------------------------------------------------------------------------- small rooms

def inward(tris):
    return tris[:, ::-1]


def open_cube(hole):
    """The unit cube seen from inside, its z = 0 face open over ``hole`` (x0, x1, y0, y1)."""
    shell = inward(box_triangles(0, 1, 0, 1, 0, 1))
    normals = np.cross(shell[:, 1] - shell[:, 0], shell[:, 2] - shell[:, 0])
    shell = shell[normals[:, 2] <= 0.5]            # drop the z = 0 face (its normal is +z)
    x0, x1, y0, y1 = hole
    parts = [shell]
    for a, b, c, d in ((0, x0, 0, 1), (x1, 1, 0, 1), (x0, x1, 0, y0), (x0, x1, y1, 1)):
        if b > a and d > c:
            q = np.array([[a, c, 0], [b, c, 0], [b, d, 0], [a, d, 0]], dtype=float)
            parts.append(np.array([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]))
    window = Window(np.array([[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0]], dtype=float),
                    np.array([0.0, 0.0, 1.0]))
    return np.concatenate(parts), window


def constant_albedo(value):
    return lambda tri, bary: np.full((tri.shape[0], 3), value, dtype=float)


def rect_view_factor(a, b):
    """Differential area to a parallel rectangle a x b (in units of the distance), the
    rectangle's corner on the area's normal."""
    pa, pb = math.sqrt(1 + a * a), math.sqrt(1 + b * b)
    return (a / pa * math.atan(b / pa) + b / pb * math.atan(a / pb)) / (2 * math.pi)


@pytest.mark.slow
def test_direct_light_matches_the_rectangle_view_factor():
    tris, window = open_cube((0.0, 1.0, 0.0, 1.0))
    params = TransportParams(element_m=0.12, refine_levels=0, patches=(4, 4), order=1, gather_rays=8,
                             window_samples=16)
    t = precompute_geometry(tris, constant_albedo(0.0), window, params, backend="numpy",
                            compress_operators=False)
    rec = t.receivers
    back = np.flatnonzero(np.abs(rec.centre[:, 2] - 1.0) < 1e-9)
    c = np.zeros((16, 1, 3))
    c[:, 0, :] = 1.0 / sh.hemi_basis(np.array([[0, 0, 1.0]]), 1)[0, 0]     # L = 1 everywhere
    e = t.irradiance(c, compressed=False)[back, 0]
    expected = []
    for x, y, _ in rec.centre[back]:
        f = sum(rect_view_factor(dx, dy) for dx in (x, 1 - x) for dy in (y, 1 - y))
        expected.append(math.pi * f)
    assert np.abs(e / np.array(expected) - 1).max() < 0.02


def test_closed_room_returns_the_albedo_series():
    closed = inward(box_triangles(0, 1, 0, 1, 0, 1))
    rec = build_receivers(closed, constant_albedo(0.7), 0.25)
    rays = NumpyRays(closed)
    hit, escaped = gather(rec, rays, len(closed), 64, np.random.default_rng(0))
    assert not escaped.any() and (hit >= 0).all()         # every ray lands on a front face
    f = form_factors(hit, np.arange(rec.count), rec.count).toarray()
    assert np.allclose(f.sum(axis=1), 1.0)
    total = np.linalg.solve(np.eye(rec.count) - 0.7 * f, np.ones(rec.count))
    assert np.allclose(total, 1.0 / (1.0 - 0.7), rtol=1e-10)


def brute_force_irradiance(tris, albedo, window, radiance, points, normals, paths, rng):
    """E at points by path tracing with numpy rays (an independent estimator): cosine
    directions, albedo at every bounce, the window's radiance(x, w) where a path leaves."""
    room, win = NumpyRays(tris, chunk=512), NumpyRays(window.triangles())
    tri_normals = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    tri_normals /= np.linalg.norm(tri_normals, axis=1, keepdims=True)
    from catalog.room.receivers import cosine_directions
    out = []
    for p0, n0 in zip(points, normals):
        o = np.repeat(p0[None] + 1e-7 * n0, paths, axis=0)
        n = np.repeat(n0[None], paths, axis=0)
        weight = np.ones(paths)
        total = np.zeros(paths)
        alive = np.ones(paths, dtype=bool)
        for _ in range(40):
            idx = np.flatnonzero(alive)
            if idx.size == 0:
                break
            d = cosine_directions(n[idx], rng)
            t_room, tri = room.intersect(o[idx], d)
            t_win, _ = win.intersect(o[idx], d)
            leave = t_win < t_room
            x = o[idx] + np.where(np.isfinite(t_win), t_win, 0)[:, None] * d
            total[idx[leave]] += weight[idx[leave]] * radiance(x[leave], -d[leave])
            hit = ~leave & np.isfinite(t_room)
            front = np.zeros(idx.size, dtype=bool)
            front[hit] = np.einsum("ni,ni->n", d[hit], tri_normals[tri[hit]]) < 0
            alive[idx[~front]] = False
            keep = idx[front]
            o[keep] = o[keep] + t_room[front, None] * d[front] + 1e-7 * tri_normals[tri[front]]
            n[keep] = tri_normals[tri[front]]
            weight[keep] *= albedo
        out.append(math.pi * total.mean())
    return np.array(out)


@pytest.mark.slow
def test_refinement_puts_the_small_receivers_where_the_light_changes():
    tris, window = open_cube((0.3, 0.7, 0.35, 0.75))
    params = TransportParams(element_m=0.25, refine_levels=3, max_receivers=900, patches=(1, 1), order=1,
                             gather_rays=8, window_samples=2)
    t = precompute_geometry(tris, constant_albedo(0.5), window, params, backend="numpy", compress_operators=False)
    rec = t.receivers
    summary = t.timings_s["refinement"]
    assert summary["receivers"] == rec.count <= 900 and sum(summary["splits"]) > 0
    near = np.abs(rec.centre[:, 2]) < 0.2                   # within 0.2 m of the window's wall
    size = np.sqrt(rec.area_m2)
    assert np.median(size[near]) < 0.6 * np.median(size[~near])
    # the far wall (z = 1) sees a smooth light: none of it at the finest level
    far = np.abs(rec.centre[:, 2] - 1) < 1e-9
    assert size[far].min() > size.min() * 1.9


@pytest.mark.slow
@pytest.mark.parametrize("receivers", [dict(element_m=0.08, refine_levels=0),
                                       dict(element_m=0.16, refine_levels=2, max_receivers=1500)],
                         ids=["uniform", "refined"])
def test_operator_matches_brute_force_path_tracing(receivers):
    tris, window = open_cube((0.3, 0.7, 0.35, 0.75))
    block = box_triangles(0.35, 0.65, 0.0, 0.25, 0.45, 0.7)
    tris = np.concatenate([tris, block])
    albedo = 0.6
    params = TransportParams(patches=(2, 2), order=2, gather_rays=512, window_samples=16, **receivers)
    t = precompute_geometry(tris, constant_albedo(albedo), window, params, backend="numpy",
                            compress_operators=False)

    def radiance(x, w):      # brighter towards +x across the window, more light travelling +x
        return (1.0 + 0.8 * (x[:, 0] - 0.3)) * (1.0 + 0.5 * w[:, 0])

    # order 2 holds (1 + 0.5 w_x) exactly (H_0 = 1 / sqrt(2 pi), H_2 = sqrt(3 / (2 pi)) w_x);
    # the patch's x factor at its centre
    h0, h2 = 1 / math.sqrt(2 * math.pi), math.sqrt(3 / (2 * math.pi))
    c = np.zeros((4, 3, 3))
    for p in range(4):
        xc = 0.3 + 0.4 * ((p % 2) + 0.5) / 2
        c[p, 0] = (1.0 + 0.8 * (xc - 0.3)) / h0
        c[p, 2] = (1.0 + 0.8 * (xc - 0.3)) * 0.5 / h2
    e = t.irradiance(c, compressed=False)[:, 0]
    rec = t.receivers
    rng = np.random.default_rng(5)
    picks = [np.argmin(np.linalg.norm(rec.centre - q, axis=1) + 10 * (rec.normal @ nq < 0.99))
             for q, nq in (((0.2, 0.0, 0.5), (0, 1, 0)), ((0.5, 0.5, 1.0), (0, 0, -1)),
                           ((0.5, 0.25, 0.55), (0, 1, 0)), ((0.0, 0.6, 0.3), (1, 0, 0)))]
    # the brute force at the receivers' own random points (the element means the operator holds)
    means = []
    for i in picks:
        pts = rec.sample_points(np.full(16, i), rng)
        means.append(brute_force_irradiance(tris, albedo, window, lambda x, w: radiance(x, w),
                                            pts, np.repeat(rec.normal[i][None], 16, axis=0), 1500,
                                            rng).mean())
    # the patch-constant x factor is exact at the patch centre, linear across: its error
    # averages out over the patch for these receivers to well under the tolerance
    print("operator / brute force - 1:", e[picks] / np.array(means) - 1)
    assert np.abs(e[picks] / np.array(means) - 1).max() < 0.05


# --------------------------------------------------------------------------- web pack

@pytest.mark.slow
def test_web_pack_is_small_and_within_its_bound_of_the_full_operator():
    from catalog.room import web_pack

    tris, window = open_cube((0.3, 0.7, 0.35, 0.75))
    params = TransportParams(element_m=0.2, refine_levels=1, max_receivers=500, patches=(2, 2), order=2,
                             gather_rays=64, window_samples=4, rank_tolerance=1e-4, bounce_rank=32)
    t = precompute_geometry(tris, constant_albedo(0.6), window, params, backend="numpy")
    loose = web_pack.pack(t, window_tolerance=3e-2, bounce_tolerance=3e-2)
    tight = web_pack.pack(t, window_tolerance=1e-3, bounce_tolerance=1e-3)
    # F is kept exactly (ray counts)
    assert np.array_equal(loose.form_factors().toarray(), t.form_factors.toarray())
    for web, tol in ((loose, 3e-2), (tight, 1e-3)):
        # the Frobenius bound holds on typical inputs (plus float16's ~5e-4 and the transport's own 1e-4)
        assert web.errors["window_rank_bound"] <= tol
        assert web.errors["window_rel_rms"] < tol + 2e-3
        assert web.errors["bounce_rel_rms"] < tol + web.errors["bounce_rel_rms_transport"] + 2e-3
    assert loose.errors["window_rank"] < tight.errors["window_rank"]
    full = t.window_basis.nbytes + t.window_modes.nbytes + t.bounce_left.nbytes + t.bounce_right.nbytes \
        + t.form_factors.data.nbytes + t.form_factors.indices.nbytes
    assert loose.nbytes()["total"] < 0.3 * full
    # the pack answers like the transport on a window light
    c = np.zeros((4, 3, 3))
    c[:, 0] = 1.0
    exact = t.irradiance(c, compressed=False)
    assert np.abs(tight.irradiance(c) - exact).max() < 5e-3 * np.abs(exact).max()


# --------------------------------------------------------------------------- buried receivers

@pytest.mark.slow
def test_receivers_buried_under_furniture_are_measured_and_left_out_of_the_weld():
    """A block standing on the floor buries the floor under its footprint: those points are
    seen by no one. exposure = the share outside the footprint (closed form), and the
    light map's corner between a buried and an exposed receiver takes the exposed one's value."""
    from catalog.room import lightmap
    from catalog.room.transport import buried, exposed_fraction

    tris, _ = open_cube((0.3, 0.7, 0.35, 0.75))
    block = box_triangles(0.35, 0.65, 0.0, 0.25, 0.45, 0.7)
    tris = np.concatenate([tris, block])
    rays = NumpyRays(tris)
    # points on the floor (normal +y): inside the footprint buried, outside and on top not
    pts = np.array([[0.5, 0.0, 0.6], [0.4, 0.0, 0.5], [0.2, 0.0, 0.6], [0.5, 0.0, 0.9], [0.5, 0.25, 0.6]])
    up = np.tile([0.0, 1.0, 0.0], (5, 1))
    assert buried(pts, up, rays, 1e-6, tris).tolist() == [True, True, False, False, False]
    rec = build_receivers(tris, constant_albedo(0.5), 0.05)
    exposed = exposed_fraction(rec, rays, 1e-6)
    floor = (np.abs(rec.centre[:, 1]) < 1e-9) & (rec.normal[:, 1] > 0.99)
    c = rec.centre
    inside = (c[:, 0] > 0.35) & (c[:, 0] < 0.65) & (c[:, 2] > 0.45) & (c[:, 2] < 0.7)
    lo, hi = rec.corners.min(axis=1), rec.corners.max(axis=1)
    wholly_in = floor & (lo[:, 0] >= 0.35) & (hi[:, 0] <= 0.65) & (lo[:, 2] >= 0.45) & (hi[:, 2] <= 0.7)
    wholly_out = floor & ((hi[:, 0] <= 0.35) | (lo[:, 0] >= 0.65) | (hi[:, 2] <= 0.45) | (lo[:, 2] >= 0.7))
    assert wholly_in.sum() > 10 and np.all(exposed[wholly_in] == 0) and np.all(exposed[wholly_out] == 1)
    area = float(np.sum(rec.area_m2[floor] * exposed[floor]))
    assert area == pytest.approx(1.0 - 0.3 * 0.25, rel=0.02)               # floor minus the footprint
    assert not np.any(inside & ~floor & (exposed < 1) & (rec.normal[:, 1] > 0.99) & (np.abs(c[:, 1] - 0.25) < 1e-9))
    # the weld: buried receivers dark, exposed ones lit; no exposed corner is darkened
    from dataclasses import replace

    rec = replace(rec, exposed=exposed)

    class T:
        receivers = rec

    value = np.where(exposed > 0, 1.0, 0.0)[:, None] * np.ones((1, 3))
    corner = lightmap.corner_irradiance(T, value)
    lit = floor & (exposed == 1)
    assert np.allclose(corner[lit], 1.0, atol=1e-5)
