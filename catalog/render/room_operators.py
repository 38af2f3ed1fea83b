"""What the frame needs of a room, numpy only: its surfaces (triangles, texture coordinates,
albedo factor and texture), its receivers, the compressed window and bounce operators of
its precomputed transport (catalog.room.transport), and the gathers from the window's
patches and from the cloth's room-side grid onto the receivers (cosine-weighted rays). Built
once per room (:func:`build`: the transport from its cache, Mitsuba's rays for the gathers)
and cached beside the transport, keyed by the file's content, so that a frame (the viewer
marks scipy absent, docs/architecture.md) loads one .npz and imports neither scipy, trimesh
nor Mitsuba: in such a process a missing bundle is built by a child process
(``python -m catalog.render.room_operators ROOM``).
"""

from __future__ import annotations

import hashlib
import json
import math
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.room.lightmap import Csr, hanging_vertices, weld_values, weld_vertices  # numpy only

#: Bumped when the bundle's content or the rules that make it (the cloth's room-side grid over
#: the room's own window, :func:`_room_side_grid`) change.
BUNDLE_VERSION = 6
#: Cosine-weighted rays from each receiver for its view of the outside (receivers outside
#: the aperture: the reveals, a sill) and of the aperture from outside (the curtain's window side).
OUTSIDE_RAYS = 64
#: How far into the room the curtain hangs before its aperture (m): the box's, as the room
#: format places it (catalog.render.scene CURTAIN_Z - WINDOW_Z).
CURTAIN_OFFSET_M = 0.12
#: The outside's basis: the hemispherical harmonics about the window's outward normal.
OUTSIDE_ORDER = 3
#: Cosine-weighted rays from each window patch centre and each point of the cloth's grid.
GATHER_RAYS_PATCH = 512
GATHER_RAYS_SIDE = 128


@dataclass(frozen=True)
class SurfaceData:
    name: str
    factor: np.ndarray
    texture: np.ndarray | None


@dataclass(frozen=True)
class RoomOperators:
    """A room's runtime bundle. Receivers: ``corners`` (E, 3, 3), ``normal``, ``area_m2`` (exposed),
    ``albedo`` (E, 3), ``surface`` (E,) and ``uvs`` (E, 3, 2); ``vertex`` (3 E,) the welded
    light-map vertex of each corner (catalog.room.lightmap's weld, weighed by ``area_m2``);
    ``hang_vertex`` (H,) the hanging vertices and ``hanging`` (H, V) their values from the
    free ones (catalog.room.lightmap.hanging_vertices)."""

    name: str
    content_sha256: str
    surfaces: tuple
    window_corners: np.ndarray
    window_normal: np.ndarray
    frame: np.ndarray
    patches: tuple
    order: int
    corners: np.ndarray
    normal: np.ndarray
    area_m2: np.ndarray
    albedo: np.ndarray
    surface: np.ndarray
    uvs: np.ndarray
    vertex: np.ndarray
    hang_vertex: np.ndarray
    hanging: Csr
    window_basis: np.ndarray
    window_modes: np.ndarray
    form_factors: Csr
    bounce_left: np.ndarray
    bounce_right: np.ndarray
    gather_patch: Csr
    gather_side: Csr
    side_grid: tuple          # (tw, th, x0, y0, w, h)
    outside_frame: np.ndarray  # (3, 3) rows x, y, z: z the window's outward normal
    outside: np.ndarray        # (E, K) irradiance per unit coefficient of the outside's radiance
    window_back: np.ndarray    # (E,) pi x share of rays meeting the aperture from outside
    gather_wall: Csr           # the cloth's plane towards the window: the surfaces round it
    bounds: np.ndarray        # (2, 3)
    triangles: np.ndarray     # (T, 3, 3) the room's triangles (its depth from the key)

    @property
    def count(self) -> int:
        return int(self.corners.shape[0])

    @property
    def centre(self) -> np.ndarray:
        return self.corners.mean(axis=1)

    @property
    def window_centre(self) -> np.ndarray:
        return self.window_corners.mean(axis=0)

    def irradiance(self, coefficients: np.ndarray) -> np.ndarray:
        """(E, 3) the receivers' irradiance from window coefficients (P, K, 3), every bounce."""
        c = np.asarray(coefficients, dtype=np.float64).reshape(-1, 3)
        modes = self.window_modes @ c
        return np.einsum("cer,rc->ec", self.window_basis, modes)

    def bounced(self, direct: np.ndarray) -> np.ndarray:
        """(E, 3) a direct irradiance (E, 3) plus every interreflection of it."""
        once = self.form_factors.dot(self.albedo * direct)
        return direct + once + np.einsum("cer,cr->ec", self.bounce_left,
                                         np.einsum("cre,ec->cr", self.bounce_right, direct))

    def corner_irradiance(self, irradiance: np.ndarray) -> np.ndarray:
        """(E, 3, 3) the light map at each receiver's corners (area-weighted over the welded
        vertex, hanging vertices from their edges: catalog.room.lightmap.corner_irradiance)."""
        corner = weld_values(self.vertex, self.area_m2, np.asarray(irradiance, dtype=np.float64),
                             (self.hang_vertex, self.hanging))
        return corner.reshape(self.count, 3, 3)


