"""Bispectral (Donaldson) matrices: reader, exact rendering, separable fit, colour-error study.

The measured matrices are read in place from the validation data's bispectral/ folder (never copied;
skipped with the reason when it is absent).
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from catalog.core.resources import data_missing_reason

from catalog.optics.bispectral import matrix as bispectral
from catalog.optics.bispectral import study
from catalog.core.errors import InputError
from catalog.optics.fluorescence import (absorbed_photon_irradiance, emitted_exitance_w_m2_nm,
                                  emitted_photon_exitance, material_from_spectra,
                                  photon_energy_j)
from catalog.optics.spectra import GRID_NM, read_spectrum

NAMES = ("CIBA12", "CIPLAW10", "HERPICER", "HERPIORA", "IXCRLALE", "PHP8HP1C", "POLGREE",
         "TEXTYELL")
ISSUE_NAMES = ("CIBA12", "CIPLAW10", "TEXTYELL")
EMISSION_NM = np.arange(380.0, 781.0, 10.0)
EXCITATION_NM = np.arange(300.0, 781.0, 10.0)


@pytest.fixture(scope="module")
def matrices(shared_data):
    return {p.stem: bispectral.read_bfc(p) for p in bispectral.list_bfc(shared_data / "bispectral")}


@pytest.fixture(scope="module")
def fits(matrices):
    return {name: bispectral.fit_separable(m) for name, m in matrices.items()}


@pytest.fixture(scope="module")
def study_rows(shared_data):
    return study.study_all(study.STUDY_LIGHTS)


def _row(rows, material, light):
    (row,) = [r for r in rows if r["material"] == material and r["light"] == light]
    return row


# ------------------------------------------------------------------------------ reader

def test_reads_all_eight_matrices(matrices):
    assert sorted(matrices) == sorted(NAMES)
    for name, m in matrices.items():
        assert m.values.shape == (41, 49), name
        np.testing.assert_array_equal(m.emission_nm, EMISSION_NM)
        np.testing.assert_array_equal(m.excitation_nm, EXCITATION_NM)
        assert m.name == name and m.description
        diagonal = m.diagonal()
        assert diagonal.shape == (41,)
        # a reflectance: between 0 and a little over 1 everywhere
        assert np.all(diagonal > 0) and np.all(diagonal < 1.2), name
        # noise: small negative entries exist, none large
        assert m.values.min() > -0.06


def test_reader_matches_the_text(shared_data, matrices):
    """Spot values read back as in the file (an independent split of the text)."""
    lines = (shared_data / "bispectral" / "CIBA12.BFC").read_text().splitlines()
    row_400 = lines[12 + 2].split("\t")
    assert float(row_400[0]) == 400.0
    m = matrices["CIBA12"]
    for j in (0, 10, 48):
        assert m.values[2, j] == float(row_400[j + 1])


def _bad_file(tmp_path, shared_data, edit):
    lines = (shared_data / "bispectral" / "TEXTYELL.BFC").read_text().splitlines()
    lines = edit(lines)
    path = tmp_path / "BAD.BFC"
    path.write_text("\r\n".join(lines) + "\r\n")
    return path


@pytest.mark.parametrize("edit, line, words", [
    (lambda ls: ls[:30], 30, "truncated"),
    (lambda ls: ls[:5], 5, "truncated"),
    (lambda ls: ls[:10] + ["380\t780\t10\t49\t300"] + ls[11:], 11, "6 numbers"),
    (lambda ls: ls[:10] + ["380\t780\t10\t50\t300\t10"] + ls[11:], 12, "do not match"),
    (lambda ls: ls[:10] + ["380\t780\t10\t49\tabc\t10"] + ls[11:], 11, "not a number"),
    (lambda ls: ls[:20] + [ls[20].replace("\t", "\tx1e-3", 1).replace("x1e-3", "oops", 1)] + ls[21:],
     21, "not a number"),
    (lambda ls: ls[:20] + [ls[20].rsplit("\t", 1)[0]] + ls[21:], 21, "expected 50 fields"),
    (lambda ls: ls[:20] + ["999" + ls[20][3:]] + ls[21:], 21, "expected 460 nm"),
    (lambda ls: ls[:11] + ["x:y:" + ls[11][4:]] + ls[12:], 12, "r:c:"),
    (lambda ls: ls[:20] + [ls[20].replace("\t", "\tnan\t", 1)] + ls[21:], 21, "fields"),
    (lambda ls: ls[:-1] + ["garbage"], 54, "unexpected content"),
])
def test_bad_files_are_refused_with_file_and_line(tmp_path, shared_data, edit, line, words):
    path = _bad_file(tmp_path, shared_data, edit)
    with pytest.raises(InputError) as info:
        bispectral.read_bfc(path)
    message = str(info.value)
    assert message.startswith(f"{path}:{line}:"), message
    assert words in message


def test_nan_entry_is_refused(tmp_path, shared_data):
    path = _bad_file(tmp_path, shared_data,
                     lambda ls: ls[:25] + [ls[25].rsplit("\t", 1)[0] + "\tnan"] + ls[26:])
    with pytest.raises(InputError, match=re.escape(f"{path}:26:") + ".*not finite"):
        bispectral.read_bfc(path)


def test_empty_and_missing_files(tmp_path):
    empty = tmp_path / "EMPTY.BFC"
    empty.write_text("")
    with pytest.raises(InputError, match="empty file"):
        bispectral.read_bfc(empty)
    with pytest.raises(InputError, match="no such file"):
        bispectral.read_bfc(tmp_path / "NONE.BFC")
    if data_missing_reason("bispectral") is None:  # a name is looked up in the validation data
        with pytest.raises(InputError, match="known: CIBA12"):
            bispectral.find_bfc("NOT_A_MATRIX")
    else:
        with pytest.raises(InputError, match="validation data not found"):
            bispectral.find_bfc("NOT_A_MATRIX")


# --------------------------------------------------------------------------- rendering

def _hand_bin_means(light, centres, width=10.0):
    """Bin means by a fine trapezoid (0.01 nm) of the linearly interpolated light."""
    out = []
    for c in centres:
        lo, hi = max(c - width / 2, GRID_NM[0]), min(c + width / 2, GRID_NM[-1])  # 0 outside
        x = np.linspace(lo, hi, int(round((hi - lo) / 0.01)) + 1)
        y = np.interp(x, GRID_NM, light)
        out.append(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)) / width)
    return np.array(out)


def test_render_exact_against_a_hand_loop(matrices):
    light = study.light_irradiance("FL11")
    m = matrices["TEXTYELL"]
    bins = _hand_bin_means(light, m.excitation_nm)
    expected = np.zeros(m.emission_nm.size)
    for k in range(m.emission_nm.size):
        for i in range(m.excitation_nm.size):
            expected[k] += m.values[k, i] * bins[i]
    np.testing.assert_allclose(bispectral.render_exact(m, light), expected, rtol=1e-9, atol=1e-12)


def test_bins_take_a_line_whole_and_split_one_on_an_edge():
    centres = np.arange(300.0, 781.0, 10.0)
    line = np.zeros(GRID_NM.size)
    line[GRID_NM == 404.0] = 1.0  # a 1 nm line well inside the 400 nm bin [395, 405]
    means = bispectral.bin_irradiance(centres, line)
    assert means[10] == pytest.approx(0.1)  # integral 1 W m^-2 over a 10 nm bin
    assert np.count_nonzero(means) == 1
    edge = np.zeros(GRID_NM.size)
    edge[GRID_NM == 405.0] = 1.0  # on the edge: half to each neighbour
    means = bispectral.bin_irradiance(centres, edge)
    assert means[10] == pytest.approx(0.05) and means[11] == pytest.approx(0.05)
    # end bins are half outside the grid, where the light is zero (as everywhere)
    flat = np.ones(GRID_NM.size)
    expected = np.ones(centres.size)
    expected[[0, -1]] = 0.5
    np.testing.assert_allclose(bispectral.bin_irradiance(centres, flat), expected)
    np.testing.assert_array_equal(bispectral.bin_irradiance(centres, np.zeros(GRID_NM.size)), 0.0)


def test_exact_result_of_a_plain_reflector_is_reflectance_times_light():
    lo, li = EMISSION_NM, EXCITATION_NM
    reflectance = 0.2 + 0.6 * (lo - 380) / 400
    values = np.where(lo[:, None] == li[None, :], reflectance[:, None], 0.0)
    m = bispectral.DonaldsonMatrix(lo, li, values, "PLAIN", "a non-fluorescent ramp")
    light = study.light_irradiance("FL2")
    expected = np.interp(GRID_NM, lo, reflectance) * light
    expected[GRID_NM < 380] = 0.0
    np.testing.assert_allclose(bispectral.exact_exitance_on_grid(m, light), expected, rtol=1e-12)
    # huge light: linear
    np.testing.assert_allclose(bispectral.exact_exitance_on_grid(m, 1e6 * light), 1e6 * expected,
                               rtol=1e-12)


# -------------------------------------------------------------------------- separable fit

def _synthetic(noise=0.0, seed=3):
    lo, li = EMISSION_NM, EXCITATION_NM
    reflectance = 0.8 - 0.5 * np.exp(-((lo - 400) / 30) ** 2)
    absorptance = 0.9 * np.exp(-((li - 370) / 25) ** 2)
    pdf = np.exp(-((lo - 440) / 25) ** 2)
    pdf /= pdf.sum() * 10
    quantum_yield = 0.7
    values = (quantum_yield * absorptance[None, :] * pdf[:, None] * (li[None, :] / lo[:, None]) * 10
              + np.where(lo[:, None] == li[None, :], reflectance[:, None], 0.0))
    values = values + np.random.default_rng(seed).normal(0.0, noise, values.shape)
    return bispectral.DonaldsonMatrix(lo, li, values, "SYN", "synthetic"), reflectance, \
        quantum_yield * 0.9


def test_fit_recovers_a_synthetic_separable_matrix():
    m, reflectance, yield_absorptance = _synthetic()
    fit = bispectral.fit_separable(m, colour_lights=None)  # least squares on the entries
    assert fit.yield_absorptance == pytest.approx(yield_absorptance, rel=2e-3)
    assert fit.excitation_peak_nm == 370 and fit.emission_peak_nm == 440
    assert fit.rank1_residual < 1e-4
    np.testing.assert_allclose(fit.reflectance, reflectance, atol=1e-6)
    # with instrument-like noise (sigma 5e-4) the strength is still within 1%
    noisy, _, _ = _synthetic(noise=5e-4)
    fit = bispectral.fit_separable(noisy, colour_lights=None)
    assert fit.yield_absorptance == pytest.approx(yield_absorptance, rel=0.01)
    assert fit.noise_sigma == pytest.approx(5e-4, rel=0.25)
    assert fit.residual_over_noise < 1.3
    # the colour refinement (the default) leaves a noisy but truly separable matrix where
    # the data put it: same strength within 1%, reflectance within 0.5%
    refined = bispectral.refine_for_colour(noisy, fit)
    assert refined.yield_absorptance == pytest.approx(yield_absorptance, rel=0.01)
    np.testing.assert_allclose(refined.reflectance, reflectance, rtol=0.005, atol=2e-3)


def test_colour_refinement_never_sees_a_goal_light():
    """The refinement trains on lights disjoint from the goal set; the nearest Planckian
    to illuminant A (a 2856 K Planckian radiator) is at least 300 K away."""
    training = set(bispectral.COLOUR_TRAINING_LIGHTS)
    assert not training & set(study.GOAL_LIGHTS)
    temperatures = [float(n.split(":")[1]) for n in training if n.startswith("planck:")]
    assert min(abs(t - 2856.0) for t in temperatures) >= 300.0
    # and they are real, distinct spectra
    spectra = np.stack([bispectral.training_light(n) for n in sorted(training)])
    assert np.all(spectra >= 0) and np.all(spectra.sum(axis=1) > 0)
    noisy, _, _ = _synthetic(noise=5e-4)
    with pytest.raises(ValueError, match="at least one training light"):
        bispectral.refine_for_colour(noisy, lights=())


@pytest.mark.slow
def test_colour_refinement_keeps_the_model_and_stays_near_the_data(matrices, fits):
    """Same supports (one absorption band, one emission band), phi <= 1, the reflectance
    within 0.01 of the least-squares one, the strength within 5%, the entries still within
    3 noise sigmas rms; and over the eight matrices the colours under the TRAINING lights
    (physical mode, computed here through catalog.optics.fluorescence, not the refinement's own
    reduced sums) are at least 10% closer to the exact ones on average."""
    errors = {"plain": [], "refined": []}
    for name, m in matrices.items():
        plain = bispectral.fit_separable(m, colour_lights=None)
        refined = fits[name]
        np.testing.assert_array_equal(refined.absorption_weight > 0, plain.absorption_weight > 0)
        np.testing.assert_array_equal(refined.emission_weight > 0, plain.emission_weight > 0)
        assert refined.quantum_yield <= 1.0 and refined.residual_over_noise < 3.0
        assert refined.yield_absorptance == pytest.approx(plain.yield_absorptance, rel=0.05)
        np.testing.assert_allclose(refined.reflectance, plain.reflectance, rtol=0, atol=0.01,
                                   err_msg=name)
        for label, fit in (("plain", plain), ("refined", refined)):
            material, reflectance = fit.material(), fit.reflectance_on_grid()
            for light_name in bispectral.COLOUR_TRAINING_LIGHTS:
                light = bispectral.training_light(light_name)
                exact = study._xyz(bispectral.exact_exitance_on_grid(m, light))
                model = study._xyz(reflectance * light + emitted_exitance_w_m2_nm(material, light))
                errors[label].append(float(study.delta_e_2000(model, exact, light @ study.cmfs(GRID_NM))))
    assert np.mean(errors["refined"]) < 0.9 * np.mean(errors["plain"]), \
        (np.mean(errors["refined"]), np.mean(errors["plain"]))


def test_fit_refuses_a_matrix_with_no_re_radiation():
    lo, li = EMISSION_NM, EXCITATION_NM
    values = np.where(lo[:, None] == li[None, :], 0.8, 0.0)
    values = values + np.random.default_rng(1).normal(0, 5e-4, values.shape)
    m = bispectral.DonaldsonMatrix(lo, li, values, "GREY", "no fluorescence")
    with pytest.raises(InputError, match="not fluorescent"):
        bispectral.fit_separable(m)


@pytest.mark.parametrize("name", NAMES)
def test_fit_of_each_measured_matrix(fits, name):
    fit = fits[name]
    # rank-1 residual: within 3 noise sigmas rms on the fitted entries, < 55% relative
    # (PHP8HP1C's re-radiation is weak, so its relative residual is mostly noise)
    assert fit.residual_over_noise < 3.0
    assert fit.rank1_residual < (0.55 if name == "PHP8HP1C" else 0.25)
    assert 0.0 < fit.quantum_yield <= 1.0
    assert 0.0 < fit.peak_absorptance <= 1.0
    assert fit.quantum_yield * fit.peak_absorptance == pytest.approx(fit.yield_absorptance)
    assert np.all(fit.reflectance >= 0) and np.all(fit.reflectance < 1.2)
    assert fit.emission_peak_nm > fit.excitation_peak_nm  # Stokes shift


def test_fitted_peaks_where_the_data_readme_says(fits):
    for name in ("CIBA12", "CIPLAW10"):  # brightened whites: excitation 380-390, emission 430-440
        assert 370 <= fits[name].excitation_peak_nm <= 390
        assert 430 <= fits[name].emission_peak_nm <= 440
    assert 430 <= fits["TEXTYELL"].excitation_peak_nm <= 450  # excitation near 440 nm
    assert fits["TEXTYELL"].emission_peak_nm == 510


def test_absorption_islands_are_anti_stokes(matrices, fits):
    """Without the single-band rule the fit of the white plastic CIPLAW10 keeps small
    absorption islands, all to the red of its emission peak: absorbing there and emitting
    at the peak would turn each photon into one of higher energy (the anti-Stokes
    artefact of the data, not the brightener), which is why single_band is the default."""
    single = fits["CIPLAW10"]
    islands = bispectral.fit_separable(matrices["CIPLAW10"], single_band=False,
                                       colour_lights=None)
    extra = islands.excitation_nm[(islands.absorption_weight > 0) & (single.absorption_weight == 0)]
    assert extra.size > 0
    assert np.all(extra > islands.emission_peak_nm)
    # the main band is unchanged by the rule (within the refit's effect on the product)
    assert islands.excitation_peak_nm == single.excitation_peak_nm
    assert islands.yield_absorptance == pytest.approx(single.yield_absorptance, rel=0.05)


@pytest.mark.parametrize("light_name", study.STUDY_LIGHTS)
def test_fitted_materials_conserve_photons(fits, light_name):
    light = study.light_irradiance(light_name)
    for name, fit in fits.items():
        material = fit.material()
        absorbed = absorbed_photon_irradiance(material, light)
        emitted = emitted_photon_exitance(material, light)
        assert 0 <= emitted <= absorbed, name
        # an independent count of the emitted photons from the emitted spectrum
        spectrum = emitted_exitance_w_m2_nm(material, light)
        assert np.sum(spectrum / photon_energy_j(GRID_NM)) == pytest.approx(emitted, rel=1e-9)


def test_physical_mode_reproduces_the_fitted_matrix(fits):
    """Under a flat light the physical-mode emission equals the fitted re-radiation applied
    to the bin means (the two integrals of a(l) l E(l) differ by the quadrature only)."""
    flat = np.full(GRID_NM.size, 0.01)  # W m^-2 nm^-1
    for name, fit in fits.items():
        emitted = emitted_exitance_w_m2_nm(fit.material(), flat)
        bins = bispectral.bin_irradiance(fit.excitation_nm, flat)
        matrix_emission = fit.fluorescence_matrix() @ bins
        at_samples = np.interp(fit.emission_nm, GRID_NM, emitted)
        np.testing.assert_allclose(at_samples, matrix_emission, rtol=0.01,
                                   atol=1e-3 * matrix_emission.max(), err_msg=name)


def test_export_round_trip_through_the_fabric_files(tmp_path, matrices, fits):
    m, fit = matrices["TEXTYELL"], fits["TEXTYELL"]
    paths = bispectral.to_fabric_measurements(m, tmp_path / "textyell", fit)
    assert sorted(p.name for p in paths.values()) == ["emission.csv", "excitation.csv",
                                                      "reflectance.csv"]
    excitation = read_spectrum(paths["excitation"], normalise=True)
    emission = read_spectrum(paths["emission"], normalise=True)
    reflectance = read_spectrum(paths["reflectance"])
    assert any("TEXTYELL.BFC" in c for c in excitation.comments)
    assert any("quantity: photons" in c for c in emission.comments)
    material = material_from_spectra(excitation, emission, peak_absorptance=fit.peak_absorptance,
                                     quantum_yield=fit.quantum_yield,
                                     saturation_photon_irradiance=math.inf)
    light = study.light_irradiance("D65")
    np.testing.assert_allclose(emitted_exitance_w_m2_nm(material, light),
                               emitted_exitance_w_m2_nm(fit.material(), light), rtol=1e-6,
                               atol=1e-12)
    np.testing.assert_allclose(reflectance.values, fit.reflectance, rtol=1e-6, atol=1e-8)
    assert not list((tmp_path / "textyell").glob(".*"))  # no temporary left behind


# ------------------------------------------------------------------- colour-error study

def test_chain_is_exact_for_an_exactly_separable_matrix():
    """A matrix that IS the separable model: physical mode matches it to quadrature error."""
    m, _, _ = _synthetic()
    models = study.prepare(m)
    for light_name in study.STUDY_LIGHTS:
        light = study.light_irradiance(light_name)
        exact = study._xyz(bispectral.exact_exitance_on_grid(m, light))
        white = study.white_xyz(light, exact)
        error = float(study.delta_e_2000(study.method_xyz(models, "physical", light), exact, white))
        # 10 nm bins against 1 nm interpolation of a(l): tiny except for a line-like UV lamp
        assert error < (0.3 if light_name == "UV-A" else 0.05), light_name


@pytest.mark.slow
def test_goal_lights_mean_and_max(study_rows):
    """Issue 2's goal for the separable fit in physical mode, 8 matrices x 5 lights:
    mean <= 0.5, max <= 1.0, and below the paper mode (both scales) in every case but the
    per-material scale at D65, where that scale was fitted to the answer."""
    goal = [r for r in study_rows if r["light"] in study.GOAL_LIGHTS]
    assert len(goal) == 40
    physical = np.array([r["physical"] for r in goal])
    assert physical.mean() <= study.GOAL_MEAN
    assert physical.max() <= study.GOAL_MAX
    for r in goal:
        assert r["physical"] < r["paper_global"], r
        if r["light"] != "D65":
            assert r["physical"] < r["paper"], r
    # the least-squares fit alone (the previous default) does not reach the max
    assert max(r["physical_lsq"] for r in goal) > study.GOAL_MAX
    # and the state of the art's reading of the same set: ignoring fluorescence 11.6 / 26.0
    ignore = np.array([r["ignore"] for r in goal])
    assert ignore.mean() == pytest.approx(11.6, abs=0.5)
    assert ignore.max() == pytest.approx(26.0, abs=1.0)


def test_physical_beats_paper_mode(study_rows):
    """Below the paper mode: everywhere against eq. 8 with one scale for all materials, and
    wherever the per-material scale was not fitted to the answer (D65), except the sun at
    500 km on the brightened whites, where the data's anti-Stokes part dominates."""
    for r in study_rows:
        data_limited = r["light"] == "sun:500" and r["material"] in ("CIBA12", "CIPLAW10")
        if data_limited:
            assert r["data_antistokes"] >= 0.9 * r["physical"], r
            continue
        assert r["physical"] < r["paper_global"], r
        if r["light"] != "D65":
            assert r["physical"] < r["paper"], r


