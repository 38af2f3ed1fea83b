"""The room's light transport, precomputed once per room (float64 numpy; rays through
catalog.room.rays).

Light enters the room only through its window. Cut the window into a grid of patches and
hold the radiance each patch sends into the room in the hemispherical harmonics of
``order`` (catalog.room.sh, in the window's frame): L_p(w) = sum_k c_pk H_k(w). The irradiance at the room's
receivers (catalog.room.receivers: elements of every surface) is linear in the c_pk:

    E = D c + F (rho E)    =>    E_ch = (I - F diag(rho_ch))^-1 D c_ch     per colour channel

- D (E, P K), the window's direct light: the integral over each patch of
  H_k(w) V cos(theta_e) cos(theta_w) / r^2 (area samples of the patch, shadow rays);
- F (E, E), the form factors: the share of an element's cosine-weighted rays that land on
  the front of each other element (a ray leaving through the window or meeting a back face
  carries nothing back: the window's light is all in D, counted once);
- the sun's beam through the curtain is drawn by the frame (shadow map, pattern, layers);
  its bounce is the receiver-to-receiver operator (I - F diag(rho))^-1 - I applied to the
  beam's direct irradiance at the receivers.

Both operators are compressed for the page: the window operator by its SVD (the leading
``rank`` modes of the three channels' stacked matrix), the bounce operator by a randomized
SVD; :class:`Transport` keeps the compressed forms and the exact ones for checks. Receivers
no ray from inside reaches (the walls' outer faces) are dropped first: a receiver most of
whose rays meet nothing faces the outside.

Receivers are refined where the window's light changes fastest (:func:`refine_receivers`,
one rule for every room): starting from elements of ``element_m``, an element is split in
four while the direct irradiance of a uniform window, sampled at its corners, edge
midpoints and centre (shadow rays to a fixed grid of window points), spans more than
``refine_tolerance`` of the room's mean, for at most ``refine_levels`` levels and
``max_receivers`` receivers (the worst split first). Near the window and at the edges of
its light patches (the sill's shadow, furniture) this halves the element size per level;
where the light is smooth the elements stay large.

Receivers are measured on their exposed part only (:func:`buried`, :func:`exposed_fraction`):
furniture stands on the floor and against walls, so parts of those surfaces lie inside
other geometry, seen by no one and lit by nothing. A receiver's sample points (the direct
term's, the form factors', the refinement's) are drawn on its exposed part, and the light
map welds corners by exposed area (Receivers.weld_weight_m2): a buried part neither darkens
its receiver nor, through a shared corner, its visible neighbours.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from catalog.room import sh
from catalog.room.build_progress import report
from catalog.room.model import Window
from catalog.room.receivers import Receivers, build_receivers, cosine_directions, refine, subset

#: Rays per receiver of the first pass that sorts receivers inside from outside.
SORT_RAYS = 16
#: Rays cast at once (memory bound of a wavefront).
CHUNK_RAYS = 1 << 20


@dataclass(frozen=True)
class TransportParams:
    """The resolutions (each error falls as it rises; benchmarks/room_transport.py)."""

    element_m: float = 0.4           # receiver size before refinement
    refine_tolerance: float = 0.15   # split while the window's direct light spans more (of the mean)
    refine_levels: int = 3           # at most this many halvings
    max_receivers: int = 5000        # refinement's bound (the dense solve grows as E^3)
    patches: tuple = (6, 6)          # window patches along its u and v edges
    order: int = 3                   # basis order (order (order + 1) / 2 coefficients per patch)
    gather_rays: int = 256           # form-factor rays per receiver
    window_samples: int = 4          # area samples per patch per receiver
    rank_tolerance: float = 1e-3     # relative Frobenius error of the compressed operators
    max_rank: int = 256
    bounce_rank: int = 48            # modes of the second and later bounces
    seed: int = 0

    def key(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}


@dataclass
class Transport:
    """The precomputed operators of one room (see the module doc)."""

    params: TransportParams
    receivers: Receivers
    window: Window
    frame: np.ndarray                # (3, 3) the window's SH frame (rows x, y, z)
    direct: np.ndarray               # D (E, P K)
    form_factors: object             # F (E, E), scipy.sparse CSR
    window_operator: np.ndarray      # (3, E, P K) irradiance per unit coefficient, all bounces
    window_basis: np.ndarray = None  # compressed: (3, E, r) and (r, P K)
    window_modes: np.ndarray = None
    bounce_left: np.ndarray = None   # compressed bounce: (3, E, r), (3, r, E)
    bounce_right: np.ndarray = None
    timings_s: dict = field(default_factory=dict)
    kept_index: np.ndarray = None    # (E_all,) receiver index of each element before the sort, -1: outside

    def receiver_at(self, triangle: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(N,) the receiver holding ``points`` on room triangles ``triangle`` (-1: a place no
        ray from inside reaches)."""
        return self.kept_index[self.receivers.element_at(triangle, points)]

    @property
    def coefficient_count(self) -> int:
        return int(np.prod(self.params.patches)) * sh.basis_count(self.params.order)

    def irradiance(self, coefficients: np.ndarray, compressed: bool = True) -> np.ndarray:
        """(E, 3) irradiance at the receivers from window coefficients (P, K, 3) (or
        (P K, 3)), every bounce included."""
        c = np.asarray(coefficients, dtype=np.float64).reshape(self.coefficient_count, 3)
        if compressed and self.window_basis is not None:
            modes = self.window_modes @ c                           # (r, 3)
            return np.einsum("cer,rc->ec", self.window_basis, modes)
        return np.einsum("cek,kc->ec", self.window_operator, c)

    def bounced(self, direct: np.ndarray, compressed: bool = True) -> np.ndarray:
        """(E, 3) total irradiance from a direct irradiance (E, 3) at the receivers (the
        sun's beam): the direct plus every interreflection."""
        direct = np.asarray(direct, dtype=np.float64)
        if compressed and self.bounce_left is not None:
            rho = self.receivers.albedo
            once = self.form_factors @ (rho * direct)
            return direct + once + np.einsum("cer,cr->ec", self.bounce_left,
                                             np.einsum("cre,ec->cr", self.bounce_right, direct))
        out = np.empty_like(direct)
        f = self.form_factors.toarray()
        for ch in range(3):
            a = np.eye(self.receivers.count) - f * self.receivers.albedo[None, :, ch]
            out[:, ch] = np.linalg.solve(a, direct[:, ch])
        return out


