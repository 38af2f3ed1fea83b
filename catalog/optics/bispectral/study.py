"""The colour-error study: fluorescence models against measured Donaldson matrices.

For a matrix and a light, every method gives the XYZ of the light the surface sends back
(reflected + re-radiated, absolute: 683 lm/W x sum cmf(l) S(l) dl, the scale of
:func:`catalog.optics.fluorescence.exitance_xyz`); the error is CIEDE2000 against the exact
matrix result (:func:`catalog.optics.bispectral.matrix.exact_exitance_on_grid`), seen against a white
that is the light reflected by a perfect white diffuser, i.e. the light's own XYZ.
Exception: when the sample is brighter than that white (a UV lamp whose visible part is a
few weak lines), the eye adapts to the glow; the white is then the sRGB (D65) white point
at the exact result's luminance.

Methods (model.md sections 6 and 8):

- ``ignore``: fluorescence ignored: the diagonal (ordinary reflectance) alone.
- ``paper``: eq. 8's per-channel form, R_c E_c + k I_fluor F_c, in the paper's linear RGB
  (eq. 2's M): R_c is the fabric's RGB albedo (the fitted reflectance under D65, per
  channel), E_c the light's RGB, I_fluor eq. 4 with the fitted excitation, F_c eq. 1-3 of
  the fitted emission (read as an energy spectrum). Eq. 8's scale is arbitrary; here the
  paper's terms are relative to the light (the white has Y = 100, as eq. 3 normalises F)
  and k is set once per material so that the result matches the exact one best (least
  squares in RGB) under D65: the paper's model at its most favourable (under D65 it is
  fitted to the answer).
- ``paper_global``: the same with ONE k for all materials (least squares under D65 over
  the eight matrices): eq. 8 as printed, which has no per-material strength.
- ``physical``: the separable fit as a physical-mode material: R(l) E(l) plus
  :func:`catalog.optics.fluorescence.emitted_exitance_w_m2_nm`, spectral at 1 nm, integrated once
  per light exactly as the renderer does.
- ``physical_rgb``: the same carried through the renderer's RGB pipeline
  (catalog/render/bands.py, N = 3): light x reflectance and the emission pre-integrated per
  (material, light) pair against the sRGB colour-matching functions, in float32, summed.
- ``rgb_product``: a plain RGB engine: a light-independent RGB albedo (the reflectance
  under D65) times the light's RGB, plus the emission's exact RGB per pair: what
  the pre-integration saves (and what remains wherever two spectra meet at run time).

- ``reduced_3x3`` (e): a reduced re-radiation matrix in the colour-matching space, after
  Fichet, Belcour and Barla 2024 as we read them (our code, not theirs): the light's XYZ
  c is upsampled with the dual basis S~ = S (S^T S)^-1 of the CMFs S, the whole matrix
  (reflectance and re-radiation) applied exactly, and the result projected back:
  XYZ_out = S^T P S~ c, a 3x3 per material, independent of the light.
  ``reduced_3x3_uv``: the same with a fourth input band, a box over 300-379 nm that
  carries the light's UV (3x4).

Diagnostics: ``physical_lsq`` is ``physical`` with the separable fit by least squares on
the matrix entries alone (``fit_separable(colour_lights=None)``, the default before the
colour refinement); ``data_antistokes`` is the colour difference the matrix's anti-Stokes entries
beyond the reflectance band make (emission at a wavelength 20 nm or more SHORTER than the
excitation: physically nothing for these materials, so measurement noise and instrument
stray light; a measure of how well the data pin the colour down); ``physical_no_antistokes``
is ``physical`` against the exact result of the matrix without those entries;
``physical_islands`` is ``physical`` with a fit that keeps absorption islands outside the
main band (``fit_separable(single_band=False, colour_lights=None)``): it follows the anti-Stokes artefact, and
is reported to show what that buys, not as a model;
``data_10nm`` is the exact result evaluated the literal way, everything (light, emission,
colour-matching functions) sampled every 10 nm, against ours.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catalog.core.constants import LUMINOUS_EFFICACY_LM_W as LM_PER_W
from catalog.optics.bispectral.matrix import (REFLECTANCE_BAND_NM, DonaldsonMatrix, SeparableFit,
                                bin_irradiance, exact_exitance_on_grid, fit_separable)
from catalog.optics.colorimetry import (M_PAPER_XYZ_TO_RGB, cmfs, delta_e_2000, linear_srgb_to_xyz,
                                 srgb_whitepoint_xy, xyz_to_linear_srgb)
from catalog.optics.spectra import GRID_NM, Spectrum

#: The lights of the goal (model.md section 8, the state of the art's set).
GOAL_LIGHTS = ("D65", "A", "FL2", "FL11", "LED-B4")
#: All lights of the study: the goal's plus a UV-A lamp and the sun at 22 and 500 km.
STUDY_LIGHTS = GOAL_LIGHTS + ("UV-A", "sun:22", "sun:500")
#: Model methods, in table order; then the data diagnostics.
METHODS = ("ignore", "paper", "paper_global", "physical", "physical_rgb", "rgb_product",
           "reduced_3x3", "reduced_3x3_uv")
#: The UV band of ``reduced_3x3_uv``, nm (a box below the visible).
UV_BAND_NM = (300.0, 379.0)
DIAGNOSTICS = ("physical_lsq", "physical_no_antistokes", "physical_islands", "data_antistokes",
               "data_10nm")
#: model.md section 8: the state of the art on the same 8 matrices x GOAL_LIGHTS, Delta E
#: 2000 (mean, max).
STATE_OF_THE_ART = {"ignoring fluorescence": (11.6, 26.0), "naive 3x3": (10.7, 20.6),
                    "Fichet et al. reduced 3x3": (3.0, 13.0),
                    "Fichet et al. 3x3 + UV band": (3.3, 8.0),
                    "separable (exact per light)": (0.48, 0.90)}
#: The goal for ``physical`` over all matrices x GOAL_LIGHTS (issue 2).
GOAL_MEAN, GOAL_MAX = 0.5, 1.0


def _xyz(spectrum: np.ndarray) -> np.ndarray:
    """Absolute XYZ of a spectrum on GRID_NM (683 lm/W x sum cmf S dl)."""
    return LM_PER_W * (np.asarray(spectrum, dtype=np.float64) @ cmfs(GRID_NM)) * float(GRID_NM[1] - GRID_NM[0])


def light_irradiance(name: str) -> np.ndarray:
    """The light's spectral irradiance on GRID_NM from the project's light library, or a
    Planckian radiator ``planck:K`` (:func:`catalog.optics.bispectral.matrix.training_light`)."""
    from catalog.optics.bispectral.matrix import training_light

    return training_light(name)


def white_xyz(light: np.ndarray, exact_xyz: np.ndarray) -> np.ndarray:
    """The reference white: the light's XYZ, or (sample brighter than it) D65 at its Y."""
    white = _xyz(light)
    if exact_xyz[1] > white[1]:
        x, y = srgb_whitepoint_xy()
        luminance = float(exact_xyz[1])
        white = np.array([x / y * luminance, luminance, (1 - x - y) / y * luminance])
    return white


