"""Gonio data: the paper's angle convention, the OGM-3 grid and the 79-point subset, and
the gonio CSV reader's refusals (catalog/fit/gonio.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.fit import gonio
from catalog.core.errors import InputError

HEADER = ",".join(gonio.GONIO_COLUMNS)


def spherical_cos_theta(light_elevation, light_azimuth, camera_elevation, camera_azimuth):
    """cos theta by the spherical law of cosines: the light travels at polar angle
    180 - light_elevation from +Z towards azimuth light_azimuth + 180; the view has polar
    angle 90 - camera_elevation at azimuth camera_azimuth."""
    p_travel = math.radians(180.0 - light_elevation)
    p_view = math.radians(90.0 - camera_elevation)
    d_azimuth = math.radians(camera_azimuth - (light_azimuth + 180.0))
    return (math.cos(p_travel) * math.cos(p_view)
            + math.sin(p_travel) * math.sin(p_view) * math.cos(d_azimuth))


def test_directions_follow_the_paper_convention():
    assert np.allclose(gonio.view_direction(90.0, 0.0), [0, 0, 1], atol=1e-15)
    assert np.allclose(gonio.light_direction(180.0, 0.0), [0, 0, -1], atol=1e-15)
    # camera elevation 0 looks along the cloth; light elevation 90 grazes it
    assert np.allclose(gonio.view_direction(0.0, 90.0), [0, 1, 0], atol=1e-15)
    assert np.allclose(gonio.light_direction(90.0, 0.0), [1, 0, 0], atol=1e-15)


def test_theta_matches_spherical_trigonometry_on_the_grid():
    grid = gonio.ogm3_grid()
    rng = np.random.default_rng(3)
    for i in rng.choice(len(grid), 300, replace=False):
        expected = spherical_cos_theta(grid.light_elevation_deg[i], grid.light_azimuth_deg[i],
                                       grid.camera_elevation_deg[i], grid.camera_azimuth_deg[i])
        assert 1.0 - grid.one_minus_cos[i] == pytest.approx(expected, abs=1e-12)
        assert math.cos(math.radians(grid.theta_deg[i])) == pytest.approx(expected, abs=1e-12)


def test_straight_through_examples():
    data = gonio.GonioData(
        light_elevation_deg=np.array([180.0, 180.0, 130.0, 130.0]),
        light_azimuth_deg=np.array([0.0, 90.0, 0.0, 0.0]),
        camera_elevation_deg=np.array([90.0, 60.0, 40.0, 40.0]),
        camera_azimuth_deg=np.array([0.0, 0.0, 180.0, 0.0]),
        transmittance=np.ones(4))
    # light from straight behind, camera 30 deg off the normal: theta = 30;
    # light at 50 deg from -Z towards azimuth 0 travels towards azimuth 180: seen straight
    # from elevation 40 at azimuth 180, and 100 deg away from azimuth 0.
    assert np.allclose(data.theta_deg, [0.0, 30.0, 0.0, 100.0], atol=1e-9)
    assert data.straight_through.tolist() == [True, False, True, False]


def test_ogm3_grid_has_4800_distinct_settings():
    grid = gonio.ogm3_grid()
    assert len(grid) == 4800
    settings = np.stack([grid.light_elevation_deg, grid.light_azimuth_deg,
                         grid.camera_elevation_deg, grid.camera_azimuth_deg], axis=1)
    assert len(np.unique(settings, axis=0)) == 4800
    camera = np.unique(grid.camera_elevation_deg)
    assert len(camera) == 40 and camera[0] == 10.0 and camera[-1] == 90.0
    assert np.allclose(np.diff(camera), 80.0 / 39.0)
    assert np.unique(grid.light_elevation_deg).tolist() == [130.0, 142.5, 155.0, 167.5, 180.0]
    assert np.unique(grid.light_azimuth_deg).tolist() == list(np.arange(0.0, 331.0, 30.0))
    assert np.unique(grid.camera_azimuth_deg).tolist() == [0.0, 180.0]
    # the lamp is seen through the gaps only from straight behind: 12 light azimuths x 2
    assert int(grid.straight_through.sum()) == 24
    assert np.all(grid.light_elevation_deg[grid.straight_through] == 180.0)


def test_paper_subset_is_79_distinct_directions():
    grid = gonio.ogm3_grid()
    mask = gonio.paper_subset_mask(grid)
    assert int(mask.sum()) == 79
    sub = grid.subset(mask)
    assert np.all(sub.light_elevation_deg == 180.0) and np.all(sub.light_azimuth_deg == 0.0)
    views = np.round(sub.view, 12)
    assert len(np.unique(views, axis=0)) == 79
    assert int(sub.straight_through.sum()) == 1
    # 40 camera elevations from azimuth 0, 39 from azimuth 180 (90 deg counted once)
    assert int((sub.camera_azimuth_deg == 0).sum()) + int((sub.camera_azimuth_deg == 180).sum()) == 79


# --- reading ---------------------------------------------------------------------------

def write(tmp_path, text, name="gonio.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def good_rows(n_extra: int = 6) -> list[str]:
    rows = ["180,0,90,0,1.5"]
    rows += [f"180,0,{90 - 5 * (k + 1)},0,{0.5 / (k + 1):.4f}" for k in range(n_extra)]
    return rows


def test_reads_a_valid_file_with_rgb_and_comments(tmp_path):
    rows = [r + ",0.1,0.2,0.3" for r in good_rows()]
    path = write(tmp_path, "# instrument: OGM-3\n# display_name: Test\n"
                 + HEADER + ",r,g,b\n" + "\n".join(rows) + "\n")
    data = gonio.read_gonio(path)
    assert len(data) == 7 and data.rgb.shape == (7, 3)
    assert data.line_numbers[0] == 4
    assert "display_name: Test" in data.comments
    assert data.straight_through[0] and not data.straight_through[1:].any()


def test_write_read_round_trip(tmp_path):
    grid = gonio.ogm3_grid()
    rng = np.random.default_rng(0)
    data = grid.with_values(rng.uniform(0.001, 2.0, len(grid)),
                            rng.uniform(0.001, 2.0, (len(grid), 3)))
    path = tmp_path / "g.csv"
    gonio.write_gonio(path, data, ("made by a test",))
    back = gonio.read_gonio(path)
    assert np.allclose(back.camera_elevation_deg, data.camera_elevation_deg, atol=1e-6)
    assert np.allclose(back.transmittance, data.transmittance, rtol=1e-5)
    assert np.allclose(back.rgb, data.rgb, rtol=1e-5)
    assert back.comments == ("made by a test",)


BROKEN = {
    "empty": ("", 1, "empty file"),
    "comments only": ("# nothing\n", 1, "empty file"),
    "wrong header": ("elevation,azimuth,a,b,t\n" + "\n".join(good_rows()), 1, "wrong header"),
    "no header": ("\n".join(good_rows()), 1, "missing header"),
    "nan": (HEADER + "\n" + "\n".join(good_rows()[:3] + ["180,0,70,0,nan"] + good_rows()[3:]),
            5, "NaN"),
    "negative": (HEADER + "\n" + "\n".join(good_rows()[:2] + ["180,0,70,0,-0.1"]
                                           + good_rows()[2:]), 4, "negative"),
    "one row": (HEADER + "\n180,0,90,0,1.5\n", 1, "at least"),
    "all zero": (HEADER + "\n" + "\n".join(r.rsplit(",", 1)[0] + ",0" for r in good_rows()),
                 2, "zero on every row"),
    "light elevation out of range": (HEADER + "\n" + "\n".join(good_rows() + ["80,0,45,0,0.1"]),
                                     9, "light_elevation_deg = 80"),
    "light elevation above 180": (HEADER + "\n" + "\n".join(good_rows() + ["181,0,45,0,0.1"]),
                                  9, "light_elevation_deg = 181"),
    "camera elevation out of range": (HEADER + "\n" + "\n".join(good_rows()[:1] + ["180,0,95,0,1"]
                                                               + good_rows()[1:]),
                                      3, "camera_elevation_deg = 95"),
    "azimuth out of range": (HEADER + "\n" + "\n".join(good_rows() + ["180,400,45,0,0.1"]),
                             9, "light_azimuth_deg = 400"),
    "no straight-through point": (HEADER + "\n" + "\n".join(good_rows()[1:] + ["150,0,80,0,1"]),
                                  1, "no straight-through point"),
    "partial rgb": (HEADER + ",r,g\n" + "\n".join(r + ",0.1,0.2" for r in good_rows()), 1,
                    "r,g,b"),
    "too few fields": (HEADER + "\n" + "\n".join(good_rows()[:2] + ["180,0,70,0"]), 4,
                       "expected 5 fields"),
}


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_broken_files_are_refused_with_file_and_line(tmp_path, case):
    text, line, problem = BROKEN[case]
    path = write(tmp_path, text)
    with pytest.raises(InputError) as excinfo:
        gonio.read_gonio(path)
    message = str(excinfo.value)
    assert message.startswith(f"{path}:{line}:"), message
    assert problem in message


def test_missing_file_is_named(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        gonio.read_gonio(tmp_path / "absent.csv")


# --- the yarn-level generator (tools/make_gonio.py) ------------------------------------------

def _make_gonio_module():
    import importlib.util
    import sys

    from catalog.core.resources import PROJECT_ROOT

    if "make_gonio" not in sys.modules:
        spec = importlib.util.spec_from_file_location("make_gonio",
                                                      PROJECT_ROOT / "tools" / "make_gonio.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules["make_gonio"] = module          # dataclasses look their module up
        spec.loader.exec_module(module)
    return sys.modules["make_gonio"]


def test_generator_reproduces_the_committed_measurement(tmp_path):
    from catalog.core.resources import FABRIC_DIR

    make_gonio = _make_gonio_module()
    fabric = next(f for f in make_gonio.CATALOG if f.name == "sheer-teal")
    make_gonio.write_fabric(fabric, tmp_path)
    for name in ("gonio.csv", "dye.csv"):
        assert (tmp_path / "sheer-teal" / name).read_text() == \
            (FABRIC_DIR / "measurements" / "sheer-teal" / name).read_text(), name


def test_open_area_of_cylinders_with_gaps():
    make_gonio = _make_gonio_module()
    fabric = next(f for f in make_gonio.CATALOG if f.name == "voile-white")
    normal = np.array([[0.0, 0.0, 1.0]])
    expected = ((1 - fabric.warp_diameter_mm / fabric.warp_spacing_mm)
                * (1 - fabric.weft_diameter_mm / fabric.weft_spacing_mm))
    assert make_gonio.open_fraction(normal, fabric)[0] == pytest.approx(expected, rel=1e-12)
    # tilting towards x closes the gaps between warp threads only: the weft factor stays
    angles = np.radians([10.0, 30.0, 50.0])
    tilted = np.stack([np.sin(angles), np.zeros(3), np.cos(angles)], axis=1)
    opening = make_gonio.open_fraction(tilted, fabric)
    assert np.all(np.diff(opening) < 0) and opening[0] < expected
    h = fabric.layer_thickness_mm - 0.5 * (fabric.warp_diameter_mm + fabric.weft_diameter_mm)
    gap = (fabric.warp_spacing_mm - fabric.warp_diameter_mm / np.cos(angles[1])
           - h * np.tan(angles[1]))
    assert opening[1] == pytest.approx(gap / fabric.warp_spacing_mm
                                       * (1 - fabric.weft_diameter_mm / fabric.weft_spacing_mm))


@pytest.mark.parametrize("nu", [None, 2.0])
def test_fibre_deflection_density_has_unit_weight(nu):
    """Over the sphere (Gauss-Legendre in cos theta x uniform azimuth), a narrow lobe
    around an oblique direction of travel integrates to 1 (Student-t: minus its tail
    beyond pi, (1 + (pi/sigma)^2/nu)^(-nu/2) < 0.2 %)."""
    make_gonio = _make_gonio_module()
    travel = np.array([math.sin(0.4), 0.0, math.cos(0.4)])
    x, w = np.polynomial.legendre.leggauss(400)
    # cos theta about the travel direction, from 1 down to -1, denser near 1
    t = 0.5 * (x + 1)
    cos_t = 1 - 2 * t ** 3
    weight_t = w * 0.5 * 6 * t ** 2
    phi = np.linspace(0, 2 * math.pi, 256, endpoint=False)
    e1 = np.array([math.cos(0.4), 0.0, -math.sin(0.4)])
    e2 = np.cross(travel, e1)
    sin_t = np.sqrt(1 - cos_t ** 2)
    view = (cos_t[:, None, None] * travel
            + sin_t[:, None, None] * (np.cos(phi)[None, :, None] * e1
                                      + np.sin(phi)[None, :, None] * e2))
    density = make_gonio.deflection_density(np.broadcast_to(travel, view.shape), view,
                                            math.radians(6.0), math.radians(4.0), nu)
    total = float(np.sum(density * weight_t[:, None]) * (2 * math.pi / len(phi)))
    assert total == pytest.approx(1.0, abs=0.01)


def test_two_exposure_measurement_keeps_peak_and_skirt():
    """From the skirt (3e-4) to far above the long exposure's saturation: unbiased, within
    ~1 % where the signal is well above the read noise, and at the read-noise floor
    (2 DN per pixel over 40x40 pixels) below that."""
    make_gonio = _make_gonio_module()
    values = np.geomspace(3e-4, 50.0, 200)
    rng = np.random.default_rng(0)
    measured = np.stack([make_gonio.measure(values, rng) for _ in range(40)])
    # the noise model written out: per-pixel read, photon and rounding noise averaged
    # over the patch, in the exposure that does not saturate; lamp flicker; the reference
    def exposure_sigma(gain):
        mean_dn = values * gain
        per_pixel = make_gonio.READ_NOISE_DN ** 2 + mean_dn / make_gonio.ELECTRONS_PER_DN
        return np.sqrt((per_pixel + 1 / 12) / make_gonio.PIXELS) / gain, \
            mean_dn + 4 * np.sqrt(per_pixel) >= make_gonio.FULL_WELL_DN
    long_sigma, long_saturated = exposure_sigma(make_gonio.LONG_GAIN_DN)
    short_sigma, _ = exposure_sigma(make_gonio.SHORT_GAIN_DN)
    expected_sigma = np.sqrt(np.where(long_saturated, short_sigma, long_sigma) ** 2
                             + ((make_gonio.FLICKER ** 2 + make_gonio.REFERENCE_NOISE ** 2)
                                * values ** 2))
    spread = np.std(measured, axis=0)
    bias = np.mean(measured, axis=0) - values
    assert np.all(spread < 1.5 * expected_sigma) and np.all(spread > 0.5 * expected_sigma)
    assert np.all(np.abs(bias) < 4 * expected_sigma / math.sqrt(40))
    strong = values > 1e-2
    assert np.all(spread[strong] / values[strong] < 0.015)
    saturating = values * make_gonio.LONG_GAIN_DN > make_gonio.FULL_WELL_DN
    assert saturating.any() and not saturating.all()