# --------------------------------------------------------------------------- building

def _csr(rows: np.ndarray, cols: np.ndarray, values: np.ndarray, shape) -> Csr:
    order = np.lexsort((cols, rows))
    rows, cols, values = rows[order], cols[order], values[order]
    indptr = np.zeros(shape[0] + 1, dtype=np.int64)
    np.add.at(indptr, rows + 1, 1)
    return Csr(values.astype(np.float64), cols.astype(np.int64), np.cumsum(indptr), tuple(shape))


def gather(transport, caster, points: np.ndarray, normal: np.ndarray, rays: int, rng) -> Csr:
    """G (N, E): the share of cosine-weighted rays from ``points`` about ``normal`` landing on
    the front of each receiver (through the window or onto a back face: nothing). The
    irradiance there from the room's radiance rho E / pi is G (rho E)."""
    from catalog.room.receivers import cosine_directions  # noqa: PLC0415

    rec = transport.receivers
    n = np.ascontiguousarray(np.broadcast_to(np.asarray(normal, dtype=np.float64), (len(points) * rays, 3)))
    o = np.repeat(points, rays, axis=0) + 1e-4 * n
    d = cosine_directions(n, rng)
    dist, tri = caster.intersect(o, d)
    hit = tri >= 0
    rows = np.repeat(np.arange(len(points)), rays)[hit]
    receiver = transport.receiver_at(tri[hit], o[hit] + dist[hit, None] * d[hit])
    front = np.einsum("ni,ni->n", d[hit], rec.normal[np.maximum(receiver, 0)]) < 0
    ok = (receiver >= 0) & front
    return _csr(rows[ok], receiver[ok], np.full(int(ok.sum()), 1.0 / rays), (len(points), rec.count))