# --------------------------------------------------------------------------- exposure

#: Redraws of a receiver's sample point found buried before it is kept as it is.
EXPOSED_REDRAWS = 4
def buried(points: np.ndarray, normals: np.ndarray, rays, eps: float, triangles: np.ndarray) -> np.ndarray:
    """(N,) True where a surface point lies inside other geometry: the ray along its normal
    first meets a back face (a floor under a rug or a sofa standing on it, a wall behind a
    shelf's back). ``rays`` casts against ``triangles`` (T, 3, 3) first (any later ones,
    the window's, face the room: never buried). Such a point is seen by no one and lit by nothing; counting it dark in a
    receiver spreads a false contact shadow over the visible part and its neighbours."""
    out = np.zeros(points.shape[0], dtype=bool)
    if not points.shape[0]:
        return out
    dist, tri = rays.intersect(points + eps * normals, normals)
    hit = (tri >= 0) & (tri < triangles.shape[0])
    if hit.any():
        t = triangles[tri[hit]]
        n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        out[np.flatnonzero(hit)] = np.einsum("ni,ni->n", n, normals[hit]) > 0
    return out


def exposed_sample_points(rec: Receivers, index: np.ndarray, rng, rays, eps: float) -> np.ndarray:
    """(N, 3) uniform random points of receivers ``index`` on their exposed part: a point
    found :func:`buried` is drawn again (EXPOSED_REDRAWS times; a wholly buried receiver
    keeps its last draw)."""
    p = rec.sample_points(index, rng)
    redo = np.flatnonzero(buried(p, rec.normal[index], rays, eps, rec.triangles))
    for _ in range(EXPOSED_REDRAWS):
        if not redo.size:
            break
        p[redo] = rec.sample_points(index[redo], rng)
        redo = redo[buried(p[redo], rec.normal[index[redo]], rays, eps, rec.triangles)]
    return p


