"""The light library: spectral irradiance of every light the catalog renders under, by name.

Names (:func:`light_names` lists the library for menus):

- every illuminant colour-science ships in ``colour.SDS_ILLUMINANTS``, spelt as colour
  spells it (``D65``, ``A``, ``FL2``, ``FL3.1``, ``LED-B4``, ``HP1``, ...). Their tables are
  relative; we interpolate them linearly onto the project grid (CIE 15 recommends linear
  interpolation of illuminant tables) and set them to zero where colour has no data (the FL,
  HP and LED tables start at 380 nm, B at 320, E at 360: no UV from those);
- ``UV-A``: a 365 nm blacklight (see :func:`uva_lamp_relative`);
- ``UV-385``: a 385 nm UV LED lamp, ``LED-405``: a 405 nm violet LED (one Gaussian band each,
  see :data:`NARROW_LAMPS`);
- ``LED-violet-white``: a violet-pumped "full spectrum" white LED (a 405 nm pump and three
  phosphors; the shape is shipped as data, ``catalog/optics/data/led_violet_white.csv``, made by
  ``tools/make_violet_led.py``, whose header names its source);
- ``LED-warm``: a warm-white phosphor LED with no UV (see :func:`warm_led_relative`);
- the sun (:mod:`catalog.optics.sun.model`): ``sun:PATH_KM`` is the paper's direct beam after Rayleigh
  scattering along PATH_KM of a uniform 22 km layer (Fig. 10), absolute;
  ``sun-clear:PATH_KM`` is a clear sky (ozone, aerosol, skylight) on a plane facing the
  sun; ``sun@2026-06-21T12:00,34.7,135.5`` is the same for a date and time (UTC), latitude
  and longitude (deg, east positive).

Absolute levels (physical-mode fluorescence scales with irradiance): daylight illuminants
(D*, ID*, B, C and the ISO 7589 daylights) are scaled to 10 000 lx; every other table
(A, E, FL*, HP*, LED-*, the ISO 7589 lamps), LED-warm and LED-violet-white to 1 000 lx;
UV-A, UV-385 and LED-405 to 10 W m^-2 in all; the sun is absolute. ``get_light(name, illuminance_lx=...)`` rescales to any level.
"""

from __future__ import annotations

import difflib
import functools
import math
from dataclasses import dataclass

import numpy as np

from catalog.core.constants import LUMINOUS_EFFICACY_LM_W as K_M_LM_PER_W
from catalog.optics import reference_tables
from catalog.core.errors import CatalogError, InputError
from catalog.optics.spectra import GRID_NM

#: Default level of the daylight illuminants (lx): an overcast-to-bright outdoor day.
DAYLIGHT_LX = 10_000.0
#: Default level of lamps (lx): a brightly lit shop or showroom.
LAMP_LX = 1_000.0
#: Default total irradiance of the UV-A lamp (W m^-2), 300-780 nm.
UVA_TOTAL_W_M2 = 10.0
#: UV-A band used for the "UV-A fraction" of a light (nm, inclusive).
UVA_BAND_NM = (315.0, 400.0)

#: The sun at the paths of the paper's Fig. 10 and a clear sky at noon and at sunset.
SUN_MENU = ("sun:22", "sun:100", "sun:200", "sun:300", "sun:400", "sun:500",
            "sun-clear:22", "sun-clear:500")

_STEP_NM = float(GRID_NM[1] - GRID_NM[0])


#: What a light is, resolved once when the library makes it (never read from its name
#: elsewhere): a CIE (or ISO) illuminant table, a visible lamp, a UV lamp, or the sun.
LIGHT_KINDS = ("illuminant", "lamp", "uv", "sun")
#: How a sun light was asked for: the paper's direct beam by path length (``sun:PATH_KM``),
#: the clear sky by path length (``sun-clear:PATH_KM``) or by date and place (``sun@...``).
SUN_MODELS = ("paper", "clear", "date")


@dataclass(frozen=True)
class SunSource:
    """The sun a light is: its model (SUN_MODELS) and the elevation (deg above the horizon)
    its path or date implies; None where the path has no solar zenith (shorter than the
    paper's layer: the frame then places it as a lamp)."""

    model: str
    elevation_deg: float | None


