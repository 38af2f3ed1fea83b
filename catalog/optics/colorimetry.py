"""Colorimetry: CIE 1931 2 deg CMFs, XYZ, sRGB, CIELAB and Delta E 2000.

The tables (CMFs, the sRGB matrix and white) are colour-science's own, read from the cache
of :mod:`catalog.optics.reference_tables` so that drawing a frame never imports colour (which takes
seconds and pulls in scipy). The few formulas here (the sRGB transfer curve, CIELAB,
CIEDE2000) are short closed forms; tests/test_colorimetry.py checks each against
colour-science's implementation. The only matrix written out is the paper's eq. 2, kept
for paper mode.
"""

from __future__ import annotations

import functools

import numpy as np

from catalog.optics import reference_tables
from catalog.optics.spectra import GRID_NM

#: Paper eq. 2: XYZ -> linear sRGB, as printed (4 significant digits).
M_PAPER_XYZ_TO_RGB = np.array([[3.241, -1.537, -0.499],
                               [-0.969, 1.876, 0.042],
                               [0.056, -0.204, 1.057]])

OBSERVER = reference_tables.CMFS_NAME


@functools.lru_cache(maxsize=8)
def _cmfs_cached(grid_key: tuple[float, float, int]) -> np.ndarray:
    start, stop, count = grid_key
    grid = np.linspace(start, stop, count)
    wl, values = reference_tables.cmfs_table()
    out = np.stack([np.interp(grid, wl, values[:, i], left=0.0, right=0.0)
                    for i in range(3)], axis=1)
    out.setflags(write=False)
    return out