@dataclass(frozen=True)
class MaterialModels:
    """Everything the methods need for one matrix, computed once."""

    matrix: DonaldsonMatrix
    fit: SeparableFit
    reflectance_diagonal: np.ndarray   # on GRID_NM
    reflectance_fit: np.ndarray        # on GRID_NM
    paper_rgb_unit: np.ndarray         # F_c of eq. 1-3 (Y = 100), paper's M
    excitation_on_grid: np.ndarray     # peak 1
    albedo_rgb_paper: np.ndarray       # R_c under D65, paper's M
    albedo_rgb_srgb: np.ndarray        # R_c under D65, colour-science sRGB
    paper_scale: float                 # k of eq. 8's fluorescence term, this material
    paper_target_d65: np.ndarray       # what k x paper_term_d65 should match under D65
    paper_term_d65: np.ndarray         # I_fluor F_c under D65
    reduced_3x3: np.ndarray            # XYZ_out = reduced_3x3 @ (S^T E), (3, 3)
    reduced_3x3_uv: np.ndarray         # XYZ_out = reduced_3x3_uv @ (S4^T E), (3, 4)
    paper_scale_global: float = float("nan")  # one k for a set of materials


def _albedo(reflectance: np.ndarray, light: np.ndarray, matrix_xyz_to_rgb) -> np.ndarray:
    return matrix_xyz_to_rgb(_xyz(reflectance * light)) / matrix_xyz_to_rgb(_xyz(light))


