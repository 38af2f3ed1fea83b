"""catalog.optics.dye_colour: the dye per display channel for the light it filters (issue 11,
seventh round), against colour-science's integration and the module's closed form."""

import dataclasses

import numpy as np
import pytest

from catalog.optics import dye_colour
from catalog.optics.spectra import GRID_NM


def _inputs(fabric: str, light_name: str, fluorescence: str = "physical"):
    from catalog.optics.lights import get_light
    from catalog.presets import find_preset, load_preset
    from catalog.render import scene as scene_lib

    light = get_light(light_name)
    inputs, _ = scene_lib.build_shading_inputs(load_preset(find_preset(fabric)), light.irradiance_w_m2_nm,
                                               np.array([0.0, 0.3, -1.0]), is_sun=False,
                                               fluorescence=fluorescence)
    return inputs


def _colour_science_rgb(spectrum):
    """Linear sRGB of a spectrum on GRID_NM by colour-science (Integration over 380-780 nm,
    k = 683; its sRGB matrix, no adaptation): independent of the project's tables."""
    import colour

    shape = colour.SpectralShape(380, 780, 1)
    visible = (GRID_NM >= 380) & (GRID_NM <= 780)
    sd = colour.SpectralDistribution(dict(zip(GRID_NM[visible], np.asarray(spectrum)[visible])))
    xyz = colour.sd_to_XYZ(sd, method="Integration", k=683.0, shape=shape)
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    return xyz @ np.asarray(srgb.matrix_XYZ_to_RGB).T


def test_the_dye_under_a_light_is_colour_sciences_ratio():
    """RGB(S x T) / RGB(S) per channel within 0.3 % (colour-science trims its CMFs to the
    shape, 1e-3 in the colorimetry test) of colour-science's, for a smooth light and a yellow
    dye's steep edge."""
    light = 1.0 + 0.5 * np.sin(GRID_NM / 40.0)
    dye = 0.05 + 0.9 / (1.0 + np.exp(-(GRID_NM - 500.0) / 12.0))
    ours = dye_colour.dye_rgb_under(light, dye, np.ones(3))
    reference = _colour_science_rgb(light * dye) / _colour_science_rgb(light)
    np.testing.assert_allclose(ours, reference, rtol=3e-3)
    # a grey dye is its own value in every channel; a negligible channel keeps the fallback
    np.testing.assert_allclose(dye_colour.dye_rgb_under(light, np.full_like(GRID_NM, 0.3), np.ones(3)), 0.3,
                               rtol=1e-12)
    dark = np.where(GRID_NM < 360, 1.0, 0.0)   # all of it outside the eye's range
    np.testing.assert_array_equal(dye_colour.dye_rgb_under(dark, dye, (7.0, 8.0, 9.0)), [7.0, 8.0, 9.0])


@pytest.mark.parametrize("fabric, light", [("voile-white", "D65"), ("safety-yellow", "D65"),
                                           ("safety-yellow", "UV-A")])
def test_without_a_glow_the_secondary_light_takes_the_keys_dye(fabric, light):
    """With fluorescence off the secondary light is the key's spectrum times a number, so its
    dye is the key's to rounding: the frame's colours of fabrics that do not glow are what
    they were before the seventh round."""
    inputs = _inputs(fabric, light, fluorescence="off")
    np.testing.assert_allclose(dye_colour.secondary_dye_rgb(inputs), dye_colour.key_dye_rgb(inputs),
                               rtol=1e-9, atol=1e-12)


def test_safety_yellows_glow_under_the_uv_lamp_passes_its_dye():
    """Under the UV-A lamp the key's visible leak is violet, which the yellow dye absorbs: the
    key's dye is about 0.05 in every channel (green too, whose key channel is negative; the
    frame's rule was 1 there before). The cloth's glow is green-yellow: the secondary light's
    green passes at the glow's own dye (> 0.85), to 2 % of the closed form from colour-science's
    RGB of the key's share K and the glow G."""
    inputs = _inputs("safety-yellow", "UV-A")
    key = dye_colour.key_dye_rgb(inputs)
    assert np.all(np.abs(key - 0.048) < 0.02), key
    secondary = dye_colour.secondary_dye_rgb(inputs)
    k = np.asarray(inputs.key_irradiance) * dye_colour.key_forward_share(inputs)
    g = dye_colour.glow_exitance(inputs)
    assert _colour_science_rgb(g)[1] > 5 * abs(_colour_science_rgb(k)[1])   # the glow's green dominates
    dye = np.asarray(inputs.dye_transmittance)
    closed = ((_colour_science_rgb(k * dye) + _colour_science_rgb(g * dye))
              / (_colour_science_rgb(k) + _colour_science_rgb(g)))
    assert secondary[1] > 0.85
    np.testing.assert_allclose(secondary[1], closed[1], rtol=0.02)
    # a white brightened lace passes everything: its secondary dye is 1
    np.testing.assert_allclose(dye_colour.secondary_dye_rgb(_inputs("lace-fwa", "UV-A")), 1.0, atol=1e-3)


