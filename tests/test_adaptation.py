"""The display's adapting white (catalog.render.adaptation, issue 33): the maths against
colour-science, the entering light against its closed form, and read-back pixels.

Tolerances (set before running): CAT16 with D against colour-science's Zhai and Luo (2018)
two-step CAT16 (which is one-step CAT16 with degree D when the second step is complete and the
output white is the target's) within 1e-10; D against colour's CIECAM02 degree of adaptation
within 1e-10; the entering irradiance against its closed form within 1e-12 relative.

Pixels: the curtain filling a close-up (0.8 m, yaw 0; the 100x50 centre of 160x90), read back
as 8-bit sRGB, CIELAB against the display's white (D65). The issue's goals (voile chroma <= 6 at
every hour 7-19, lace b* at least 1.5 below the voile's under every daylight, the voile's b* > 5
at sunset) are strict xfails where they are not met yet (docs/accuracy.md says why); what the
adaptation achieves is asserted as measured (bounds with their margin stated).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.render import adaptation, display
from catalog.render.settings import SunHour, orbit


def test_degree_of_adaptation_is_cat16s():
    colour = pytest.importorskip("colour")
    for la in (0.0, 16.0, 100.0, 1e4):
        ours = adaptation.degree_of_adaptation(la, 1.0)
        theirs = float(colour.appearance.ciecam02.degree_of_adaptation(1.0, la))
        assert ours == pytest.approx(theirs, abs=1e-10)
    assert adaptation.degree_of_adaptation() == pytest.approx(0.8521, abs=1e-4)


@pytest.mark.parametrize("degree", [0.0, 0.5, adaptation.degree_of_adaptation(), 1.0])
def test_cat16_with_degree_against_colour_science(degree):
    colour = pytest.importorskip("colour")
    m = display.tables()["cat16"]
    source = np.array([1.0985, 1.0, 0.3558])  # illuminant A's white
    target = display.d65_white_xyz()
    xyz = np.array([[0.3, 0.4, 0.2], [0.05, 0.02, 0.4], source])
    ours = xyz @ adaptation.cat16_matrix(source, target, degree, m).T
    theirs = colour.adaptation.chromatic_adaptation_Zhai2018(
        xyz * 100, source * 100, target * 100, degree, 1.0, target * 100, transform="CAT16") / 100
    np.testing.assert_allclose(ours, theirs, atol=1e-10)
    if degree == 0.0:
        np.testing.assert_allclose(ours, xyz, atol=1e-12)


def _inputs(fabric: str, light_name: str):
    from catalog.optics.lights import get_light
    from catalog.pathtrace.scene import key_light_for
    from catalog.presets import find_preset, load_preset
    from catalog.render.scene import build_shading_inputs

    light = get_light(light_name)
    to_light, is_sun = key_light_for(light)
    inputs, _ = build_shading_inputs(load_preset(find_preset(fabric)), light.irradiance_w_m2_nm,
                                     to_light, is_sun=is_sun, paper_beam=light.name.startswith("sun:"))
    return inputs


def test_entering_irradiance_closed_form():
    inputs = _inputs("linen-dense", "sun:22")
    d = inputs.key_to_light / np.linalg.norm(inputs.key_to_light)
    assert d[2] < 0  # the sun is outside (the room on +z)
    expected = inputs.key_irradiance * -d[2] + math.pi / 2 * (inputs.sky_radiance + inputs.ground_radiance)
    np.testing.assert_allclose(adaptation.entering_irradiance(inputs), expected, rtol=1e-12)


def test_adapting_white_is_the_same_for_every_fabric():
    """The window's light, not filtered by the cloth: a dyed curtain is not taken for a tinted
    illuminant (fabrics compare under one adaptation)."""
    whites = [adaptation.adapting_white_xyz(_inputs(f, "D65")) for f in ("voile-white", "fluoro-pink", "sheer-teal")]
    for white in whites[1:]:
        np.testing.assert_allclose(white, whites[0], rtol=1e-12)


def test_noon_room_light_is_bluer_than_the_sun():
    """Under a high sun the window lets in more sky than beam: the room's white is bluer
    (lower x) than the key's own."""
    from catalog.optics.shading_reference import white_xyz
    from catalog.render.scene import sun_at_hour

    inputs = _inputs("voile-white", sun_at_hour(12.0).light_name)
    room = adaptation.adapting_white_xyz(inputs)
    key = white_xyz(inputs)
    assert room[0] / room.sum() < key[0] / key.sum() - 0.01