def _paper_rgb(xyz):
    return M_PAPER_XYZ_TO_RGB @ np.asarray(xyz)


def _sensors(with_uv: bool) -> np.ndarray:
    """S: the CIE 1931 CMFs on GRID_NM as columns, plus a UV box when asked."""
    sensors = np.asarray(cmfs(GRID_NM))
    if with_uv:
        uv = ((GRID_NM >= UV_BAND_NM[0]) & (GRID_NM <= UV_BAND_NM[1])).astype(np.float64)
        sensors = np.hstack([sensors, uv[:, None]])
    return sensors


def reduced_matrix(matrix: DonaldsonMatrix, with_uv: bool = False) -> np.ndarray:
    """S^T P S~ with S~ = S (S^T S)^-1: column j is the XYZ the matrix returns for the
    (signed) basis light S~_j. Apply it to S^T E (sums over GRID_NM, dl = 1 nm) and
    multiply by 683 for the absolute XYZ of :func:`_xyz`."""
    sensors = _sensors(with_uv)
    dual = sensors @ np.linalg.inv(sensors.T @ sensors)
    return np.stack([_xyz(exact_exitance_on_grid(matrix, dual[:, j])) / LM_PER_W
                     for j in range(dual.shape[1])], axis=1)


def prepare(matrix: DonaldsonMatrix, fit: SeparableFit | None = None) -> MaterialModels:
    """Fit the matrix (unless given a fit) and set the paper mode's scale under D65."""
    from catalog.optics.fluorescence import paper_colour, paper_intensity

    fit = fit_separable(matrix) if fit is None else fit
    r_diag = np.interp(GRID_NM, matrix.emission_nm, matrix.diagonal())
    r_fit = fit.reflectance_on_grid()
    # the emitted ENERGY spectrum (what a spectrofluorometer reports): photons x hc / l
    emission_energy = fit.emission_pdf_on_grid() / GRID_NM
    _, f_rgb = paper_colour(Spectrum(GRID_NM, emission_energy, f"{matrix.name} fitted emission"))
    excitation = fit.excitation_on_grid()
    d65 = light_irradiance("D65")
    albedo_paper = _albedo(r_fit, d65, _paper_rgb)
    albedo_srgb = _albedo(r_fit, d65, xyz_to_linear_srgb)
    # k: least squares, in the paper's RGB relative to the light (Y_white = 100), under D65
    exact = _xyz(exact_exitance_on_grid(matrix, d65))
    white = _xyz(d65)
    target = _paper_rgb(exact * 100.0 / white[1]) - albedo_paper * _paper_rgb(white * 100.0 / white[1])
    term = paper_intensity(d65, excitation) * f_rgb
    k = float(target @ term / (term @ term))
    return MaterialModels(matrix, fit, r_diag, r_fit, f_rgb, excitation, albedo_paper,
                          albedo_srgb, k, target, term, reduced_matrix(matrix, False),
                          reduced_matrix(matrix, True))


