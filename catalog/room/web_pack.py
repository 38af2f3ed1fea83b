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
