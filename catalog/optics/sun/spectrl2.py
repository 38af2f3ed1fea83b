"""Our clear sky (:func:`catalog.optics.sun.model.clear_sky`) against Bird & Riordan's SPECTRL2 (pvlib).

SPECTRL2 (Bird & Riordan 1986, as ``pvlib.spectrum.spectrl2``) is an independent,
empirically tuned clear-sky model: its own extraterrestrial spectrum (~10 nm bands), its
own Rayleigh formula, air mass (Kasten-Young), aerosol transmittances and a diffuse model
with empirical corrections. We run it with the same atmosphere (ozone column, aerosol
optical depth at 500 nm, Angstrom exponent, single-scattering albedo, asymmetry, ground
albedo, pressure) and no water vapour (we model none), at 1 AU, and compare at its own
wavelengths in 300-780 nm, leaving out the three where its mixed-gas (O2) absorption is
non-zero (690, 762.5, 767.5 nm), which we do not model. Our 1 nm spectra are averaged
over each SPECTRL2 band (edges halfway between its wavelengths) before comparing.

Measures, per zenith angle:

- ``dni_integral_ratio``, ``ghi_integral_ratio``: ours / SPECTRL2, trapezoid over 300-780 nm;
- ``dni_rel_rms_400_780``, ``ghi_rel_rms_400_780``: RMS of (ours - SPECTRL2) / SPECTRL2 over
  400-780 nm (where both spectra are large);
- ``transmittance_rel_rms_400_780``: the same for the direct transmittance (direct / own
  extraterrestrial): the atmosphere alone, without the two extraterrestrial spectra's
  differences;
- ``uv_ghi_ratio``: ours / SPECTRL2 for the global irradiance in 315-400 nm.
"""

from __future__ import annotations

import math

import numpy as np

from catalog.optics.spectra import GRID_NM
from catalog.optics.sun.model import LAYER_KM, Atmosphere, clear_sky, relative_airmass_kasten_young

#: The zenith angles of the comparison (deg).
ZENITHS_DEG = (0.0, 30.0, 60.0, 75.0, 85.0)
#: SPECTRL2 wavelengths where its O2 (mixed-gas) absorption is non-zero: left out.
MIXED_GAS_NM = (690.0, 762.5, 767.5)


def _band_average(values_on_grid: np.ndarray, centres_nm: np.ndarray) -> np.ndarray:
    """Average of a 1 nm spectrum over bands whose edges lie halfway between centres."""
    edges = np.concatenate([[centres_nm[0] - (centres_nm[1] - centres_nm[0]) / 2],
                            (centres_nm[1:] + centres_nm[:-1]) / 2,
                            [centres_nm[-1] + (centres_nm[-1] - centres_nm[-2]) / 2]])
    out = np.empty(centres_nm.size)
    for i in range(centres_nm.size):
        inside = (GRID_NM >= edges[i]) & (GRID_NM < edges[i + 1])
        if not inside.any():  # a band narrower than the grid step: nearest sample
            inside = np.abs(GRID_NM - centres_nm[i]) == np.min(np.abs(GRID_NM - centres_nm[i]))
        out[i] = float(np.mean(values_on_grid[inside]))
    return out


def spectrl2_clear_sky(zenith_deg: float, atmosphere: Atmosphere,
                       relative_airmass: float | None = None) -> dict[str, np.ndarray]:
    """pvlib's SPECTRL2 at ``zenith_deg`` for a horizontal plane, 1 AU, no water vapour.

    ``relative_airmass``: Kasten & Young's (as the NREL code uses) unless given.

    Returns ``wavelength`` (nm), ``dni``, ``ghi``, ``dhi``, ``et`` (W m^-2 nm^-1) in 300-780 nm.
    """
    from pvlib.spectrum import spectrl2  # noqa: PLC0415

    result = spectrl2(
        apparent_zenith=np.array([zenith_deg]), aoi=np.array([zenith_deg]),
        surface_tilt=np.array([0.0]), ground_albedo=atmosphere.ground_albedo,
        surface_pressure=atmosphere.pressure_hpa * 100.0,
        relative_airmass=np.array([relative_airmass_kasten_young(zenith_deg)
                                   if relative_airmass is None else relative_airmass]),
        precipitable_water=np.array([0.0]), ozone=np.array([atmosphere.ozone_atm_cm]),
        aerosol_turbidity_500nm=np.array([atmosphere.aod_500nm]),
        dayofyear=np.array([1]), scattering_albedo_400nm=atmosphere.aerosol_albedo,
        alpha=atmosphere.angstrom_alpha, wavelength_variation_factor=0.0,
        aerosol_asymmetry_factor=atmosphere.aerosol_asymmetry)
    wavelength = np.asarray(result["wavelength"], dtype=np.float64)
    # undo the Earth-Sun distance factor SPECTRL2 applies for the date (we compare at 1 AU)
    d = float(np.asarray(result["dni_extra"])[0, 0] / _spectrl2_et()[0])
    keep = (wavelength >= 300.0) & (wavelength <= 780.0)
    dni = np.asarray(result["dni"])[:, 0] / d
    dhi = np.asarray(result["dhi"])[:, 0] / d
    cos_z = math.cos(math.radians(zenith_deg))
    return {"wavelength": wavelength[keep], "dni": dni[keep], "dhi": dhi[keep],
            "ghi": (dni * cos_z + dhi)[keep], "et": _spectrl2_et()[keep]}