@pytest.mark.parametrize("name", ISSUE_NAMES)
def test_issue_materials_all_lights(study_rows, name):
    """CIBA12, CIPLAW10, TEXTYELL under every light of the issue, with stated bounds."""
    bounds = {"D65": 0.5, "A": 1.2, "FL2": 0.5, "FL11": 0.8, "LED-B4": 0.5,
              "UV-A": 5.5,      # rank 1 misses part of the UV-excited emission; the colour
                                # refinement, trained on no UV lamp, moves CIPLAW10 3.8 -> 5.1
                                # (the data's own noise floor under UV-A: p95 6.5)
              "sun:22": 0.5,
              "sun:500": 7.5}   # data-limited for the whites (see test_physical_beats_paper_mode)
    for light_name, bound in bounds.items():
        r = _row(study_rows, name, light_name)
        assert r["physical"] <= bound, r
        assert r["physical"] < r["ignore"], r
        # the RGB pipeline (pre-integrated per material and light, float32) adds nothing
        assert abs(r["physical_rgb"] - r["physical"]) < 0.02, r


def test_reduced_matrix_of_a_grey_reflector_is_the_identity_times_its_reflectance():
    lo, li = EMISSION_NM, EXCITATION_NM
    values = np.where(lo[:, None] == li[None, :], 0.6, 0.0)
    grey = bispectral.DonaldsonMatrix(lo, li, values, "GREY", "flat 0.6")
    reduced = study.reduced_matrix(grey)
    # the CMFs are zero below 360 nm, where the grey reflector (from 380 nm) is not defined,
    # so only the 360-380 nm tail of the basis lights makes it differ from 0.6 I
    np.testing.assert_allclose(reduced, 0.6 * np.eye(3), atol=2e-3)