def outside_operators(transport, caster, window, rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The outside seen directly by receivers outside the aperture's plane (the reveals, a
    sill): (frame (3, 3), O (E, K), B (E,)). O: pi / N x the sum over a receiver's
    cosine-weighted rays that meet nothing (and do not cross the aperture) of the outward
    hemispherical basis, so that E_outside = O c for the outside's radiance coefficients c;
    B: pi x the share of rays from a receiver outside the aperture's plane that cross it (the
    closed curtain's window side, hung just inside it). Rays from inside the room that leave
    through the aperture are the window's (the transport's D), not these."""
    from catalog.room import sh  # noqa: PLC0415
    from catalog.room.rays import ray_caster  # noqa: PLC0415
    from catalog.room.receivers import cosine_directions  # noqa: PLC0415

    rec = transport.receivers
    frame = sh.frame_of(-np.asarray(window.normal, dtype=np.float64), window.u_edge)
    window_caster = ray_caster(window.triangles())
    idx = np.repeat(np.arange(rec.count), OUTSIDE_RAYS)
    n = np.ascontiguousarray(rec.normal[idx])
    o = rec.sample_points(idx, rng) + 1e-4 * n
    d = cosine_directions(n, rng)
    dist_room, tri_room = caster.intersect(o, d)
    dist_win, tri_win = window_caster.intersect(o, d)
    crosses = (tri_win >= 0) & ((tri_room < 0) | (dist_win < dist_room))
    escaped = (tri_room < 0) & ~crosses
    outside_side = ((rec.centre - window.origin) @ window.normal) < 0
    local = d @ frame.T
    basis = sh.hemi_basis(np.where(local[:, 2:3] >= 0, local, local * [1, 1, -1]), OUTSIDE_ORDER)
    basis = basis * escaped[:, None]
    o_matrix = math.pi / OUTSIDE_RAYS * basis.reshape(rec.count, OUTSIDE_RAYS, -1).sum(axis=1)
    back = math.pi * crosses.reshape(rec.count, OUTSIDE_RAYS).mean(axis=1) * outside_side
    return frame, o_matrix, back


def receiver_uvs(room, transport) -> tuple[np.ndarray, np.ndarray]:
    """(E,) the surface of each receiver and (E, 3, 2) its corners' texture coordinates
    (zeros where the surface has none), by the corners' barycentrics in their triangle."""
    rec = transport.receivers
    surface_of, local_of = room.surface_of_triangle()
    surface = surface_of[rec.triangle]
    uvs = np.zeros((rec.count, 3, 2))
    tri = rec.triangles[rec.triangle]                       # (E, 3, 3)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    d11, d12, d22 = (np.einsum("ni,ni->n", e1, e1), np.einsum("ni,ni->n", e1, e2),
                     np.einsum("ni,ni->n", e2, e2))
    det = d11 * d22 - d12 * d12
    for k in range(3):
        p = rec.corners[:, k] - tri[:, 0]
        p1, p2 = np.einsum("ni,ni->n", p, e1), np.einsum("ni,ni->n", p, e2)
        b1 = (d22 * p1 - d12 * p2) / det
        b2 = (d11 * p2 - d12 * p1) / det
        bary = np.stack([1 - b1 - b2, b1, b2], axis=1)
        for s_index, s in enumerate(room.surfaces):
            if s.uvs is None:
                continue
            sel = np.flatnonzero(surface == s_index)
            uvs[sel, k] = np.einsum("nk,nkj->nj", bary[sel], s.uvs[local_of[rec.triangle[sel]]])
    return surface, uvs


def _weld(transport) -> tuple:
    """(vertex, hang_vertex, hanging Csr) of the transport's light map."""
    vertex = weld_vertices(transport.receivers)
    return (vertex, *hanging_vertices(transport.receivers, vertex))


def side_grid(placement=None) -> tuple:
    """The cloth's room-side grid: (tw, th, x0, y0, w, h) of curtain.vert's ROOM_SIDE texture,
    over the window of ``placement`` (catalog.render.placement; None: the box's)."""
    from catalog.render.curtain_frames import CURTAIN_SIDE_TEXELS, curtain_side_rect  # noqa: PLC0415

    tw, th = CURTAIN_SIDE_TEXELS
    return (int(tw), int(th), *(float(v) for v in curtain_side_rect(placement)))


def _room_side_grid(window_corners) -> tuple:
    """:func:`side_grid` over the room's own window: its corners' bounds to the micrometre, the
    window_rect catalog.render.placement.placement_of gives the frame (that module loads this
    one's bundles, so the rule is restated here rather than imported)."""
    from types import SimpleNamespace  # noqa: PLC0415

    c = np.asarray(window_corners, dtype=np.float64)
    rect = tuple(round(float(v), 6) for v in (c[:, 0].min(), c[:, 0].max(), c[:, 1].min(), c[:, 1].max()))
    return side_grid(SimpleNamespace(window_rect=rect))