def test_the_glow_exitance_follows_the_saturation_of_eq_10():
    """pi L of the effective photons n / (1 + n / N_sat): halving N_sat lowers it, and with the
    emission per photon 0 there is none."""
    inputs = _inputs("safety-yellow", "UV-A")
    full = dye_colour.glow_exitance(inputs)
    n = float(inputs.absorbed_photons[0])
    half = dye_colour.glow_exitance(dataclasses.replace(inputs, saturation_photons=n))
    np.testing.assert_allclose(half.sum() / full.sum(),
                               (n / 2.0) / (n / (1.0 + n / float(inputs.saturation_photons))), rtol=1e-9)
    none = dataclasses.replace(inputs, emission_per_photon=np.zeros_like(full))
    assert not dye_colour.glow_exitance(none).any()


@pytest.mark.gl
def test_the_frame_passes_the_rooms_and_folds_light_by_the_secondary_dye(gl):
    """FrameRenderer: the curtain's reflectance of the room's light and its forward
    transmittance of the folds' light take the secondary dye (safety-yellow under the UV lamp:
    green > 0.85 of the undyed factors), the beam the key's (its green 0.048 of the undyed
    thread's, where the frame's rule gave 1 for the key's negative green channel)."""
    from catalog.optics.shading_reference import hg_hemisphere_factors
    from catalog.render.frame import FrameRenderer

    r = FrameRenderer(gl, (32, 24))
    r.update(fabric="safety-yellow", light="UV-A")
    inputs = r.shading_inputs()
    secondary, key = dye_colour.secondary_dye_rgb(inputs), dye_colour.key_dye_rgb(inputs)
    back = (inputs.a_diff * hg_hemisphere_factors(inputs.g_diff)[1]
            + inputs.a_spec * hg_hemisphere_factors(inputs.g_spec)[1])
    np.testing.assert_allclose(r.terms.curtain_room_reflectance_rgb(inputs), np.clip(secondary * back, 0, 1), rtol=1e-9)
    assert r.terms.curtain_room_reflectance_rgb(inputs)[1] > 0.85 * back
    diffuse, _directional = r.terms.curtain_forward_rgb(inputs)
    forward = inputs.a_diff * hg_hemisphere_factors(inputs.g_diff)[0]
    np.testing.assert_allclose(diffuse, np.clip(secondary * forward, 0, 1), rtol=1e-9)
    thread = np.asarray(r.terms.room_colours(inputs)["u_thread_beam_rgb"])
    undyed = inputs.a_spec * hg_hemisphere_factors(inputs.g_spec)[0] / (1.0 - inputs.direct)
    np.testing.assert_allclose(thread, np.clip(key * undyed, 0, 1), rtol=1e-6)
    assert thread[1] < 0.1 * undyed
    r.release()




def test_an_ill_conditioned_channel_keeps_the_fallback():
    """Under the HP1 sodium lamp the light's linear-sRGB blue is a near-cancellation of the
    colour-matching lobes (a few 1e-6 of its largest channel); sheer-teal's dye made the ratio
    there about -1.4e4, which sent rare huge sparkles through the RGB reference. That channel
    now keeps the fallback; the well-conditioned channels keep the exact ratio, and a dye's
    ordinary out-of-gamut channels (sheer-teal's green under D65, 1.42) are untouched."""
    from catalog.optics.lights import get_light
    from catalog.presets import find_preset, load_preset
    from catalog.render import scene as scene_lib

    teal = scene_lib.dye_transmittance(load_preset(find_preset("sheer-teal")))
    sodium = get_light("HP1").irradiance_w_m2_nm
    light = dye_colour._rgb(sodium)
    dyed = dye_colour._rgb(sodium * teal)
    ours = dye_colour.dye_rgb_under(sodium, teal, (7.0, 8.0, 9.0))
    bad = np.abs(dyed) > dye_colour.MAX_CHANNEL_RATIO * np.abs(light)
    assert bad.any()                                   # the case this guards exists
    assert np.all(np.abs(ours) <= dye_colour.MAX_CHANNEL_RATIO)
    np.testing.assert_array_equal(ours[bad], np.array([7.0, 8.0, 9.0])[bad])
    np.testing.assert_allclose(ours[~bad], dyed[~bad] / light[~bad], rtol=1e-12)
    d65 = get_light("D65").irradiance_w_m2_nm
    np.testing.assert_allclose(dye_colour.dye_rgb_under(d65, teal, np.ones(3)),
                               dye_colour._rgb(d65 * teal) / dye_colour._rgb(d65), rtol=1e-12)