def _spectrl2_et() -> np.ndarray:
    import importlib  # noqa: PLC0415

    table = importlib.import_module("pvlib.spectrum.spectrl2")._SPECTRL2_COEFFS  # noqa: SLF001
    return np.asarray(table["spectral_irradiance_et"], dtype=np.float64)


def _rel_rms(ours: np.ndarray, ref: np.ndarray) -> float:
    return float(np.sqrt(np.mean(((ours - ref) / ref) ** 2)))


def compare_at_zenith(zenith_deg: float, atmosphere: Atmosphere = Atmosphere(),
                      diffuse_method: str = "delta-eddington",
                      spectrl2_airmass: str = "kasten-young") -> dict:
    """One row of the comparison (see the module docstring for the measures).

    ``spectrl2_airmass="shell"`` runs SPECTRL2 with our air mass (path / 22 km) instead of
    Kasten & Young's, to separate the geometry from the rest of the model.
    """
    ours = clear_sky(zenith_deg, atmosphere=atmosphere, diffuse_method=diffuse_method)
    if spectrl2_airmass not in ("kasten-young", "shell"):
        raise ValueError(f"spectrl2_airmass {spectrl2_airmass!r}: 'kasten-young' or 'shell'")
    airmass = ours.path_km / LAYER_KM if spectrl2_airmass == "shell" else None
    ref = spectrl2_clear_sky(zenith_deg, atmosphere, airmass)
    wl = ref["wavelength"]
    keep = ~np.isin(wl, MIXED_GAS_NM)
    wl = wl[keep]
    ref = {k: v[keep] for k, v in ref.items() if k != "wavelength"}
    dni = _band_average(ours.direct_normal, wl)
    ghi = _band_average(ours.global_horizontal, wl)
    transmittance = np.interp(wl, GRID_NM, ours.direct_normal / ours.extraterrestrial)
    ref_transmittance = ref["dni"] / ref["et"]
    vis = wl >= 400.0
    uv = (wl >= 315.0) & (wl <= 400.0)
    return {
        "zenith_deg": float(zenith_deg),
        "path_km": float(ours.path_km),
        "dni_integral_ratio": float(np.trapezoid(dni, wl) / np.trapezoid(ref["dni"], wl)),
        "dni_rel_rms_400_780": _rel_rms(dni[vis], ref["dni"][vis]),
        "transmittance_rel_rms_400_780": _rel_rms(transmittance[vis], ref_transmittance[vis]),
        "ghi_integral_ratio": float(np.trapezoid(ghi, wl) / np.trapezoid(ref["ghi"], wl)),
        "ghi_rel_rms_400_780": _rel_rms(ghi[vis], ref["ghi"][vis]),
        "uv_ghi_ratio": float(np.trapezoid(ghi[uv], wl[uv]) / np.trapezoid(ref["ghi"][uv], wl[uv])),
    }


def comparison_table(zeniths_deg=ZENITHS_DEG, atmosphere: Atmosphere = Atmosphere(),
                     diffuse_method: str = "delta-eddington") -> list[dict]:
    """:func:`compare_at_zenith` for each zenith angle."""
    return [compare_at_zenith(z, atmosphere, diffuse_method) for z in zeniths_deg]
