"""The clear sky seen through the window (issue 13): radiance by direction, consistent with
the project's sun and atmosphere (:mod:`catalog.optics.sun.model`).

- Angular distribution and chromaticity: Preetham, Shirley & Smits 1999, "A practical
  analytic model for daylight" (the Perez et al. 1993 all-weather function
  F(theta, gamma) = (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2 gamma) for
  Y, x and y, coefficients linear in the turbidity T; zenith values from their appendix).
- Turbidity: from the atmosphere's aerosol, T = (beta + 0.04586) / 0.04608 (Preetham's
  appendix), beta = AOD(500 nm) 0.5^alpha the Angstrom coefficient at 1 um; held in the
  model's range 2..10.
- Scale and spectrum: the diffuse horizontal irradiance of :func:`catalog.optics.sun.model.clear_sky`
  for the same sun zenith (the same path length, ozone, aerosol and ground): the sky's
  radiance integrated with cos(theta) over the upper hemisphere equals it, channel by
  channel of linear sRGB (the Preetham colour only redistributes it over the sky).
- Below the horizon: the ground (albedo of the atmosphere, lit by the global horizontal
  irradiance, Lambertian), seen through the haze of the horizon: the radiance blends from
  the horizon's sky to the ground over HAZE_RAD of depression, so there is no seam.

No GL here; shaders/background.frag evaluates the same functions per pixel (the
``SKY_MODEL`` variant) and tests/test_render_sky.py compares the two.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

#: Depression (rad) over which the ground fades in from the horizon's sky (haze).
HAZE_RAD = 0.06
#: Preetham's turbidity range.
TURBIDITY_RANGE = (2.0, 10.0)
#: Below this cos(theta) the Perez gradation term is evaluated at the horizon's value.
MIN_COS_THETA = 0.01

# Preetham et al. 1999, appendix: Perez coefficients (A..E) as a T + b for Y, x, y.
_PEREZ_Y = ((0.1787, -1.4630), (-0.3554, 0.4275), (-0.0227, 5.3251), (0.1206, -2.5771), (-0.0670, 0.3703))
_PEREZ_X = ((-0.0193, -0.2592), (-0.0665, 0.0008), (-0.0004, 0.2125), (-0.0641, -0.8989), (-0.0033, 0.0452))
_PEREZ_YC = ((-0.0167, -0.2608), (-0.0950, 0.0092), (-0.0079, 0.2102), (-0.0441, -1.6537), (-0.0109, 0.0529))


def turbidity_from_atmosphere(atmosphere=None) -> float:
    """Preetham's turbidity T of a :class:`catalog.optics.sun.model.Atmosphere` (default: the project's)."""
    from catalog.optics.sun.model import Atmosphere  # noqa: PLC0415

    atm = atmosphere if atmosphere is not None else Atmosphere()
    beta = atm.aod_500nm * 0.5 ** atm.angstrom_alpha
    t = (beta + 0.04586) / 0.04608
    return float(min(max(t, TURBIDITY_RANGE[0]), TURBIDITY_RANGE[1]))


def perez_coefficients(turbidity: float) -> np.ndarray:
    """(5, 3): A..E for x, y, Y (the order of :func:`zenith_xyY`)."""
    t = float(turbidity)
    return np.array([[a * t + b for a, b in (px, pyc, py)]
                     for py, px, pyc in zip(_PEREZ_Y, _PEREZ_X, _PEREZ_YC)])


def zenith_xyY(turbidity: float, sun_zenith_rad: float) -> np.ndarray:
    """Zenith chromaticity x, y and luminance Y (cd m^-2) after Preetham's appendix."""
    t, s = float(turbidity), float(sun_zenith_rad)
    chi = (4.0 / 9.0 - t / 120.0) * (math.pi - 2.0 * s)
    y_lum = ((4.0453 * t - 4.9710) * math.tan(chi) - 0.2155 * t + 2.4192) * 1000.0
    s2, s3 = s * s, s * s * s
    x = (t * t * (0.00166 * s3 - 0.00375 * s2 + 0.00209 * s)
         + t * (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * s + 0.00394)
         + (0.11693 * s3 - 0.21196 * s2 + 0.06052 * s + 0.25886))
    y = (t * t * (0.00275 * s3 - 0.00610 * s2 + 0.00317 * s)
         + t * (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * s + 0.00516)
         + (0.15346 * s3 - 0.26756 * s2 + 0.06670 * s + 0.26688))
    return np.array([x, y, max(y_lum, 0.0)])


