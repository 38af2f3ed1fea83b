"""The accuracy bench (benchmarks.accuracy, issue 33): the scene draw, the neutral display
against closed forms and colour-science, the option checks, and the CI sample against its
recorded figures (fails when a scene's FLIP exceeds its record by more than the reference's noise).

Tolerances (set before running): the tone curve and sRGB curve within 1e-6 of their closed
forms; the display's Delta E 2000 within 1e-6 of the project's own CIEDE2000 (an independent
implementation); the CI sample's FLIP at most the recorded value plus the recorded noise.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from benchmarks import accuracy

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.slow   # the draw loads the built-in rooms (each camera's limit is its room's)
def test_draw_is_seeded_and_covers_the_space():
    first = accuracy.draw_scenes(100, 7)
    assert first == accuracy.draw_scenes(100, 7)
    assert first != accuracy.draw_scenes(100, 8)
    assert {s["fabric"] for s in first} == set(accuracy.catalog_fabrics())
    assert {s["light_family"] for s in first} == set(accuracy.LIGHT_FAMILIES)
    hours_lo, hours_hi = accuracy.sun_hours()
    assert 6.0 <= hours_lo < 7.0 and 18.5 < hours_hi <= 20.0
    for scene in first:
        cam = scene["camera"]
        assert accuracy.YAW_RANGE_DEG[0] <= cam["yaw_deg"] <= accuracy.YAW_RANGE_DEG[1]
        assert accuracy.PITCH_RANGE_DEG[0] <= cam["pitch_deg"] <= accuracy.PITCH_RANGE_DEG[1]
        assert accuracy.DISTANCE_MIN_M * 0.999 <= cam["distance_m"] <= 12.0
        assert scene["room"] in accuracy.ROOMS
    from catalog.room.load import BUILTIN_ROOMS

    assert set(accuracy.ROOMS) == set(BUILTIN_ROOMS)          # every built-in room is drawn
    assert {s["room"] for s in first} == set(BUILTIN_ROOMS)


@pytest.mark.slow  # three rooms loaded
def test_every_drawn_camera_is_inside_the_room_it_is_drawn_in():
    """The distance's limit is the drawn room's own interior (the bedroom is 0.9 m shorter
    than the box): the camera never stands behind a wall, in the tune or the report seed."""
    from catalog.render.placement import placement_of_room
    from catalog.render.settings import orbit
    from catalog.room.load import load_room

    placements = {name: placement_of_room(load_room(name)) for name in accuracy.ROOMS}
    for seed in (accuracy.TUNE_SEED, accuracy.REPORT_SEED):
        for scene in accuracy.draw_scenes(48, seed):
            cam, placement = scene["camera"], placements[scene["room"]]
            free = orbit(cam["yaw_deg"], cam["pitch_deg"], cam["distance_m"], placement=placement)
            kept = orbit(cam["yaw_deg"], cam["pitch_deg"], cam["distance_m"], placement=placement,
                         inside=True)
            assert np.allclose(free.position, kept.position, atol=1e-3), scene["label"]   # not clamped
            for axis, (lo, hi) in enumerate(placement.interior):
                assert lo < free.position[axis] < hi, scene["label"]


def test_the_image_benchs_scenes_are_named_cases():
    from benchmarks import image

    cases = accuracy.named_cases()
    assert [c["label"] for c in cases] == [label for label, *_ in image.SCENES]
    assert all(c["fabric"] in accuracy.catalog_fabrics() for c in cases)


def test_sun_hours_are_above_the_horizon():
    from catalog.render.scene import solar_zenith_deg

    lo, hi = accuracy.sun_hours()
    assert solar_zenith_deg(lo) < 89.0 and solar_zenith_deg(hi) < 89.0
    assert solar_zenith_deg(hi + 0.2) > 89.0


def test_tone_curve_and_srgb_closed_forms():
    x = np.array([0.0, 0.5, 1.0, accuracy.TONE_WHITE, 10.0])
    w = accuracy.TONE_WHITE
    np.testing.assert_allclose(accuracy.tone(x), x * (1 + x / w ** 2) / (1 + x), atol=1e-12)
    assert accuracy.tone(np.array([w]))[0] == pytest.approx(1.0, abs=1e-12)
    assert np.all(np.diff(accuracy.tone(np.linspace(0, w, 50))) > 0)
    # the sRGB curve against its inverse (IEC 61966-2-1's decoding), and its two pieces meeting
    c = np.linspace(0, 1, 101)
    encoded = accuracy.srgb_encode(c)
    decoded = np.where(encoded <= 0.04045, encoded / 12.92, ((encoded + 0.055) / 1.055) ** 2.4)
    np.testing.assert_allclose(decoded, c, atol=1e-6)
    assert accuracy.srgb_encode(np.array([0.0031308]))[0] == pytest.approx(0.04045, abs=1e-5)


def test_exposure_is_the_reference_alone():
    rng = np.random.default_rng(3)
    reference = rng.uniform(0, 50, (20, 30, 3))
    scale = accuracy.exposure_from_reference(reference)
    p99 = np.percentile(accuracy.luminance(reference), 99)
    assert scale * p99 == pytest.approx(accuracy.P99_TARGET, rel=1e-12)
    grey = np.full((2, 2, 3), p99)
    shown = accuracy.neutral_display(grey, scale)
    expected = accuracy.srgb_encode(accuracy.tone(np.array([accuracy.P99_TARGET])))[0]
    np.testing.assert_allclose(shown, expected, atol=1e-6)


@pytest.mark.slow  # colour-science's import
def test_curtain_delta_e_against_the_projects_ciede2000():
    from catalog.optics.colorimetry import delta_e_2000_lab

    import colour

    rng = np.random.default_rng(5)
    a, b = rng.uniform(0, 1, (2, 8, 9, 3)).astype(np.float32)
    mask = rng.uniform(size=(8, 9)) > 0.4
    de = accuracy.curtain_delta_e(a, b, mask)

    def lab(img):
        return colour.XYZ_to_Lab(colour.sRGB_to_XYZ(img[mask].astype(np.float64)))

    np.testing.assert_allclose(de, delta_e_2000_lab(lab(a), lab(b)), atol=1e-6)
    assert accuracy.curtain_delta_e(a, a, mask).max() < 1e-9
    assert accuracy.curtain_delta_e(a, b, np.zeros((8, 9), bool)) is None


def test_summary_statistics():
    rows = [{"mean_flip": f, "curtain_delta_e_mean": 1.0 + f, "speedup": 2000.0, "frame_ms": 1.0,
             "reference_s": 2.0, "reference_flip_noise": 0.01, "noise_below_fifth": True,
             "label": str(f), "light_family": "LED", "fabric": "voile-white", "spp": 512, "spp_for_noise_rule": 1024.0} for f in np.linspace(0.01, 0.1, 10)]
    s = accuracy.summarise(rows)
    assert s["mean_flip"]["median"] == pytest.approx(0.055)
    assert s["mean_flip"]["p90"] == pytest.approx(np.percentile(np.linspace(0.01, 0.1, 10), 90))
    assert s["mean_flip"]["max"] == pytest.approx(0.1)
    assert s["worst"][0] == str(0.1)
    assert s["goal_met"]["median_mean_flip"] and s["goal_met"]["max_mean_flip"]
    assert not s["goal_met"]["scenes"]
    assert s["spp_for_noise_rule_median"] == 1024.0
    assert s["reference_s_for_noise_rule_total"] == pytest.approx(10 * 2.0 * 2)


@pytest.mark.slow
def test_unknown_room_is_refused_in_one_line(tmp_path):
    out = tmp_path / "bench"
    proc = subprocess.run([sys.executable, "-m", "catalog", "bench", "--sections", "accuracy",
                           "--room", "castle", "--out", str(out)], capture_output=True, text=True,
                          cwd=ROOT)
    assert proc.returncode == 2
    assert "--room" in proc.stderr and "castle" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.slow
def test_ci_sample_within_recorded_flip_plus_noise(tmp_path):
    """The CI sample (3 scenes of the tune seed, 64x36, 64 spp) against benchmarks/bench_accuracy_ci.json."""
    from catalog.pathtrace.backend import find_llvm

    if find_llvm() is None:
        pytest.skip("no LLVM library for Mitsuba")
    recorded = json.loads((ROOT / accuracy.CI_JSON).read_text())
    proc = subprocess.run([sys.executable, "-m", "catalog", "bench", "--quick", "--sections", "accuracy",
                           "--scenes", str(recorded["scenes"]), "--seed", str(recorded["seed"]),
                           "--out", str(tmp_path / "bench"), "--json"],
                          capture_output=True, text=True, cwd=ROOT, timeout=900)
    assert proc.returncode == 0, proc.stderr[-2000:]
    rows = json.loads(proc.stdout)["sections"]["accuracy"]["rows"]
    assert [r["label"] for r in rows] == [r["label"] for r in recorded["rows"]]
    for now, then in zip(rows, recorded["rows"]):
        assert math.isfinite(now["mean_flip"])
        assert now["mean_flip"] <= then["mean_flip"] + then["reference_flip_noise"], now["label"]
    assert len(list((tmp_path / "bench").glob("accuracy-worst-*.png"))) == len(rows)
