"""The room transport in web size: the operators a page needs, truncated by an error bound
and stored in 16 bits (numpy only).

From a compressed :class:`catalog.room.transport.Transport`:

- the window operator W (3 E x P K, the channels stacked) as U_r (S V^T)_r: the fewest SVD
  modes whose discarded share of W's Frobenius norm is at most ``window_tolerance``
  (the singular values are the column norms of ``window_basis``); U_r in float16 (its
  columns are unit vectors: float16's 11 bits give ~5e-4 relative per entry), S V^T in
  float32 (r x P K, small);
- the sun beam's bounce as the transport holds it: the first bounce F diag(rho) exact and
  sparse, F's entries stored as ray counts (uint8: F = count / gather_rays) with 16- or
  32-bit column indices, and the later bounces B2 re-truncated from their low-rank factors
  to ``bounce_tolerance`` (Frobenius, per channel), float16.

:func:`pack` returns a :class:`WebPack`, whose :meth:`WebPack.irradiance` and
:meth:`WebPack.bounced` answer as the transport's do, and whose ``errors`` state what the
packing adds (measured against the transport's full operator).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class WebPack:
    window_left: np.ndarray          # (3, E, r) float16: U_r
    window_right: np.ndarray         # (r, P K) float32: (S V^T)_r
    albedo: np.ndarray               # (E, 3) float32
    f_counts: np.ndarray             # (nnz,) uint8: F's entries x gather_rays
    f_indices: np.ndarray            # (nnz,) uint16 or uint32
    f_indptr: np.ndarray             # (E + 1,) uint32
    gather_rays: int
    bounce_left: np.ndarray          # (3, E, rb) float16
    bounce_right: np.ndarray         # (3, rb, E) float16
    bounce_scale: np.ndarray         # (3, rb) float32: bounce = left diag(scale) right
    errors: dict = field(default_factory=dict)

    @property
    def count(self) -> int:
        return int(self.albedo.shape[0])

    def arrays(self) -> dict:
        """The arrays as stored (npz or the page's binary)."""
        return {name: getattr(self, name) for name in (
            "window_left", "window_right", "albedo", "f_counts", "f_indices", "f_indptr",
            "bounce_left", "bounce_right", "bounce_scale")}

    def nbytes(self) -> dict:
        """Bytes per part and in all."""
        a = self.arrays()
        parts = {"window": a["window_left"].nbytes + a["window_right"].nbytes,
                 "first_bounce": a["f_counts"].nbytes + a["f_indices"].nbytes + a["f_indptr"].nbytes
                 + a["albedo"].nbytes,
                 "later_bounces": a["bounce_left"].nbytes + a["bounce_right"].nbytes + a["bounce_scale"].nbytes}
        parts["total"] = sum(parts.values())
        return parts

    def form_factors(self):
        import scipy.sparse  # noqa: PLC0415

        data = self.f_counts.astype(np.float64) / self.gather_rays
        return scipy.sparse.csr_matrix((data, self.f_indices.astype(np.int64), self.f_indptr.astype(np.int64)),
                                       shape=(self.count, self.count))

    def irradiance(self, coefficients: np.ndarray) -> np.ndarray:
        """(E, 3) from window coefficients (P, K, 3) or (P K, 3), as Transport.irradiance."""
        c = np.asarray(coefficients, dtype=np.float64).reshape(self.window_right.shape[1], 3)
        modes = self.window_right.astype(np.float64) @ c                    # (r, 3)
        return np.einsum("cer,rc->ec", self.window_left.astype(np.float64), modes)

    def bounced(self, direct: np.ndarray) -> np.ndarray:
        """(E, 3) the direct irradiance (E, 3) plus every bounce, as Transport.bounced."""
        direct = np.asarray(direct, dtype=np.float64)
        once = self.form_factors() @ (self.albedo.astype(np.float64) * direct)
        right = np.einsum("cre,ec->cr", self.bounce_right.astype(np.float64), direct) * self.bounce_scale
        return direct + once + np.einsum("cer,cr->ec", self.bounce_left.astype(np.float64), right)


def _rank_for(singular: np.ndarray, tolerance: float) -> tuple[int, float]:
    """The fewest leading modes whose discarded Frobenius share is <= tolerance, and that share."""
    total = float(np.sum(singular ** 2))
    tail = np.sqrt(np.maximum(0.0, total - np.cumsum(singular ** 2)) / max(total, 1e-300))
    rank = int(min(singular.size, np.searchsorted(-tail, -tolerance) + 1))
    return rank, float(tail[rank - 1]) if rank else 1.0


def _truncate_product(left: np.ndarray, right: np.ndarray, tolerance: float):
    """left (E, r) @ right (r, E) as U diag(s) V^T truncated to ``tolerance``: U, s, V^T."""
    ql, rl = np.linalg.qr(left)
    qr_, rr = np.linalg.qr(right.T)
    u, s, vt = np.linalg.svd(rl @ rr.T)
    keep = s > (s[0] * 1e-12 if s.size else 0)
    u, s, vt = u[:, keep], s[keep], vt[keep]
    rank, _ = _rank_for(s, tolerance)
    return ql @ u[:, :rank], s[:rank], vt[:rank] @ qr_.T


def pack(transport, window_tolerance: float = 3e-2, bounce_tolerance: float = 3e-2,
         seed: int = 0) -> WebPack:
    """The :class:`WebPack` of a compressed transport (see the module doc); ``errors``: the
    Frobenius bounds and the relative RMS over receivers on random inputs (window
    coefficients; beam irradiances on a random receiver patch) against the full operator."""
    if transport.window_basis is None or transport.bounce_left is None:
        raise ValueError("pack needs a transport computed with compress_operators=True")
    rec = transport.receivers
    e = rec.count
    basis = transport.window_basis.reshape(3 * e, -1)                 # U S, columns by falling s
    singular = np.linalg.norm(basis, axis=0)
    rank, tail = _rank_for(singular, window_tolerance)
    window_left = (basis[:, :rank] / singular[:rank]).reshape(3, e, rank).astype(np.float16)
    window_right = (singular[:rank, None] * transport.window_modes[:rank]).astype(np.float32)
    f = transport.form_factors.tocsr()
    rays = int(transport.params.gather_rays)
    counts = np.rint(f.data * rays)
    if counts.max(initial=0) > 255:
        raise ValueError("a form-factor entry over 255 rays: raise gather_rays' storage")
    lefts, rights, scales = [], [], []
    for ch in range(3):
        u, s, vt = _truncate_product(transport.bounce_left[ch], transport.bounce_right[ch], bounce_tolerance)
        lefts.append(u)
        rights.append(vt)
        scales.append(s)
    rb = max(1, max(s.size for s in scales))
    bl, br, bs = np.zeros((3, e, rb)), np.zeros((3, rb, e)), np.zeros((3, rb))
    for ch in range(3):
        k = scales[ch].size
        bl[ch, :, :k], br[ch, :k], bs[ch, :k] = lefts[ch], rights[ch], scales[ch]
    web = WebPack(window_left=window_left, window_right=window_right, albedo=rec.albedo.astype(np.float32),
                  f_counts=counts.astype(np.uint8),
                  f_indices=f.indices.astype(np.uint16 if e <= 65535 else np.uint32),
                  f_indptr=f.indptr.astype(np.uint32), gather_rays=rays,
                  bounce_left=bl.astype(np.float16), bounce_right=br.astype(np.float16),
                  bounce_scale=bs.astype(np.float32))
    web.errors = measure(transport, web, seed)
    web.errors.update({"window_rank": rank, "window_rank_bound": tail, "bounce_rank": rb})
    return web


def measure(transport, web: WebPack, seed: int = 0, trials: int = 8) -> dict:
    """Relative RMS (over receivers and channels) of the pack against the transport's full
    operators: window light for random positive coefficients' DC terms with random
    directional terms, and beam bounces of direct light on random receiver patches."""
    rng = np.random.default_rng(seed)
    rec = transport.receivers
    patches = int(np.prod(transport.params.patches))
    window_err, bounce_err = [], []
    for _ in range(trials):
        c = rng.normal(size=(patches, transport.coefficient_count // patches, 3)) * 0.3
        c[:, 0] += rng.random((patches, 3)) * 3                  # a positive mean radiance per patch
        exact = transport.irradiance(c, compressed=False)
        window_err.append(np.sqrt(np.mean((web.irradiance(c) - exact) ** 2)) / np.sqrt(np.mean(exact ** 2)))
        centre = rec.centre[rng.integers(rec.count)]
        direct = np.where((np.linalg.norm(rec.centre - centre, axis=1) < 0.5)[:, None],
                          rng.random((1, 3)) + 0.5, 0.0)
        reference = transport.bounced(direct, compressed=True)
        full = _bounced_iterative(transport, direct)
        bounce_err.append({"pack": np.sqrt(np.mean((web.bounced(direct) - full) ** 2)) / np.sqrt(np.mean(full ** 2)),
                           "transport": np.sqrt(np.mean((reference - full) ** 2)) / np.sqrt(np.mean(full ** 2))})
    return {"window_rel_rms": float(np.max(window_err)),
            "bounce_rel_rms": float(max(b["pack"] for b in bounce_err)),
            "bounce_rel_rms_transport": float(max(b["transport"] for b in bounce_err))}


def _bounced_iterative(transport, direct: np.ndarray, tolerance: float = 1e-10) -> np.ndarray:
    """The exact bounce E = direct + F rho E by the Neumann series (F's rows sum to <= 1 and
    rho < 1: it converges), per channel; no dense matrix."""
    f = transport.form_factors
    rho = transport.receivers.albedo
    total = direct.copy()
    term = direct.copy()
    for _ in range(2000):
        term = f @ (rho * term)
        total += term
        if np.abs(term).max() <= tolerance * np.abs(total).max():
            break
    return total


# --------------------------------------------------------------------------- the page's file

#: The page's pack file: ``window.CATALOG_ROOM_PACK = {"header": {...}, "payload": B}`` where B
#: is base64 of zlib of the arrays laid end to end (each at an 8-byte boundary, little-endian).
PAGE_FORMAT = "catalog-room-pack/2"
#: The page's pack file name in a site.
PAGE_FILE = "room_pack.js"
_PAGE_DTYPES = ("float16", "float32", "float64", "uint8", "uint16", "uint32", "int32")


def page_arrays(web: WebPack, ops) -> dict:
    """What the page's host step needs of a room (ops: its
    :class:`catalog.render.room_operators.RoomOperators`, from the same transport as ``web``):
    the pack's operators; the light map's weld (each receiver corner's vertex, the receivers'
    exposed areas, the hanging vertices and their free vertices' weights in float64: CSR
    ``hang``); the gathers onto the window's patches, the cloth's room-side grid and the
    wall's grid (CSR, float32); the outside's operator on the receivers outside the aperture
    and the closed curtain's window side."""
    if ops.count != web.count or not np.array_equal(np.asarray(ops.albedo, np.float32), web.albedo):
        raise ValueError("the room's bundle and its web pack come from different transports")
    out = dict(web.arrays())
    out["vertex"] = np.asarray(ops.vertex, dtype=np.int32)
    out["weld_weight_m2"] = np.asarray(ops.area_m2, dtype=np.float32)
    out["hang_vertex"] = np.asarray(ops.hang_vertex, dtype=np.uint32)
    out["hang_data"] = np.asarray(ops.hanging.data, dtype=np.float64)
    out["hang_indices"] = np.asarray(ops.hanging.indices, dtype=np.uint32)
    out["hang_indptr"] = np.asarray(ops.hanging.indptr, dtype=np.uint32)
    small = np.uint16 if ops.count <= 65535 else np.uint32
    for name in ("gather_patch", "gather_side", "gather_wall"):
        m = getattr(ops, name)
        out[f"{name}_data"] = np.asarray(m.data, dtype=np.float32)
        out[f"{name}_indices"] = np.asarray(m.indices, dtype=small)
        out[f"{name}_indptr"] = np.asarray(m.indptr, dtype=np.uint32)
    out["outside"] = np.asarray(ops.outside, dtype=np.float32)
    out["outside_frame"] = np.asarray(ops.outside_frame, dtype=np.float32)
    out["window_back"] = np.asarray(ops.window_back, dtype=np.float32)
    return out


def page_script(web: WebPack, ops, room_name: str) -> str:
    """The pack file's text (see :data:`PAGE_FORMAT`)."""
    import base64  # noqa: PLC0415
    import hashlib  # noqa: PLC0415
    import json  # noqa: PLC0415
    import zlib  # noqa: PLC0415

    arrays = page_arrays(web, ops)
    entries, chunks, offset = [], [], 0
    for name, a in arrays.items():
        a = np.ascontiguousarray(a)
        if a.dtype.name not in _PAGE_DTYPES:
            raise ValueError(f"{name}: {a.dtype} is not a page dtype")
        raw = a.astype(a.dtype.newbyteorder("<"), copy=False).tobytes()
        entries.append({"name": name, "dtype": a.dtype.name, "shape": list(a.shape), "offset": offset})
        pad = (-len(raw)) % 8
        chunks.append(raw + bytes(pad))
        offset += len(raw) + pad
    payload = b"".join(chunks)
    nu, nv = ops.patches
    header = {"format": PAGE_FORMAT, "room": room_name, "content_sha256": ops.content_sha256,
              "receivers": int(web.count), "patches": [int(nu), int(nv)], "order": int(ops.order),
              "gather_rays": int(web.gather_rays), "side_grid": [float(v) for v in ops.side_grid],
              "payload_bytes": len(payload), "payload_sha256": hashlib.sha256(payload).hexdigest(),
              "arrays": entries, "errors": {k: float(v) for k, v in web.errors.items()}}
    body = base64.b64encode(zlib.compress(payload, 9)).decode("ascii")
    return ("window.CATALOG_ROOM_PACK = " + json.dumps({"header": header, "payload": body},
                                                        separators=(",", ":")) + ";\n")


def read_page_script(text: str, source: str = PAGE_FILE) -> tuple[dict, dict]:
    """(header, arrays) of a pack file, checked as the page checks it (assets/room_transport.js
    ``checkPack``: the same rules); a bad one is refused in one line naming the file and the
    field (:class:`catalog.core.errors.InputError`)."""
    import base64  # noqa: PLC0415
    import binascii  # noqa: PLC0415
    import hashlib  # noqa: PLC0415
    import json  # noqa: PLC0415
    import zlib  # noqa: PLC0415

    from catalog.core.errors import InputError  # noqa: PLC0415

    def refuse(field_name: str, problem: str):
        raise InputError(f"{field_name}: {problem}", path=source)

    prefix = "window.CATALOG_ROOM_PACK = "
    body = text.strip()
    if not body.startswith(prefix) or not body.endswith(";"):
        refuse("file", "not a room pack (it must set window.CATALOG_ROOM_PACK)")
    try:
        pack_obj = json.loads(body[len(prefix):-1])
        header, payload_text = pack_obj["header"], pack_obj["payload"]
    except (json.JSONDecodeError, KeyError, TypeError):
        refuse("file", "not a room pack's JSON (header and payload)")
    if header.get("format") != PAGE_FORMAT:
        refuse("header.format", f"{json.dumps(header.get('format'))}, expected {json.dumps(PAGE_FORMAT)}")
    try:
        payload = zlib.decompress(base64.b64decode(payload_text, validate=True))
    except (binascii.Error, zlib.error, TypeError):
        refuse("payload", "not base64 of zlib data")
    if len(payload) != header.get("payload_bytes"):
        refuse("payload", f"{len(payload)} bytes, the header says {header.get('payload_bytes')}")
    if hashlib.sha256(payload).hexdigest() != header.get("payload_sha256"):
        refuse("payload", "its SHA-256 differs from the header's (the file is damaged)")
    arrays = {}
    for entry in header.get("arrays", []):
        name = entry.get("name")
        if entry.get("dtype") not in _PAGE_DTYPES:
            refuse(f"arrays.{name}", f"dtype {entry.get('dtype')!r}")
        dtype = np.dtype(entry["dtype"]).newbyteorder("<")
        count = int(np.prod(entry["shape"])) if entry["shape"] else 1
        start, end = entry["offset"], entry["offset"] + count * dtype.itemsize
        if start % 8 or end > len(payload):
            refuse(f"arrays.{name}", "outside the payload")
        arrays[name] = np.frombuffer(payload[start:end], dtype=dtype).reshape(entry["shape"])
    _check_arrays(header, arrays, refuse)
    return header, arrays


def _check_arrays(header: dict, a: dict, refuse) -> None:
    """The pack's shapes agree with each other and its indices stay in range."""
    need = ("window_left", "window_right", "albedo", "f_counts", "f_indices", "f_indptr",
            "bounce_left", "bounce_right", "bounce_scale", "vertex", "weld_weight_m2",
            "hang_vertex", "hang_data", "hang_indices", "hang_indptr", "gather_patch_data", "gather_patch_indices", "gather_patch_indptr", "gather_side_data",
            "gather_side_indices", "gather_side_indptr", "gather_wall_data", "gather_wall_indices",
            "gather_wall_indptr", "outside", "outside_frame", "window_back")
    for name in need:
        if name not in a:
            refuse(f"arrays.{name}", "missing")
    e = header.get("receivers")
    nu, nv = header.get("patches", (0, 0))
    k = header.get("order", 0) * (header.get("order", 0) + 1) // 2
    rank = a["window_left"].shape[-1]
    shapes = {"window_left": (3, e, rank), "window_right": (rank, nu * nv * k), "albedo": (e, 3),
              "vertex": (3 * e,), "weld_weight_m2": (e,), "window_back": (e,), "outside_frame": (3, 3),
              "f_indptr": (e + 1,)}
    for name, shape in shapes.items():
        if tuple(a[name].shape) != tuple(shape):
            refuse(f"arrays.{name}", f"shape {list(a[name].shape)}, expected {list(shape)}")
    rb = a["bounce_scale"].shape[-1]
    for name, shape in {"bounce_left": (3, e, rb), "bounce_right": (3, rb, e)}.items():
        if tuple(a[name].shape) != shape:
            refuse(f"arrays.{name}", f"shape {list(a[name].shape)}, expected {list(shape)}")
    if a["outside"].shape[0] != e:
        refuse("arrays.outside", f"{a['outside'].shape[0]} rows, expected {e}")
    tw, th = (int(v) for v in header.get("side_grid", (0, 0))[:2])
    if a["vertex"].size and (int(a["vertex"].min()) < 0 or int(a["vertex"].max()) >= 3 * e):
        refuse("arrays.vertex", "a light-map vertex out of range")
    vertices = int(a["vertex"].max()) + 1 if a["vertex"].size else 0
    # each CSR operator: its rows, its values' array, and what its columns index
    for prefix, rows, data, columns, what in (
            ("f", e, "f_counts", e, "receivers"), ("gather_patch", nu * nv, "gather_patch_data", e, "receivers"),
            ("gather_side", tw * th, "gather_side_data", e, "receivers"),
            ("gather_wall", tw * th, "gather_wall_data", e, "receivers"),
            ("hang", a["hang_vertex"].size, "hang_data", vertices, "light-map vertices")):
        ptr, idx = a[f"{prefix}_indptr"], a[f"{prefix}_indices"]
        if ptr.shape != (rows + 1,) or ptr[0] != 0 or np.any(np.diff(ptr.astype(np.int64)) < 0) \
                or ptr[-1] != idx.size or a[data].size != idx.size:
            refuse(f"arrays.{prefix}_indptr", "not a CSR row index of its entries")
        if idx.size and int(idx.max()) >= columns:
            refuse(f"arrays.{prefix}_indices", f"a column {int(idx.max())} >= {columns} {what}")
    if a["hang_vertex"].size and int(a["hang_vertex"].max()) >= vertices:
        refuse("arrays.hang_vertex", f"a vertex {int(a['hang_vertex'].max())} >= {vertices} light-map vertices")
    for name in ("window_left", "window_right", "bounce_left", "bounce_right", "bounce_scale",
                 "albedo", "outside", "window_back", "weld_weight_m2", "hang_data"):
        if not np.all(np.isfinite(a[name])):
            refuse(f"arrays.{name}", "a value is not finite")