@dataclass(frozen=True, eq=False)
class Light:
    """A light: spectral irradiance on :data:`GRID_NM` (300-780 nm), W m^-2 nm^-1, absolute;
    its ``kind`` (LIGHT_KINDS) and, for the sun, where it stands (``sun``)."""

    name: str
    description: str
    irradiance_w_m2_nm: np.ndarray
    kind: str = "illuminant"
    sun: SunSource | None = None

    @property
    def is_sun(self) -> bool:
        return self.kind == "sun"

    @property
    def illuminance_lx(self) -> float:
        """Photopic illuminance: 683 lm/W * sum ybar(l) E(l) dl (CIE 1931 2 deg ybar)."""
        return illuminance_lx(self.irradiance_w_m2_nm)

    @property
    def total_w_m2(self) -> float:
        """Irradiance integrated over the grid (300-780 nm), W m^-2."""
        return float(np.sum(self.irradiance_w_m2_nm) * _STEP_NM)

    @property
    def uva_fraction(self) -> float:
        """Irradiance in 315-400 nm over the irradiance in 300-780 nm (0 for a dark light)."""
        total = self.total_w_m2
        if total <= 0:
            return 0.0
        band = (GRID_NM >= UVA_BAND_NM[0]) & (GRID_NM <= UVA_BAND_NM[1])
        return float(np.sum(self.irradiance_w_m2_nm[band]) * _STEP_NM / total)

    def scaled_to(self, illuminance: float) -> "Light":
        """The same spectrum scaled to ``illuminance`` lx (refused for a light with none)."""
        target = float(illuminance)
        if not math.isfinite(target) or target < 0:
            raise InputError(f"illuminance {illuminance!r} lx must be a finite number >= 0",
                             field=f"light {self.name!r}")
        current = self.illuminance_lx
        if not current > 0:
            raise InputError("has no visible light (0 lx): cannot scale it to "
                             f"{target:g} lx", field=f"light {self.name!r}")
        return _make(self.name, self.description, self.irradiance_w_m2_nm * (target / current),
                     self.kind, self.sun)


def _make(name: str, description: str, irradiance: np.ndarray, kind: str = "illuminant",
          sun: SunSource | None = None) -> Light:
    values = np.array(irradiance, dtype=np.float64)
    if values.shape != GRID_NM.shape:
        raise ValueError(f"light {name!r}: spectrum has {values.shape} samples, "
                         f"the grid {GRID_NM.shape}")
    if kind not in LIGHT_KINDS or (kind == "sun") != (sun is not None):
        raise ValueError(f"light {name!r}: kind {kind!r} (one of {', '.join(LIGHT_KINDS)}; "
                         "the sun, and only the sun, has a SunSource)")
    values.setflags(write=False)
    return Light(name, description, values, kind, sun)


def _elevation_from_path(path_km: float) -> float | None:
    """The sun's elevation (deg) for a path through the paper's layer, None where no zenith has it."""
    from catalog.optics.sun.model import zenith_deg_from_path  # noqa: PLC0415

    try:
        return 90.0 - zenith_deg_from_path(path_km)
    except (ValueError, CatalogError):
        return None


def illuminance_lx(irradiance_w_m2_nm: np.ndarray, grid_nm: np.ndarray = GRID_NM) -> float:
    """683 lm/W * sum ybar(l) E(l) dl: illuminance (lx) of a spectral irradiance on ``grid_nm``."""
    from catalog.optics.colorimetry import cmfs  # noqa: PLC0415

    grid_nm = np.asarray(grid_nm, dtype=np.float64)
    step = float(grid_nm[1] - grid_nm[0])
    ybar = cmfs(grid_nm)[:, 1]
    return float(K_M_LM_PER_W * np.sum(ybar * np.asarray(irradiance_w_m2_nm)) * step)


# --------------------------------------------------------------------------------------
# CIE (colour-science) illuminants


@functools.lru_cache(maxsize=1)
def cie_names() -> tuple[str, ...]:
    """Every illuminant name in colour-science's SDS_ILLUMINANTS, in colour's order
    (read from catalog.optics.reference_tables' cache: no colour import at run time)."""
    return reference_tables.illuminant_names()


def _is_daylight(name: str) -> bool:
    """Daylight illuminants (default 10 000 lx): D*, ID*, B, C and the ISO 7589 daylights."""
    return (name.startswith("D") or name.startswith("ID") or name in ("B", "C")
            or (name.startswith("ISO 7589") and "Daylight" in name))


def cie_relative(name: str) -> tuple[np.ndarray, float, float]:
    """colour-science's table for ``name`` on GRID_NM (linear, 0 outside), and its range (nm)."""
    wl, values = reference_tables.illuminant_table(name)
    on_grid = np.interp(GRID_NM, wl, values, left=0.0, right=0.0)
    return on_grid, float(wl[0]), float(wl[-1])


