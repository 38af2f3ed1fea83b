"""Colorimetry wrappers against colour-science's own functions."""

from __future__ import annotations

import colour
import numpy as np
import pytest

from catalog.optics import colorimetry as cm
from catalog.optics.spectra import GRID_NM


def test_cmfs_match_colour_on_its_own_wavelengths():
    table = colour.MSDS_CMFS[cm.OBSERVER]
    ours = cm.cmfs(GRID_NM)
    for wl in (380.0, 455.0, 555.0, 700.0, 780.0):
        i = int(wl - GRID_NM[0])
        np.testing.assert_allclose(ours[i], table[wl], rtol=1e-12)
    assert np.all(ours[GRID_NM < 360] == 0)  # outside the CIE table: zero, not extrapolated


def test_spectrum_to_xyz_matches_colour_integration_for_d65():
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(
        colour.SpectralShape(380, 780, 1))
    ours = cm.spectrum_to_xyz(np.interp(GRID_NM, d65.wavelengths, d65.values, left=0, right=0))
    ref = colour.sd_to_XYZ(d65, method="Integration", k=1,
                           shape=colour.SpectralShape(380, 780, 1))
    np.testing.assert_allclose(ours, ref, rtol=1e-3)  # tolerance: colour trims CMFs to the shape


def test_srgb_round_trip_is_exact_and_white_is_white():
    rng = np.random.default_rng(1)
    xyz = rng.uniform(0, 1, (50, 3))
    np.testing.assert_allclose(cm.linear_srgb_to_xyz(cm.xyz_to_linear_srgb(xyz)), xyz,
                               rtol=0, atol=1e-14)
    white = colour.xy_to_XYZ(cm.srgb_whitepoint_xy())
    np.testing.assert_allclose(cm.xyz_to_linear_srgb(white), [1, 1, 1], atol=2e-4)


def test_srgb_encode_is_the_piecewise_curve_not_a_power():
    x = np.array([0.0, 0.002, 0.0031308, 0.18, 1.0])
    ref = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    np.testing.assert_allclose(cm.srgb_encode(x), ref, atol=1e-12)
    np.testing.assert_allclose(cm.srgb_decode(cm.srgb_encode(x)), x, atol=1e-12)


@pytest.mark.parametrize("pair, expected", [
    # Sharma, Wu, Dalal (2005) CIEDE2000 test data, pairs 1 and 17
    (((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485)), 2.0425),
    (((50.0, 2.5, 0.0), (73.0, 25.0, -18.0)), 27.1492),
])
def test_delta_e_2000_on_sharma_pairs(pair, expected):
    white = colour.xy_to_XYZ(cm.srgb_whitepoint_xy()) * 100
    xy = colour.XYZ_to_xy(white)
    xyz_a = colour.Lab_to_XYZ(np.array(pair[0]), xy) * 100
    xyz_b = colour.Lab_to_XYZ(np.array(pair[1]), xy) * 100
    assert cm.delta_e_2000(xyz_a, xyz_b, white) == pytest.approx(expected, abs=1e-4)


def test_lab_matches_colour_science():
    rng = np.random.default_rng(7)
    white = np.array([95.047, 100.0, 108.883])
    xyz = rng.uniform(0, 120, (200, 3))
    xyz[:5] *= 1e-4  # the linear segment near black
    ref = colour.XYZ_to_Lab(xyz / 100, colour.XYZ_to_xy(white))
    np.testing.assert_allclose(cm.xyz_to_lab(xyz, white), ref, atol=1e-9)


def test_delta_e_2000_matches_colour_science_on_random_and_edge_pairs():
    rng = np.random.default_rng(11)
    lab_a = np.column_stack([rng.uniform(0, 100, 2000), rng.uniform(-120, 120, (2000, 2))])
    lab_b = lab_a + rng.normal(0, 8, (2000, 3))
    # edges: neutral greys (C = 0, hue undefined), hues across 0/360, identical colours
    edges_a = np.array([[50, 0, 0], [50, 0, 0], [60, 10, -0.01], [40, 3, 4], [70, -5, 0]])
    edges_b = np.array([[60, 0, 0], [50, 5, 5], [60, 10, 0.01], [40, 3, 4], [70, 5, 0]])
    lab_a = np.vstack([lab_a, edges_a])
    lab_b = np.vstack([lab_b, edges_b])
    ref = colour.delta_E(lab_a, lab_b, method="CIE 2000")
    np.testing.assert_allclose(cm.delta_e_2000_lab(lab_a, lab_b), ref, atol=1e-9)


@pytest.mark.slow
def test_colorimetry_does_not_import_colour_or_scipy():
    import subprocess
    import sys

    code = ("import sys, numpy as np\n"
            "from catalog.optics import colorimetry as cm\n"
            "cm.delta_e_2000(np.ones(3), np.ones(3) * 2, np.ones(3) * 3)\n"
            "cm.spectrum_to_xyz(np.ones(481)); cm.xyz_to_linear_srgb(np.ones(3))\n"
            "print(sorted({'colour', 'scipy'} & {m.split('.')[0] for m in sys.modules}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"
