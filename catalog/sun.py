"""Sunlight through the atmosphere (model.md section 4).

Three models, from the paper's to a clear-sky one:

- :func:`direct_beam_w_m2_nm` (the paper, Fig. 10): the extraterrestrial spectrum attenuated
  by Rayleigh scattering along a geometric path of ``path_km`` through a uniform layer
  22 km thick, optical depth ``tau_R(l) * path_km / 22`` (Beer-Lambert). Direct normal
  irradiance only, no ozone, no aerosol, no sky.
- :func:`clear_sky` (beyond the paper): the same Rayleigh path, plus ozone absorption
  (Chappuis and Huggins bands), aerosol extinction (Angstrom turbidity) and the diffuse
  skylight (single scattering: half of the Rayleigh-scattered light and the forward part of
  the aerosol-scattered light reach the ground; one ground-sky bounce).
- :func:`solar_zenith_deg` and :func:`path_km_from_zenith`: date, hour, latitude and
  longitude -> solar zenith -> path through the 22 km spherical shell (22 km at zenith,
  530 km at the horizon; the paper's 500 km is sunset).

Sources: the extraterrestrial spectrum is ASTM G173-03 as pvlib ships it; the Rayleigh
optical depth is Bodhaine et al. (1999) eq. 30; the ozone absorption coefficients are the
table of Bird & Riordan (1986, after Leckner 1978) that pvlib's SPECTRL2 carries. pvlib and
pandas are imported lazily: only the sun needs them.

All spectra are on :data:`catalog.spectra.GRID_NM` (300-780 nm, 1 nm) in W m^-2 nm^-1.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from catalog.errors import CatalogError
from catalog.spectra import GRID_NM

#: Thickness of the paper's uniform Rayleigh layer, and the path at the zenith (km).
LAYER_KM = 22.0
#: Mean Earth radius (km), for the spherical-shell geometry.
EARTH_RADIUS_KM = 6371.0
#: The sanity range of a path length (km). The horizon path through the shell is 529.9 km;
#: the direct-beam model still accepts longer paths (a thicker atmosphere, a lower sun),
#: but nothing shorter than a kilometre or longer than 2000 km means anything here.
MIN_PATH_KM = 1.0
MAX_PATH_KM = 2000.0


# --------------------------------------------------------------------------------------
# The extraterrestrial spectrum


@functools.lru_cache(maxsize=1)
def _g173_extraterrestrial() -> tuple[np.ndarray, np.ndarray]:
    """ASTM G173-03 extraterrestrial spectrum (280-4000 nm, W m^-2 nm^-1) from pvlib."""
    from pvlib.spectrum import get_reference_spectra  # noqa: PLC0415  (lazy: pandas)

    table = get_reference_spectra(standard="ASTM G173-03")
    wavelength_nm = np.asarray(table.index, dtype=np.float64)
    values = np.asarray(table["extraterrestrial"], dtype=np.float64)
    return wavelength_nm, values


@functools.lru_cache(maxsize=4)
def _extraterrestrial_cached(grid_key: tuple[float, float, int]) -> np.ndarray:
    grid = np.linspace(*grid_key)
    wl, values = _g173_extraterrestrial()
    out = np.interp(grid, wl, values)
    out.setflags(write=False)
    return out


def extraterrestrial_w_m2_nm(grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """Solar spectral irradiance at the top of the atmosphere, 1 AU (ASTM G173-03).

    G173 is tabulated every 0.5 nm below 400 nm and every 1 nm above, so on the project's
    1 nm grid this is the table's own values at whole nanometres (linear interpolation in
    between for other grids). Evenly spaced ``grid_nm`` only.
    """
    grid_nm = np.asarray(grid_nm, dtype=np.float64)
    return _extraterrestrial_cached((float(grid_nm[0]), float(grid_nm[-1]), int(grid_nm.size)))


# --------------------------------------------------------------------------------------
# Rayleigh scattering (the paper's model)


def rayleigh_optical_depth(wavelength_nm: np.ndarray | float) -> np.ndarray:
    """Sea-level total Rayleigh optical depth, Bodhaine et al. (1999) eq. 30.

    Standard atmosphere: 1013.25 hPa, 45 deg latitude, 360 ppm CO2. Gives 0.630 at 350 nm,
    0.221 at 450, 0.097 at 550 and 0.036 at 700 nm (their Table 3, to 3 decimals).
    """
    lam_um = np.asarray(wavelength_nm, dtype=np.float64) / 1000.0
    inv2 = lam_um ** -2
    sq = lam_um ** 2
    return 0.0021520 * (1.0455996 - 341.29061 * inv2 - 0.90230850 * sq) / (
        1.0 + 0.0027059889 * inv2 - 85.968563 * sq)


def check_path_km(path_km: float, name: str = "sun") -> float:
    """Refuse a path length outside [MIN_PATH_KM, MAX_PATH_KM] with a message naming ``name``."""
    try:
        value = float(path_km)
    except (TypeError, ValueError):
        raise CatalogError(f"light {name!r}: path length {path_km!r} is not a number "
                           f"(km)") from None
    if not math.isfinite(value) or not MIN_PATH_KM <= value <= MAX_PATH_KM:
        raise CatalogError(f"light {name!r}: path length {path_km!r} km is outside "
                           f"{MIN_PATH_KM:g}-{MAX_PATH_KM:g} km (22 km = sun at the zenith, "
                           f"about 530 km = the horizon)")
    return value


def rayleigh_transmittance(path_km: float, grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """exp(-tau_R(l) * path_km / 22 km): Beer-Lambert through the paper's uniform layer.

    ``path_km = 0`` gives 1 everywhere (no atmosphere); negative paths are refused.
    """
    path_km = float(path_km)
    if not path_km >= 0 or not math.isfinite(path_km):
        raise CatalogError(f"path length {path_km!r} km must be a finite number >= 0")
    return np.exp(-rayleigh_optical_depth(grid_nm) * (path_km / LAYER_KM))


def direct_beam_w_m2_nm(path_km: float, grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """The paper's sunlight (Fig. 10): G173 extraterrestrial x Rayleigh transmittance.

    Direct normal spectral irradiance (W m^-2 nm^-1) after ``path_km`` of the uniform
    22 km layer; no ozone, aerosol or skylight. ``path_km = 0`` is the top of the atmosphere.
    """
    return extraterrestrial_w_m2_nm(grid_nm) * rayleigh_transmittance(path_km, grid_nm)


# --------------------------------------------------------------------------------------
# Geometry: zenith <-> path through the 22 km shell


def path_km_from_zenith(zenith_deg: float, layer_km: float = LAYER_KM,
                        earth_radius_km: float = EARTH_RADIUS_KM) -> float:
    """Length of the ray from the ground to the top of a shell ``layer_km`` thick.

    L = sqrt((R cos z)^2 + 2 R H + H^2) - R cos z: H at the zenith, sqrt(2 R H + H^2)
    (529.9 km for H = 22 km) at the horizon. Zenith angles beyond 90 deg are refused
    (the sun is set).
    """
    z = float(zenith_deg)
    if not 0.0 <= z <= 90.0:
        raise CatalogError(f"solar zenith {z:g} deg is outside 0-90 deg (the sun is set)")
    r_cos = earth_radius_km * math.cos(math.radians(z))
    return math.sqrt(r_cos * r_cos + 2.0 * earth_radius_km * layer_km + layer_km ** 2) - r_cos


def horizon_path_km(layer_km: float = LAYER_KM,
                    earth_radius_km: float = EARTH_RADIUS_KM) -> float:
    """The path at zenith 90 deg: sqrt(2 R H + H^2) (529.9 km for the 22 km shell)."""
    return math.sqrt(2.0 * earth_radius_km * layer_km + layer_km ** 2)


def zenith_deg_from_path(path_km: float, layer_km: float = LAYER_KM,
                         earth_radius_km: float = EARTH_RADIUS_KM) -> float:
    """Inverse of :func:`path_km_from_zenith`: cos z = (2 R H + H^2 - L^2) / (2 L R).

    Paths shorter than the layer or longer than the horizon path have no zenith: refused.
    """
    length = float(path_km)
    horizon = horizon_path_km(layer_km, earth_radius_km)
    if not layer_km <= length <= horizon:
        raise CatalogError(f"path {length:g} km has no solar zenith: a path through the "
                           f"{layer_km:g} km shell is {layer_km:g} km (zenith) to "
                           f"{horizon:.1f} km (horizon)")
    cos_z = (2.0 * earth_radius_km * layer_km + layer_km ** 2 - length ** 2) / (
        2.0 * length * earth_radius_km)
    return math.degrees(math.acos(min(1.0, max(0.0, cos_z))))
