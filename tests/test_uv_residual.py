"""Issue 15, second part: the measured residual beside the banded fit.

The representation the renderer carries is the banded fit (non-negative bands, quantum
yield <= 1) plus the matrix's signed rest off the diagonal, pre-integrated per light.
Each numerical check is against an independent float64 computation (explicit loops over
the matrix), with the tolerance stated in the test. Bounds on the real data were set after
the benchmark's figures were known (the benchmark is the place that states its bounds
first); they are regressions guards with the figure they guard written beside them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.core.errors import InputError
from catalog.core.resources import data_missing_reason
from catalog.optics.spectra import GRID_NM

HAS_MATRICES = data_missing_reason("bispectral") is None
needs_matrices = pytest.mark.skipif(not HAS_MATRICES,
                                    reason=str(data_missing_reason("bispectral")))


def _noisy_matrix(seed: int = 4):
    """A white with a UV brightener (absorbs 300-400, emits at 440) + the artefacts of the
    measured matrices: anti-Stokes offset 3e-4, noise 5e-4 (some entries negative), an
    antisymmetric +-3% pair next to the diagonal (the registration pattern of TEXTYELL)."""
    from catalog.optics.bispectral.matrix import DonaldsonMatrix

    rng = np.random.default_rng(seed)
    lo = np.arange(380.0, 781.0, 10.0)
    li = np.arange(300.0, 781.0, 10.0)
    shift = lo[:, None] - li[None, :]
    v = np.where(li <= 400, 0.012 * np.exp(-0.5 * ((li - 360) / 20) ** 2), 0.0)
    u = np.exp(-0.5 * ((lo - 440) / 20) ** 2)
    values = np.outer(u, v) * (li[None, :] / lo[:, None] * 10.0)
    values = values + np.where(shift == 0, 0.8, 0.0)
    values = values + np.where(shift == -10, 0.024, 0.0) - np.where(shift == 10, 0.024, 0.0)
    values = values + np.where(shift < -10, 3e-4, 0.0)
    values = values + np.where(shift != 0, rng.normal(0.0, 5e-4, values.shape), 0.0)
    return DonaldsonMatrix(lo, li, values, "NOISY", "synthetic brightened white with artefacts")


def _double_sum_exitance(matrix_values, lo, li, light, skip_diagonal=True):
    """Independent reference: L(lo_i) = sum_j D_ij E_bin(li_j) by explicit loops, the bin
    means by a midpoint sum at 0.01 nm of the light linearly interpolated (float64)."""
    fine = np.arange(GRID_NM[0] + 0.005, GRID_NM[-1], 0.01)  # midpoints of 0.01 nm cells
    light_fine = np.interp(fine, GRID_NM, light)
    bins = []
    for centre in li:
        inside = (fine >= centre - 5.0) & (fine < centre + 5.0)
        # the light is zero outside GRID_NM: divide by the full 10 nm bin
        bins.append(float(np.sum(light_fine[inside])) * 0.01 / 10.0)
    out = np.zeros(lo.size)
    for i in range(lo.size):
        total = 0.0
        for j in range(li.size):
            if skip_diagonal and lo[i] == li[j]:
                continue
            total += float(matrix_values[i, j]) * bins[j]
        out[i] = total
    return np.interp(GRID_NM, lo, out, left=0.0, right=0.0)


def _lights():
    from catalog.optics.lights import get_light

    return {name: get_light(name).irradiance_w_m2_nm for name in ("UV-385", "LED-405", "D65", "A")}


def test_whole_residual_completes_the_matrix_against_a_double_sum():
    """bands (10 nm entries) + residual applied to the bins = the matrix's off-diagonal
    double sum: relative 1e-6 of the peak (the reference's 0.01 nm midpoint bin means)."""
    from catalog.optics.bispectral.bands import fit_banded

    matrix = _noisy_matrix()
    fit = fit_banded(matrix, residual=True)
    from catalog.optics.bispectral.matrix import bin_irradiance

    for name, light in _lights().items():
        want = _double_sum_exitance(matrix.values, matrix.emission_nm, matrix.excitation_nm, light)
        bins = bin_irradiance(matrix.excitation_nm, light)
        off = np.where(matrix.stokes_shift_nm() == 0, 0.0, fit.fluorescence_matrix())
        got = fit.residual_exitance_w_m2_nm(light) + np.interp(
            GRID_NM, matrix.emission_nm, off @ bins, left=0.0, right=0.0)
        assert np.max(np.abs(got - want)) <= 1e-6 * np.max(np.abs(want)), name


def test_whole_residual_model_reproduces_the_exact_colour():
    """With the whole residual the model's colour is the matrix's up to the bands' 1 nm
    evaluation against the exact result's 10 nm bins: Delta E 2000 below 1.0 here (0.80
    under the 405 nm LED, whose 15 nm line the 10 nm bins blur; bound set after seeing it;
    bench on the 8 real matrices: 0.07 mean, 0.57 max), while the bands alone miss the
    artefacts by more under A."""
    from catalog.optics.bispectral import study as st
    from catalog.optics.bispectral.bands import fit_banded
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid
    from catalog.optics.colorimetry import delta_e_2000

    matrix = _noisy_matrix()
    bands_only = fit_banded(matrix)
    whole = fit_banded(matrix, residual=True)
    for name, light in _lights().items():
        exact = st._xyz(exact_exitance_on_grid(matrix, light))
        white = st.white_xyz(light, exact)
        assert delta_e_2000(st._xyz(whole.exitance_w_m2_nm(light)), exact, white) < 1.0, name
    light = _lights()["A"]
    exact = st._xyz(exact_exitance_on_grid(matrix, light))
    white = st.white_xyz(light, exact)
    assert (delta_e_2000(st._xyz(bands_only.exitance_w_m2_nm(light)), exact, white)
            > delta_e_2000(st._xyz(whole.exitance_w_m2_nm(light)), exact, white))


def test_physical_part_stays_physical():
    """The residual never enters the bands: every band non-negative, quantum yield <= 1,
    the same bands with and without the residual; the reflectance line >= 0."""
    from catalog.optics.bispectral.bands import fit_banded

    matrix = _noisy_matrix()
    plain = fit_banded(matrix)
    fit = fit_banded(matrix, residual=True)
    for a, b in zip(plain.components, fit.components):
        assert np.array_equal(a.absorption, b.absorption)
        assert np.min(b.absorption) >= 0 and np.min(b.emission_pdf) >= 0
    for material in fit.materials():
        assert 0 < material.quantum_yield <= 1
        assert np.max(material.absorptance) <= 1
    assert np.min(fit.reflectance) >= 0


def test_truncated_residual_is_the_leading_singular_pairs():
    from catalog.optics.bispectral.bands import fit_banded

    matrix = _noisy_matrix()
    whole = fit_banded(matrix, residual=True)
    two = fit_banded(matrix, residual=True, residual_rank=2)
    assert np.linalg.matrix_rank(two.residual, tol=1e-12) == 2
    s = np.linalg.svd(whole.residual, compute_uv=False)
    # Eckart-Young: the Frobenius error of the best rank-2 approximation
    assert np.linalg.norm(whole.residual - two.residual) == pytest.approx(
        math.sqrt(float(np.sum(s[2:] ** 2))), rel=1e-9)
    assert two.stored_numbers() < whole.stored_numbers()
    with pytest.raises(ValueError, match="rank"):
        fit_banded(matrix, residual=True, residual_rank=-1)


def test_light_with_no_uv_sees_no_uv_column():
    """A light with nothing below 430 nm: the UV bands emit nothing and the residual's UV
    columns add nothing (zeroing them changes the result by at most 1e-15 W m^-2 nm^-1)."""
    from catalog.optics.bispectral.bands import fit_banded
    from catalog.optics.fluorescence import emitted_exitance_w_m2_nm

    matrix = _noisy_matrix()
    fit = fit_banded(matrix, residual=True)
    light = np.where(GRID_NM >= 440, 1.0, 0.0)
    uv = [m for m in fit.materials() if np.max(m.absorptance[GRID_NM >= 440]) == 0]
    assert uv, "the fit has UV-only bands"
    for material in uv:
        assert np.max(np.abs(emitted_exitance_w_m2_nm(material, light))) == 0
    import dataclasses

    cut = dataclasses.replace(fit, residual=np.where(matrix.excitation_nm[None, :] < 430, 0.0,
                                                     fit.residual))
    assert np.max(np.abs(cut.residual_exitance_w_m2_nm(light)
                         - fit.residual_exitance_w_m2_nm(light))) <= 1e-15


def test_matrix_with_no_off_diagonal_has_a_zero_residual():
    """A pure reflector (diagonal only): the separable fit refuses it in one line (nothing to
    fit); a banded fit without bands plus its residual has a zero residual, no material, and
    is R x E at 1 nm, equal to the exact result to 1e-12 relative."""
    from catalog.optics.bispectral.bands import BandedFit, with_residual
    from catalog.optics.bispectral.matrix import DonaldsonMatrix, exact_exitance_on_grid, fit_separable

    lo = np.arange(380.0, 781.0, 10.0)
    li = np.arange(300.0, 781.0, 10.0)
    r = 0.2 + 0.6 * (lo - 380) / 400
    values = np.where(lo[:, None] == li[None, :], r[:, None], 0.0)
    matrix = DonaldsonMatrix(lo, li, values, "PLAIN", "diagonal only")
    with pytest.raises(InputError, match="not fluorescent") as info:
        fit_separable(matrix, colour_lights=None)
    assert "\n" not in str(info.value)
    empty = BandedFit("PLAIN", lo, li, 10.0, (), r.copy(), ())
    fit = with_residual(matrix, empty)
    assert np.max(np.abs(fit.residual)) == 0
    assert not fit.materials()
    for light in _lights().values():
        want = exact_exitance_on_grid(matrix, light)
        got = fit.exitance_w_m2_nm(light)
        assert np.max(np.abs(got - want)) <= 1e-12 * np.max(want)


# ------------------------------------------------------------------ the residual file

def test_residual_file_round_trip(tmp_path):
    from catalog.optics.bispectral.bands import fit_banded
    from catalog.optics.measured_residual import read_residual, write_residual

    fit = fit_banded(_noisy_matrix(), residual=True)
    path = tmp_path / "residual.csv"
    write_residual(path, fit.emission_nm, fit.excitation_nm, fit.residual, 10.0, ["test"])
    back = read_residual(path)
    assert np.array_equal(back.emission_nm, fit.emission_nm)
    assert np.array_equal(back.excitation_nm, fit.excitation_nm)
    # 6 significant digits
    assert np.max(np.abs(back.values - fit.residual)) <= 5e-6 * np.max(np.abs(fit.residual))
    light = _lights()["LED-405"]
    want = fit.residual_exitance_w_m2_nm(light)
    assert np.max(np.abs(back.exitance_w_m2_nm(light) - want)) <= 1e-5 * np.max(np.abs(want))


@pytest.mark.parametrize("text, message", [
    ("emission_nm,300,310\n380,0,0\n", "missing '# excitation bin width nm"),
    ("# excitation bin width nm: 10\nwavelength,300,310\n380,0,0\n", ":2: header"),
    ("# excitation bin width nm: 10\nemission_nm,310,300\n380,0,0\n", ":2: excitation axis must"),
    ("# excitation bin width nm: 10\nemission_nm,300,310\n380,0\n", ":3: row has 1 entries"),
    ("# excitation bin width nm: 10\nemission_nm,300,310\n380,0,x\n", ":3: row: 'x' is not"),
    ("# excitation bin width nm: 10\nemission_nm,300,310\n380,0,1.5\n", ":3: residual entries"),
    ("# excitation bin width nm: 10\nemission_nm,300,310\n380,0,nan\n", ":3: row: 'nan' is not finite"),
    ("# excitation bin width nm: -1\nemission_nm,300,310\n380,0,0\n", ":1: bin width must"),
    ("# excitation bin width nm: 10\nemission_nm,300,310\n", "no header or no rows"),
])
def test_bad_residual_file_is_refused_in_one_line(tmp_path, text, message):
    from catalog.optics.measured_residual import read_residual

    path = tmp_path / "residual.csv"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        read_residual(path)
    assert message in str(info.value)
    assert "\n" not in str(info.value)
    assert str(path) in str(info.value)


def test_bad_residual_field_in_a_preset_is_refused_naming_it(tmp_path):
    from catalog.presets.banded import banded_preset
    from catalog.optics.bispectral.bands import fit_banded
    from catalog.presets import find_preset, load_preset, preset_from_dict, preset_to_dict

    preset = banded_preset(load_preset(find_preset("lace-fwa")),
                           fit_banded(_noisy_matrix(), residual=True), tmp_path)
    # in the preset's own folder (catalog.presets.bundle)
    assert preset.fluorescence.extra["residual"] == f"{preset.name}/residual.csv"
    doc = preset_to_dict(preset)
    for value, message in ((3, "must be a path string"), ("gone.csv", "cannot read the residual")):
        doc["fluorescence"]["residual"] = value
        with pytest.raises(InputError, match="fluorescence.residual|gone.csv") as info:
            preset_from_dict(doc, preset.path)
        assert message in str(info.value) and "\n" not in str(info.value)


@pytest.mark.slow
def test_renderer_carries_bands_plus_residual_under_the_key(tmp_path):
    """The per-light pre-integration: the emission the shader gets for the key light at
    normal incidence is the bands' emission plus the residual's spectrum (float64
    reference: the fit's own sum), relative 1e-4 (CSV files at 6-8 digits); the absorbed
    photons (what the shader multiplies) are those of the bands alone, relative 1e-5."""
    from catalog.presets.banded import banded_preset
    from catalog.optics.bispectral.bands import fit_banded
    from catalog.presets import find_preset, load_preset
    from catalog.render import scene

    fit = fit_banded(_noisy_matrix(), residual=True)
    preset = banded_preset(load_preset(find_preset("lace-fwa")), fit, tmp_path)
    from catalog.optics.fluorescence import absorbed_photon_irradiance
    for name, key in _lights().items():
        inputs, decision = scene.build_shading_inputs(preset, key, np.array([0.0, 0.3, -1.0]),
                                                      is_sun=False)
        assert decision.used == "physical"
        n_key = inputs.absorbed_photons[0]
        effective = n_key / (1.0 + n_key / inputs.saturation_photons)
        got = inputs.emission_per_photon * effective * 2 * math.pi
        want = fit.emitted_w_m2_nm(key) + fit.residual_exitance_w_m2_nm(key)
        assert np.max(np.abs(got - want)) <= 1e-4 * np.max(np.abs(want)), name
        bands_only = absorbed_photon_irradiance(fit.effective_material(key), key)
        assert n_key == pytest.approx(bands_only, rel=1e-5)


# ------------------------------------------------------------------ with the real data

@needs_matrices
@pytest.mark.slow
def test_real_matrices_residual_model_meets_the_bounds_on_test_lights():
    """The chosen model on the 8 matrices x the issue's 8 test lights: mean Delta E 2000
    <= 1.5 (the issue's bound; bench 0.07) and every case below 1.0 (bench max 0.57); the
    bands stay physical (quantum yield <= 1, non-negative) and the reflectance line loses
    at most 0.002 to its clip at 0."""
    from benchmarks.uv_fluorescence import TEST_LIGHTS, light_spectrum
    from catalog.optics.bispectral import study as st
    from catalog.optics.bispectral.bands import (DEFAULT_RESIDUAL, DEFAULT_RESIDUAL_RANK,
                                                 fit_banded)
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid, list_bfc, read_bfc
    from catalog.optics.colorimetry import delta_e_2000

    errors = []
    for path in list_bfc():
        matrix = read_bfc(path)
        fit = fit_banded(matrix, residual=DEFAULT_RESIDUAL, residual_rank=DEFAULT_RESIDUAL_RANK)
        for component in fit.components:
            assert np.min(component.absorption) >= 0 and np.min(component.emission_pdf) >= 0
        for material in fit.materials():
            assert material.quantum_yield <= 1
        on_diagonal = matrix.stokes_shift_nm() == 0
        raw = np.sum(np.where(on_diagonal, matrix.values - fit.fluorescence_matrix(), 0), axis=1)
        assert np.max(fit.reflectance - raw) <= 0.002
        for name in TEST_LIGHTS:
            light = light_spectrum(name)
            exact = st._xyz(exact_exitance_on_grid(matrix, light))
            white = st.white_xyz(light, exact)
            errors.append(float(delta_e_2000(st._xyz(fit.exitance_w_m2_nm(light)), exact, white)))
    assert np.mean(errors) <= 1.5
    assert np.max(errors) < 1.0


# ------------------------------------------------------------ the near-diagonal study

def test_near_diagonal_study_sees_a_bandpass_smear_and_collapse_keeps_row_sums():
    """A matrix whose neighbours are a 10 nm triangular smear (0.25 of the diagonal on both
    sides) reads as +25% at +-10 nm and 0 beyond; collapsing the neighbours onto the diagonal
    keeps every row's sum (to 1e-15) and leaves the far entries untouched."""
    from benchmarks.uv_fluorescence import collapsed_band, near_diagonal_case
    from catalog.optics.bispectral.matrix import DonaldsonMatrix

    lo = np.arange(380.0, 781.0, 10.0)
    li = np.arange(300.0, 781.0, 10.0)
    shift = lo[:, None] - li[None, :]
    r = 0.3 + 0.5 * (li - 300) / 480
    values = np.where(shift == 0, 1.0, np.where(np.abs(shift) == 10, 0.25, 0.0)) * r[None, :]
    values = values + np.where(shift > 30, 1e-3, 0.0)
    matrix = DonaldsonMatrix(lo, li, values, "SMEAR", "triangular bandpass")
    study = near_diagonal_case(matrix)
    assert study["-1"]["median_ratio"] == pytest.approx(0.25, rel=1e-12)
    assert study["1"]["median_ratio"] == pytest.approx(0.25, rel=1e-12)
    assert study["2"]["median_ratio"] == 0 and study["-2"]["median_ratio"] == 0
    collapsed = collapsed_band(matrix)
    assert np.max(np.abs(collapsed.values.sum(axis=1) - values.sum(axis=1))) <= 1e-15
    far = np.abs(shift) > 10
    assert np.array_equal(collapsed.values[far], values[far])
    assert np.all(collapsed.values[np.abs(shift) == 10] == 0)


@needs_matrices
def test_committed_benchmark_verdict_and_choice():
    """The committed bench_uv.json: the whole residual chosen on the selection lights, the
    issue's bounds met (test mean <= 1.5, no case above its floor, goal 0.5 / 1.0, held-out
    not worse) and the physical part alone reported beside it (its test mean > 1.5: the
    goal is met by the residual, docs/bispectral.md)."""
    import json

    from catalog.core.resources import PROJECT_ROOT
    from catalog.optics.bispectral.bands import BANDS_CHOSEN, CHOSEN

    result = json.loads((PROJECT_ROOT / "benchmarks" / "bench_uv.json").read_text())
    summary = result["summary"]
    assert summary["choice"] == CHOSEN
    verdict = summary["verdict"]
    assert verdict["test_mean_met"] and verdict["goal_met"] and verdict["held_out_not_worse"]
    assert verdict["cases_over_floor"] == []
    assert summary["per_candidate"][BANDS_CHOSEN]["test"]["mean"] > 1.5
    assert "frame" in result
    ratios = [row["frame_ratio"] for row in result["frame"]["rows"]]
    assert max(abs(r - 1.0) for r in ratios) <= 0.05
