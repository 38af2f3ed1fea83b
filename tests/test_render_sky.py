"""The outside (issue 13): the clear sky by direction against its float64 twin (catalog/optics/sun/sky.py),
its illuminance against the atmosphere's (catalog.optics.sun.model.clear_sky), no seam at the horizon;
and the glare (bloom) keeps the frame's energy."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.optics.sun import sky
from catalog.optics.shading_reference import spectral_to_linear_srgb
from catalog.render import scene as scene_lib
from catalog.render.frame import FrameRenderer
from catalog.render.settings import orbit

pytestmark = pytest.mark.gl

SIZE = (96, 64)


def _rays(r):
    from catalog.render.curtain_frames import pixel_rays

    w, h = r.size
    return pixel_rays(r.camera.view_projection(w / h), r.camera.position, r.size)


def test_sky_illuminance_is_the_atmospheres_diffuse():
    """The sky's radiance integrated with cos(theta) over the upper hemisphere equals the
    diffuse horizontal irradiance of catalog.optics.sun.model.clear_sky at the same zenith, per linear
    sRGB channel, within 0.5 % (the midpoint rule on 96 x 192 cells; the scale is fitted on the
    same grid, so a finer grid checks the quadrature: 1 %)."""
    to_sun = scene_lib.key_direction(35.0, 20.0)
    model = sky.sky_model(to_sun)
    from catalog.optics.sun.model import clear_sky

    expected = spectral_to_linear_srgb(clear_sky(55.0).diffuse_horizontal)
    got = sky.horizontal_irradiance_rgb(model.radiance, n_theta=192)
    assert np.allclose(got, expected, rtol=0.01)


def test_sky_is_brighter_towards_the_sun_and_bluer_at_the_zenith():
    """Preetham's shape: the circumsolar sky is brighter than the sky opposite the sun, and the
    zenith's blue / red exceeds the horizon's below the sun."""
    to_sun = scene_lib.key_direction(30.0, 0.0)
    model = sky.sky_model(to_sun)
    near = np.array([0.0, math.sin(math.radians(40)), -math.cos(math.radians(40))])
    opposite = np.array([0.0, math.sin(math.radians(40)), math.cos(math.radians(40))])
    lum = np.array([0.2126, 0.7152, 0.0722])
    assert model.radiance(near[None])[0] @ lum > 2.0 * (model.radiance(opposite[None])[0] @ lum)
    zenith = model.radiance(np.array([[0.0, 1.0, 0.0]]))[0]
    horizon = model.radiance(np.array([[0.0, 0.02, -1.0]]) / np.linalg.norm([0.0, 0.02, -1.0]))[0]
    assert zenith[2] / zenith[0] > horizon[2] / horizon[0]


def test_no_seam_at_the_horizon():
    """Just above and just below the horizon (0.1 deg apart) the radiance differs by less
    than 2 %; the old flat model jumped from sky to ground there."""
    model = sky.sky_model(scene_lib.key_direction(25.0))
    for azimuth in (-60.0, 0.0, 45.0):
        a = math.radians(azimuth)
        up = np.array([math.sin(a), math.sin(math.radians(0.05)), -math.cos(a)])
        down = np.array([math.sin(a), -math.sin(math.radians(0.05)), -math.cos(a)])
        hi, lo = model.radiance(up[None])[0], model.radiance(down[None])[0]
        assert np.all(np.abs(hi - lo) <= 0.02 * np.abs(hi))


def _looking_out_under_the_sun(gl):
    """A renderer with the curtain open, looking out of the window under sun:60 (no glare)."""
    r = FrameRenderer(gl, SIZE)
    r.update(fabric="lace-fwa",
             light="sun:60",
             curtain_open=True,
             bloom=False,
             camera=orbit(0.0, 5.0, 1.0))
    return r


@pytest.mark.slow
def test_background_pixels_match_the_sky_model(gl):
    """Curtain open, looking out of the window under the sun: every pixel whose ray leaves
    through the opening (10 cm inside its edge, off the sun's disc) equals the float64 sky
    within 0.3 % (float32 exp and acos)."""
    r = _looking_out_under_the_sun(gl)
    r.render()
    img = r.read_linear()
    d, ok = _window_rays(r)
    assert ok.sum() > 0.3 * ok.size
    assert not any(v.get("SKY_BANDS") for k, v in _background_variants(r))
    model = r.background.sky_model_for(r.shading_inputs())
    expected = model.radiance(d[ok])
    assert np.allclose(img[ok], expected, rtol=3e-3, atol=1e-3 * np.abs(expected).max())
    r.release()


def _background_variants(r):
    return [(k, dict(k[2])) for k in r.gl.programs if k[1] == "background.frag"]


def _window_rays(r):
    """Each pixel's ray and whether it leaves through the opening (10 cm inside its edge, off
    the sun's disc)."""
    d = _rays(r)
    eye = r.camera.position
    z0 = scene_lib.ROOM_BOX[2][0]
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    ok = np.ones(d.shape[:2], dtype=bool)
    for z in (z0, z0 - 0.1):
        s = (z - eye[2]) / d[..., 2]
        q = eye[:2] + s[..., None] * d[..., :2]
        ok &= (q[..., 0] > wx0 + 0.1) & (q[..., 0] < wx1 - 0.1) & (q[..., 1] > wy0 + 0.1) & (q[..., 1] < wy1 - 0.1)
    to_sun = r.shading_inputs().key_to_light
    ok &= np.linalg.norm(d - to_sun, axis=-1) > 0.05
    return d, ok


def _spectral_sky(zenith_deg=30.0):
    from catalog.optics.sun.model import clear_sky

    c = clear_sky(zenith_deg)
    return c, sky.spectral_sky(scene_lib.key_direction(90.0 - zenith_deg), c.diffuse_horizontal,
                               0.2 * c.global_horizontal / math.pi)


@pytest.mark.slow  # 1-3 s: measured with --durations (issue 10)
def test_spectral_sky_irradiance_is_the_atmospheres_diffuse_per_wavelength():
    """The per-band sky (Preetham's spectral reconstruction scaled by s(l)): its horizontal
    irradiance, integrated on a finer grid (192 x 384) than the one s(l) was fitted on
    (48 x 96), equals the atmosphere's diffuse spectrum within 0.5 % where it is above 1 % of
    its peak."""
    c, sp = _spectral_sky()
    got = sky.horizontal_irradiance_rgb(sp.radiance, n_theta=192)
    target = c.diffuse_horizontal
    big = target > 0.01 * target.max()
    assert np.allclose(got[big], target[big], rtol=5e-3)


def test_spectral_sky_agrees_with_the_rgb_sky_in_colour():
    """Shown in linear sRGB (exact colour matching), the spectral sky is the RGB sky within
    5 % per channel, above the horizon: the same Preetham luminance and chromaticity, the same
    irradiance, only the spectral scaling differs from the per-channel one."""
    c, sp = _spectral_sky()
    d = np.array([[math.sin(a) * math.cos(t), math.cos(a), -math.sin(a) * math.sin(t)]
                  for a in np.radians([5.0, 30.0, 60.0, 85.0]) for t in np.radians([0.0, 90.0, 200.0])])
    spectral = spectral_to_linear_srgb(sp.radiance(d))
    rgb = sp.model.radiance(d)
    assert np.allclose(spectral, rgb, rtol=0.05)


@pytest.mark.parametrize("n_bands", [16])
@pytest.mark.slow
def test_band_frame_sky_is_the_band_integral_of_the_spectral_sky(gl, n_bands):
    """In 6/9/16 bands the sky behind the window follows the bands: every pixel through the
    opening equals the numpy reference -- the spectral sky L(l, d) of each pixel's ray on the
    1 nm grid, integrated over the renderer's band weights and shown through its display
    matrix -- within 0.5 % (float32 exp, acos and the M1, M2 divisions). The same scene in RGB
    is still the RGB model (the test above) and the two differ visibly (more than 0.5 % on
    some pixel), so the test can fail."""
    from catalog.render import bands as band_lib

    r = _looking_out_under_the_sun(gl)
    r.update(bands=n_bands)
    r.render()
    img = r.read_linear()
    d, ok = _window_rays(r)
    assert ok.sum() > 0.3 * ok.size
    assert any(v.get("SKY_BANDS") for k, v in _background_variants(r))
    inputs = r.shading_inputs()
    weights, to_rgb = band_lib.band_weights(n_bands, inputs.key_irradiance)
    spectral = r.background.spectral_sky_for(inputs).radiance(d[ok])          # (n, L) W m^-2 sr^-1 nm^-1
    expected = (weights @ spectral.T).T @ to_rgb.T
    assert np.allclose(img[ok], expected, rtol=5e-3, atol=1e-3 * np.abs(expected).max())
    rgb = r.background.sky_model_for(inputs).radiance(d[ok])
    assert np.abs(img[ok] - rgb).max() > 5e-3 * np.abs(rgb).max()
    r.release()


@pytest.mark.slow
def test_bloom_keeps_the_frames_energy_and_glows_around_the_sun(gl):
    """The bloomed frame's total radiance equals the unbloomed frame's within 1 % (box blurs
    keep the integral; the edges lose a little), and pixels a few degrees from the sun's disc
    brighten by more than 5 %."""
    from catalog.render.passes import glare as glare_lib

    r = FrameRenderer(gl, (256, 192))   # 0.26 deg a pixel: the sun's disc (0.53 deg) is drawn
    r.update(fabric="lace-fwa", light="sun:60", curtain_open=True, camera=orbit(0.0, -10.0, 1.0))   # looking up at the sun through the window
    r.update(bloom=True)
    r.render()
    sharp = r.read_linear()
    w, h = r.size
    glow = r.glare.read_glow(w, h)   # quarter size: each texel spread over its 4 x 4 pixels
    glow = np.repeat(np.repeat(glow, 4, axis=0), 4, axis=1)[:h, :w]
    strength = glare_lib.BLOOM_STRENGTH
    bloomed = (1.0 - strength) * sharp + strength * glow   # the mix tonemap.frag does
    assert bloomed.sum() == pytest.approx(sharp.sum(), rel=0.01)
    d = _rays(r)
    angle = np.degrees(np.arccos(np.clip(d @ r.shading_inputs().key_to_light, -1, 1)))
    ring = (angle > 2.0) & (angle < 6.0)
    assert ring.sum() > 10
    assert bloomed[ring].sum() > 1.05 * sharp[ring].sum()
    r.release()


@pytest.mark.slow
def test_another_image_shown_through_the_frames_display_step(gl):
    """FrameRenderer.display_of (the image bench shows the path-traced reference through it):
    the frame's own radiance shown again gives the frame's display image (FXAA off: display_of
    leaves out the anti-aliasing) within one 8-bit level, glare included; the same radiance
    through metrics.display (no glare) differs by more around the sun; and an image of the
    wrong size is refused with one line naming the size."""
    from catalog.core.errors import CatalogError
    from catalog.pathtrace import metrics

    r = FrameRenderer(gl, (128, 96))
    r.update(fabric="lace-fwa",
             light="sun:60",
             curtain_open=True,
             camera=orbit(0.0, -10.0, 1.0),
             antialiasing="off")
    r.render()
    own = r.read_srgb8().astype(int)
    linear = r.read_linear()
    again = r.display_of(linear).astype(int)
    assert np.abs(again - own).max() <= 1
    plain = np.round(255 * metrics.display(linear, r.exposure_scale(), r.white_balance_matrix())).astype(int)
    assert np.abs(plain - own).max() > 8   # the glare
    with pytest.raises(CatalogError, match="64x48"):
        r.display_of(np.zeros((48, 64, 3)))
    r.release()


def test_a_dated_sun_stands_where_it_stands_then():
    """sun@WHEN,LAT,LON: the key light (and so the sky behind the window) at the elevation
    catalog.optics.sun.model.sun_position gives for that time and place (it stood at a lamp's 25 deg)."""
    from catalog.optics.sun.model import sun_position

    name = "sun@2026-12-21T12:00,34.7,135.5"
    expected = 90.0 - sun_position("2026-12-21T12:00", 34.7, 135.5).zenith_deg
    from catalog.optics.lights import get_light

    assert scene_lib.key_elevation_for(get_light(name)) == pytest.approx(expected, abs=1e-9)
    assert abs(expected - scene_lib.LAMP_ELEVATION_DEG) > 5.0