def with_global_paper_scale(models: list[MaterialModels]) -> list[MaterialModels]:
    """Set one eq. 8 scale for all ``models``: least squares under D65 over all of them."""
    from dataclasses import replace

    numerator = sum(float(m.paper_target_d65 @ m.paper_term_d65) for m in models)
    denominator = sum(float(m.paper_term_d65 @ m.paper_term_d65) for m in models)
    k = numerator / denominator
    return [replace(m, paper_scale_global=k) for m in models]


def method_xyz(models: MaterialModels, method: str, light: np.ndarray) -> np.ndarray:
    """Absolute XYZ of the surface under ``light`` (on GRID_NM) according to ``method``."""
    from catalog.optics.fluorescence import emitted_exitance_w_m2_nm, paper_intensity

    if method == "ignore":
        return _xyz(models.reflectance_diagonal * light)
    if method in ("paper", "paper_global"):
        scale = models.paper_scale if method == "paper" else models.paper_scale_global
        white = _xyz(light)
        if not white[1] > 0:
            return np.zeros(3)
        relative = 100.0 / white[1]
        light_rgb = _paper_rgb(white * relative)
        fluorescence = scale * paper_intensity(light, models.excitation_on_grid) \
            * models.paper_rgb_unit  # eq. 4 x eq. 1-3
        rgb = models.albedo_rgb_paper * light_rgb + fluorescence  # eq. 8
        return np.linalg.solve(M_PAPER_XYZ_TO_RGB, rgb) / relative
    if method in ("reduced_3x3", "reduced_3x3_uv"):
        with_uv = method == "reduced_3x3_uv"
        reduced = models.reduced_3x3_uv if with_uv else models.reduced_3x3
        return LM_PER_W * reduced @ (_sensors(with_uv).T @ light)
    material = models.fit.material()
    emitted = emitted_exitance_w_m2_nm(material, light)
    if method == "physical":
        return _xyz(models.reflectance_fit * light + emitted)
    if method == "physical_rgb":
        reflected_rgb = xyz_to_linear_srgb(_xyz(models.reflectance_fit * light)).astype(np.float32)
        emitted_rgb = xyz_to_linear_srgb(_xyz(emitted)).astype(np.float32)
        return linear_srgb_to_xyz((reflected_rgb + emitted_rgb).astype(np.float64))
    if method == "rgb_product":
        light_rgb = xyz_to_linear_srgb(_xyz(light))
        emitted_rgb = xyz_to_linear_srgb(_xyz(emitted))
        return linear_srgb_to_xyz(models.albedo_rgb_srgb * light_rgb + emitted_rgb)
    raise ValueError(f"unknown method {method!r}; choose from {METHODS}")


def without_antistokes(matrix: DonaldsonMatrix) -> DonaldsonMatrix:
    """The matrix with its anti-Stokes entries beyond the reflectance band set to 0."""
    shift = matrix.stokes_shift_nm()
    return DonaldsonMatrix(matrix.emission_nm, matrix.excitation_nm,
                           np.where(shift < -REFLECTANCE_BAND_NM, 0.0, matrix.values),
                           matrix.name, matrix.description, matrix.path)


def _diagnostic_delta_e(models: MaterialModels, name: str, light: np.ndarray,
                        exact: np.ndarray, white: np.ndarray) -> float:
    matrix = models.matrix
    if name in ("data_antistokes", "physical_no_antistokes"):
        cleaned = _xyz(exact_exitance_on_grid(without_antistokes(matrix), light))
        if name == "data_antistokes":
            return float(delta_e_2000(cleaned, exact, white))
        return float(delta_e_2000(method_xyz(models, "physical", light), cleaned,
                                  white_xyz(light, cleaned)))
    if name in ("physical_islands", "physical_lsq"):
        from dataclasses import replace

        other = fit_separable(matrix, single_band=name == "physical_lsq", colour_lights=None)
        return float(delta_e_2000(method_xyz(replace(models, fit=other,
                                                     reflectance_fit=other.reflectance_on_grid()),
                                             "physical", light), exact, white))
    if name == "data_10nm":
        lo = matrix.emission_nm
        cmf10 = cmfs(lo)
        step = matrix.emission_step_nm
        bins = bin_irradiance(matrix.excitation_nm, light, width_nm=matrix.excitation_step_nm)
        sample = LM_PER_W * (matrix.values @ bins) @ cmf10 * step
        white10 = LM_PER_W * bin_irradiance(lo, light, width_nm=step) @ cmf10 * step
        if sample[1] > white10[1]:
            white10 = white * sample[1] / white[1]
        # both whites on their own discretisation: compare L*a*b*, each with its own white
        from catalog.optics.colorimetry import xyz_to_lab
        import colour  # noqa: PLC0415 (lazy, as in catalog.optics.colorimetry)

        return float(colour.delta_E(xyz_to_lab(sample, white10), xyz_to_lab(exact, white),
                                    method="CIE 2000"))
    raise ValueError(f"unknown diagnostic {name!r}")