def test_reduced_3x3_reproduces_the_published_figures(study_rows):
    """Our reading of Fichet et al.'s reduction against their figures on the same set
    (model.md section 8): 3.0 / 13.0, and 3.3 / 8.0 with a UV band (their UV band is not
    ours, so a wider tolerance there)."""
    goal = [r for r in study_rows if r["light"] in study.GOAL_LIGHTS]
    reduced = np.array([r["reduced_3x3"] for r in goal])
    assert reduced.mean() == pytest.approx(3.0, abs=0.3)
    assert reduced.max() == pytest.approx(13.0, abs=1.0)
    with_uv = np.array([r["reduced_3x3_uv"] for r in goal])
    assert with_uv.mean() == pytest.approx(3.3, abs=0.8)
    assert with_uv.max() == pytest.approx(8.0, abs=1.0)
    # the separable fit in physical mode: several times lower on the mean and the max
    physical = np.array([r["physical"] for r in goal])
    assert physical.mean() < with_uv.mean() / 5 and physical.max() < with_uv.max() / 5


def test_rgb_product_is_worse_than_pre_integration(study_rows):
    goal = [r for r in study_rows if r["light"] in study.GOAL_LIGHTS]
    assert np.mean([r["rgb_product"] for r in goal]) > 3 * np.mean([r["physical"] for r in goal])