def cmfs(grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """CIE 1931 2 deg xbar, ybar, zbar on ``grid_nm`` (shape (N, 3)); zero outside 360-830 nm.

    ``grid_nm`` must be evenly spaced (the project's grids are).
    """
    grid_nm = np.asarray(grid_nm, dtype=np.float64)
    return _cmfs_cached((float(grid_nm[0]), float(grid_nm[-1]), int(grid_nm.size)))


def spectrum_to_xyz(spectral: np.ndarray, grid_nm: np.ndarray = GRID_NM,
                    step_nm: float | None = None) -> np.ndarray:
    """Unnormalised tristimulus values: sum_l cmf(l) S(l) dl over the last axis of ``spectral``.

    ``spectral`` has shape (..., N) on ``grid_nm``; the result has shape (..., 3). With S a
    spectral radiance in W m^-2 sr^-1 nm^-1, multiply by 683 lm/W for luminance units.
    """
    grid_nm = np.asarray(grid_nm, dtype=np.float64)
    if step_nm is None:
        step_nm = float(grid_nm[1] - grid_nm[0]) if grid_nm.size > 1 else 1.0
    return np.asarray(spectral, dtype=np.float64) @ cmfs(grid_nm) * step_nm


@functools.lru_cache(maxsize=1)
def _srgb():
    to_rgb = np.array(reference_tables.srgb_xyz_to_rgb(), dtype=np.float64)
    # colour rounds its two sRGB matrices separately (a round trip costs ~0.005 Delta E);
    # the exact inverse keeps XYZ -> RGB -> XYZ the identity.
    return to_rgb, np.linalg.inv(to_rgb), np.array(reference_tables.srgb_whitepoint_xy())


def xyz_to_linear_srgb(xyz: np.ndarray) -> np.ndarray:
    """XYZ -> linear sRGB (colour-science's matrix, D65 white; no clipping, so negatives stay)."""
    return np.asarray(xyz, dtype=np.float64) @ _srgb()[0].T


def linear_srgb_to_xyz(rgb: np.ndarray) -> np.ndarray:
    """Linear sRGB -> XYZ (the exact inverse of :func:`xyz_to_linear_srgb`)."""
    return np.asarray(rgb, dtype=np.float64) @ _srgb()[1].T


def srgb_whitepoint_xy() -> np.ndarray:
    """The sRGB (D65) white point chromaticity xy."""
    return _srgb()[2].copy()


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1, piecewise), not a 2.2 power."""
    x = np.asarray(linear, dtype=np.float64)
    with np.errstate(invalid="ignore"):  # the power branch is only kept where x > 0.0031308
        return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.abs(x) ** (1 / 2.4) - 0.055)


def srgb_decode(encoded: np.ndarray) -> np.ndarray:
    """Inverse of :func:`srgb_encode`."""
    v = np.asarray(encoded, dtype=np.float64)
    return np.where(v <= 0.04045, v / 12.92, ((np.abs(v) + 0.055) / 1.055) ** 2.4)


def xy_to_xyz(xy: np.ndarray) -> np.ndarray:
    """Chromaticity xy -> XYZ with Y = 1."""
    x, y = np.asarray(xy, dtype=np.float64)[..., 0], np.asarray(xy, dtype=np.float64)[..., 1]
    return np.stack([x / y, np.ones_like(x), (1 - x - y) / y], axis=-1)


def xyz_to_lab(xyz: np.ndarray, white_xyz: np.ndarray) -> np.ndarray:
    """CIELAB (CIE 15:2004) of ``xyz`` relative to the reference white ``white_xyz`` (same scale)."""
    ratio = np.asarray(xyz, dtype=np.float64) / np.asarray(white_xyz, dtype=np.float64)
    epsilon, kappa = 216 / 24389, 24389 / 27
    f = np.where(ratio > epsilon, np.cbrt(ratio), (kappa * ratio + 16) / 116)
    return np.stack([116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]),
                     200 * (f[..., 1] - f[..., 2])], axis=-1)


def delta_e_2000_lab(lab_a: np.ndarray, lab_b: np.ndarray) -> np.ndarray:
    """CIEDE2000 (Sharma, Wu and Dalal 2005, with kL = kC = kH = 1) between CIELAB colours."""
    L1, a1, b1 = np.moveaxis(np.asarray(lab_a, dtype=np.float64), -1, 0)
    L2, a2, b2 = np.moveaxis(np.asarray(lab_b, dtype=np.float64), -1, 0)
    c_mean = (np.hypot(a1, b1) + np.hypot(a2, b2)) / 2
    g = 0.5 * (1 - np.sqrt(c_mean ** 7 / (c_mean ** 7 + 25.0 ** 7)))
    a1p, a2p = (1 + g) * a1, (1 + g) * a2
    c1p, c2p = np.hypot(a1p, b1), np.hypot(a2p, b2)
    h1p = np.degrees(np.arctan2(b1, a1p)) % 360  # atan2(0, 0) = 0, as the paper defines
    h2p = np.degrees(np.arctan2(b2, a2p)) % 360
    dLp = L2 - L1
    dCp = c2p - c1p
    dh = h2p - h1p
    dh = np.where(dh > 180, dh - 360, np.where(dh < -180, dh + 360, dh))
    dh = np.where(c1p * c2p == 0, 0.0, dh)
    dHp = 2 * np.sqrt(c1p * c2p) * np.sin(np.radians(dh) / 2)
    Lp_mean = (L1 + L2) / 2
    Cp_mean = (c1p + c2p) / 2
    h_sum = h1p + h2p
    hp_mean = np.where(np.abs(h1p - h2p) <= 180, h_sum / 2,
                       np.where(h_sum < 360, (h_sum + 360) / 2, (h_sum - 360) / 2))
    hp_mean = np.where(c1p * c2p == 0, h_sum, hp_mean)
    t = (1 - 0.17 * np.cos(np.radians(hp_mean - 30)) + 0.24 * np.cos(np.radians(2 * hp_mean))
         + 0.32 * np.cos(np.radians(3 * hp_mean + 6))
         - 0.20 * np.cos(np.radians(4 * hp_mean - 63)))
    d_theta = 30 * np.exp(-(((hp_mean - 275) / 25) ** 2))
    r_c = 2 * np.sqrt(Cp_mean ** 7 / (Cp_mean ** 7 + 25.0 ** 7))
    s_l = 1 + 0.015 * (Lp_mean - 50) ** 2 / np.sqrt(20 + (Lp_mean - 50) ** 2)
    s_c = 1 + 0.045 * Cp_mean
    s_h = 1 + 0.015 * Cp_mean * t
    r_t = -np.sin(np.radians(2 * d_theta)) * r_c
    return np.sqrt((dLp / s_l) ** 2 + (dCp / s_c) ** 2 + (dHp / s_h) ** 2
                   + r_t * (dCp / s_c) * (dHp / s_h))


def delta_e_2000(xyz_a: np.ndarray, xyz_b: np.ndarray, white_xyz: np.ndarray) -> np.ndarray:
    """CIEDE2000 colour difference between two XYZ colours seen against ``white_xyz``.

    All three on the same absolute scale; the white has L* = 100.
    """
    white_xyz = np.asarray(white_xyz, dtype=np.float64)
    return delta_e_2000_lab(xyz_to_lab(xyz_a, white_xyz), xyz_to_lab(xyz_b, white_xyz))