def _perez(coefficients: np.ndarray, cos_theta, gamma) -> np.ndarray:
    a, b, c, d, e = coefficients
    cos_theta = np.maximum(np.asarray(cos_theta, dtype=np.float64)[..., None], MIN_COS_THETA)
    gamma = np.asarray(gamma, dtype=np.float64)[..., None]
    return (1.0 + a * np.exp(b / cos_theta)) * (1.0 + c * np.exp(d * gamma) + e * np.cos(gamma) ** 2)


def preetham_rgb(directions: np.ndarray, to_sun: np.ndarray, turbidity: float) -> np.ndarray:
    """Preetham's sky as linear sRGB (cd m^-2) for unit directions (..., 3), y up; directions
    below the horizon get the horizon's value."""
    from catalog.optics.colorimetry import xyz_to_linear_srgb  # noqa: PLC0415

    xyy = preetham_xyY(directions, to_sun, turbidity)
    x, y, lum = xyy[..., 0], xyy[..., 1], xyy[..., 2]
    xyz = np.stack([x * lum / y, lum, (1.0 - x - y) * lum / y], axis=-1)
    return xyz_to_linear_srgb(xyz)


@functools.lru_cache(maxsize=64)
def _hemisphere_grid(n_theta: int = 96, n_phi: int = 192) -> tuple[np.ndarray, np.ndarray]:
    """Midpoint directions over the upper hemisphere and their cos(theta) d(omega) weights."""
    theta = (np.arange(n_theta) + 0.5) * (math.pi / 2) / n_theta
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    dirs = np.stack([np.sin(tt) * np.cos(pp), np.cos(tt), np.sin(tt) * np.sin(pp)], axis=-1)
    weights = np.cos(tt) * np.sin(tt) * (math.pi / 2 / n_theta) * (2 * math.pi / n_phi)
    return dirs, weights


def horizontal_irradiance_rgb(radiance_of, n_theta: int = 96) -> np.ndarray:
    """Integral of radiance_of(directions) cos(theta) over the upper hemisphere (midpoint rule)."""
    dirs, weights = _hemisphere_grid(n_theta, 2 * n_theta)
    return np.tensordot(weights, radiance_of(dirs), axes=([0, 1], [0, 1]))


@dataclass(frozen=True)
class SkyModel:
    """What background.frag needs (all linear sRGB, cd m^-2 scale)."""

    turbidity: float
    to_sun: np.ndarray
    perez: np.ndarray          # (5, 3) A..E for x, y, Y
    zenith: np.ndarray         # x, y, Y at the zenith
    perez_sun: np.ndarray      # F(0, theta_s) for x, y, Y
    scale_rgb: np.ndarray      # per channel: clear_sky diffuse / Preetham's horizontal irradiance
    ground_rgb: np.ndarray     # the ground's radiance

    def radiance(self, directions: np.ndarray) -> np.ndarray:
        """The sky (and the hazy ground below the horizon) by direction, linear sRGB."""
        d = np.asarray(directions, dtype=np.float64)
        horizon = d.copy()
        horizon[..., 1] = np.maximum(horizon[..., 1], 0.0)
        horizon /= np.maximum(np.linalg.norm(horizon, axis=-1, keepdims=True), 1e-12)
        sky = self.scale_rgb * preetham_rgb(horizon, self.to_sun, self.turbidity)
        depression = np.arcsin(np.clip(-d[..., 1], 0.0, 1.0))
        fade = np.exp(-depression / HAZE_RAD)[..., None]
        return np.where(d[..., 1:2] >= 0.0, sky, fade * sky + (1.0 - fade) * self.ground_rgb)