def exposed_fraction(rec: Receivers, rays, eps: float, side: int = 4) -> np.ndarray:
    """(E,) the share of each receiver's area not :func:`buried`, by the centres of a
    side x side barycentric grid (side^2 points, the same in every receiver)."""
    from catalog.room.receivers import _grid  # noqa: PLC0415

    g = _grid(side).mean(axis=1)                                   # (side^2, 2) cell centres
    bary = np.concatenate([1 - g.sum(axis=1, keepdims=True), g], axis=1)
    pts = np.einsum("qc,ecj->eqj", bary, rec.corners).reshape(-1, 3)
    out = np.empty(pts.shape[0], dtype=bool)
    normals = np.repeat(rec.normal, bary.shape[0], axis=0)
    for start in range(0, pts.shape[0], CHUNK_RAYS):
        sl = slice(start, start + CHUNK_RAYS)
        out[sl] = buried(pts[sl], normals[sl], rays, eps, rec.triangles)
    return 1.0 - out.reshape(rec.count, -1).mean(axis=1)


# --------------------------------------------------------------------------- window

def patch_points(window: Window, patches: tuple, s: np.ndarray, t: np.ndarray,
                 patch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points on patch ``patch`` at local (s, t) in [0, 1)^2 and their area Jacobian
    (m^2 per unit of (s, t) over the whole window), by the bilinear map of the corners."""
    nu, nv = patches
    su = ((patch % nu) + s) / nu
    tv = ((patch // nu) + t) / nv
    c = window.corners
    p = ((1 - su) * (1 - tv))[:, None] * c[0] + (su * (1 - tv))[:, None] * c[1] \
        + (su * tv)[:, None] * c[2] + ((1 - su) * tv)[:, None] * c[3]
    dps = (1 - tv)[:, None] * (c[1] - c[0]) + tv[:, None] * (c[2] - c[3])
    dpt = (1 - su)[:, None] * (c[3] - c[0]) + su[:, None] * (c[2] - c[1])
    return p, np.linalg.norm(np.cross(dps, dpt), axis=1)


def direct_operator(rec: Receivers, window: Window, params: TransportParams, rays, rng,
                    frame: np.ndarray) -> np.ndarray:
    """D (E, P K): irradiance at each receiver per unit SH coefficient of each patch
    (visibility by shadow rays against the room)."""
    nu, nv = params.patches
    patches = nu * nv
    k = sh.basis_count(params.order)
    s_count = params.window_samples
    out = np.zeros((rec.count, patches * k))
    per_receiver = patches * s_count
    step = max(1, CHUNK_RAYS // per_receiver)
    size = float(np.linalg.norm(np.ptp(rec.triangles.reshape(-1, 3), axis=0)))
    eps = 1e-5 * size
    # stratified samples in each patch: s_count jittered points on a sqrt grid
    side = max(1, int(math.ceil(math.sqrt(s_count))))
    for start in range(0, rec.count, step):
        report("direct light", start, rec.count)
        e = np.arange(start, min(rec.count, start + step))
        ee = np.repeat(e, per_receiver)
        patch = np.tile(np.repeat(np.arange(patches), s_count), e.size)
        cell = np.tile(np.arange(s_count), e.size * patches)
        s = ((cell % side) + rng.random(ee.size)) / side
        t = (np.minimum(cell // side, side - 1) + rng.random(ee.size)) / max(1, int(math.ceil(s_count / side)))
        xw, jac = patch_points(window, params.patches, s, t, patch)
        xe = exposed_sample_points(rec, ee, rng, rays, eps) + eps * rec.normal[ee]
        d = xw - xe
        r = np.linalg.norm(d, axis=1)
        d /= r[:, None]
        cos_e = np.einsum("ni,ni->n", d, rec.normal[ee])
        cos_w = -(d @ window.normal)
        ok = (cos_e > 0) & (cos_w > 0)
        hit, _ = rays.intersect(xe[ok], d[ok])
        visible = np.zeros(ee.size, dtype=bool)
        visible[np.flatnonzero(ok)] = hit >= r[ok] * (1 - 1e-6) - eps
        g = np.where(visible, cos_e * cos_w / (r * r), 0.0) * jac / (patches * s_count)
        y = sh.hemi_basis(-d @ frame.T, params.order)              # light travels window -> receiver
        contrib = (g[:, None] * y).reshape(e.size, patches, s_count, k).sum(axis=2)
        out[e] = contrib.reshape(e.size, patches * k)
    return out


# --------------------------------------------------------------------------- refinement

#: Window points (per side) of the refinement's direct-light estimate, and the element's
#: sample points (barycentric): corners pulled 10 % in, edge midpoints, centre.
REFINE_WINDOW_SIDE = 8
_REFINE_POINTS = np.array([[0.9, 0.05, 0.05], [0.05, 0.9, 0.05], [0.05, 0.05, 0.9],
                           [0.475, 0.475, 0.05], [0.05, 0.475, 0.475], [0.475, 0.05, 0.475],
                           [1 / 3, 1 / 3, 1 / 3]])


def uniform_window_irradiance(points: np.ndarray, normals: np.ndarray, window: Window, rays) -> np.ndarray:
    """(N,) irradiance at ``points`` (N, 3) with ``normals`` from the window sending unit
    radiance everywhere, by a fixed midpoint grid of window points and shadow rays (the
    same quadrature at every point: a smooth function of position away from shadows)."""
    side = REFINE_WINDOW_SIDE
    g = (np.arange(side) + 0.5) / side
    ss, tt = [a.ravel() for a in np.meshgrid(g, g)]
    xw, jac = patch_points(window, (1, 1), ss, tt, np.zeros(ss.size, dtype=np.int64))
    weight = jac / ss.size
    out = np.zeros(points.shape[0])
    size = float(np.linalg.norm(np.ptp(points, axis=0))) + 1.0
    eps = 1e-5 * size
    step = max(1, CHUNK_RAYS // ss.size)
    for start in range(0, points.shape[0], step):
        i = np.arange(start, min(points.shape[0], start + step))
        xe = np.repeat(points[i] + eps * normals[i], ss.size, axis=0)
        ne = np.repeat(normals[i], ss.size, axis=0)
        d = np.tile(xw, (i.size, 1)) - xe
        r = np.linalg.norm(d, axis=1)
        d /= r[:, None]
        cos_e, cos_w = np.einsum("ni,ni->n", d, ne), -(d @ window.normal)
        ok = (cos_e > 0) & (cos_w > 0)
        visible = np.zeros(xe.shape[0], dtype=bool)
        if ok.any():
            hit, _ = rays.intersect(xe[ok], d[ok])
            visible[np.flatnonzero(ok)] = hit >= r[ok] * (1 - 1e-6) - eps
        g_ = np.where(visible, cos_e * cos_w / (r * r), 0.0) * np.tile(weight, i.size)
        out[i] = g_.reshape(i.size, ss.size).sum(axis=1)
    return out


def refine_receivers(rec: Receivers, inside: np.ndarray, albedo_of, window: Window, params: TransportParams,
                     rays) -> tuple[Receivers, np.ndarray, dict]:
    """The receivers refined by the rule of the module doc, the inside mask carried to
    them, and a summary (receivers, splits per round).

    Greedy in rounds: each round splits the elements whose error estimate is within a
    factor 2 of the largest (the span times sqrt(area / base area): an element's share of
    the light map's L2 error) among those whose span exceeds the tolerance and whose
    level is below ``refine_levels``, as many as ``max_receivers`` leaves room for."""
    eps = 1e-5 * float(np.linalg.norm(np.ptp(rec.triangles.reshape(-1, 3), axis=0)))

    def spans(r: Receivers, which: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pts = np.einsum("qc,ecj->eqj", _REFINE_POINTS, r.corners[which]).reshape(-1, 3)
        e = uniform_window_irradiance(pts, np.repeat(r.normal[which], len(_REFINE_POINTS), axis=0), window, rays)
        e = e.reshape(which.size, len(_REFINE_POINTS))
        # a buried point is seen by no one: its darkness is no error of the light map
        hidden = buried(pts, np.repeat(r.normal[which], len(_REFINE_POINTS), axis=0), rays, eps,
                        r.triangles).reshape(e.shape)
        lo = np.where(hidden, np.inf, e).min(axis=1)
        hi = np.where(hidden, -np.inf, e).max(axis=1)
        span = np.where(hidden.all(axis=1), 0.0, hi - lo)
        return span, np.where(hidden.all(axis=1), 0.0, np.where(hidden, 0.0, e).sum(axis=1)
                              / np.maximum(1, (~hidden).sum(axis=1)))

    summary = {"base_receivers": int(inside.sum()), "splits": []}
    span = np.full(rec.count, np.nan)
    level = np.zeros(rec.count, dtype=np.int64)
    todo = np.flatnonzero(inside)
    span[todo], mean = spans(rec, todo)
    area = rec.area_m2[todo]
    scale = max(float(np.sum(area * mean) / np.sum(area)), 1e-300)
    base_area = float(np.mean(area))
    for _ in range(4 * params.refine_levels):
        todo = np.flatnonzero(inside & np.isnan(span))
        if todo.size:
            span[todo] = spans(rec, todo)[0]
        relative = np.where(inside, np.nan_to_num(span) / scale, 0.0)
        eligible = (relative > params.refine_tolerance) & (level < params.refine_levels)
        room_for = max(0, (params.max_receivers - int(inside.sum())) // 3)
        if not eligible.any() or room_for == 0:
            break
        priority = np.where(eligible, relative * np.sqrt(rec.area_m2 / base_area), 0.0)
        chosen = np.flatnonzero(priority >= 0.5 * priority.max())
        chosen = chosen[np.argsort(-priority[chosen])][:room_for]
        summary["splits"].append(int(chosen.size))
        split = np.zeros(rec.count, dtype=bool)
        split[chosen] = True
        rec, parent = refine(rec, split, albedo_of)
        fresh = split[parent]
        inside, level = inside[parent], level[parent] + fresh
        span = np.where(fresh, np.nan, span[parent])
    summary["receivers"] = int(inside.sum())
    summary["levels"] = np.bincount(level[inside], minlength=params.refine_levels + 1).tolist()
    return rec, inside, summary


# --------------------------------------------------------------------------- room

def gather(rec: Receivers, rays_room, window_tris_first: int, count: int, rng,
           receivers: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Cosine-weighted rays from each receiver: (hit receiver index or -1, escaped) per ray,
    shape (E, count). The ray caster holds the room's triangles then the window's two."""
    index = np.arange(rec.count) if receivers is None else receivers
    hit_rec = np.full((index.size, count), -1, dtype=np.int64)
    escaped = np.zeros((index.size, count), dtype=bool)
    size = float(np.linalg.norm(np.ptp(rec.triangles.reshape(-1, 3), axis=0)))
    eps = 1e-5 * size
    step = max(1, CHUNK_RAYS // count)
    for start in range(0, index.size, step):
        rows = np.arange(start, min(index.size, start + step))
        ee = np.repeat(index[rows], count)
        n = rec.normal[ee]
        o = exposed_sample_points(rec, ee, rng, rays_room, eps) + eps * n
        d = cosine_directions(n, rng)
        dist, tri = rays_room.intersect(o, d)
        out = tri < 0
        through = tri >= window_tris_first
        room_hit = ~out & ~through
        j = np.full(ee.size, -1, dtype=np.int64)
        if room_hit.any():
            p = o[room_hit] + dist[room_hit, None] * d[room_hit]
            elem = rec.element_at(tri[room_hit], p)
            front = np.einsum("ni,ni->n", d[room_hit], rec.normal[elem]) < 0
            j[np.flatnonzero(room_hit)] = np.where(front, elem, -1)
        hit_rec[rows] = j.reshape(rows.size, count)
        escaped[rows] = out.reshape(rows.size, count)
    return hit_rec, escaped


def form_factors(hit: np.ndarray, new_index: np.ndarray, count: int):
    """F (E', E') as a CSR matrix (at most rays entries a row) from gathered hits (old
    receiver indices), over the kept receivers."""
    import scipy.sparse  # noqa: PLC0415

    e = hit.shape[0]
    rows = np.repeat(np.arange(e), hit.shape[1])
    cols = new_index[np.where(hit.ravel() >= 0, hit.ravel(), 0)]
    keep = (hit.ravel() >= 0) & (cols >= 0)
    f = scipy.sparse.csr_matrix((np.full(int(keep.sum()), 1.0 / hit.shape[1]), (rows[keep], cols[keep])),
                                shape=(e, count))
    f.sum_duplicates()
    return f


def _orthonormal(a: np.ndarray) -> np.ndarray:
    """An orthonormal basis of a's columns by Cholesky-QR twice (eigh of the small Gram
    matrix, then matrix products): LAPACK's QR of a tall thin matrix runs ~50x slower here
    when its threads compete for the shared cores."""
    for _ in range(2):
        w, v = np.linalg.eigh(a.T @ a)
        keep = w > w.max() * 1e-13
        a = a @ (v[:, keep] / np.sqrt(w[keep]))
    return a


def _svd_wide(small: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The SVD of a (k, n) matrix with k << n through its (k, k) Gram matrix."""
    w, u = np.linalg.eigh(small @ small.T)
    order = np.argsort(w)[::-1]
    w, u = np.maximum(w[order], 0.0), u[:, order]
    s = np.sqrt(w)
    keep = s > s[0] * 1e-7 if s.size and s[0] > 0 else np.zeros(s.size, dtype=bool)
    return u[:, keep], s[keep], (u[:, keep].T @ small) / s[keep, None]


def compress(matrix: np.ndarray, tolerance: float, max_rank: int) -> tuple[np.ndarray, np.ndarray, float]:
    """(left, right) with left @ right ~ matrix to relative Frobenius error <= tolerance (or
    at max_rank), and the error reached (the SVD from the narrow side's Gram matrix)."""
    vt_u, s, u_t = _svd_wide(matrix.T)                # matrix^T = V S U^T
    u, vt = u_t.T, vt_u.T
    total = float(np.sum(s * s))
    tail = np.sqrt(np.maximum(0.0, total - np.cumsum(s * s)) / max(total, 1e-300))
    rank = int(min(max_rank, np.searchsorted(-tail, -tolerance) + 1, s.size))
    return u[:, :rank] * s[:rank], vt[:rank], float(tail[rank - 1]) if rank else 1.0


def precompute_geometry(triangles: np.ndarray, albedo_of, window: Window,
                        params: TransportParams = TransportParams(), backend: str = "mitsuba",
                        compress_operators: bool = True) -> Transport:
    """The :class:`Transport` of a room given as triangles (T, 3, 3) with ``albedo_of``
    (catalog.room.receivers.build_receivers) and its window."""
    from catalog.room.rays import ray_caster  # noqa: PLC0415

    rng = np.random.default_rng(params.seed)
    timings = {}
    start = time.perf_counter()
    report("receivers")
    rec_all = build_receivers(triangles, albedo_of, params.element_m)
    with_window = np.concatenate([np.asarray(triangles, dtype=np.float64), window.triangles()])
    rays_gather = ray_caster(with_window, backend)
    rays_room = ray_caster(triangles, backend)
    _, escaped = gather(rec_all, rays_gather, len(triangles), SORT_RAYS, rng)
    inside = escaped.mean(axis=1) < 0.5
    if params.refine_levels > 0:
        rec_all, inside, refinement = refine_receivers(rec_all, inside, albedo_of, window, params, rays_room)
        timings["refinement"] = refinement
    eps = 1e-5 * float(np.linalg.norm(np.ptp(np.asarray(triangles).reshape(-1, 3), axis=0)))
    rec_all = replace(rec_all, exposed=exposed_fraction(rec_all, rays_room, eps))
    rec, new_index = subset(rec_all, inside)
    timings["exposed_share"] = float(np.sum(rec.weld_weight_m2) / np.sum(rec.area_m2))
    timings["receivers_s"] = time.perf_counter() - start
    start = time.perf_counter()
    report("form factors")
    hit, _ = gather(rec_all, rays_gather, len(triangles), params.gather_rays, rng,
                    receivers=np.flatnonzero(inside))
    f = form_factors(hit, new_index, rec.count)
    timings["form_factors_s"] = time.perf_counter() - start
    start = time.perf_counter()
    frame = sh.frame_of(window.normal, window.u_edge)
    d = direct_operator(rec, window, params, rays_room, rng, frame)
    timings["direct_s"] = time.perf_counter() - start
    start = time.perf_counter()
    import scipy.linalg  # noqa: PLC0415

    operator = np.empty((3, rec.count, d.shape[1]))
    lus = []
    dense = f.toarray()
    for ch in range(3):
        report("solve", ch, 3)
        lu = scipy.linalg.lu_factor(np.eye(rec.count) - dense * rec.albedo[None, :, ch], overwrite_a=True)
        lus.append(lu)
        operator[ch] = scipy.linalg.lu_solve(lu, d)
    timings["solve_s"] = time.perf_counter() - start
    del dense
    transport = Transport(params, rec, window, frame, d, f, operator, timings_s=timings,
                          kept_index=new_index)
    if compress_operators:
        start = time.perf_counter()
        report("compress")
        left, right, err = compress(operator.reshape(3 * rec.count, -1), params.rank_tolerance, params.max_rank)
        transport.window_basis = left.reshape(3, rec.count, -1)
        transport.window_modes = right
        transport.bounce_left, transport.bounce_right, bounce_err = bounce_low_rank(
            lus, f, rec.albedo, params, rng)
        timings["compress_s"] = time.perf_counter() - start
        timings["window_rank"] = int(right.shape[0])
        timings["window_rank_error"] = err
        timings["bounce_rank"] = int(transport.bounce_left.shape[2])
        timings["bounce_rank_error"] = bounce_err
    return transport


def bounce_low_rank(lus, f: np.ndarray, albedo: np.ndarray, params: TransportParams, rng):
    """Randomized SVD (one power iteration) of the second and later bounces of the
    receiver-to-receiver operator, B_ch = (I - F diag rho)^-1 (F diag rho)^2, per channel:
    (3, E, r), (3, r, E) and the largest relative error on a random probe. The first
    bounce F diag rho stays exact and sparse (at most gather_rays entries a row): it holds
    the near field (corners, contact), which no low rank carries."""
    import scipy.linalg  # noqa: PLC0415

    e = f.shape[0]
    rank = min(params.bounce_rank, e)
    lefts, rights, errors = [], [], []
    for ch in range(3):
        lu = lus[ch]
        rho = albedo[:, ch]

        def apply(x, lu=lu, rho=rho):      # (I - F rho)^-1 (F rho)^2 x
            return scipy.linalg.lu_solve(lu, f @ (rho[:, None] * (f @ (rho[:, None] * x))))

        def apply_t(x, lu=lu, rho=rho):
            y = rho[:, None] * (f.T @ scipy.linalg.lu_solve(lu, x, trans=1))
            return rho[:, None] * (f.T @ y)

        omega = rng.normal(size=(e, min(e, rank + 10)))
        q = _orthonormal(apply(omega))
        q = _orthonormal(apply(apply_t(q)))
        small = apply_t(q).T                               # q^T B  (k, E)
        u, s, vt = _svd_wide(small)
        total = float(np.sum(s * s))
        tail = np.sqrt(np.maximum(0.0, total - np.cumsum(s * s)) / max(total, 1e-300))
        r = int(min(rank, np.searchsorted(-tail, -params.rank_tolerance) + 1, s.size))
        left = q @ (u[:, :r] * s[:r])
        lefts.append(left)
        rights.append(vt[:r])
        probe = rng.normal(size=(e, 8))
        exact = apply(probe)
        errors.append(float(np.linalg.norm(exact - left @ (vt[:r] @ probe)) / np.linalg.norm(exact)))
    r = max(x.shape[1] for x in lefts)
    pad_l = np.zeros((3, e, r))
    pad_r = np.zeros((3, r, e))
    for ch in range(3):
        pad_l[ch, :, :lefts[ch].shape[1]] = lefts[ch]
        pad_r[ch, :rights[ch].shape[0]] = rights[ch]
    return pad_l, pad_r, max(errors)


def precompute(room, params: TransportParams = TransportParams(), backend: str = "mitsuba",
               compress_operators: bool = True) -> Transport:
    """The :class:`Transport` of a loaded :class:`catalog.room.model.Room`."""
    from catalog.room.receivers import room_albedo_of  # noqa: PLC0415

    return precompute_geometry(room.triangles(), room_albedo_of(room), room.window, params,
                               backend, compress_operators)
