"""Fluorescence of optical brighteners and fluorescent dyes: paper mode and physical mode.

Paper mode (model.md sections 2-3) is the paper's eq. 1-4 exactly: a colour F with Y forced
to 100 (eq. 1-3) and a dimensionless intensity I_fluor (eq. 4), both over 380-780 nm.

Physical mode (the default of the project) counts photons over the whole excitation range
of the grid (300-780 nm):

    N_abs = sum_l a(l) E(l) l / (h c) dl                (absorbed photons, m^-2 s^-1)
    N_eff = N_abs / (1 + N_abs / N_sat)                 (saturation)
    M(l)  = phi * N_eff * p(l) * h c / l                (emitted exitance, W m^-2 nm^-1)

a: absorptance of the brightener (fraction of incident photons absorbed), E: spectral
irradiance (W m^-2 nm^-1), phi: quantum yield <= 1, p: emitted photon spectrum normalised
to integrate to 1 over nm, N_sat: saturation photon irradiance. Emitted photons
phi * N_eff never exceed absorbed photons N_abs, so no energy is created (each emitted
photon also carries less energy than the absorbed one whenever the emission lies to the
red of the excitation). The emission is diffuse (Lambertian): radiance M / pi.

Colours in physical mode are absolute: XYZ = 683 lm/W * sum cmf(l) S(l) dl, so the Y of a
light's irradiance is its illuminance in lux and the Y of an exitance is a luminous
exitance in lm m^-2 (a perfect white diffuser under the light has the light's Y).

Only numpy is imported here at module level; colour-science comes in lazily through
:mod:`catalog.optics.colorimetry` when a colour is asked for.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catalog.core.constants import LUMINOUS_EFFICACY_LM_W
from catalog.optics.colorimetry import (M_PAPER_XYZ_TO_RGB, cmfs, delta_e_2000,
                                 linear_srgb_to_xyz, xyz_to_linear_srgb)
from catalog.core.errors import CatalogError, InputError
from catalog.optics.spectra import GRID_NM, VISIBLE_NM, Spectrum

#: Planck constant, J s (CODATA 2018, exact since the 2019 SI redefinition).
PLANCK_J_S = 6.62607015e-34
#: Speed of light in vacuum, m s^-1 (CODATA 2018, exact by definition of the metre).
LIGHT_SPEED_M_S = 299792458.0

#: Grid step of GRID_NM (1 nm): every sum over the grid is a Riemann sum with this dl.
GRID_STEP_NM = 1.0

#: Default physical-mode parameters (docs/fluorescence.md says where they come from).
DEFAULT_QUANTUM_YIELD = 0.6
DEFAULT_PEAK_ABSORPTANCE = 0.5
#: Ground-state depletion of a dye with absorption cross-section ~1e-20 m^2 and an excited
#: lifetime ~1 ns saturates near 1 / (sigma tau) = 1e29 incident photons m^-2 s^-1; with
#: an absorptance below 1 the absorbed rate at that point is ~1e28. Sunlight brings ~1e20,
#: so saturation only matters for lasers and focused lamps; it is kept for completeness
#: (the paper's future-work note) and can be lowered per material.
DEFAULT_SATURATION_PHOTON_IRRADIANCE = 1.0e28
#: Below this colour change (Delta E 2000) the fluorescence pass may be skipped: well under
#: the ~1 of a just-noticeable difference, so skipping it can never be seen.
NEEDED_DELTA_E = 0.1


def photon_energy_j(wavelength_nm: np.ndarray | float) -> np.ndarray:
    """Energy of one photon, h c / l, in J (``wavelength_nm`` in nm)."""
    return PLANCK_J_S * LIGHT_SPEED_M_S / (np.asarray(wavelength_nm, dtype=np.float64) * 1e-9)


@dataclass(frozen=True)
class FluorescentMaterial:
    """A fluorescent material for physical mode, everything on ``catalog.optics.spectra.GRID_NM``.

    absorptance: fraction of incident excitation photons absorbed by the brightener or dye,
        in [0, 1] (= peak_absorptance * excitation spectrum normalised to a peak of 1).
    emission_pdf_per_nm: the emitted photon spectrum, nm^-1, integrating to 1 over the grid.
    quantum_yield: emitted photons per absorbed photon, in [0, 1].
    saturation_photon_irradiance: absorbed photons m^-2 s^-1 at which the effective absorbed
        rate is halved; ``math.inf`` for no saturation.
    """

    absorptance: np.ndarray
    emission_pdf_per_nm: np.ndarray
    quantum_yield: float
    saturation_photon_irradiance: float = DEFAULT_SATURATION_PHOTON_IRRADIANCE

    def __post_init__(self) -> None:
        absorptance = _on_grid("absorptance", self.absorptance)
        pdf = _on_grid("emission_pdf_per_nm", self.emission_pdf_per_nm)
        if np.any(absorptance < 0) or np.any(absorptance > 1):
            raise CatalogError("absorptance must lie in [0, 1] at every wavelength")
        if not np.any(absorptance > 0):
            raise CatalogError("absorptance is zero everywhere: the material absorbs nothing")
        if np.any(pdf < 0):
            raise CatalogError("emission_pdf_per_nm must be >= 0")
        area = float(np.sum(pdf) * GRID_STEP_NM)
        if not abs(area - 1.0) < 1e-9:
            raise CatalogError(f"emission_pdf_per_nm must integrate to 1 over the grid, not {area:.6g}")
        if not 0.0 <= float(self.quantum_yield) <= 1.0:
            raise CatalogError(f"quantum_yield must lie in [0, 1], not {self.quantum_yield!r}")
        if not float(self.saturation_photon_irradiance) > 0:
            raise CatalogError("saturation_photon_irradiance must be > 0 (math.inf: none), "
                               f"not {self.saturation_photon_irradiance!r}")
        absorptance.setflags(write=False)
        pdf.setflags(write=False)
        object.__setattr__(self, "absorptance", absorptance)
        object.__setattr__(self, "emission_pdf_per_nm", pdf)
        object.__setattr__(self, "quantum_yield", float(self.quantum_yield))
        object.__setattr__(self, "saturation_photon_irradiance",
                           float(self.saturation_photon_irradiance))

    @property
    def peak_absorptance(self) -> float:
        return float(np.max(self.absorptance))


def _on_grid(name: str, values: np.ndarray) -> np.ndarray:
    array = np.array(values, dtype=np.float64)  # a private copy
    if array.shape != GRID_NM.shape:
        raise CatalogError(f"{name} must be sampled on GRID_NM ({GRID_NM.size} values, "
                           f"{GRID_NM[0]:g}-{GRID_NM[-1]:g} nm), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise CatalogError(f"{name} has NaN or infinite values")
    return array


def _irradiance_on_grid(irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
    irradiance = _on_grid("irradiance_w_m2_nm", irradiance_w_m2_nm)
    if np.any(irradiance < 0):
        raise CatalogError("irradiance_w_m2_nm must be >= 0")
    return irradiance


# --------------------------------------------------------------------------- physical mode

def absorbed_photon_irradiance(material: FluorescentMaterial,
                               irradiance_w_m2_nm: np.ndarray) -> float:
    """N_abs = sum_l a(l) E(l) l / (h c) dl over the whole grid, photons m^-2 s^-1."""
    irradiance = _irradiance_on_grid(irradiance_w_m2_nm)
    photon_irradiance = irradiance / photon_energy_j(GRID_NM)  # photons m^-2 s^-1 nm^-1
    return float(np.sum(material.absorptance * photon_irradiance) * GRID_STEP_NM)


def effective_absorbed_photons(material: FluorescentMaterial, absorbed: float) -> float:
    """Saturation: N_eff = N_abs / (1 + N_abs / N_sat) (N_sat = inf gives N_eff = N_abs)."""
    return absorbed / (1.0 + absorbed / material.saturation_photon_irradiance)


def emitted_photon_exitance(material: FluorescentMaterial,
                            irradiance_w_m2_nm: np.ndarray) -> float:
    """Emitted photons m^-2 s^-1: quantum_yield * N_eff (never above N_abs)."""
    absorbed = absorbed_photon_irradiance(material, irradiance_w_m2_nm)
    return material.quantum_yield * effective_absorbed_photons(material, absorbed)


def emitted_exitance_w_m2_nm(material: FluorescentMaterial,
                             irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
    """Spectral exitance M(l) = phi N_eff p(l) h c / l on GRID_NM, W m^-2 nm^-1.

    Diffuse emission: the radiance is M / pi in every direction (a thin cloth shares it
    between its two sides; that split is the renderer's).
    """
    emitted = emitted_photon_exitance(material, irradiance_w_m2_nm)
    return emitted * material.emission_pdf_per_nm * photon_energy_j(GRID_NM)


def combine_under_light(materials, irradiance_w_m2_nm: np.ndarray):
    """ONE fluorophore that emits under this light what ``materials`` (the excitation bands
    of one surface, docs/bispectral.md) emit together: the per-(material, light)
    pre-integration the renderer does once per light, so a banded material costs the
    shader nothing more than a single one.

    absorptance: the bands' sum (where that exceeds 1, overlapping bands: the photon yield
    spectrum sum phi_k a_k, scaled to a peak of at most 1); emission pdf: the bands' pdfs
    weighted by the photons each emits, phi_k N_abs,k; quantum yield: emitted over absorbed
    photons of that absorptance (<= 1). Without saturation the emitted exitance equals the
    sum of the bands' exactly for this light and any light proportional to it (unless the
    bands emit more photons than arrive, which no physical fit does). Saturation: the first
    material's. Returns None when the light excites none of them.
    """
    materials = tuple(materials)
    if len(materials) == 1:
        return materials[0]
    emitted = np.array([m.quantum_yield * absorbed_photon_irradiance(m, irradiance_w_m2_nm)
                        for m in materials])
    total = float(np.sum(emitted))
    if not total > 0:
        return None
    pdf = sum(e * m.emission_pdf_per_nm for e, m in zip(emitted, materials)) / total
    pdf = pdf / (float(np.sum(pdf)) * GRID_STEP_NM)
    absorptance = sum(m.absorptance for m in materials)
    if float(np.max(absorptance)) > 1.0:
        # overlapping bands absorb "more than everything": carry the photon yield spectrum
        # sum phi_k a_k instead (emitted photons per incident photon), quantum yield 1
        absorptance = sum(m.quantum_yield * m.absorptance for m in materials)
        absorptance = absorptance / max(1.0, float(np.max(absorptance)))
    probe = FluorescentMaterial(absorptance=absorptance, emission_pdf_per_nm=pdf,
                                quantum_yield=1.0)
    absorbed = absorbed_photon_irradiance(probe, irradiance_w_m2_nm)
    return FluorescentMaterial(absorptance=absorptance, emission_pdf_per_nm=pdf,
                               quantum_yield=min(1.0, total / absorbed),
                               saturation_photon_irradiance=materials[0].saturation_photon_irradiance)


def light_xyz(irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
    """Absolute XYZ of an irradiance on GRID_NM: Y is the illuminance in lux."""
    irradiance = _irradiance_on_grid(irradiance_w_m2_nm)
    return LUMINOUS_EFFICACY_LM_W * (irradiance @ cmfs(GRID_NM)) * GRID_STEP_NM


def exitance_xyz(exitance_w_m2_nm: np.ndarray) -> np.ndarray:
    """Absolute XYZ of a spectral exitance on GRID_NM: Y in lm m^-2.

    Same scale as :func:`light_xyz`: a perfect white diffuser under a light has the light's
    XYZ. Divide by pi for the XYZ of the (Lambertian) radiance in cd m^-2.
    """
    exitance = np.asarray(exitance_w_m2_nm, dtype=np.float64)
    return LUMINOUS_EFFICACY_LM_W * (exitance @ cmfs(GRID_NM)) * GRID_STEP_NM


def emission_xyz(material: FluorescentMaterial, irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
    """Absolute XYZ of the emitted exitance under a light (Y in lm m^-2)."""
    return exitance_xyz(emitted_exitance_w_m2_nm(material, irradiance_w_m2_nm))


def emission_linear_srgb(material: FluorescentMaterial,
                         irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
    """Linear sRGB of the emitted exitance, absolute (Y scale of lm m^-2), negatives KEPT.

    A blue brightener's emission lies outside the sRGB gamut, so its G (sometimes R) is
    negative. The renderer carries this signed triple and adds it to the reflected and
    transmitted light, which is exact because XYZ -> RGB is linear; the sum of a lit white
    cloth is back in gamut (docs/fluorescence.md measures the error of the alternatives).
    """
    return xyz_to_linear_srgb(emission_xyz(material, irradiance_w_m2_nm))


def emission_relative_srgb(material: FluorescentMaterial,
                           irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
    """Linear sRGB of the emission per unit of the light's illuminance (signed).

    The emission of the material as a fraction of what a perfect white diffuser reflects
    (Y of the white = 1). Below saturation it does not change when the light is scaled.
    Refused for a light with no visible part (the ratio is undefined; use the absolute value).
    """
    illuminance = float(light_xyz(irradiance_w_m2_nm)[1])
    if not illuminance > 0:
        raise CatalogError("the light has no visible part (illuminance 0 lx): "
                           "use emission_linear_srgb for the absolute emission")
    return emission_linear_srgb(material, irradiance_w_m2_nm) / illuminance


#: How an emission colour outside the sRGB gamut is carried to the shader (docs/fluorescence.md).
CARRY_METHODS = ("signed", "clip", "desaturate")


def carry_emission_rgb(emission_rgb: np.ndarray, method: str = "signed") -> np.ndarray:
    """The linear-sRGB triple handed to the shader for an emission colour.

    ``signed`` (the project's choice): unchanged, negatives kept; added to the reflected and
    transmitted light this is exact (XYZ -> RGB is linear), and only a final sum that is
    itself out of gamut is clipped, at display. ``clip``: negative components set to 0
    (adds light the emission does not have). ``desaturate``: mixed toward the grey of the
    same luminance until no component is negative (keeps Y and the hue angle, loses purity).
    """
    rgb = np.asarray(emission_rgb, dtype=np.float64)
    if method == "signed":
        return rgb.copy()
    if method == "clip":
        return np.maximum(rgb, 0.0)
    if method == "desaturate":
        # the grey of the same luminance: (g, g, g) with Y(g, g, g) = Y(rgb); the white's Y
        # is 1 only to the rounding of the sRGB matrices, so divide by it
        grey = (linear_srgb_luminance(rgb) / linear_srgb_luminance(np.ones(3)))[..., None]
        lowest = np.min(rgb, axis=-1, keepdims=True)
        out_of_gamut = lowest < 0
        with np.errstate(divide="ignore", invalid="ignore"):  # only used where lowest < 0 <= Y
            keep = np.where(out_of_gamut & (grey > 0), grey / (grey - lowest), 1.0)
        mapped = grey + keep * (rgb - grey)
        return np.where(out_of_gamut & (grey <= 0), 0.0, mapped)
    raise CatalogError(f"unknown carry method {method!r}; one of {', '.join(CARRY_METHODS)}")


def linear_srgb_luminance(rgb: np.ndarray) -> np.ndarray:
    """Y of linear sRGB (colour-science's RGB -> XYZ matrix, second row)."""
    return linear_srgb_to_xyz(np.asarray(rgb, dtype=np.float64))[..., 1]


def _reflectance_on_grid(reflectance_background: float | np.ndarray) -> np.ndarray:
    reflectance = np.broadcast_to(np.asarray(reflectance_background, dtype=np.float64),
                                  GRID_NM.shape)
    if not np.all(np.isfinite(reflectance)) or np.any(reflectance < 0):
        raise CatalogError("reflectance_background must be finite and >= 0")
    return reflectance


def fluorescence_delta_e(material: FluorescentMaterial, irradiance_w_m2_nm: np.ndarray,
                         reflectance_background: float | np.ndarray = 0.85) -> float:
    """Delta E 2000 between the lit cloth with and without its fluorescent emission.

    The cloth reflects ``reflectance_background`` (a number or a spectrum on GRID_NM) times
    the light; the viewer is adapted to the light (white = a perfect diffuser under it).
    A light with no visible part (a UV lamp) makes any emission visible against black:
    the white is then taken as the emission itself, so the answer is large.
    """
    irradiance = _irradiance_on_grid(irradiance_w_m2_nm)
    reflected = exitance_xyz(_reflectance_on_grid(reflectance_background) * irradiance)
    emitted = emission_xyz(material, irradiance)
    white = light_xyz(irradiance)
    if not white[1] > 0:
        if not emitted[1] > 0:
            return 0.0
        white = emitted
    return float(delta_e_2000(reflected + emitted, reflected, white))


def fluorescence_needed(material: FluorescentMaterial, irradiance_w_m2_nm: np.ndarray,
                        reflectance_background: float | np.ndarray = 0.85,
                        threshold_delta_e: float = NEEDED_DELTA_E) -> bool:
    """True when the emission changes the colour of the lit cloth by more than
    ``threshold_delta_e`` (Delta E 2000): the renderer skips the fluorescence pass otherwise.

    It is a judgement of the overlap of the light with the excitation: a UV-excited
    brightener under a white LED (no UV) is not needed; a blue-excited dye under it is.
    """
    return fluorescence_delta_e(material, irradiance_w_m2_nm,
                                reflectance_background) > threshold_delta_e


def emission_is_photon_spectrum(emission: Spectrum) -> bool:
    """True when a header comment reads ``quantity: photon...`` (e.g. "quantity: photons per nm").

    Corrected spectrofluorometer output is an energy spectrum, the default; a file that
    counts photons says so in a ``quantity:`` comment line.
    """
    for comment in emission.comments:
        key, _, value = comment.partition(":")
        if key.strip().lower() == "quantity" and value.strip().lower().startswith("photon"):
            return True
    return False


def material_from_spectra(excitation: Spectrum, emission: Spectrum, *,
                          peak_absorptance: float = DEFAULT_PEAK_ABSORPTANCE,
                          quantum_yield: float = DEFAULT_QUANTUM_YIELD,
                          saturation_photon_irradiance: float = DEFAULT_SATURATION_PHOTON_IRRADIANCE,
                          emission_in_photons: bool | None = None) -> FluorescentMaterial:
    """A physical-mode material from measured excitation and emission spectra.

    The excitation is normalised to a peak of 1 over its measured range and scaled by
    ``peak_absorptance`` (in (0, 1]). The emission is read as an energy spectrum (W per nm,
    what spectrofluorometers report once corrected) unless ``emission_in_photons`` is True
    or, when it is None, the emission file has a header comment ``# quantity: photons ...``
    (see :func:`emission_is_photon_spectrum`); an energy spectrum S(l) becomes the photon
    spectrum S(l) l (photons per nm are power per nm divided by h c / l), then normalised to
    integrate to 1.
    """
    if not 0.0 < float(peak_absorptance) <= 1.0:
        raise CatalogError(f"peak_absorptance must lie in (0, 1], not {peak_absorptance!r}")
    excitation_values = np.asarray(excitation.values, dtype=np.float64)
    if excitation_values.size == 0 or not np.max(excitation_values) > 0:
        raise InputError("excitation spectrum is empty or zero everywhere",
                         path=excitation.source or None)
    emission_values = np.asarray(emission.values, dtype=np.float64)
    if emission_values.size == 0 or not np.max(emission_values) > 0:
        raise InputError("emission spectrum is empty or zero everywhere",
                         path=emission.source or None)

    absorptance = float(peak_absorptance) * excitation.resample(GRID_NM) / float(np.max(excitation_values))
    if not np.any(absorptance > 0):
        raise InputError(f"excitation spectrum has nothing inside {GRID_NM[0]:g}-{GRID_NM[-1]:g} nm",
                         path=excitation.source or None)

    if emission_in_photons is None:
        emission_in_photons = emission_is_photon_spectrum(emission)
    emission_on_grid = emission.resample(GRID_NM)
    photons = emission_on_grid if emission_in_photons else emission_on_grid * GRID_NM
    area = float(np.sum(photons) * GRID_STEP_NM)
    if not area > 0:
        raise InputError(f"emission spectrum has nothing inside {GRID_NM[0]:g}-{GRID_NM[-1]:g} nm",
                         path=emission.source or None)
    return FluorescentMaterial(absorptance=absorptance, emission_pdf_per_nm=photons / area,
                               quantum_yield=quantum_yield,
                               saturation_photon_irradiance=saturation_photon_irradiance)


# ---------------------------------------------------------------------------- paper mode

def _visible_mask(grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    return (grid_nm >= VISIBLE_NM[0]) & (grid_nm <= VISIBLE_NM[1])


def paper_colour(emission: Spectrum) -> tuple[np.ndarray, np.ndarray]:
    """Paper eq. 1-3: the fluorescence colour of an emission spectrum.

    X, Y, Z = K sum_{l=380..780} cmf(l) Le(l)  (eq. 1), K = 100 / sum ybar Le  (eq. 3),
    [R G B] = M [X Y Z] with the paper's M  (eq. 2). Le is the emission linearly
    interpolated onto a 1 nm grid (zero outside its measured range). Returns (xyz, rgb);
    Y is 100 and rgb may have negative components (an emission outside the sRGB gamut).
    """
    values = np.asarray(emission.values, dtype=np.float64)
    if values.size == 0 or not np.max(values) > 0:
        raise InputError("emission spectrum is empty or zero everywhere",
                         path=emission.source or None)
    visible = np.arange(VISIBLE_NM[0], VISIBLE_NM[1] + 1.0, 1.0)
    le = emission.resample(visible)
    sums = le @ cmfs(visible)  # eq. 1 without K
    if not sums[1] > 0:
        raise InputError("emission has no luminance in 380-780 nm: eq. 3 divides by zero",
                         path=emission.source or None)
    k = 100.0 / sums[1]  # eq. 3
    xyz = k * sums  # eq. 1
    rgb = M_PAPER_XYZ_TO_RGB @ xyz  # eq. 2
    return xyz, rgb


def paper_intensity(irradiance_on_grid: np.ndarray, excitation_on_grid: np.ndarray) -> float:
    """Paper eq. 4: I = sum I_light I_exci / sum I_light over l = 380..780 nm at 1 nm.

    Both arguments are sampled on GRID_NM. The excitation must already be normalised to a
    peak of 1 over its measured range, as ``read_spectrum(path, normalise=True)`` loads it
    (formats.md), then resampled: its maximum on the grid may be below 1 when the measured
    peak lies under 300 nm (Calcofluor White peaks at 254 nm), and one above 1 is refused as
    not normalised. The result is dimensionless and does not change when the light is scaled.
    """
    irradiance = _irradiance_on_grid(irradiance_on_grid)
    excitation = _on_grid("excitation_on_grid", excitation_on_grid)
    if np.any(excitation < 0):
        raise CatalogError("excitation_on_grid must be >= 0")
    peak = float(np.max(excitation))
    if not peak > 0:
        raise CatalogError("excitation is zero everywhere on the grid")
    if peak > 1.0 + 1e-9:
        raise CatalogError(f"excitation_on_grid peaks at {peak:.6g}: normalise the excitation "
                           "spectrum to a peak of 1 first (read_spectrum(..., normalise=True))")
    visible = _visible_mask()
    light = irradiance[visible]
    total = float(np.sum(light))
    if not total > 0:
        raise CatalogError("the light is zero over 380-780 nm: eq. 4 divides by zero")
    return float(np.sum(light * excitation[visible]) / total)  # eq. 4