def _cie_light(name: str) -> Light:
    relative, first_nm, last_nm = cie_relative(name)
    level = DAYLIGHT_LX if _is_daylight(name) else LAMP_LX
    kind = "daylight illuminant" if _is_daylight(name) else "illuminant"
    if first_nm > GRID_NM[0]:
        coverage = (f"tabulated {first_nm:g}-{last_nm:g} nm, zero below {first_nm:g} nm "
                    f"(no data there, so no UV)")
    else:
        coverage = f"tabulated from {first_nm:g} nm"
    description = (f"colour-science {kind} {name} ({coverage}; linear interpolation), "
                   f"scaled to {level:,.0f} lx")
    relative_lx = illuminance_lx(relative)
    return _make(name, description, relative * (level / relative_lx))


# --------------------------------------------------------------------------------------
# Our own lamps


def _gaussian(center_nm: float, fwhm_nm: float, grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """A Gaussian line of unit area (per nm) at ``center_nm`` with full width ``fwhm_nm``."""
    sigma = fwhm_nm / (2.0 * math.sqrt(2.0 * math.log(2.0)))
    return np.exp(-0.5 * ((grid_nm - center_nm) / sigma) ** 2) / (sigma * math.sqrt(2 * math.pi))


#: UV-A lamp: (centre nm, FWHM nm, fraction of the radiant power). A blacklight-blue lamp:
#: the 365 nm band (10 nm FWHM, as 365 nm LEDs and filtered mercury lamps give) and the
#: visible mercury lines its Wood's-glass envelope leaks, 404.7 nm and 435.8 nm, drawn 2 nm
#: wide. The leak fractions are illustrative (a real BLB tube glows faintly violet), not
#: measured.
UVA_LINES = ((365.0, 10.0, 0.985), (404.7, 2.0, 0.012), (435.8, 2.0, 0.003))


def uva_lamp_relative(grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """Relative spectrum of the UV-A lamp (integrates to 1 W m^-2 over the grid)."""
    spectrum = sum(frac * _gaussian(c, w, grid_nm) for c, w, frac in UVA_LINES)
    return spectrum / (np.sum(spectrum) * (grid_nm[1] - grid_nm[0]))


#: Warm-white LED: an InGaN blue pump and two phosphors, each a Gaussian (centre nm, FWHM nm):
#: a broad yellow-green garnet (YAG:Ce-like) and a red nitride, as warm-white LEDs combine
#: them. The three weights are solved so that the mix has the chromaticity of a Planckian
#: radiator at WARM_LED_CCT_K (Duv 0). Nothing at or below 400 nm: the pump's Gaussian
#: tail there (< 1e-7 of its peak) is cut to exactly zero, as a real LED package has no UV.
WARM_LED_BANDS = ((450.0, 20.0), (555.0, 110.0), (625.0, 90.0))
WARM_LED_CCT_K = 2800.0
WARM_LED_UV_CUTOFF_NM = 400.0


def planck_w_m2_nm(temperature_k: float, grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """Planck's law, spectral radiant exitance shape (arbitrary scale) at ``temperature_k``."""
    c2_m_k = 1.438776877e-2  # second radiation constant h c / k (m K)
    wl_m = np.asarray(grid_nm, dtype=np.float64) * 1e-9
    return wl_m ** -5 / np.expm1(c2_m_k / (wl_m * temperature_k))


def warm_led_relative(grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """Relative spectrum of LED-warm: pump + phosphors mixed to the WARM_LED_CCT_K white."""
    from catalog.optics.colorimetry import spectrum_to_xyz  # noqa: PLC0415

    bands = np.stack([_gaussian(c, w, grid_nm) for c, w in WARM_LED_BANDS])
    bands[:, grid_nm <= WARM_LED_UV_CUTOFF_NM] = 0.0
    band_xyz = spectrum_to_xyz(bands, grid_nm)              # (3 bands, XYZ)
    target_xyz = spectrum_to_xyz(planck_w_m2_nm(WARM_LED_CCT_K, grid_nm), grid_nm)
    weights = np.linalg.solve(band_xyz.T, target_xyz)       # sum_i w_i XYZ_i = XYZ_target
    if np.any(weights <= 0):  # the three bands cannot make that white: a coding error
        raise ValueError(f"LED-warm bands cannot mix to {WARM_LED_CCT_K:g} K: {weights}")
    return weights @ bands


def _uva_light() -> Light:
    description = ("365 nm UV-A blacklight (Gaussian, 10 nm FWHM) with 1.5% leak in the "
                   "mercury lines 404.7 and 435.8 nm (illustrative); "
                   f"{UVA_TOTAL_W_M2:g} W/m2 in all")
    return _make("UV-A", description, uva_lamp_relative() * UVA_TOTAL_W_M2, "uv")


def _warm_led_light() -> Light:
    relative = warm_led_relative()
    description = (f"warm-white LED, {WARM_LED_CCT_K:g} K: 450 nm blue pump + yellow-green "
                   "and red phosphors (Gaussians mixed to the Planckian white), nothing "
                   f"at or below 400 nm; scaled to {LAMP_LX:,.0f} lx")
    return _make("LED-warm", description, relative * (LAMP_LX / illuminance_lx(relative)), "lamp")


#: Narrow-band lamps: name -> (centre nm, FWHM nm, description). One Gaussian band each,
#: 10 W m^-2 in all like UV-A. 385 nm UV LEDs have about 10 nm FWHM, 405 nm violet LEDs
#: (the InGaN pumps of violet-pumped white LEDs and of "UV" torches) about 15 nm.
NARROW_LAMPS = {
    "UV-385": (385.0, 10.0, "385 nm UV LED lamp (Gaussian, 10 nm FWHM)"),
    "LED-405": (405.0, 15.0, "405 nm violet LED (Gaussian, 15 nm FWHM)"),
}
#: The violet-pumped white LED's spectrum, shipped with the package (relative, 1 nm).
VIOLET_WHITE_FILE = "led_violet_white.csv"


def _narrow_lamp(name: str) -> Light:
    centre, fwhm, what = NARROW_LAMPS[name]
    relative = _gaussian(centre, fwhm)
    relative = relative / (np.sum(relative) * _STEP_NM)
    return _make(name, f"{what}; {UVA_TOTAL_W_M2:g} W/m2 in all", relative * UVA_TOTAL_W_M2,
                 "uv" if centre < 400.0 else "lamp")


def violet_white_relative() -> tuple[np.ndarray, str]:
    """LED-violet-white's relative spectrum on GRID_NM and its source line (from the CSV)."""
    from importlib import resources  # noqa: PLC0415

    from catalog.optics.spectra import read_spectrum  # noqa: PLC0415

    ref = resources.files("catalog.optics") / "data" / VIOLET_WHITE_FILE
    with resources.as_file(ref) as path:
        spectrum = read_spectrum(path)
        source = next((ln[1:].strip() for ln in path.read_text().splitlines()
                       if ln.startswith("# source:")), "")
    return spectrum.resample(GRID_NM), source


def _violet_white_light() -> Light:
    relative, source = violet_white_relative()
    description = ("violet-pumped white LED ('full spectrum'): 405 nm pump + blue, green and "
                   f"red phosphors, 4000 K; {source or 'see ' + VIOLET_WHITE_FILE}; scaled to "
                   f"{LAMP_LX:,.0f} lx")
    return _make("LED-violet-white", description,
                 relative * (LAMP_LX / illuminance_lx(relative)), "lamp")


# --------------------------------------------------------------------------------------
# The sun


def _parse_path(name: str, text: str) -> float:
    from catalog.optics.sun.model import check_path_km  # noqa: PLC0415

    try:
        value = float(text)
    except ValueError:
        raise InputError(f"path length {text!r} is not a number of km "
                         f"(write e.g. 'sun:22' or 'sun:500')", field=f"light {name!r}") from None
    try:
        return check_path_km(value, f"light {name!r}")
    except CatalogError as exc:  # its message already names the light
        raise InputError(str(exc)) from None


def _sun_direct_light(name: str, path_km: float) -> Light:
    from catalog.optics.sun.model import direct_beam_w_m2_nm  # noqa: PLC0415

    description = (f"sun, direct beam after {path_km:g} km of Rayleigh scattering through the "
                   "paper's uniform 22 km layer (ASTM G173 extraterrestrial, no ozone, "
                   "aerosol or sky), absolute")
    return _make(name, description, direct_beam_w_m2_nm(path_km), "sun",
                 SunSource("paper", _elevation_from_path(path_km)))


def _sun_clear_light(name: str, path_km: float) -> Light:
    from catalog.optics.sun.model import Atmosphere, clear_sky  # noqa: PLC0415

    atmosphere = Atmosphere()
    try:
        sky = clear_sky(path_km=path_km, atmosphere=atmosphere)
    except CatalogError as exc:
        raise InputError(f"{exc} (sun-clear needs a path the sun can have; 'sun:PATH_KM' "
                         "takes any)", field=f"light {name!r}") from None
    description = (f"clear sky, sun at zenith {sky.zenith_deg:.1f} deg ({path_km:g} km "
                   f"through the 22 km shell): direct + skylight (delta-Eddington) + ground "
                   f"on a plane facing the sun; ozone {atmosphere.ozone_atm_cm:g} atm-cm, aerosol "
                   f"{atmosphere.aod_500nm:g} at 500 nm, absolute")
    return _make(name, description, sky.sun_facing(atmosphere.ground_albedo), "sun",
                 SunSource("clear", _elevation_from_path(path_km)))


def _sun_at_light(name: str, spec: str) -> Light:
    from catalog.optics.sun.model import Atmosphere, clear_sky, sun_position  # noqa: PLC0415

    parts = [p.strip() for p in spec.split(",")]
    if len(parts) not in (2, 3):
        raise InputError("write 'sun@DATE[THH:MM[+HH:MM]],LAT[,LON]', e.g. "
                         "'sun@2026-06-21T12:00,34.7,135.5' (naive time = local mean solar "
                         "time)", field=f"light {name!r}")
    try:
        lat = float(parts[1])
        lon = float(parts[2]) if len(parts) == 3 else 0.0
    except ValueError:
        raise InputError(f"latitude/longitude {parts[1:]} are not numbers (deg)",
                         field=f"light {name!r}") from None
    try:
        position = sun_position(parts[0], lat, lon)
    except CatalogError as exc:
        raise InputError(str(exc), field=f"light {name!r}") from None
    if position.path_km is None:
        raise InputError(f"the sun is below the horizon then (zenith "
                         f"{position.zenith_deg:.1f} deg at {position.when_utc})",
                         field=f"light {name!r}")
    atmosphere = Atmosphere()
    sky = clear_sky(position.zenith_deg, atmosphere=atmosphere,
                    earth_sun_factor=position.earth_sun_factor)
    description = (f"clear sky at {position.when_utc} UTC, {lat:g} N {lon:g} E: zenith "
                   f"{position.zenith_deg:.1f} deg, path {position.path_km:.0f} km; direct + "
                   "skylight (delta-Eddington) + ground on a plane facing the sun, absolute")
    return _make(name, description, sky.sun_facing(atmosphere.ground_albedo), "sun",
                 SunSource("date", 90.0 - position.zenith_deg))


# --------------------------------------------------------------------------------------
# The library


@functools.lru_cache(maxsize=1)
def _own_names() -> tuple[str, ...]:
    return ("UV-A", "UV-385", "LED-405", "LED-warm", "LED-violet-white")


def light_names() -> list[str]:
    """Every light of the library, for menus: CIE tables, our lamps, sun samples."""
    return [*cie_names(), *_own_names(), *SUN_MENU]


@functools.lru_cache(maxsize=256)
def _base_light(name: str) -> Light:
    if name == "UV-A":
        return _uva_light()
    if name == "LED-warm":
        return _warm_led_light()
    if name in NARROW_LAMPS:
        return _narrow_lamp(name)
    if name == "LED-violet-white":
        return _violet_white_light()
    if name.startswith("sun:"):
        return _sun_direct_light(name, _parse_path(name, name[len("sun:"):]))
    if name.startswith("sun-clear:"):
        return _sun_clear_light(name, _parse_path(name, name[len("sun-clear:"):]))
    if name.startswith("sun@"):
        return _sun_at_light(name, name[len("sun@"):])
    canonical = _canonical_cie(name)
    if canonical is not None:
        return _cie_light(canonical)
    close = difflib.get_close_matches(name, light_names(), n=4, cutoff=0.5)
    hint = f"; close names: {', '.join(close)}" if close else ""
    raise InputError(f"unknown light{hint} (`catalog lights` lists them all; the sun is "
                     "'sun:PATH_KM', 'sun-clear:PATH_KM' or 'sun@DATE,LAT,LON')",
                     field=f"light {name!r}")


def _canonical_cie(name: str) -> str | None:
    names = cie_names()
    if name in names:
        return name
    folded = {n.casefold(): n for n in names}
    return folded.get(name.casefold())


def get_light(name: str, illuminance_lx: float | None = None) -> Light:
    """The light called ``name`` (see the module docstring), at its default absolute level,
    or rescaled to ``illuminance_lx`` (lx) when given. Unknown names raise InputError.
    """
    if not isinstance(name, str) or not name.strip():
        raise InputError("empty light name (`catalog lights` lists them)", field="light")
    light = _base_light(name.strip())
    if illuminance_lx is not None:
        light = light.scaled_to(illuminance_lx)
    return light
