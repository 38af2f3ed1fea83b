"""The display's adapting white (catalog.render.adaptation, issue 33): the maths against
colour-science, the entering light against its closed form, the visible white against the
frame's own light (where the cloth is neutral) and read-back pixels.

Tolerances (set before running): CAT16 with D against colour-science's Zhai and Luo (2018)
two-step CAT16 (which is one-step CAT16 with degree D when the second step is complete and the
output white is the target's) within 1e-10; D against colour's CIECAM02 degree of adaptation
within 1e-10; the entering irradiance against its closed form within 1e-12 relative; the
visible white of an undyed, unbrightened voile against the frame's mean light on the same
samples within 3 % in Y and 0.003 in xy (the float64 twin against the shader).

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
    """(fabric, hour) -> the close-up curtain's mean CIELAB (L, a, b) and mean chroma. One
    renderer per fabric, only the sun changed between hours: the same pixels as a new
    renderer per hour (checked: equal at 7, 12 and 18 h), without its 1.5-3 s of set-up."""
    from catalog.presets import find_preset, load_preset
    from catalog.render.frame import FrameRenderer
    from catalog.render.snapshot import ring_xs_m, simulated_curtain

    cache = {}
    renderers = {}

    def renderer(fabric: str):
        if fabric not in renderers:
            preset = load_preset(find_preset(fabric))
            r = renderers[fabric] = FrameRenderer(gl_context, (160, 90))
            r.update(fabric=preset, camera=orbit(0.0, 0.0, 0.8))
            *mesh, size = simulated_curtain(preset, 0)
            r.set_mesh(*mesh, fabric_size_m=size)
            r.set_rings(ring_xs_m(preset))
        return renderers[fabric]

    def measure(fabric: str, hour: float):
        if (fabric, hour) not in cache:
            r = renderer(fabric)
            r.update(light=SunHour(hour))
            r.render()
            lab = _lab(r.read_srgb8()[20:70, 30:130]).reshape(-1, 3)
            cache[fabric, hour] = (lab.mean(axis=0), float(np.hypot(lab[:, 1], lab[:, 2]).mean()))
        return cache[fabric, hour]

    yield measure
    for r in renderers.values():
        r.release()


HOURS = tuple(float(h) for h in range(7, 20))


@pytest.fixture(scope="module")
def close_up(gl_context):
    """(fabric, light name) -> a rendered close-up FrameRenderer's visible white, the frame's
    mean XYZ on the same field samples, and the field's curtain share."""
    from catalog.optics.colorimetry import linear_srgb_to_xyz
    from catalog.optics.lights import get_light
    from catalog.presets import find_preset, load_preset
    from catalog.render.frame import FrameRenderer
    from catalog.render.snapshot import ring_xs_m, simulated_curtain

    def measure(fabric: str, light: str):
        preset = load_preset(find_preset(fabric))
        r = FrameRenderer(gl_context, (160, 90))
        try:
            r.update(fabric=preset, light=get_light(light), camera=orbit(0.0, 0.0, 0.8))
            *mesh, size = simulated_curtain(preset, 0)
            r.set_mesh(*mesh, fabric_size_m=size)
            r.set_rings(ring_xs_m(preset))
            r.render()
            white = adaptation.visible_white_xyz(r)
            rows, columns = adaptation.field_samples((90, 160))
            shown = linear_srgb_to_xyz(r.read_linear()[rows, columns].reshape(-1, 3).astype(np.float64))
            share = float(r.render_gbuffer()["mask"][rows, columns].mean())
        finally:
            r.release()
        return white, shown.mean(axis=0), share

    return measure


def _xy(xyz):
    return np.asarray(xyz[:2]) / float(np.sum(xyz))


@pytest.mark.slow
def test_visible_white_of_a_white_voile_is_what_the_frame_shows(close_up):
    """The white voile has no dye and no brightener: its neutral twin is the voile itself, so
    the visible white equals the frame's own mean light on the field (the float64 twin against
    the shader). Bounds: Y within 3 %, xy within 0.003."""
    white, shown, share = close_up("voile-white", "D65")
    assert share > 0.9   # the close-up's field is the curtain
    assert white[1] == pytest.approx(shown[1], rel=0.03)
    np.testing.assert_allclose(_xy(white), _xy(shown), atol=0.003)


@pytest.mark.slow
def test_visible_white_leaves_out_the_brighteners_glow(close_up):
    """Under D65 the brightened lace glows blue: the frame's mean light on the field is bluer
    (lower x and y) than the visible white, which is the lace's light without its glow.
    Bound: at least 0.003 lower in x."""
    white, shown, _ = close_up("lace-fwa", "D65")
    assert _xy(shown)[0] < _xy(white)[0] - 0.003


@pytest.mark.slow
def test_visible_white_is_not_the_dye(close_up):
    """A teal-dyed sheer is not taken for a teal light: its visible white under D65 stays
    within 0.01 in xy of the undyed voile's, while the frame's own mean is far off (> 0.02)."""
    teal_white, teal_shown, _ = close_up("sheer-teal", "D65")
    voile_white, _, _ = close_up("voile-white", "D65")
    assert np.hypot(*(_xy(teal_white) - _xy(voile_white))) < 0.01
    assert np.hypot(*(_xy(teal_shown) - _xy(teal_white))) > 0.02


@pytest.mark.slow
def test_voile_near_neutral_in_the_day(curtain_lab):
    """The goal (chroma <= 6) at 7-18 h, adapted to the visible white (7.2-7.5 adapted to the
    light entering the room, 15.4 at noon to the sun's own white). Missed at noon (6.04) while
    the box's curtain took its room side from the special-case captures; met since it takes
    it from the room's transport."""
    chroma = {hour: round(float(curtain_lab("voile-white", hour)[1]), 2) for hour in HOURS[:-1]}
    assert max(chroma.values()) <= 6.0, chroma


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 33 goal not met at 19 h: chroma 10.7 (a 2900 K light "
                                      "with D = 0.852 keeps 15 % of its warmth, what the sunset goal "
                                      "asks for; no single D meets both: docs/accuracy.md)")
def test_voile_near_neutral_every_daylight_hour(curtain_lab):
    for hour in HOURS:
        assert curtain_lab("voile-white", hour)[1] <= 6.0, hour


@pytest.mark.slow
def test_voile_stays_warm_at_sunset(curtain_lab):
    """The goal b* > 5 at the last hour the sun is up: measured b* 6.5, a* 8.0."""
    from benchmarks.accuracy import sun_hours

    assert curtain_lab("voile-white", sun_hours()[1])[0][2] > 5.0


@pytest.mark.slow
def test_lace_bluer_than_voile_in_the_day(curtain_lab):
    """The brightener's blue survives the adaptation: lace b* at least 1.5 below the voile's,
    7-18 h (measured 1.7-4.7 below, the least at 18 h)."""
    for hour in HOURS[:-1]:
        assert curtain_lab("lace-fwa", hour)[0][2] <= curtain_lab("voile-white", hour)[0][2] - 1.5, hour


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 33 goal not met at 19 h: the lace's b* is 0.4 above the "
                                      "voile's; its glow lowers b* by 0.2 at 19 h (4.2 at noon): the "
                                      "low sun holds little UV to excite it (docs/accuracy.md)")
def test_lace_bluer_than_voile_under_every_daylight(curtain_lab):
    for hour in HOURS:
        assert curtain_lab("lace-fwa", hour)[0][2] <= curtain_lab("voile-white", hour)[0][2] - 1.5, hour