def sky_model(to_sun: np.ndarray, atmosphere=None, diffuse_horizontal=None,
              ground_radiance=None) -> SkyModel:
    """The clear sky for a sun direction (y up), scaled to :func:`catalog.optics.sun.model.clear_sky`
    or, given, to ``diffuse_horizontal`` (W m^-2 nm^-1 on the grid: the light's own sky), with
    the ground ``ground_radiance`` (W m^-2 sr^-1 nm^-1) instead of the atmosphere's."""
    from catalog.optics.shading_reference import spectral_to_linear_srgb as spectrum_to_display_rgb  # noqa: PLC0415
    from catalog.optics.sun.model import Atmosphere, clear_sky  # noqa: PLC0415

    atm = atmosphere if atmosphere is not None else Atmosphere()
    to_sun = np.asarray(to_sun, dtype=np.float64) / np.linalg.norm(to_sun)
    zenith_deg = math.degrees(math.acos(max(min(to_sun[1], 1.0), -1.0)))
    zenith_deg = min(zenith_deg, 89.5)
    turbidity = turbidity_from_atmosphere(atm)
    sky = clear_sky(zenith_deg, atmosphere=atm)
    target = spectrum_to_display_rgb(sky.diffuse_horizontal if diffuse_horizontal is None
                                     else np.asarray(diffuse_horizontal, dtype=np.float64))
    preetham = horizontal_irradiance_rgb(lambda d: preetham_rgb(d, to_sun, turbidity))
    scale = target / np.where(np.abs(preetham) > 0, preetham, 1.0)
    ground = spectrum_to_display_rgb(atm.ground_albedo * sky.global_horizontal / math.pi
                                     if ground_radiance is None
                                     else np.asarray(ground_radiance, dtype=np.float64))
    sun_zenith = math.radians(zenith_deg)
    perez = perez_coefficients(turbidity)
    perez_sun = _perez(perez, math.cos(sun_zenith), sun_zenith)
    return SkyModel(turbidity, to_sun, perez, zenith_xyY(turbidity, sun_zenith), perez_sun,
                    scale, ground)


# ---- The sky per band (issue 13): Preetham's spectral reconstruction -----------------------
# The chromaticity x, y of a direction selects a CIE daylight spectrum S0 + M1 S1 + M2 S2
# (Preetham et al. 1999, section 4 and appendix: the CIE D-series method for any x, y), scaled
# to the luminance Y. A spectral factor s(l) then makes the sky's horizontal irradiance equal
# the atmosphere's diffuse spectrum wavelength by wavelength (not only per display channel).
# Because S is linear in (1, M1, M2), its integral against any band weight w_b(l) is the same
# linear combination of three band vectors: the shader needs three colours, whatever N is.


def daylight_m1_m2(x, y) -> tuple[np.ndarray, np.ndarray]:
    """The CIE D-series weights M1, M2 of chromaticity x, y (CIE 15, eq. for S(l))."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    m = 0.0241 + 0.2562 * x - 0.7341 * y
    return (-1.3515 - 1.7703 * x + 5.9114 * y) / m, (0.0300 - 31.4424 * x + 30.0717 * y) / m


@functools.lru_cache(maxsize=1)
def daylight_basis_on_grid() -> np.ndarray:
    """(3, len(GRID_NM)): S0, S1, S2 interpolated (linearly) onto the project's grid."""
    from catalog.optics.reference_tables import daylight_basis_table  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    wl, basis = daylight_basis_table()
    out = np.stack([np.interp(GRID_NM, wl, b, left=0.0, right=0.0) for b in basis])
    out.setflags(write=False)
    return out


def preetham_xyY(directions: np.ndarray, to_sun: np.ndarray, turbidity: float) -> np.ndarray:
    """Preetham's x, y, Y (cd m^-2) for unit directions (..., 3), y up (clamped at the horizon)."""
    to_sun = np.asarray(to_sun, dtype=np.float64) / np.linalg.norm(to_sun)
    sun_zenith = math.acos(max(min(to_sun[1], 1.0), -1.0))
    coefficients = perez_coefficients(turbidity)
    d = np.asarray(directions, dtype=np.float64)
    gamma = np.arccos(np.clip(d @ to_sun, -1.0, 1.0))
    ratio = _perez(coefficients, d[..., 1], gamma) / _perez(coefficients, math.cos(sun_zenith), sun_zenith)
    return zenith_xyY(turbidity, min(sun_zenith, math.pi / 2)) * ratio


