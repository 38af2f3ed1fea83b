"""Fluorescence: paper mode (eq. 1-4) against colour-science and hand sums, physical mode
against conservation, linearity, saturation and the edge cases (zero light, huge light,
empty spectra)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.core.resources import FABRIC_DIR
from catalog.optics import fluorescence as fl
from catalog.optics.colorimetry import M_PAPER_XYZ_TO_RGB
from catalog.core.errors import CatalogError, InputError
from catalog.optics.lights import get_light
from catalog.optics.spectra import GRID_NM, Spectrum, read_spectrum

LACE = FABRIC_DIR / "measurements" / "lace-fwa"


def _raw_csv(path):
    """An independent reader: split lines by hand, skipping comments and the header."""
    rows = [line.split(",") for line in path.read_text().splitlines()
            if line.strip() and not line.startswith("#")]
    assert rows[0] == ["wavelength_nm", "intensity"]
    numeric = np.array(rows[1:], dtype=np.float64)
    return numeric[:, 0], numeric[:, 1]


@pytest.fixture(scope="module")
def calcofluor(shared_data):
    folder = shared_data / "brightener"
    return (read_spectrum(folder / "calcofluor_white_excitation.csv", normalise=True),
            read_spectrum(folder / "calcofluor_white_emission.csv", normalise=True),
            folder)


@pytest.fixture(scope="module")
def lace():
    excitation = read_spectrum(LACE / "excitation.csv", normalise=True)
    emission = read_spectrum(LACE / "emission.csv", normalise=True)
    return excitation, emission


@pytest.fixture(scope="module")
def lace_material(lace):
    return fl.material_from_spectra(*lace, quantum_yield=0.6, peak_absorptance=0.5)


# ----------------------------------------------------------------------------- paper mode

def _colour_science_paper_colour(path):
    """Eq. 1-3 with colour-science's own sd_to_XYZ and XYZ_to_RGB (the paper's matrix)."""
    import colour

    wl, values = _raw_csv(path)
    visible = np.arange(380.0, 781.0, 1.0)
    le = np.interp(visible, wl, values / values.max(), left=0.0, right=0.0)
    shape = colour.SpectralShape(380, 780, 1)
    sd = colour.SpectralDistribution(dict(zip(visible, le)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().trim(shape)
    equal_energy = colour.sd_ones(shape)
    xyz = colour.sd_to_XYZ(sd, cmfs, equal_energy, method="Integration")
    xyz = xyz * 100.0 / xyz[1]  # eq. 3: Y = 100
    paper_space = colour.RGB_Colourspace(
        "paper eq. 2", colour.RGB_COLOURSPACES["sRGB"].primaries,
        colour.RGB_COLOURSPACES["sRGB"].whitepoint,
        matrix_RGB_to_XYZ=np.linalg.inv(M_PAPER_XYZ_TO_RGB), matrix_XYZ_to_RGB=M_PAPER_XYZ_TO_RGB)
    rgb = colour.XYZ_to_RGB(xyz, paper_space, illuminant=None, chromatic_adaptation_transform=None)
    return xyz, rgb


def test_paper_colour_of_measured_calcofluor_matches_colour_science(calcofluor):
    _, emission, folder = calcofluor
    xyz, rgb = fl.paper_colour(emission)
    ref_xyz, ref_rgb = _colour_science_paper_colour(folder / "calcofluor_white_emission.csv")
    np.testing.assert_allclose(xyz, ref_xyz, rtol=1e-3)
    np.testing.assert_allclose(rgb, ref_rgb, rtol=1e-3)
    assert xyz[1] == pytest.approx(100.0, rel=1e-12)
    # model.md: the measured Calcofluor White gives F ~ (39, -52, 1792), out of gamut.
    np.testing.assert_allclose(rgb, [39.0, -52.0, 1792.0], atol=1.0)


def test_paper_colour_of_lace_matches_colour_science(lace):
    xyz, rgb = fl.paper_colour(lace[1])
    ref_xyz, ref_rgb = _colour_science_paper_colour(LACE / "emission.csv")
    np.testing.assert_allclose(xyz, ref_xyz, rtol=1e-3)
    np.testing.assert_allclose(rgb, ref_rgb, rtol=1e-3)
    assert rgb[1] < 0 < rgb[2]  # a blue brightener's emission is outside the sRGB gamut


def test_paper_colour_ignores_scale_and_light_outside_380_780():
    wl = np.arange(300.0, 801.0, 1.0)
    base = np.exp(-0.5 * ((wl - 450.0) / 20.0) ** 2)
    uv_and_ir = np.where((wl < 380) | (wl > 780), 5.0, 0.0)
    a = fl.paper_colour(Spectrum(wl, base))
    b = fl.paper_colour(Spectrum(wl, 7.5 * base + uv_and_ir))
    np.testing.assert_allclose(a[0], b[0], rtol=1e-12)
    np.testing.assert_allclose(a[1], b[1], rtol=1e-12)


def _hand_eq4(light_wl, light_values, excitation_path):
    """Eq. 4 by a plain Python loop over l = 380..780 nm."""
    ex_wl, ex_values = _raw_csv(excitation_path)
    peak = max(ex_values)
    numerator = denominator = 0.0
    for nm in range(380, 781):
        light = float(np.interp(nm, light_wl, light_values))
        excitation = float(np.interp(nm, ex_wl, ex_values, left=0.0, right=0.0)) / peak
        numerator += light * excitation
        denominator += light
    return numerator / denominator


@pytest.mark.parametrize("which", ["calcofluor", "lace"])
def test_paper_intensity_under_d65_matches_a_hand_sum(which, calcofluor, lace):
    import colour

    if which == "calcofluor":
        excitation, path = calcofluor[0], calcofluor[2] / "calcofluor_white_excitation.csv"
    else:
        excitation, path = lace[0], LACE / "excitation.csv"
    d65 = colour.SDS_ILLUMINANTS["D65"]
    hand = _hand_eq4(np.asarray(d65.wavelengths), np.asarray(d65.values), path)
    ours = fl.paper_intensity(get_light("D65").irradiance_w_m2_nm, excitation.resample(GRID_NM))
    assert ours == pytest.approx(hand, rel=1e-3)
    assert 0 < ours < 1


def test_paper_intensity_ignores_the_scale_of_the_light_and_the_uv(lace):
    excitation = lace[0].resample(GRID_NM)
    e = get_light("D65").irradiance_w_m2_nm
    base = fl.paper_intensity(e, excitation)
    assert fl.paper_intensity(1e3 * e, excitation) == pytest.approx(base, rel=1e-12)
    more_uv = e + np.where(GRID_NM < 380, 50.0, 0.0)  # eq. 4 starts at 380 nm
    assert fl.paper_intensity(more_uv, excitation) == pytest.approx(base, rel=1e-12)


def test_paper_intensity_refuses_a_light_dark_in_the_visible(lace):
    uv_only = np.where(GRID_NM < 380, 1.0, 0.0)
    with pytest.raises(CatalogError, match="380-780"):
        fl.paper_intensity(uv_only, lace[0].resample(GRID_NM))
    with pytest.raises(CatalogError, match="zero everywhere"):
        fl.paper_intensity(np.ones(GRID_NM.size), np.zeros(GRID_NM.size))
    with pytest.raises(CatalogError, match="normalise"):
        fl.paper_intensity(np.ones(GRID_NM.size), 3.0 * lace[0].resample(GRID_NM))


def test_paper_colour_refuses_empty_and_dark_emission():
    with pytest.raises(InputError):
        fl.paper_colour(Spectrum(np.array([]), np.array([])))
    with pytest.raises(InputError):
        fl.paper_colour(Spectrum(np.array([400.0, 500.0]), np.zeros(2)))
    with pytest.raises(InputError, match="no luminance"):
        fl.paper_colour(Spectrum(np.array([300.0, 350.0]), np.ones(2)))


# -------------------------------------------------------------------------- physical mode

def _hand_absorbed(material, irradiance):
    from scipy.constants import c, h  # independent constants

    total = 0.0
    for nm, a, e in zip(GRID_NM, material.absorptance, irradiance):
        total += a * e * (nm * 1e-9) / (h * c)  # photons per nm, times dl = 1 nm
    return total


LIGHTS = ("D65", "A", "FL2", "LED-B4", "UV-A", "sun:22", "sun:500")


@pytest.mark.parametrize("light", LIGHTS)
def test_absorbed_photons_match_a_hand_sum(lace_material, light):
    e = get_light(light).irradiance_w_m2_nm
    assert fl.absorbed_photon_irradiance(lace_material, e) == pytest.approx(
        _hand_absorbed(lace_material, e), rel=1e-12)


def _photons_in(exitance):
    from scipy.constants import c, h

    return float(np.sum(exitance * GRID_NM * 1e-9 / (h * c)))


@pytest.mark.parametrize("light", LIGHTS)
def test_conservation_emitted_photons_and_energy_never_exceed_absorbed(lace_material, light):
    e = get_light(light).irradiance_w_m2_nm
    absorbed = fl.absorbed_photon_irradiance(lace_material, e)
    exitance = fl.emitted_exitance_w_m2_nm(lace_material, e)
    emitted = _photons_in(exitance)
    assert emitted <= absorbed
    assert emitted == pytest.approx(0.6 * absorbed, rel=1e-6)  # N_sat >> N_abs here
    absorbed_w = float(np.sum(lace_material.absorptance * e))
    assert float(np.sum(exitance)) <= absorbed_w  # the Stokes shift loses energy too


def test_quantum_yield_one_without_saturation_conserves_photons_exactly(lace):
    material = fl.material_from_spectra(*lace, quantum_yield=1.0, peak_absorptance=1.0,
                                        saturation_photon_irradiance=math.inf)
    for light in LIGHTS:
        e = get_light(light).irradiance_w_m2_nm
        absorbed = fl.absorbed_photon_irradiance(material, e)
        assert _photons_in(fl.emitted_exitance_w_m2_nm(material, e)) == pytest.approx(
            absorbed, rel=1e-12)


@pytest.mark.parametrize("scale", [1e-6, 0.37, 7.0, 1e4])
def test_linear_in_irradiance_below_saturation(lace, scale):
    material = fl.material_from_spectra(*lace, saturation_photon_irradiance=math.inf)
    e = get_light("D65").irradiance_w_m2_nm
    base = fl.emitted_exitance_w_m2_nm(material, e)
    scaled = fl.emitted_exitance_w_m2_nm(material, scale * e)
    np.testing.assert_allclose(scaled, scale * base, rtol=1e-12, atol=0)
    assert fl.emission_xyz(material, scale * e) == pytest.approx(
        scale * fl.emission_xyz(material, e), rel=1e-12)


def test_default_saturation_is_invisible_for_real_lights(lace_material):
    e = get_light("sun:22").irradiance_w_m2_nm  # the brightest light of the library
    absorbed = fl.absorbed_photon_irradiance(lace_material, e)
    effective = fl.effective_absorbed_photons(lace_material, absorbed)
    assert 1 - effective / absorbed < 1e-7


def test_saturation_halves_at_n_sat_and_limits_huge_light(lace):
    e = get_light("D65").irradiance_w_m2_nm
    unsaturated = fl.material_from_spectra(*lace, quantum_yield=0.8,
                                           saturation_photon_irradiance=math.inf)
    n_abs = fl.absorbed_photon_irradiance(unsaturated, e)
    material = fl.material_from_spectra(*lace, quantum_yield=0.8,
                                        saturation_photon_irradiance=n_abs)
    assert fl.emitted_photon_exitance(material, e) == pytest.approx(0.8 * n_abs / 2, rel=1e-12)
    rates = [fl.emitted_photon_exitance(material, k * e) for k in (1.0, 10.0, 1e3, 1e6, 1e9)]
    assert all(b > a for a, b in zip(rates, rates[1:]))  # still grows, ever more slowly
    limit = 0.8 * n_abs
    assert all(r < limit for r in rates)
    assert rates[-1] == pytest.approx(limit, rel=1e-8)  # QY * N_sat for a huge light
    assert _photons_in(fl.emitted_exitance_w_m2_nm(material, 1e9 * e)) == pytest.approx(
        rates[-1], rel=1e-12)


def test_zero_light_gives_zero(lace_material):
    dark = np.zeros(GRID_NM.size)
    assert fl.absorbed_photon_irradiance(lace_material, dark) == 0.0
    assert not np.any(fl.emitted_exitance_w_m2_nm(lace_material, dark))
    assert not np.any(fl.emission_linear_srgb(lace_material, dark))
    assert fl.fluorescence_delta_e(lace_material, dark) == 0.0
    assert not fl.fluorescence_needed(lace_material, dark)


def test_emitted_energy_spectrum_has_the_shape_of_the_emission_file(lace, lace_material):
    """The emission CSV is an energy spectrum: M(l) must be proportional to it."""
    _, emission = lace
    exitance = fl.emitted_exitance_w_m2_nm(lace_material, get_light("D65").irradiance_w_m2_nm)
    shape = emission.resample(GRID_NM)
    inside = shape > 1e-3
    ratio = exitance[inside] / shape[inside]
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-12)


def test_photon_emission_files_are_taken_as_photons(tmp_path, lace):
    wl = np.arange(400.0, 601.0, 1.0)
    values = np.exp(-0.5 * ((wl - 480.0) / 30.0) ** 2)
    lines = ["# quantity: photons per nm, relative", "wavelength_nm,intensity"]
    lines += [f"{w},{v}" for w, v in zip(wl, values)]
    path = tmp_path / "em.csv"
    path.write_text("\n".join(lines) + "\n")
    emission = read_spectrum(path, normalise=True)
    assert fl.emission_is_photon_spectrum(emission)
    material = fl.material_from_spectra(lace[0], emission)
    inside = (GRID_NM >= 400) & (GRID_NM <= 600)
    pdf = material.emission_pdf_per_nm[inside]
    np.testing.assert_allclose(pdf / pdf.max(), values / values.max(), rtol=1e-12)
    energy = fl.material_from_spectra(lace[0], emission, emission_in_photons=False)
    np.testing.assert_allclose(energy.emission_pdf_per_nm[inside] / material.emission_pdf_per_nm[inside],
                               wl / np.sum(values * wl) * np.sum(values), rtol=1e-12)


def test_absolute_colour_scale_matches_the_light_library():
    light = get_light("A")
    assert fl.light_xyz(light.irradiance_w_m2_nm)[1] == pytest.approx(light.illuminance_lx, rel=1e-12)


def test_relative_emission_does_not_change_with_the_light_level(lace_material):
    e = get_light("D65").irradiance_w_m2_nm
    # Only saturation bends it: by 20 N_abs / N_sat = 8e-9 relative under 20 x D65.
    n_abs = fl.absorbed_photon_irradiance(lace_material, e)
    bound = 20 * n_abs / lace_material.saturation_photon_irradiance
    np.testing.assert_allclose(fl.emission_relative_srgb(lace_material, 20 * e),
                               fl.emission_relative_srgb(lace_material, e), rtol=bound)
    with pytest.raises(CatalogError, match="no visible part"):
        fl.emission_relative_srgb(lace_material, np.where(GRID_NM < 355, 1.0, 0.0))


def test_material_validation(lace):
    excitation, emission = lace
    good = fl.material_from_spectra(excitation, emission)
    with pytest.raises(CatalogError, match="quantum_yield"):
        fl.FluorescentMaterial(good.absorptance, good.emission_pdf_per_nm, 1.01)
    with pytest.raises(CatalogError, match="absorptance"):
        fl.FluorescentMaterial(good.absorptance * 3, good.emission_pdf_per_nm, 0.5)
    with pytest.raises(CatalogError, match="absorbs nothing"):
        fl.FluorescentMaterial(np.zeros(GRID_NM.size), good.emission_pdf_per_nm, 0.5)
    with pytest.raises(CatalogError, match="integrate to 1"):
        fl.FluorescentMaterial(good.absorptance, 2 * good.emission_pdf_per_nm, 0.5)
    with pytest.raises(CatalogError, match="GRID_NM"):
        fl.FluorescentMaterial(good.absorptance[:-1], good.emission_pdf_per_nm, 0.5)
    with pytest.raises(CatalogError, match="saturation"):
        fl.FluorescentMaterial(good.absorptance, good.emission_pdf_per_nm, 0.5, 0.0)
    with pytest.raises(CatalogError, match="peak_absorptance"):
        fl.material_from_spectra(excitation, emission, peak_absorptance=0.0)
    with pytest.raises(CatalogError, match="peak_absorptance"):
        fl.material_from_spectra(excitation, emission, peak_absorptance=1.2)
    assert good.absorptance.max() == pytest.approx(fl.DEFAULT_PEAK_ABSORPTANCE)
    with pytest.raises(ValueError):
        good.absorptance[0] = 1.0  # read-only: the material is immutable


def test_empty_zero_and_out_of_range_spectra_are_refused(lace):
    excitation, emission = lace
    empty = Spectrum(np.array([]), np.array([]), source="empty.csv")
    zero = Spectrum(np.array([400.0, 500.0]), np.zeros(2), source="zero.csv")
    infrared = Spectrum(np.array([900.0, 1000.0]), np.ones(2), source="ir.csv")
    for bad in (empty, zero, infrared):
        with pytest.raises(InputError, match=bad.source):
            fl.material_from_spectra(bad, emission)
        with pytest.raises(InputError, match=bad.source):
            fl.material_from_spectra(excitation, bad)


def test_bad_irradiance_is_refused(lace_material):
    with pytest.raises(CatalogError, match="GRID_NM"):
        fl.absorbed_photon_irradiance(lace_material, np.ones(10))
    with pytest.raises(CatalogError, match=">= 0"):
        fl.absorbed_photon_irradiance(lace_material, -np.ones(GRID_NM.size))
    with pytest.raises(CatalogError, match="NaN"):
        fl.emitted_exitance_w_m2_nm(lace_material, np.full(GRID_NM.size, np.nan))


# ------------------------------------------------------------ which lights need fluorescence

def _material(name, **params):
    folder = FABRIC_DIR / "measurements" / name
    return fl.material_from_spectra(read_spectrum(folder / "excitation.csv", normalise=True),
                                    read_spectrum(folder / "emission.csv", normalise=True),
                                    **params)


@pytest.mark.parametrize("light,needed", [("LED-B4", False), ("LED-warm", False),
                                          ("D65", True), ("sun:22", True), ("UV-A", True),
                                          ("A", True)])
def test_uv_excited_brightener_needs_fluorescence_only_where_the_light_has_uv(
        lace_material, light, needed):
    assert fl.fluorescence_needed(lace_material, get_light(light).irradiance_w_m2_nm) is needed


def test_measured_calcofluor_under_a_white_led_is_not_needed(calcofluor):
    material = fl.material_from_spectra(calcofluor[0], calcofluor[1])
    assert not fl.fluorescence_needed(material, get_light("LED-B4").irradiance_w_m2_nm)
    assert fl.fluorescence_needed(material, get_light("D65").irradiance_w_m2_nm)


@pytest.mark.parametrize("name", ["safety-yellow", "fluoro-pink"])
@pytest.mark.parametrize("light", ["LED-B4", "LED-warm", "FL11"])
def test_visible_excited_dyes_need_fluorescence_under_leds(name, light):
    material = _material(name, quantum_yield=0.6, peak_absorptance=0.9)
    assert fl.fluorescence_delta_e(material, get_light(light).irradiance_w_m2_nm) > 1.0


# -------------------------------------------------------------------------- carry methods

def test_carry_methods():
    rgb = np.array([0.39, -0.52, 17.92])
    np.testing.assert_array_equal(fl.carry_emission_rgb(rgb, "signed"), rgb)
    np.testing.assert_array_equal(fl.carry_emission_rgb(rgb, "clip"), [0.39, 0.0, 17.92])
    mapped = fl.carry_emission_rgb(rgb, "desaturate")
    assert mapped.min() == pytest.approx(0.0, abs=1e-12)
    assert fl.linear_srgb_luminance(mapped) == pytest.approx(fl.linear_srgb_luminance(rgb), rel=1e-12)
    # in gamut: unchanged by every method
    inside = np.array([0.2, 0.3, 0.4])
    for method in fl.CARRY_METHODS:
        np.testing.assert_allclose(fl.carry_emission_rgb(inside, method), inside, rtol=1e-15)
    with pytest.raises(CatalogError, match="unknown carry method"):
        fl.carry_emission_rgb(rgb, "magic")


# ------------------------------------------------------------------- property: conservation

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


def _bump(center, width, grid=GRID_NM):
    return np.exp(-0.5 * ((grid - center) / width) ** 2)


@settings(max_examples=60, deadline=None)
@given(ex_center=st.floats(300, 700), ex_width=st.floats(3, 80),
       em_center=st.floats(380, 780), em_width=st.floats(3, 80),
       # no subnormal yields (below 2.2e-308): their products lose relative precision (a
       # subnormal has fewer significant bits), so no relative bound holds for them
       peak_absorptance=st.floats(0.01, 1.0),
       quantum_yield=st.floats(0.0, 1.0, allow_subnormal=False),
       log_n_sat=st.floats(14, 30), light_center=st.floats(300, 780),
       light_width=st.floats(2, 300), log_level=st.floats(-6, 6))
def test_emitted_photons_never_exceed_absorbed_for_any_material_and_light(
        ex_center, ex_width, em_center, em_width, peak_absorptance, quantum_yield, log_n_sat,
        light_center, light_width, log_level):
    excitation = Spectrum(GRID_NM, _bump(ex_center, ex_width))
    emission = Spectrum(GRID_NM, _bump(em_center, em_width))
    material = fl.material_from_spectra(excitation, emission, peak_absorptance=peak_absorptance,
                                        quantum_yield=quantum_yield,
                                        saturation_photon_irradiance=10.0 ** log_n_sat)
    light = 10.0 ** log_level * _bump(light_center, light_width)
    absorbed = fl.absorbed_photon_irradiance(material, light)
    emitted = _photons_in(fl.emitted_exitance_w_m2_nm(material, light))
    assert emitted <= absorbed * (1 + 1e-12)
    assert emitted <= quantum_yield * material.saturation_photon_irradiance * (1 + 1e-12)
    assert np.all(material.absorptance <= 1.0)