def reference_models() -> list[MaterialModels]:
    """The eight shared matrices, fitted and prepared, with the global paper scale set."""
    from catalog.optics.bispectral.matrix import list_bfc, read_bfc

    return with_global_paper_scale([prepare(read_bfc(p)) for p in list_bfc()])


def study_material(models: MaterialModels, lights: tuple[str, ...] = STUDY_LIGHTS) -> list[dict]:
    """One row per light: Delta E 2000 of every method and diagnostic for one material.

    ``models`` comes from :func:`prepare` (then :func:`with_global_paper_scale`, or the
    ``paper_global`` column is NaN) or :func:`reference_models`.
    """
    matrix = models.matrix
    rows = []
    for light_name in lights:
        light = light_irradiance(light_name)
        exact = _xyz(exact_exitance_on_grid(matrix, light))
        white = white_xyz(light, exact)
        row = {"material": matrix.name, "light": light_name}
        for method in METHODS:
            if method == "paper_global" and not np.isfinite(models.paper_scale_global):
                row[method] = float("nan")
                continue
            row[method] = float(delta_e_2000(method_xyz(models, method, light), exact, white))
        for name in DIAGNOSTICS:
            row[name] = _diagnostic_delta_e(models, name, light, exact, white)
        rows.append(row)
    return rows


def noise_floor(matrix: DonaldsonMatrix, light: np.ndarray, sigma: float, draws: int = 30,
                seed: int = 0) -> np.ndarray:
    """Delta E 2000 of the exact colour when the matrix's off-diagonal noise is re-drawn.

    Each draw adds independent N(0, sigma) to every off-diagonal entry (sigma: the fit's
    noise estimate) and compares the exact result with the unperturbed one: how well a
    matrix measured with this noise pins the colour down.
    """
    rng = np.random.default_rng(seed)
    shift = matrix.stokes_shift_nm()
    exact = _xyz(exact_exitance_on_grid(matrix, light))
    white = white_xyz(light, exact)
    out = np.empty(draws)
    for k in range(draws):
        noisy = matrix.values + np.where(shift == 0, 0.0, rng.normal(0.0, sigma, shift.shape))
        other = DonaldsonMatrix(matrix.emission_nm, matrix.excitation_nm, noisy, matrix.name,
                                matrix.description)
        out[k] = float(delta_e_2000(_xyz(exact_exitance_on_grid(other, light)), exact, white))
    return out


def study_all(lights: tuple[str, ...] = STUDY_LIGHTS) -> list[dict]:
    """The study over the eight shared matrices: one row per (material, light)."""
    return [row for models in reference_models() for row in study_material(models, lights)]


def summarise(rows: list[dict], lights: tuple[str, ...] = GOAL_LIGHTS) -> dict[str, dict[str, float]]:
    """Mean and max of every method over the rows whose light is in ``lights``."""
    chosen = [r for r in rows if r["light"] in lights]
    return {m: {"mean": float(np.mean([r[m] for r in chosen])),
                "max": float(np.max([r[m] for r in chosen]))}
            for m in METHODS + DIAGNOSTICS}