def build(room) -> RoomOperators:
    """The bundle of a loaded room (catalog.room.model.Room): its transport from the cache
    (computed there when absent), the gathers by Mitsuba's rays."""
    from catalog.room.cache import room_transport  # noqa: PLC0415
    from catalog.room.rays import ray_caster  # noqa: PLC0415

    from catalog.room.build_progress import report  # noqa: PLC0415

    t = room_transport(room)
    report("gathers")
    if t.window_basis is None or t.bounce_left is None:
        raise ValueError("the room's transport is not compressed")
    caster = ray_caster(room.triangles())
    rng = np.random.default_rng(1)
    nu, nv = t.params.patches
    su, tv = np.meshgrid((np.arange(nu) + 0.5) / nu, (np.arange(nv) + 0.5) / nv)
    s, tt = su.ravel(), tv.ravel()
    c = room.window.corners
    patch_points = (((1 - s) * (1 - tt))[:, None] * c[0] + (s * (1 - tt))[:, None] * c[1]
                    + (s * tt)[:, None] * c[2] + ((1 - s) * tt)[:, None] * c[3])
    tw, th, x0, y0, w, h = _room_side_grid(room.window.corners)
    n = room.window.normal
    plane = float(room.window.centre @ n)
    gx, gy = np.meshgrid(x0 + (np.arange(tw) + 0.5) / tw * w, y0 + (np.arange(th) + 0.5) / th * h)
    gz = (plane - n[0] * gx - n[1] * gy) / n[2]        # the grid on the window's plane
    side_points = np.stack([gx.ravel(), gy.ravel(), gz.ravel()], axis=1)
    surface, uvs = receiver_uvs(room, t)
    f = t.form_factors.tocsr()
    outside_frame, outside, window_back = outside_operators(t, caster, room.window, rng)
    vertex, hang_vertex, hanging = _weld(t)
    return RoomOperators(
        name=room.name, content_sha256=room.content_sha256,
        surfaces=tuple(SurfaceData(s_.name, np.asarray(s_.factor, dtype=np.float64), s_.texture)
                       for s_ in room.surfaces),
        window_corners=room.window.corners, window_normal=room.window.normal, frame=t.frame,
        patches=tuple(t.params.patches), order=int(t.params.order),
        corners=t.receivers.corners, normal=t.receivers.normal, area_m2=t.receivers.weld_weight_m2,
        albedo=t.receivers.albedo, surface=surface, uvs=uvs, vertex=vertex,
        hang_vertex=hang_vertex, hanging=hanging,
        window_basis=t.window_basis, window_modes=t.window_modes,
        form_factors=Csr(f.data.astype(np.float64), f.indices.astype(np.int64),
                         f.indptr.astype(np.int64), f.shape),
        bounce_left=t.bounce_left, bounce_right=t.bounce_right,
        gather_patch=gather(t, caster, patch_points, n, GATHER_RAYS_PATCH, rng),
        gather_side=gather(t, caster, side_points, n, GATHER_RAYS_SIDE, rng),
        gather_wall=gather(t, caster, side_points + CURTAIN_OFFSET_M * n, -n, GATHER_RAYS_SIDE, rng),
        side_grid=(tw, th, x0, y0, w, h), outside_frame=outside_frame, outside=outside,
        window_back=window_back, bounds=room.bounds(), triangles=room.triangles())


# --------------------------------------------------------------------------- the cache

