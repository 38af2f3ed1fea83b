"""Colorimetry through colour-science: CIE 1931 2 deg CMFs, XYZ, sRGB, Delta E 2000.

colour-science is imported lazily (it takes about a second); nothing here copies a colour
table by hand. The only matrix written out is the paper's eq. 2, kept for paper mode.
"""

from __future__ import annotations

import functools

import numpy as np

from catalog.spectra import GRID_NM

#: Paper eq. 2: XYZ -> linear sRGB, as printed (4 significant digits).
M_PAPER_XYZ_TO_RGB = np.array([[3.241, -1.537, -0.499],
                               [-0.969, 1.876, 0.042],
                               [0.056, -0.204, 1.057]])

OBSERVER = "CIE 1931 2 Degree Standard Observer"


def _colour():
    import colour  # noqa: PLC0415  (lazy: heavy import)
    return colour


@functools.lru_cache(maxsize=8)
def _cmfs_cached(grid_key: tuple[float, float, int]) -> np.ndarray:
    start, stop, count = grid_key
    grid = np.linspace(start, stop, count)
    cmfs = _colour().MSDS_CMFS[OBSERVER]
    wl = np.asarray(cmfs.wavelengths, dtype=np.float64)
    values = np.asarray(cmfs.values, dtype=np.float64)
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
    colour = _colour()
    space = colour.RGB_COLOURSPACES["sRGB"]
    to_rgb = np.asarray(space.matrix_XYZ_to_RGB, dtype=np.float64)
    # colour rounds its two sRGB matrices separately (a round trip costs ~0.005 Delta E);
    # the exact inverse keeps XYZ -> RGB -> XYZ the identity.
    return (to_rgb, np.linalg.inv(to_rgb), np.asarray(space.whitepoint, dtype=np.float64))


def xyz_to_linear_srgb(xyz: np.ndarray) -> np.ndarray:
    """XYZ -> linear sRGB (colour-science's matrix, D65 white; no clipping, so negatives stay)."""
    return np.asarray(xyz, dtype=np.float64) @ _srgb()[0].T


def linear_srgb_to_xyz(rgb: np.ndarray) -> np.ndarray:
    """Linear sRGB -> XYZ (colour-science's matrix)."""
    return np.asarray(rgb, dtype=np.float64) @ _srgb()[1].T


def srgb_whitepoint_xy() -> np.ndarray:
    """The sRGB (D65) white point chromaticity xy."""
    return _srgb()[2].copy()


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1, piecewise), not a 2.2 power."""
    return np.asarray(_colour().cctf_encoding(np.asarray(linear, dtype=np.float64),
                                              function="sRGB"))


def srgb_decode(encoded: np.ndarray) -> np.ndarray:
    """Inverse of :func:`srgb_encode`."""
    return np.asarray(_colour().cctf_decoding(np.asarray(encoded, dtype=np.float64),
                                              function="sRGB"))


def xyz_to_lab(xyz: np.ndarray, white_xyz: np.ndarray) -> np.ndarray:
    """CIELAB of ``xyz`` relative to the reference white ``white_xyz`` (same scale)."""
    colour = _colour()
    white_xyz = np.asarray(white_xyz, dtype=np.float64)
    xy = colour.XYZ_to_xy(white_xyz)
    scale = white_xyz[..., 1:2] if white_xyz.ndim else 1.0
    return np.asarray(colour.XYZ_to_Lab(np.asarray(xyz, dtype=np.float64) / scale, xy))


def delta_e_2000(xyz_a: np.ndarray, xyz_b: np.ndarray, white_xyz: np.ndarray) -> np.ndarray:
    """CIEDE2000 colour difference between two XYZ colours seen against ``white_xyz``.

    All three on the same absolute scale; the white sets Y = 100 (L* = 100).
    """
    colour = _colour()
    white_xyz = np.asarray(white_xyz, dtype=np.float64)
    lab_a = xyz_to_lab(xyz_a, white_xyz)
    lab_b = xyz_to_lab(xyz_b, white_xyz)
    return np.asarray(colour.delta_E(lab_a, lab_b, method="CIE 2000"))
