"""The renderer's CPU side (no GL): scene meshes, the sun by the hour, band integration,
the hemisphere factors of eq. 6, and the reference's terms against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.optics import shading_reference as ref
from catalog.core.errors import CatalogError, InputError
from catalog.render import bands, scene
from catalog.optics.spectra import GRID_NM


def test_draped_curtain_frame_is_orthonormal_and_faces_the_room():
    mesh = scene.draped_curtain(40, 30)
    n = mesh.normals.astype(np.float64)
    t = mesh.tangents.astype(np.float64)
    assert np.allclose(np.linalg.norm(n, axis=1), 1, atol=1e-6)
    assert np.allclose(np.linalg.norm(t, axis=1), 1, atol=1e-6)
    assert np.abs(np.sum(n * t, axis=1)).max() < 1e-6
    assert n[:, 2].mean() > 0.8  # towards the room (+z) on average
    assert mesh.indices.max() == 40 * 30 - 1 and mesh.indices.shape == (2 * 39 * 29, 3)
    with pytest.raises(CatalogError):
        scene.draped_curtain(1, 5)


def test_room_props_have_the_window_open():
    positions, normals = scene.room_props()
    assert positions.shape == normals.shape and positions.shape[0] % 3 == 0
    # no triangle of the window wall covers the opening's centre
    x0, x1, y0, y1 = scene.WINDOW_RECT
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    tri = positions.reshape(-1, 3, 3)
    on_wall = np.all(np.abs(tri[:, :, 2] - scene.WINDOW_Z) < 1e-6, axis=1)
    for a, b, c in tri[on_wall][:, :, :2]:
        v0, v1, v2 = c - a, b - a, centre - a
        d = v0[0] * v1[1] - v0[1] * v1[0]
        if abs(d) < 1e-12:
            continue
        u = (v2[0] * v1[1] - v2[1] * v1[0]) / d
        v = (v0[0] * v2[1] - v0[1] * v2[0]) / d
        assert not (u >= 0 and v >= 0 and u + v <= 1)


@pytest.mark.parametrize("hour", [6.0, 9.0, 12.0, 15.5, 18.5])
def test_solar_zenith_matches_pvlib_spa(hour):
    """The renderer's closed-form sun (no pvlib at draw time) against pvlib's NREL SPA
    through catalog.optics.sun.model, at the same date, local mean solar time and latitude."""
    from catalog.optics.sun.model import sun_position

    minutes = int(round(hour * 60))
    lon = 135.5
    spa = sun_position(f"{scene.SUN_DATE}T{minutes // 60:02d}:{minutes % 60:02d}",
                       scene.SUN_LATITUDE_DEG, lon)
    ours = scene.solar_zenith_deg(hour)
    # pvlib's apparent zenith includes refraction (up to ~0.5 deg near the horizon)
    assert abs(ours - spa.zenith_deg) < (0.6 if spa.zenith_deg > 85 else 0.3)


def test_sun_by_the_hour():
    noon = scene.sun_at_hour(12.0)
    assert 10 < noon.zenith_deg < 13  # 34.7 N at the solstice: ~11 deg
    assert 22.0 <= noon.path_km < 23.0 and noon.light_name.startswith("sun:")
    evening = scene.sun_at_hour(18.0)
    assert evening.path_km > 4 * noon.path_km
    with pytest.raises(InputError, match="below the horizon"):
        scene.sun_at_hour(2.0)
    with pytest.raises(InputError, match="hour"):
        scene.sun_at_hour(25.0)


@pytest.mark.parametrize("g", [0.0, 0.3, -0.4, 0.97, 0.999, -0.999])
def test_hemisphere_factors_against_adaptive_quadrature(g):
    """The closed form against scipy's adaptive quadrature of eq. 6 (catalog.optics.btdf), split at
    the peak; and its invariants (g = 0, mirror symmetry, forward > backward for g > 0)."""
    from scipy.integrate import quad

    from catalog.optics.btdf import hg_phase_one_minus_cos

    forward, backward = ref.hg_hemisphere_factors(g)

    def lobe(mu, sign):  # 2 pi ph(theta) mu, cos(theta) = sign * mu
        return 2 * math.pi * float(hg_phase_one_minus_cos(1.0 - sign * mu, g)) * mu

    width = (1 - abs(g)) ** 2 / (2 * max(abs(g), 1e-3))
    points = [max(0.0, 1.0 - k * width) for k in (1, 10, 100)]
    numeric_f = quad(lobe, 0.0, 1.0, args=(1.0,), points=points, limit=500, epsabs=0, epsrel=1e-11)[0]
    numeric_b = quad(lobe, 0.0, 1.0, args=(-1.0,), points=points, limit=500, epsabs=0, epsrel=1e-11)[0]
    assert forward == pytest.approx(numeric_f, rel=1e-8)
    assert backward == pytest.approx(numeric_b, rel=1e-8)
    f_neg, b_neg = ref.hg_hemisphere_factors(-g)
    assert forward == pytest.approx(b_neg, rel=1e-12) and backward == pytest.approx(f_neg, rel=1e-12)
    if g == 0.0:
        assert forward == pytest.approx(0.25, rel=1e-15) and backward == pytest.approx(0.25, rel=1e-15)
    if g > 0:
        assert forward > backward


def test_hemisphere_factors_near_g_one():
    """Beyond what quadrature resolves: monotone towards forward = 1, backward = 0."""
    previous = ref.hg_hemisphere_factors(0.999)
    for g in (0.9999, 0.99999, 0.999999):
        forward, backward = ref.hg_hemisphere_factors(g)
        assert previous[0] < forward < 1.0 and 0.0 < backward < previous[1]
        assert ref.hg_hemisphere_factors(-g) == pytest.approx((backward, forward), rel=1e-12)
        previous = (forward, backward)
    with pytest.raises(ValueError):
        ref.hg_hemisphere_factors(1.0)


def test_rgb_bands_are_exact_linear_srgb_and_interval_bands_exact_for_the_key():
    from catalog.optics.lights import get_light

    key = get_light("FL11").irradiance_w_m2_nm
    exact = ref.spectral_to_linear_srgb(key)
    weights, to_rgb = bands.band_weights(3, key)
    assert np.allclose(to_rgb @ (weights @ key), exact, rtol=1e-12)
    for n in (6, 9, 16):
        weights, to_rgb = bands.band_weights(n, key)
        assert np.allclose(to_rgb @ (weights @ key), exact, rtol=1e-10)
        assert np.allclose(weights.sum(axis=0)[(GRID_NM >= 360)], 1.0)  # a partition of 360-780
    with pytest.raises(CatalogError, match="--bands"):
        bands.check_band_count(5)


def test_uniform_packing_in_vec4_chunks():
    assert [bands.chunks(n) for n in (3, 6, 9, 16)] == [1, 2, 3, 4]


def test_relative_dye_keeps_the_grey_fit_on_average():
    from catalog.optics.colorimetry import cmfs

    t = np.clip((GRID_NM - 420) / 100, 0.05, 0.9)
    shape = scene.relative_dye(t)
    ybar = cmfs(GRID_NM)[:, 1]
    assert float(shape @ ybar) / float(ybar.sum()) == pytest.approx(1.0, rel=1e-12)
    assert np.allclose(scene.relative_dye(np.ones(GRID_NM.size)), 1.0)


def test_room_solids_match_trimesh_and_face_outwards():
    """The numpy boxes and rod against trimesh's own solids: same volume and area, closed,
    normals pointing out (trimesh is the independent reference; the renderer avoids importing
    it because it imports scipy)."""
    import trimesh

    for solid in scene._room_parts():
        vertices = solid.reshape(-1, 3)
        faces = np.arange(vertices.shape[0]).reshape(-1, 3)
        mesh = trimesh.Trimesh(vertices, faces, process=True)
        assert mesh.is_watertight and mesh.is_winding_consistent
        assert mesh.volume > 0  # positive volume: counter-clockwise seen from outside
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        if len(solid) == 12:  # a box
            reference = trimesh.creation.box(extents=hi - lo)
        else:  # the rod
            reference = trimesh.creation.cylinder(radius=0.015, height=hi[0] - lo[0], sections=16)
        assert mesh.volume == pytest.approx(reference.volume, rel=1e-9)
        assert mesh.area == pytest.approx(reference.area, rel=1e-9)


@pytest.mark.slow
def test_frame_setup_imports_no_scipy():
    """Drawing a frame must not import scipy (the viewer's rule): checked in a fresh process."""
    import subprocess
    import sys

    code = ("import sys\n"
            "from catalog.render import scene, bands, frame, camera, snapshot\n"
            "from catalog.gl import shaderlib\n"
            "scene.room_props(); scene.draped_curtain(); scene.sun_at_hour(12.0)\n"
            "from catalog.optics.lights import get_light; get_light(scene.sun_at_hour(17.0).light_name)\n"
            "print('scipy' in sys.modules, 'trimesh' in sys.modules, 'pvlib' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["False", "False", "False"]