def bundle_key(content_sha256: str) -> str:
    from catalog.room.transport import TransportParams  # noqa: PLC0415  (numpy only)

    text = json.dumps({"room": content_sha256, "params": TransportParams().key(),
                       "version": BUNDLE_VERSION, "patch_rays": GATHER_RAYS_PATCH,
                       "side_rays": GATHER_RAYS_SIDE, "side_texels": side_grid()[:2],
                       "outside_rays": OUTSIDE_RAYS, "outside_order": OUTSIDE_ORDER,
                       "curtain_offset_m": CURTAIN_OFFSET_M}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def bundle_path(spec) -> tuple[Path, str, str]:
    """(path, key, name) of the bundle of ``spec``: a loaded Room (keyed by the hash its
    loader took: nothing read here), or a built-in name or a .glb path (the viewer's, which
    keeps trimesh off its path: keyed by the file's hash, the one read of it here)."""
    from catalog.room.cache import cache_dir  # noqa: PLC0415  (numpy only: no scipy at import)
    from catalog.room.load import BUILTIN_ROOMS, room_path  # noqa: PLC0415

    if hasattr(spec, "content_sha256"):
        key = bundle_key(spec.content_sha256)
        builtin = spec.name in BUILTIN_ROOMS and Path(spec.source) == room_path(spec.name)
        name = spec.name if builtin else Path(spec.source).stem
        return cache_dir().parent / "room_frame" / f"{name}-{key[:24]}.npz", key, name
    path = room_path(spec)
    sha = hashlib.sha256(path.read_bytes()).hexdigest()
    key = bundle_key(sha)
    name = str(spec) if str(spec) in BUILTIN_ROOMS else path.stem
    return cache_dir().parent / "room_frame" / f"{name}-{key[:24]}.npz", key, name


def save(bundle: RoomOperators, path: Path, key: str) -> None:
    arrays = {}
    for name in ("window_corners", "window_normal", "frame", "corners", "normal", "area_m2", "albedo",
                 "surface", "uvs", "vertex", "hang_vertex", "window_basis", "window_modes", "bounce_left",
                 "bounce_right", "bounds", "triangles", "outside_frame", "outside", "window_back"):
        arrays[name] = getattr(bundle, name)
    for name in ("form_factors", "gather_patch", "gather_side", "gather_wall", "hanging"):
        m = getattr(bundle, name)
        arrays.update({f"{name}_data": m.data, f"{name}_indices": m.indices, f"{name}_indptr": m.indptr,
                       f"{name}_shape": np.asarray(m.shape)})
    for k, s in enumerate(bundle.surfaces):
        arrays[f"surface{k}_factor"] = s.factor
        if s.texture is not None:
            arrays[f"surface{k}_texture"] = s.texture.astype(np.float32)
    meta = {"key": key, "name": bundle.name, "content_sha256": bundle.content_sha256,
            "patches": list(bundle.patches), "order": bundle.order, "side_grid": list(bundle.side_grid),
            "surfaces": [s.name for s in bundle.surfaces]}
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    from catalog.core.atomic import atomic_path  # noqa: PLC0415

    with atomic_path(path) as tmp:   # the project's atomic write (its temporaries, signals)
        np.savez(tmp, **arrays)


def load(path: Path, key: str) -> RoomOperators | None:
    try:
        with np.load(path) as data:
            meta = json.loads(bytes(data["meta"]).decode())
            if meta.get("key") != key:
                return None
            arrays = {name: data[name] for name in data.files if name != "meta"}
    except (OSError, ValueError, KeyError, json.JSONDecodeError):
        return None

    def csr(name):
        return Csr(arrays[f"{name}_data"], arrays[f"{name}_indices"], arrays[f"{name}_indptr"],
                   tuple(int(v) for v in arrays[f"{name}_shape"]))

    surfaces = tuple(SurfaceData(name, arrays[f"surface{k}_factor"], arrays.get(f"surface{k}_texture"))
                     for k, name in enumerate(meta["surfaces"]))
    plain = {name: arrays[name] for name in ("window_corners", "window_normal", "frame", "corners", "normal",
                                             "area_m2", "albedo", "surface", "uvs", "vertex", "hang_vertex",
                                             "window_basis",
                                             "window_modes", "bounce_left", "bounce_right", "bounds",
                                             "triangles", "outside_frame", "outside", "window_back")}
    return RoomOperators(name=meta["name"], content_sha256=meta["content_sha256"], surfaces=surfaces,
                         patches=tuple(meta["patches"]), order=int(meta["order"]),
                         form_factors=csr("form_factors"), gather_patch=csr("gather_patch"),
                         gather_side=csr("gather_side"), gather_wall=csr("gather_wall"), hanging=csr("hanging"),
                         side_grid=tuple(meta["side_grid"]), **plain)


def room_operators(spec) -> RoomOperators:
    """The bundle of ``spec`` (a loaded Room, a built-in name or a .glb path) from the cache;
    built (the room loaded and checked unless given loaded, its transport, the gathers) and
    stored when absent: in this process, or where scipy is marked absent (the viewer) in a
    child process."""
    path, key, _name = bundle_path(spec)
    bundle = load(path, key)
    if bundle is not None:
        return bundle
    if "scipy" in sys.modules and sys.modules["scipy"] is None:
        result = subprocess.run([sys.executable, "-m", "catalog.render.room_operators",
                                 str(getattr(spec, "source", spec))],
                                capture_output=True, text=True)
        if result.returncode != 0:
            from catalog.core.errors import InputError  # noqa: PLC0415

            lines = (result.stderr.strip() or "failed").splitlines()
            raise InputError(lines[-1], field="--room")
        bundle = load(path, key)
        if bundle is None:
            raise RuntimeError(f"the room bundle {path} was not written")
        return bundle
    if hasattr(spec, "content_sha256"):
        bundle = build(spec)
    else:
        from catalog.room.load import load_room  # noqa: PLC0415

        bundle = build(load_room(spec))
    save(bundle, path, key)
    return bundle


def main(argv=None) -> int:
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    argv = sys.argv[1:] if argv is None else argv
    try:
        if "--progress" in argv[1:]:   # lines on stdout while it builds (the viewer's first start)
            from catalog.room.build_progress import LinePrinter, listening  # noqa: PLC0415

            with listening(LinePrinter(Path(argv[0]).stem if argv[0].endswith(".glb") else argv[0])):
                room_operators(argv[0])
            return 0
        room_operators(argv[0])
    except CatalogError as exc:
        print(str(exc), file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