def preetham_spectral(directions: np.ndarray, to_sun: np.ndarray, turbidity: float) -> np.ndarray:
    """Preetham's sky as spectral radiance (..., len(GRID_NM)) on the grid, luminance Y
    (cd m^-2 scale: 683 sum ybar L dl = Y), unscaled (s(l) = 1)."""
    from catalog.optics.colorimetry import cmfs  # noqa: PLC0415
    from catalog.optics.shading_reference import LUMINOUS_EFFICACY_LM_W, STEP_NM  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    xyy = preetham_xyY(directions, to_sun, turbidity)
    m1, m2 = daylight_m1_m2(xyy[..., 0], xyy[..., 1])
    s0, s1, s2 = daylight_basis_on_grid()
    spectrum = s0 + m1[..., None] * s1 + m2[..., None] * s2
    lum = LUMINOUS_EFFICACY_LM_W * STEP_NM * (spectrum @ cmfs(GRID_NM)[:, 1])
    return spectrum * (xyy[..., 2] / lum)[..., None]


@dataclass(frozen=True)
class SpectralSky:
    """The clear sky per wavelength: L(l, d) = s(l) Y(d) S(l; x(d), y(d)) / Y_S(x(d), y(d))."""

    model: SkyModel
    spectral_scale: np.ndarray     # s(l) on the grid
    ground: np.ndarray             # the ground's spectral radiance

    def radiance(self, directions: np.ndarray) -> np.ndarray:
        """Spectral radiance (..., len(GRID_NM)), the hazy ground below the horizon (no seam)."""
        d = np.asarray(directions, dtype=np.float64)
        horizon = d.copy()
        horizon[..., 1] = np.maximum(horizon[..., 1], 0.0)
        horizon /= np.maximum(np.linalg.norm(horizon, axis=-1, keepdims=True), 1e-12)
        sky = self.spectral_scale * preetham_spectral(horizon, self.model.to_sun, self.model.turbidity)
        depression = np.arcsin(np.clip(-d[..., 1], 0.0, 1.0))
        fade = np.exp(-depression / HAZE_RAD)[..., None]
        return np.where(d[..., 1:2] >= 0.0, sky, fade * sky + (1.0 - fade) * self.ground)

    def band_colours(self, weights: np.ndarray, band_to_rgb: np.ndarray) -> dict[str, np.ndarray]:
        """What background.frag's SKY_BANDS needs for band weights (N, L) and a display matrix
        (3, N): the display colours C_i = band_to_rgb (weights (s S_i)) of the three basis
        spectra, the basis's luminances Y_i (so Y_S = Y0 + M1 Y1 + M2 Y2) and the ground's."""
        from catalog.optics.colorimetry import cmfs  # noqa: PLC0415
        from catalog.optics.shading_reference import LUMINOUS_EFFICACY_LM_W, STEP_NM  # noqa: PLC0415
        from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

        basis = daylight_basis_on_grid()
        colours = band_to_rgb @ (weights @ (self.spectral_scale * basis).T)   # (3, 3): columns C_i
        lum = LUMINOUS_EFFICACY_LM_W * STEP_NM * (basis @ cmfs(GRID_NM)[:, 1])
        return {"basis_rgb": colours.T, "basis_luminance": lum,
                "ground_rgb": band_to_rgb @ (weights @ self.ground)}


def spectral_sky(to_sun: np.ndarray, diffuse_horizontal: np.ndarray, ground_radiance: np.ndarray,
                 atmosphere=None, n_theta: int = 48) -> SpectralSky:
    """The sky of :func:`sky_model` per wavelength: s(l) makes its horizontal irradiance
    ``diffuse_horizontal`` (W m^-2 nm^-1 on the grid) at every wavelength."""
    model = sky_model(to_sun, atmosphere, diffuse_horizontal, ground_radiance)
    target = np.asarray(diffuse_horizontal, dtype=np.float64)
    unscaled = horizontal_irradiance_rgb(lambda d: preetham_spectral(d, model.to_sun, model.turbidity),
                                         n_theta=n_theta)
    scale = np.where(unscaled > 0, target / np.where(unscaled > 0, unscaled, 1.0), 0.0)
    return SpectralSky(model, scale, np.asarray(ground_radiance, dtype=np.float64))