@pytest.mark.data
@pytest.mark.slow
def test_table_tool_prints_markdown_and_json(tmp_path):
    import json
    import subprocess
    import sys

    from catalog.core.resources import PROJECT_ROOT

    out = tmp_path / "table.json"
    doc = tmp_path / "doc.md"
    doc.write_text("intro\n<!-- bispectral-table:begin -->\nold\n<!-- bispectral-table:end -->\nend\n")
    result = subprocess.run([sys.executable, str(PROJECT_ROOT / "tools" / "bispectral_table.py"),
                             "--json", str(out), "--update-doc", str(doc), "--noise-draws", "2"],
                            capture_output=True, text=True, check=True)
    assert "| (c) physical |" in result.stdout
    payload = json.loads(out.read_text())
    assert len(payload["rows"]) == 8 * len(study.STUDY_LIGHTS)
    text = doc.read_text()
    assert text.startswith("intro\n") and text.endswith("end\n") and "old" not in text
    assert "### Per matrix and light" in text
    assert set(payload["noise_floor"]) == set(study.STUDY_LIGHTS)


@pytest.mark.data
@pytest.mark.slow
def test_command_json_and_export(tmp_path, capsys):
    import json

    from catalog.commands.cli import main

    assert main(["bispectral", "CIBA12", "--json", "--lights", "D65,A",
                 "--export", str(tmp_path / "ciba")]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["name"] == "CIBA12" and payload["shape"] == [41, 49]
    assert [r["light"] for r in payload["delta_e_2000"]] == ["D65", "A"]
    assert payload["fit"]["quantum_yield"] <= 1.0
    assert (tmp_path / "ciba" / "emission.csv").is_file()
    assert main(["bispectral", "NOPE"]) == 2
    assert "NOPE" in capsys.readouterr().err
