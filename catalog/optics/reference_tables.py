"""Reference tables taken from colour-science and pvlib, cached so the viewer starts fast.

``import colour`` takes seconds and pulls in scipy; ``import pvlib`` pulls in pandas. The
renderer and the viewer need only a few of their tables (the CIE 1931 2 deg CMFs, the CIE
illuminants, the sRGB matrix, ASTM G173's extraterrestrial spectrum, Bird & Riordan's ozone
coefficients, the CIE daylight basis S0 S1 S2), so ``tools/make_reference_tables.py`` copies them once, by program, from the
installed packages into ``catalog/optics/data/reference_tables.npz``. Nothing is typed in by hand,
and ``tests/test_reference_tables.py`` regenerates the file from the packages and checks it
is identical, so the cache cannot drift from its sources.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

TABLE_PATH = Path(__file__).resolve().parent / "data" / "reference_tables.npz"
CMFS_NAME = "CIE 1931 2 Degree Standard Observer"


def build_tables() -> dict[str, np.ndarray]:
    """Collect the tables from colour-science and pvlib (slow: imports both)."""
    import importlib

    import colour
    from pvlib.spectrum import get_reference_spectra

    cmfs = colour.MSDS_CMFS[CMFS_NAME]
    names = [str(k) for k in colour.SDS_ILLUMINANTS.keys()]
    wl_parts, value_parts, offsets = [], [], [0]
    for name in names:
        sd = colour.SDS_ILLUMINANTS[name]
        wl_parts.append(np.asarray(sd.wavelengths, dtype=np.float64))
        value_parts.append(np.asarray(sd.values, dtype=np.float64))
        offsets.append(offsets[-1] + len(wl_parts[-1]))
    space = colour.RGB_COLOURSPACES["sRGB"]
    daylight = colour.colorimetry.SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES
    g173 = get_reference_spectra(standard="ASTM G173-03")
    spectrl2 = importlib.import_module("pvlib.spectrum.spectrl2")
    coeffs = spectrl2._SPECTRL2_COEFFS  # noqa: SLF001  (pvlib keeps the table module-private)
    return {
        "cmfs_wavelength_nm": np.asarray(cmfs.wavelengths, dtype=np.float64),
        "cmfs_values": np.asarray(cmfs.values, dtype=np.float64),
        "illuminant_names": np.asarray(names),
        "illuminant_offsets": np.asarray(offsets, dtype=np.int64),
        "illuminant_wavelength_nm": np.concatenate(wl_parts),
        "illuminant_values": np.concatenate(value_parts),
        "srgb_xyz_to_rgb": np.asarray(space.matrix_XYZ_to_RGB, dtype=np.float64),
        "srgb_whitepoint_xy": np.asarray(space.whitepoint, dtype=np.float64),
        "g173_wavelength_nm": np.asarray(g173.index, dtype=np.float64),
        "g173_extraterrestrial": np.asarray(g173["extraterrestrial"], dtype=np.float64),
        "ozone_wavelength_nm": np.asarray(coeffs["wavelength"], dtype=np.float64),
        "ozone_absorption_per_atm_cm": np.asarray(coeffs["ozone_absorption"], dtype=np.float64),
        "daylight_wavelength_nm": np.asarray(daylight["S0"].wavelengths, dtype=np.float64),
        "daylight_basis": np.stack([np.asarray(daylight[k].values, dtype=np.float64)
                                    for k in ("S0", "S1", "S2")]),
    }


@functools.lru_cache(maxsize=1)
def tables() -> dict[str, np.ndarray]:
    """The cached tables (read-only arrays). Regenerate with tools/make_reference_tables.py."""
    if not TABLE_PATH.exists():
        from catalog.core.errors import CatalogError

        raise CatalogError(f"{TABLE_PATH}: missing; run tools/make_reference_tables.py")
    with np.load(TABLE_PATH, allow_pickle=False) as data:
        out = {key: data[key] for key in data.files}
    for value in out.values():
        value.setflags(write=False)
    return out


def cmfs_table() -> tuple[np.ndarray, np.ndarray]:
    """CIE 1931 2 deg colour-matching functions: wavelengths (nm) and (N, 3) xbar ybar zbar."""
    t = tables()
    return t["cmfs_wavelength_nm"], t["cmfs_values"]


def daylight_basis_table() -> tuple[np.ndarray, np.ndarray]:
    """The CIE D-series basis S0, S1, S2: wavelengths (nm) and (3, N) values."""
    t = tables()
    return t["daylight_wavelength_nm"], t["daylight_basis"]


def illuminant_names() -> tuple[str, ...]:
    """colour-science's SDS_ILLUMINANTS names, in colour's order."""
    return tuple(str(n) for n in tables()["illuminant_names"])


def illuminant_table(name: str) -> tuple[np.ndarray, np.ndarray]:
    """(wavelength_nm, relative spectral power) of a CIE illuminant as colour-science ships it."""
    t = tables()
    index = illuminant_names().index(name)
    lo, hi = t["illuminant_offsets"][index], t["illuminant_offsets"][index + 1]
    return t["illuminant_wavelength_nm"][lo:hi], t["illuminant_values"][lo:hi]


def srgb_xyz_to_rgb() -> np.ndarray:
    """colour-science's XYZ -> linear sRGB matrix (D65)."""
    return tables()["srgb_xyz_to_rgb"]


def srgb_whitepoint_xy() -> np.ndarray:
    return tables()["srgb_whitepoint_xy"]


def g173_extraterrestrial() -> tuple[np.ndarray, np.ndarray]:
    """ASTM G173-03 extraterrestrial spectrum as pvlib ships it (nm, W m^-2 nm^-1)."""
    t = tables()
    return t["g173_wavelength_nm"], t["g173_extraterrestrial"]


def ozone_table() -> tuple[np.ndarray, np.ndarray]:
    """Bird & Riordan (1986) ozone absorption coefficients (nm, 1/atm-cm) as pvlib carries them."""
    t = tables()
    return t["ozone_wavelength_nm"], t["ozone_absorption_per_atm_cm"]