def _lab(srgb8: np.ndarray) -> np.ndarray:
    import colour

    return colour.XYZ_to_Lab(colour.sRGB_to_XYZ(srgb8.astype(np.float64) / 255.0))


@pytest.fixture(scope="module")
def curtain_lab(gl_context):
    """(fabric, hour) -> the close-up curtain's mean CIELAB (L, a, b) and mean chroma."""
    from catalog.presets import find_preset, load_preset
    from catalog.render.frame import FrameRenderer
    from catalog.render.snapshot import ring_xs_m, simulated_curtain

    cache = {}

    def measure(fabric: str, hour: float):
        if (fabric, hour) not in cache:
            preset = load_preset(find_preset(fabric))
            r = FrameRenderer(gl_context, (160, 90))
            try:
                r.update(fabric=preset, camera=orbit(0.0, 0.0, 0.8))
                *mesh, size = simulated_curtain(preset, 0)
                r.set_mesh(*mesh, fabric_size_m=size)
                r.set_rings(ring_xs_m(preset))
                r.update(light=SunHour(hour))
                r.render()
                lab = _lab(r.read_srgb8()[20:70, 30:130]).reshape(-1, 3)
            finally:
                r.release()
            cache[fabric, hour] = (lab.mean(axis=0), float(np.hypot(lab[:, 1], lab[:, 2]).mean()))
        return cache[fabric, hour]

    return measure


HOURS = tuple(float(h) for h in range(7, 20))


@pytest.mark.slow
def test_voile_chroma_halved_against_the_keys_white(curtain_lab):
    """Measured: the voile's mean chroma 7.2-7.5 at 7-19 h (15.4 at noon adapted to the key's
    own white, before issue 33). Bound: <= 8 at every hour."""
    for hour in HOURS:
        assert curtain_lab("voile-white", hour)[1] <= 8.0, hour


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 33 goal not met: the voile reads 7.2-7.5 chroma "
                                      "(bluish): the curtain seen from the room is lit more by the "
                                      "sky than the room's mean irradiance is (docs/accuracy.md)")
def test_voile_near_neutral_every_daylight_hour(curtain_lab):
    for hour in HOURS:
        assert curtain_lab("voile-white", hour)[1] <= 6.0, hour


@pytest.mark.slow
def test_lace_bluer_than_voile_in_the_day(curtain_lab):
    """The brightener's blue survives: lace b* at least 1.5 below the voile's, 7-18 h
    (measured 2.7-5.1 below)."""
    for hour in HOURS[:-1]:
        assert curtain_lab("lace-fwa", hour)[0][2] <= curtain_lab("voile-white", hour)[0][2] - 1.5, hour


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 33 goal not met at 19 h (0.6 b* below the voile): "
                                      "the low sun excites little brightener")
def test_lace_bluer_than_voile_under_every_daylight(curtain_lab):
    for hour in HOURS:
        assert curtain_lab("lace-fwa", hour)[0][2] <= curtain_lab("voile-white", hour)[0][2] - 1.5, hour


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 33 goal not met: at sunset the voile reads b* -3.5 "
                                      "against the beam-dominated room white (docs/accuracy.md)")
def test_voile_stays_warm_at_sunset(curtain_lab):
    from benchmarks.accuracy import sun_hours

    assert curtain_lab("voile-white", sun_hours()[1])[0][2] > 5.0
