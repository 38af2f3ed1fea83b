"""The window's directional basis: hemispherical harmonics from the real SH (float64 numpy).

The radiance a window patch sends into the room, L(w) for w in the hemisphere around the
window's normal (z, in the window's frame: x along its u edge), is held as
sum_k c_k H_k(w) with H = sqrt(2) Y_lm over the real SH of degree l < order with l + m
even: the SH even in z, orthonormal over the hemisphere, order (order + 1) / 2 of them.
They expand L mirrored onto the back hemisphere, which is continuous at the horizon; the
full SH would expand L with zero behind the window, whose jump at the horizon converges
slowly (order 1 holds half of a uniform radiance). :func:`project` takes the coefficients
from radiance samples with quadrature weights (the captured views of the aperture).
"""

from __future__ import annotations

import math

import numpy as np

MAX_ORDER = 8


def real_sh(directions: np.ndarray, order: int) -> np.ndarray:
    """(N, order**2) orthonormal real SH at unit ``directions`` (N, 3); index l*l + l + m.
    Associated Legendre functions by the standard recurrence (no Condon-Shortley phase)."""
    if not 1 <= order <= MAX_ORDER:
        raise ValueError(f"SH order {order} outside 1..{MAX_ORDER}")
    d = np.asarray(directions, dtype=np.float64)
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    phi = np.arctan2(y, x)
    s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    out = np.zeros((d.shape[0], order * order))
    p = {(0, 0): np.ones_like(z)}
    for m in range(1, order):
        p[(m, m)] = (2 * m - 1) * s * p[(m - 1, m - 1)]
    for m in range(order):
        if m + 1 < order:
            p[(m + 1, m)] = (2 * m + 1) * z * p[(m, m)]
        for ell in range(m + 2, order):
            p[(ell, m)] = ((2 * ell - 1) * z * p[(ell - 1, m)] - (ell + m - 1) * p[(ell - 2, m)]) / (ell - m)
    for ell in range(order):
        for m in range(-ell, ell + 1):
            am = abs(m)
            k = math.sqrt((2 * ell + 1) / (4 * math.pi) * math.factorial(ell - am) / math.factorial(ell + am))
            if m == 0:
                out[:, ell * ell + ell] = k * p[(ell, 0)]
            elif m > 0:
                out[:, ell * ell + ell + m] = math.sqrt(2) * k * p[(ell, am)] * np.cos(am * phi)
            else:
                out[:, ell * ell + ell + m] = math.sqrt(2) * k * p[(ell, am)] * np.sin(am * phi)
    return out


def basis_count(order: int) -> int:
    """Functions of the hemispherical basis of ``order``: order (order + 1) / 2."""
    return order * (order + 1) // 2


def even_indices(order: int) -> np.ndarray:
    """Indices (into :func:`real_sh`) of the SH with l + m even, by l then m."""
    return np.array([ell * ell + ell + m for ell in range(order) for m in range(-ell, ell + 1)
                     if (ell + m) % 2 == 0])


def hemi_basis(directions: np.ndarray, order: int) -> np.ndarray:
    """(N, basis_count(order)) the hemispherical basis at unit local ``directions`` (z >= 0)."""
    return math.sqrt(2.0) * real_sh(directions, order)[:, even_indices(order)]


def hemisphere_quadrature(n_theta: int, n_phi: int) -> tuple[np.ndarray, np.ndarray]:
    """Directions (n_theta n_phi, 3) over z >= 0 and their weights (sr, summing to 2 pi):
    Gauss-Legendre in cos(theta) on [0, 1], uniform in phi (exact for SH products on the
    hemisphere up to degree 2 n_theta - 1 in z)."""
    nodes, weights = np.polynomial.legendre.leggauss(n_theta)
    mu, wmu = 0.5 * (nodes + 1.0), 0.5 * weights
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    mm, pp = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - mm * mm)
    dirs = np.stack([s * np.cos(pp), s * np.sin(pp), mm], axis=-1).reshape(-1, 3)
    w = (wmu[:, None] * np.full(n_phi, 2 * math.pi / n_phi)[None, :]).ravel()
    return dirs, w


def project(directions: np.ndarray, weights: np.ndarray, radiance: np.ndarray, order: int) -> np.ndarray:
    """Coefficients (basis_count(order), ...) of radiance samples (N, ...) at local
    hemisphere ``directions`` (N, 3) with quadrature ``weights`` (N,) (sr):
    c_k = sum_s w_s L_s H_k(w_s)."""
    y = hemi_basis(directions, order)
    return np.einsum("nk,n,n...->k...", y, weights, radiance)


def frame_of(normal: np.ndarray, u_edge: np.ndarray) -> np.ndarray:
    """(3, 3) rows x, y, z of the window's frame: z the normal, x along its u edge."""
    z = normal / np.linalg.norm(normal)
    x = u_edge - (u_edge @ z) * z
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z])
