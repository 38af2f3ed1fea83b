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
table of Bird & Riordan (1986, after Leckner 1978) that pvlib's SPECTRL2 carries; both tables
are read from the cache of :mod:`catalog.optics.reference_tables`. pvlib and pandas are imported
lazily, only for a date and time (solar position) and the SPECTRL2 comparison.

All spectra are on :data:`catalog.optics.spectra.GRID_NM` (300-780 nm, 1 nm) in W m^-2 nm^-1.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from catalog.optics import reference_tables
from catalog.core.errors import CatalogError
from catalog.optics.spectra import GRID_NM

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


def _g173_extraterrestrial() -> tuple[np.ndarray, np.ndarray]:
    """ASTM G173-03 extraterrestrial spectrum (280-4000 nm, W m^-2 nm^-1) as pvlib ships it,
    read from catalog.optics.reference_tables' cache (no pvlib/pandas import at run time)."""
    return reference_tables.g173_extraterrestrial()


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


def check_path_km(path_km: float, what: str = "light 'sun'") -> float:
    """Refuse a path length outside [MIN_PATH_KM, MAX_PATH_KM]; the message starts with
    ``what`` (the light or the option that gave the path)."""
    try:
        value = float(path_km)
    except (TypeError, ValueError):
        raise CatalogError(f"{what}: path length {path_km!r} is not a number "
                           f"(km)") from None
    if not math.isfinite(value) or not MIN_PATH_KM <= value <= MAX_PATH_KM:
        raise CatalogError(f"{what}: path length {path_km!r} km is outside "
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


# --------------------------------------------------------------------------------------
# Beyond the paper: a clear sky (ozone, aerosol, skylight)


@dataclass(frozen=True)
class Atmosphere:
    """A clear, cloudless atmosphere. Defaults: the ASTM G173-03 reference atmosphere
    (ozone 0.3438 atm-cm, aerosol optical depth 0.084 at 500 nm), rural aerosol after Bird &
    Riordan (Angstrom exponent 1.14, single-scattering albedo 0.945, asymmetry 0.65), sea
    level, ground albedo 0.2 (grass, soil). Water vapour and O2 are not modelled: their bands
    in 300-780 nm are narrow lines at 590, 690-730 and 760 nm.
    """

    ozone_atm_cm: float = 0.3438
    aod_500nm: float = 0.084
    angstrom_alpha: float = 1.14
    aerosol_albedo: float = 0.945
    aerosol_asymmetry: float = 0.65
    pressure_hpa: float = 1013.25
    ground_albedo: float = 0.2
    #: Height of the ozone layer (km): its slant factor is that of a thin shell there.
    ozone_height_km: float = 22.0

    def __post_init__(self):
        checks = {"ozone_atm_cm": (0.0, 1.0), "aod_500nm": (0.0, 5.0),
                  "angstrom_alpha": (-1.0, 4.0), "aerosol_albedo": (0.0, 1.0),
                  "aerosol_asymmetry": (-0.95, 0.95), "pressure_hpa": (1.0, 1100.0),
                  "ground_albedo": (0.0, 0.99), "ozone_height_km": (1.0, 60.0)}
        for field_name, (low, high) in checks.items():
            value = getattr(self, field_name)
            if not (math.isfinite(value) and low <= value <= high):
                raise CatalogError(f"atmosphere: {field_name} = {value!r} is outside "
                                   f"{low:g}-{high:g}")


def _ozone_table() -> tuple[np.ndarray, np.ndarray]:
    """Ozone absorption coefficients (per atm-cm) of Bird & Riordan (1986) after Leckner (1978),
    as pvlib's SPECTRL2 carries them (Huggins band below 350 nm, Chappuis 450-780 nm); read
    from catalog.optics.reference_tables' cache."""
    return reference_tables.ozone_table()


def ozone_absorption_per_atm_cm(wavelength_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """k_O3(l) (1/atm-cm): vertical ozone optical depth = k_O3 * ozone column (atm-cm).

    The table is 5-10 nm apart; the Huggins band falls by ~2x every 5 nm, so it is
    interpolated in log k where both neighbours are positive, linearly elsewhere.
    """
    wl_table, k_table = _ozone_table()
    wl = np.asarray(wavelength_nm, dtype=np.float64)
    linear = np.interp(wl, wl_table, k_table)
    positive = k_table > 0
    with np.errstate(divide="ignore"):
        log_k = np.where(positive, np.log(np.where(positive, k_table, 1.0)), -np.inf)
    log_interp = np.exp(np.interp(wl, wl_table, log_k))
    # log interpolation only between two positive entries (else the -inf pulls it to 0)
    idx = np.clip(np.searchsorted(wl_table, wl), 1, wl_table.size - 1)
    both_positive = positive[idx] & positive[idx - 1]
    return np.where(both_positive, log_interp, linear)


def aerosol_optical_depth(atmosphere: Atmosphere,
                          wavelength_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """Angstrom's law: tau_a(l) = tau_a(500 nm) * (l / 500 nm)^-alpha (vertical)."""
    wl = np.asarray(wavelength_nm, dtype=np.float64)
    return atmosphere.aod_500nm * (wl / 500.0) ** (-atmosphere.angstrom_alpha)


def relative_airmass_kasten_young(zenith_deg: float) -> float:
    """Kasten & Young (1989): m = 1 / (cos z + 0.50572 (96.07995 - z)^-1.6364), z in deg.

    The air mass of the real, exponentially thinning atmosphere (38 at the horizon); used
    for the aerosol, which sits in the lowest kilometres.
    """
    z = float(zenith_deg)
    return 1.0 / (math.cos(math.radians(z)) + 0.50572 * (96.07995 - z) ** -1.6364)


def ozone_slant_factor(zenith_deg: float, height_km: float = 22.0,
                       earth_radius_km: float = EARTH_RADIUS_KM) -> float:
    """Slant factor of a thin layer at ``height_km``: 1 / cos z', sin z' = R sin z / (R + h)."""
    s = earth_radius_km / (earth_radius_km + height_km) * math.sin(math.radians(zenith_deg))
    return 1.0 / math.sqrt(1.0 - s * s)


@functools.lru_cache(maxsize=64)
def hg_downward_fraction(cos_zenith: float, g: float, nodes: int = 48) -> float:
    """Fraction of light scattered by a Henyey-Greenstein particle (eq. 6) that goes down,
    for a beam travelling down at ``cos_zenith`` to the vertical.

    Integral of the phase function over the lower hemisphere (Gauss-Legendre in the cosine,
    uniform in azimuth). 0.5 for g = 0 at any zenith (Rayleigh's phase function is also
    symmetric, so its downward fraction is exactly 0.5); -> 1 as g -> 1 for an overhead sun.
    """
    from catalog.optics.btdf import hg_phase  # noqa: PLC0415  (eq. 6, one copy in the project)

    mu0 = float(cos_zenith)
    x, w = np.polynomial.legendre.leggauss(nodes)
    mu = 0.5 * (x + 1.0)                       # downward direction cosines in (0, 1)
    w_mu = 0.5 * w
    phi = (np.arange(4 * nodes) + 0.5) * (2.0 * math.pi / (4 * nodes))
    sin0 = math.sqrt(max(0.0, 1.0 - mu0 * mu0))
    cos_theta = mu0 * mu[:, None] + sin0 * np.sqrt(1.0 - mu[:, None] ** 2) * np.cos(phi)[None, :]
    integrand = hg_phase(np.clip(cos_theta, -1.0, 1.0), g)
    return float(np.sum(w_mu[:, None] * integrand) * (2.0 * math.pi / (4 * nodes)))


#: Diffusivity factor: the mean slant of diffuse light through a plane layer (Elsasser).
DIFFUSIVITY = 1.66


def eddington_layer(tau, omega, g, mu0, ground_albedo):
    """Delta-Eddington two-stream solution for one homogeneous layer lit by a beam.

    Joseph, Wiscombe & Weinman (1976), "The delta-Eddington approximation for radiative flux
    transfer", J. Atmos. Sci. 33, 2452: the intensity is I0 + mu I1 (Eddington), the phase
    function's forward peak (fraction g^2) is put back into the beam (delta scaling). Inputs
    broadcast (one value per wavelength): vertical optical depth ``tau``, single-scattering
    albedo ``omega``, asymmetry ``g``, beam cosine ``mu0``, Lambertian ``ground_albedo``.

    Returns (diffuse down at the ground, diffuse up at the top), both per unit beam flux
    through a surface normal to the beam, so the beam brings ``mu0`` per unit horizontal area.
    Without absorption (omega = 1, albedo 0) up + diffuse down + direct mu0 e^(-tau/mu0)
    = mu0: nothing is created or lost.
    """
    tau, omega, g, mu0 = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                               for x in (tau, omega, g, mu0)))
    # delta scaling: the forward peak f = g^2 goes back into the beam
    f = g * g
    tau_s = (1.0 - omega * f) * tau
    omega_s = (1.0 - f) * omega / (1.0 - omega * f)
    g_s = g / (1.0 + g)
    # omega = 1 exactly makes k = 0 (a double root): a 1e-9 absorption changes nothing
    # measurable and keeps the exponential solution
    omega_s = np.minimum(omega_s, 1.0 - 1e-9)
    k = np.sqrt(3.0 * (1.0 - omega_s) * (1.0 - omega_s * g_s))
    p = k / (1.0 - omega_s * g_s)
    # k mu0 = 1 is a removable singularity of the particular solution: step off it
    mu0 = np.where(np.abs(1.0 - (k * mu0) ** 2) < 1e-6, mu0 * (1.0 + 1e-4), mu0)
    f0 = 1.0 / math.pi  # beam flux pi F0 = 1
    # particular solution I0 = -a e^(-t/mu0), I1 = -b e^(-t/mu0) of
    # dI1/dt = 3 (1 - w) I0 - 3/4 w F0 e^(-t/mu0),  dI0/dt = (1 - w g) I1 + 3/4 w g mu0 F0 e^(-t/mu0)
    a = 0.75 * omega_s * f0 * mu0 ** 2 * (1.0 + g_s - omega_s * g_s) / (1.0 - (k * mu0) ** 2)
    b = -3.0 * (1.0 - omega_s) * mu0 * a - 0.75 * omega_s * f0 * mu0
    e_k = np.exp(-k * tau_s)
    e_beam = np.exp(-tau_s / mu0)
    q = 2.0 * p / 3.0
    alb = np.asarray(ground_albedo, dtype=np.float64)
    # homogeneous part C1 e^(-kt) + C2 e^(k(t - tau)); fluxes pi (I0 -+ 2/3 I1)
    # top: no diffuse light comes down; ground: up = albedo * (diffuse down + beam)
    m11, m12 = 1.0 + q, e_k * (1.0 - q)
    m21, m22 = e_k * ((1.0 - q) - alb * (1.0 + q)), (1.0 + q) - alb * (1.0 - q)
    r1 = a - 2.0 * b / 3.0
    r2 = (alb * mu0 * f0 + (a + 2.0 * b / 3.0) - alb * (a - 2.0 * b / 3.0)) * e_beam
    det = m11 * m22 - m12 * m21
    c1 = (r1 * m22 - m12 * r2) / det
    c2 = (m11 * r2 - m21 * r1) / det
    i0_ground = c1 * e_k + c2 - a * e_beam
    i1_ground = -p * (c1 * e_k - c2) - b * e_beam
    i0_top = c1 + c2 * e_k - a
    i1_top = -p * (c1 - c2 * e_k) - b
    down_scaled = math.pi * (i0_ground - 2.0 * i1_ground / 3.0)
    up_top = math.pi * (i0_top + 2.0 * i1_top / 3.0)
    # the scaled beam still carries the forward peak: hand it back to the diffuse light
    forward_peak = mu0 * (e_beam - np.exp(-tau / mu0))
    return down_scaled + forward_peak, up_top


def _single_scattering_diffuse(slant_r, slant_a, cos_z, atm):
    """Diffuse horizontal per unit beam flux, single scattering in a mixed layer, plus one
    ground-sky bounce series (the "single" method of :func:`clear_sky`)."""
    slant_ext = slant_r + slant_a
    f_aer_down = hg_downward_fraction(round(cos_z, 6), atm.aerosol_asymmetry)
    down_scat = 0.5 * slant_r + f_aer_down * atm.aerosol_albedo * slant_a
    diffuse_sky = cos_z * -np.expm1(-slant_ext) * down_scat / slant_ext
    return diffuse_sky


def _sky_albedo_single(tau_r, tau_a, atm):
    """The sky's reflectance for light going up from the ground (single scattering at the
    diffusivity slant 1.66, the HG part scattered back down)."""
    f_back = 1.0 - hg_downward_fraction(round(1.0 / DIFFUSIVITY, 6), atm.aerosol_asymmetry)
    diff_r = DIFFUSIVITY * tau_r
    diff_a = DIFFUSIVITY * tau_a
    diff_ext = diff_r + diff_a
    return -np.expm1(-diff_ext) * (0.5 * diff_r + f_back * atm.aerosol_albedo * diff_a) / diff_ext


#: Skylight methods of :func:`clear_sky`.
DIFFUSE_METHODS = ("delta-eddington", "single")


@dataclass(frozen=True, eq=False)
class ClearSky:
    """Clear-sky spectra on ``wavelength_nm`` (W m^-2 nm^-1)."""

    wavelength_nm: np.ndarray
    zenith_deg: float
    path_km: float
    direct_normal: np.ndarray
    diffuse_horizontal: np.ndarray
    extraterrestrial: np.ndarray

    @property
    def cos_zenith(self) -> float:
        return math.cos(math.radians(self.zenith_deg))

    @property
    def global_horizontal(self) -> np.ndarray:
        return self.direct_normal * self.cos_zenith + self.diffuse_horizontal

    def sun_facing(self, ground_albedo: float) -> np.ndarray:
        """Global irradiance on a plane facing the sun (tilted by the zenith angle): the
        direct beam at normal incidence, the isotropic sky it sees ((1 + cos z) / 2) and
        the ground it sees ((1 - cos z) / 2 of the ground's reflected global)."""
        tilt_cos = self.cos_zenith
        return (self.direct_normal + self.diffuse_horizontal * (1.0 + tilt_cos) / 2.0
                + ground_albedo * self.global_horizontal * (1.0 - tilt_cos) / 2.0)


def clear_sky(zenith_deg: float | None = None, *, path_km: float | None = None,
              atmosphere: Atmosphere = Atmosphere(), earth_sun_factor: float = 1.0,
              diffuse_method: str = "delta-eddington",
              grid_nm: np.ndarray = GRID_NM) -> ClearSky:
    """Direct and diffuse clear-sky spectra for a solar zenith (or a path in the 22 km shell).

    Direct normal (Beer-Lambert along the slant paths of each constituent)::

        E_dn = f E0 exp(-tau_R L/22 km - k_O3 U m_O3 - tau_a m_a)

    with the paper's Rayleigh path L (shell geometry), the ozone column U through a thin
    shell at 22 km, the aerosol along the Kasten-Young air mass m_a, f the Earth-Sun
    distance factor (1 at 1 AU).

    Diffuse horizontal: the ozone (stratospheric, above the scatterers) dims the beam
    first; below it one homogeneous layer of air and aerosol (vertical optical depth
    tau_R + tau_a, single-scattering albedo (tau_R + w_a tau_a) / tau, asymmetry
    w_a tau_a g_a / (tau_R + w_a tau_a): Rayleigh's phase function has g = 0) over a
    Lambertian ground scatters it. ``diffuse_method``:

    - ``"delta-eddington"`` (default): :func:`eddington_layer`, multiple scattering and the
      ground-sky bounces included. The beam enters at the effective cosine
      mu = tau / (tau_R L/22 + tau_a m_a), the slant the shell gives it, so the sky stays
      lit at sunset as a spherical atmosphere's does (pseudo-spherical);
    - ``"single"``: single scattering in the mixed layer (half of the Rayleigh-scattered
      light and the downward part of the aerosol's HG phase function reach the ground,
      :func:`hg_downward_fraction`), and the ground-sky series
      E_g = (E_dn cos z + E_d) rho_g rho_s / (1 - rho_g rho_s). Too bright in the UV,
      where the sky is optically thick; kept for comparison.
    """
    if (zenith_deg is None) == (path_km is None):
        raise CatalogError("clear_sky: give exactly one of zenith_deg and path_km")
    if diffuse_method not in DIFFUSE_METHODS:
        raise CatalogError(f"clear_sky: diffuse_method {diffuse_method!r} is not one of "
                           f"{', '.join(DIFFUSE_METHODS)}")
    if path_km is not None:
        path_km = float(path_km)
        zenith_deg = zenith_deg_from_path(path_km)
    else:
        zenith_deg = float(zenith_deg)
        path_km = path_km_from_zenith(zenith_deg)
    grid = np.asarray(grid_nm, dtype=np.float64)
    cos_z = math.cos(math.radians(zenith_deg))
    atm = atmosphere
    e0 = extraterrestrial_w_m2_nm(grid) * float(earth_sun_factor)

    tau_r = rayleigh_optical_depth(grid) * (atm.pressure_hpa / 1013.25)  # vertical
    tau_o3 = ozone_absorption_per_atm_cm(grid) * atm.ozone_atm_cm        # vertical
    tau_a = aerosol_optical_depth(atm, grid)                             # vertical
    slant_r = tau_r * (path_km / LAYER_KM)
    slant_a = tau_a * relative_airmass_kasten_young(zenith_deg)
    beam_top = e0 * np.exp(-tau_o3 * ozone_slant_factor(zenith_deg, atm.ozone_height_km))
    direct_normal = beam_top * np.exp(-(slant_r + slant_a))

    if diffuse_method == "delta-eddington":
        tau = tau_r + tau_a
        scattering = tau_r + atm.aerosol_albedo * tau_a
        mu_eff = tau / (slant_r + slant_a)
        down, _ = eddington_layer(tau, scattering / tau,
                                  atm.aerosol_albedo * tau_a * atm.aerosol_asymmetry / scattering,
                                  mu_eff, atm.ground_albedo)
        diffuse = beam_top * down
    else:
        diffuse_sky = beam_top * _single_scattering_diffuse(slant_r, slant_a, cos_z, atm)
        rho = atm.ground_albedo * _sky_albedo_single(tau_r, tau_a, atm)
        diffuse = diffuse_sky + (direct_normal * cos_z + diffuse_sky) * rho / (1.0 - rho)
    return ClearSky(grid, zenith_deg, path_km, direct_normal, diffuse, e0)


# --------------------------------------------------------------------------------------
# Date, time and place -> zenith


def solar_declination_and_equation_of_time(day_of_year: int) -> tuple[float, float]:
    """Spencer (1971), "Fourier series representation of the position of the sun": the
    declination (rad) and the equation of time (minutes) for a day of the year."""
    g = 2 * math.pi * (day_of_year - 1) / 365.0
    declination = (0.006918 - 0.399912 * math.cos(g) + 0.070257 * math.sin(g)
                   - 0.006758 * math.cos(2 * g) + 0.000907 * math.sin(2 * g)
                   - 0.002697 * math.cos(3 * g) + 0.00148 * math.sin(3 * g))
    equation_of_time_min = 229.18 * (0.000075 + 0.001868 * math.cos(g) - 0.032077 * math.sin(g)
                                     - 0.014615 * math.cos(2 * g) - 0.040849 * math.sin(2 * g))
    return declination, equation_of_time_min


def solar_zenith_deg_at_solar_time(hour: float, day_of_year: int, latitude_deg: float) -> float:
    """Geometric solar zenith (deg) at ``hour`` of local mean solar time: hour angle from the
    apparent solar time (mean time + equation of time), cos z = sin(phi) sin(delta) +
    cos(phi) cos(delta) cos(h). Within a few tenths of a degree of pvlib's NREL SPA above
    the horizon (tests/test_render_scene.py checks it), without importing pvlib and scipy,
    which drawing a frame must not."""
    declination, eot_min = solar_declination_and_equation_of_time(day_of_year)
    hour_angle = math.radians(15.0 * (hour + eot_min / 60.0 - 12.0))
    lat = math.radians(latitude_deg)
    cos_z = (math.sin(lat) * math.sin(declination)
             + math.cos(lat) * math.cos(declination) * math.cos(hour_angle))
    return math.degrees(math.acos(max(-1.0, min(1.0, cos_z))))


def solar_zenith_deg(when, latitude_deg: float, longitude_deg: float = 0.0) -> float:
    """Apparent (refracted) solar zenith (deg) at ``when`` (an aware datetime, or a naive one
    read as UTC) and the place (latitude north, longitude east, deg), by pvlib's NREL SPA."""
    import pandas as pd  # noqa: PLC0415
    from pvlib.solarposition import get_solarposition  # noqa: PLC0415

    stamp = pd.Timestamp(when)
    stamp = stamp.tz_localize("UTC") if stamp.tzinfo is None else stamp.tz_convert("UTC")
    position = get_solarposition(pd.DatetimeIndex([stamp]), float(latitude_deg),
                                 float(longitude_deg))
    return float(position["apparent_zenith"].iloc[0])


def earth_sun_factor(when) -> float:
    """(1 AU / Earth-Sun distance)^2 on the date of ``when`` (Spencer 1971, via pvlib)."""
    import pandas as pd  # noqa: PLC0415
    from pvlib.irradiance import get_extra_radiation  # noqa: PLC0415

    return float(get_extra_radiation(pd.Timestamp(when).day_of_year, method="spencer",
                                     solar_constant=1.0))


def parse_when(text: str, longitude_deg: float = 0.0):
    """An ISO date-time -> an aware UTC ``pandas.Timestamp``.

    With an offset (``2026-06-21T12:00+09:00``, ``...Z``) the time is taken as written. A
    naive time is local mean solar time at ``longitude_deg`` (UTC + longitude / 15 h), so
    ``T12:00`` is about noon wherever you are (within the equation of time, +-16 min). A date
    alone means 12:00.
    """
    import pandas as pd  # noqa: PLC0415

    text = str(text).strip()
    if not text[:4].isdigit():  # pandas would also take "now" and "today": not reproducible
        raise CatalogError(f"date-time {text!r} is not ISO 8601 "
                           "(e.g. 2026-06-21T12:00 or 2026-06-21T12:00+09:00)")
    try:
        stamp = pd.Timestamp(text)
    except (ValueError, TypeError):
        raise CatalogError(f"date-time {text!r} is not ISO 8601 "
                           "(e.g. 2026-06-21T12:00 or 2026-06-21T12:00+09:00)") from None
    if stamp is pd.NaT:
        raise CatalogError(f"date-time {text!r} is empty")
    if "T" not in text and " " not in text:
        stamp = stamp + pd.Timedelta(hours=12)
    if stamp.tzinfo is None:
        stamp = (stamp - pd.Timedelta(hours=float(longitude_deg) / 15.0)).tz_localize("UTC")
    return stamp.tz_convert("UTC")


def check_place(latitude_deg: float, longitude_deg: float) -> tuple[float, float]:
    """Refuse a latitude outside [-90, 90] or a longitude outside [-180, 360] deg."""
    lat, lon = float(latitude_deg), float(longitude_deg)
    if not (math.isfinite(lat) and -90.0 <= lat <= 90.0):
        raise CatalogError(f"latitude {latitude_deg!r} deg is outside -90..90")
    if not (math.isfinite(lon) and -180.0 <= lon <= 360.0):
        raise CatalogError(f"longitude {longitude_deg!r} deg is outside -180..360")
    return lat, lon


@dataclass(frozen=True)
class SunPosition:
    """Where the sun is for a date, time and place, and the path that gives."""

    when_utc: str
    latitude_deg: float
    longitude_deg: float
    zenith_deg: float
    path_km: float | None  # None when the sun is below the horizon
    earth_sun_factor: float


def sun_position(when_text: str, latitude_deg: float, longitude_deg: float = 0.0) -> SunPosition:
    """Date-time text (see :func:`parse_when`) and place -> zenith and shell path."""
    lat, lon = check_place(latitude_deg, longitude_deg)
    stamp = parse_when(when_text, lon)
    zenith = solar_zenith_deg(stamp, lat, lon)
    path = path_km_from_zenith(zenith) if zenith <= 90.0 else None
    return SunPosition(stamp.isoformat(), lat, lon, zenith, path, earth_sun_factor(stamp))
