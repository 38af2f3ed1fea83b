"""The display step's numpy side (catalog/render/display.py) against colour-science.

Tolerances, set before running: the copied matrices are equal to a fresh copy (bit for bit);
CAT16 and OKLab agree with colour-science's implementations to 1e-10 (float64 rounding of a
few 3x3 products); the gamut compression keeps OKLab L and hue to 1e-9 and leaves colours
inside R_KNEE of the boundary untouched (exactly); the meter returns the EV of a uniform frame
to within one histogram bin (36 / 128 EV).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.render import display


def test_tables_equal_a_fresh_copy_from_colour_science():
    fresh = display.build_display_tables()
    cached = display.tables()
    assert sorted(fresh) == sorted(cached)
    for key, value in fresh.items():
        np.testing.assert_array_equal(cached[key], value, err_msg=key)


@pytest.mark.parametrize("light", ["A", "FL2", "LED-warm", "sun:500"])
def test_cat16_matches_colour_science(light):
    import colour

    from catalog.optics.colorimetry import spectrum_to_xyz
    from catalog.optics.lights import get_light

    white = spectrum_to_xyz(get_light(light).irradiance_w_m2_nm)
    ours = display.cat16_xyz_matrix(white, display.d65_white_xyz())
    theirs = colour.adaptation.matrix_chromatic_adaptation_VonKries(
        white / white[1], display.d65_white_xyz(), transform="CAT16")
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-10)
    # and the light's white becomes D65 (same Y)
    m = display.white_balance_matrix(white, "room")
    rgb_white = display.matrices().xyz_to_rgb @ (white / white[1])
    d65 = display.matrices().xyz_to_rgb @ display.d65_white_xyz()   # (1, 1, 1) to 2e-4
    np.testing.assert_allclose(m @ rgb_white, d65, atol=1e-9)


def test_white_balance_choices():
    from catalog.optics.colorimetry import spectrum_to_xyz
    from catalog.optics.lights import get_light

    uva = spectrum_to_xyz(get_light("UV-A").irradiance_w_m2_nm)
    a = spectrum_to_xyz(get_light("A").irradiance_w_m2_nm)
    assert display.planckian_distance(a) < 0.001           # A is a Planckian radiator
    assert display.planckian_distance(uva) > display.MAX_WHITE_DUV
    np.testing.assert_array_equal(display.white_balance_matrix(uva, "room"), np.eye(3))
    np.testing.assert_array_equal(display.white_balance_matrix(a, "camera"), np.eye(3))
    assert not np.allclose(display.white_balance_matrix(a, "room"), np.eye(3))
    with pytest.raises(Exception, match="white balance"):
        display.white_balance_matrix(a, "tungsten")


def test_oklab_matches_colour_science():
    import colour

    rng = np.random.default_rng(1)
    rgb = rng.uniform(-0.2, 1.5, (200, 3))
    xyz = rgb @ display.matrices().rgb_to_xyz.T
    np.testing.assert_allclose(display.rgb_to_oklab(rgb), colour.XYZ_to_Oklab(xyz), atol=1e-10)
    np.testing.assert_allclose(display.oklab_to_rgb(display.rgb_to_oklab(rgb)), rgb, atol=1e-10)


def test_gamut_compression_keeps_lightness_and_hue_and_lands_inside():
    rng = np.random.default_rng(2)
    # colours of luminance below the tone curve's ceiling, many far outside the cube
    rgb = rng.uniform(-0.5, 2.0, (4000, 3))
    y = rgb @ display.matrices().luminance
    rgb = rgb[(y > 1e-3) & (y < 0.97)]
    out = display.gamut_compress(rgb)
    assert np.all(out >= -1e-12) and np.all(out <= display.CUBE_TOP + 1e-12)
    lab_in, lab_out = display.rgb_to_oklab(rgb), display.rgb_to_oklab(out)
    np.testing.assert_allclose(lab_out[:, 0], np.clip(lab_in[:, 0], 0, display.lightness_ceiling()),
                               atol=1e-9)
    chroma_in = np.hypot(lab_in[:, 1], lab_in[:, 2])
    # hue is only defined where chroma is left (the brightest are compressed to their grey)
    coloured = (np.hypot(lab_out[:, 1], lab_out[:, 2]) > 1e-6) & (lab_in[:, 0] > 0)
    hue_in = np.arctan2(lab_in[coloured, 2], lab_in[coloured, 1])
    hue_out = np.arctan2(lab_out[coloured, 2], lab_out[coloured, 1])
    assert np.abs(np.angle(np.exp(1j * (hue_out - hue_in)))).max() < 1e-9
    assert np.all(np.hypot(lab_out[:, 1], lab_out[:, 2]) <= chroma_in + 1e-12)


def test_colours_well_inside_the_gamut_are_untouched():
    grey_ish = np.array([[0.2, 0.21, 0.19], [0.5, 0.45, 0.4], [0.05, 0.05, 0.06]])
    np.testing.assert_array_equal(display.gamut_compress(grey_ish), grey_ish)


def test_compress_ratio_is_continuous_monotone_and_below_the_limit():
    r = np.linspace(0.0, 50.0, 20001)
    c = display.compress_ratio(r)
    assert np.all(np.diff(c) >= 0) and c.max() < display.R_LIMIT
    np.testing.assert_array_equal(c[r <= display.R_KNEE], r[r <= display.R_KNEE])
    # slope 1 at the knee (no kink)
    k = display.R_KNEE
    assert abs((display.compress_ratio(k + 1e-7) - k) / 1e-7 - 1.0) < 1e-5


def test_tone_curve_keeps_mid_grey_and_never_reaches_one():
    assert display.tone_curve(display.TONE_MID_GREY) == pytest.approx(display.TONE_MID_GREY, rel=1e-12)
    x = np.geomspace(1e-4, 1e6, 500)
    y = display.tone_curve(x)
    assert np.all(np.diff(y) > 0) and y.max() < 1.0


@pytest.mark.parametrize("luminance", [3.0, 300.0, 30000.0])
def test_meter_of_a_uniform_frame(luminance):
    hist = display.luminance_histogram(np.full((48, 64), luminance))
    expected = math.log2(luminance * 100 / 12.5)
    bin_ev = (display.HISTOGRAM_LOG2_RANGE[1] - display.HISTOGRAM_LOG2_RANGE[0]) / display.HISTOGRAM_BINS
    assert abs(display.meter_ev100(hist) - max(expected, display.AUTO_EV_MIN)) <= bin_ev


def test_meter_ignores_the_dark_half_and_the_brightest_few_percent():
    frame = np.concatenate([np.full(500, 0.01), np.full(470, 500.0), np.full(30, 1e6)])
    ev = display.meter_ev100(display.luminance_histogram(frame))
    assert abs(ev - math.log2(500.0 * 8)) < 0.5
    assert display.meter_ev100(np.zeros(display.HISTOGRAM_BINS)) == display.AUTO_EV_MIN


def test_adaptation_over_time():
    assert display.adapt_ev(None, 10.0, 0.1) == 10.0
    assert display.adapt_ev(5.0, 10.0, None) == 10.0
    half = display.adapt_ev(5.0, 10.0, display.ADAPTATION_TAU_S * math.log(2))
    assert half == pytest.approx(7.5, rel=1e-12)


def test_exposure_scale_and_ev_range():
    assert display.exposure_scale(10.0) / display.exposure_scale(11.0) == pytest.approx(2.0)
    for bad in (float("nan"), 40.0, -20.0):
        with pytest.raises(Exception, match="--ev"):
            display.check_ev(bad)


def test_highlights_roll_off_and_desaturate_toward_white():
    """A saturated red exposed brighter and brighter: lightness rises toward the cube's top
    grey and chroma falls toward zero (no channel clips on the way), at a constant hue."""
    red = np.array([1.0, 0.1, 0.05])
    scales = np.geomspace(0.3, 3000.0, 40)
    toned = display.tone_mapped(red[None, :] * scales[:, None], 1.0, np.eye(3))
    shown = np.clip(display.gamut_compress(toned), 0.0, 1.0)
    lab = display.rgb_to_oklab(shown)
    # the frame's table (display_lut) follows the exact path (tests/test_display_lut.py: bounds)
    table_lab = display.rgb_to_oklab(display.display_linear(red[None, :] * scales[:, None], 1.0, np.eye(3)))
    assert np.abs(table_lab[:, 0] - lab[:, 0]).max() < 0.01
    chroma = np.hypot(lab[:, 1], lab[:, 2])
    assert np.all(np.diff(lab[:, 0]) > -1e-12)        # up to the ceiling, then held there
    assert lab[-1, 0] == pytest.approx(display.lightness_ceiling(), abs=1e-9)
    peak = int(np.argmax(chroma))
    assert np.all(np.diff(chroma[peak:]) < 1e-12) and chroma[-1] < 0.1 * chroma[peak]
    assert np.all(shown <= display.CUBE_TOP + 1e-12) and np.all(shown >= 0)
    hue = np.arctan2(lab[:, 2], lab[:, 1])
    assert np.ptp(hue[chroma > 1e-3]) < 1e-6


def test_display_shader_compiles_as_glsl_es_300(tmp_path):
    """The web page compiles the same sources as GLSL ES 3.00: tonemap.frag (with
    common.glsl) and fullscreen.vert, with the #version line swapped, pass glslangValidator
    (tools/setup.sh installs glslang-tools)."""
    import shutil
    import subprocess

    from catalog.gl.shaderlib import load_source

    validator = shutil.which("glslangValidator")
    if validator is None:
        pytest.fail("glslangValidator missing: tools/setup.sh installs glslang-tools")
    for name, stage in (("tonemap.frag", "frag"), ("fullscreen.vert", "vert")):
        for stages in ((0, 1, 2, 3) if stage == "frag" else (3,)):
            lines = load_source(name, {"DISPLAY_STAGES": stages}).splitlines()
            assert lines[0].startswith("#version")
            path = tmp_path / f"es_{stages}.{stage}"
            path.write_text("\n".join(["#version 300 es", "precision highp float;", *lines[1:]]) + "\n")
            result = subprocess.run([validator, str(path)], capture_output=True, text=True)
            assert result.returncode == 0, f"{name} (DISPLAY_STAGES {stages}): {result.stdout}"
