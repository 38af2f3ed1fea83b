"""Carrying an out-of-gamut emission colour to the shader: the measured colour errors
(Delta E 2000 against the exact spectral colour) of docs/fluorescence.md, with bounds."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def tables(shared_data):  # the measured brightener is one of the emissions studied
    from benchmarks import fluorescence_tables

    return fluorescence_tables


@pytest.fixture(scope="module")
def rows(tables):
    return tables.gamut_rows()


def _row(rows, material, background, light):
    (row,) = [r for r in rows if r["material"] == material and r["background"].startswith(background)
              and r["light"] == light]
    return row


def test_the_emissions_studied_are_out_of_gamut(rows):
    for material in ("lace-fwa", "calcofluor (measured)"):
        assert min(_row(rows, material, "black", "D65")["emission_rgb_relative"]) < 0


def test_signed_carry_is_exact_in_linear_light(rows):
    """XYZ -> RGB is linear, so the signed emission added to the reflected light is exact."""
    assert max(r["signed"] for r in rows) < 1e-9


def test_signed_carry_loses_only_what_the_display_loses_anyway(rows):
    for r in rows:
        assert r["signed_display"] == pytest.approx(r["display_floor"], abs=1e-9)
        assert r["signed_display"] <= r["clip_display"] + 1e-9


@pytest.mark.parametrize("material", ["lace-fwa", "calcofluor (measured)"])
def test_on_a_white_cloth_the_sum_is_in_gamut_and_clipping_the_emission_costs_up_to_0_3(
        rows, material):
    for light in ("D65", "A", "FL2", "FL11", "LED-B4", "sun:22"):
        r = _row(rows, material, "white", light)
        assert r["sum_in_gamut"]
        assert r["display_floor"] < 1e-9
        assert r["clip"] < 0.3
        assert r["desaturate"] < 1.5
    daylight = _row(rows, material, "white", "D65")
    assert 0.05 < daylight["clip"] < daylight["desaturate"]


@pytest.mark.parametrize("material", ["lace-fwa", "calcofluor (measured)"])
def test_against_black_the_display_gamut_dominates(rows, material):
    r = _row(rows, material, "black", "D65")
    assert not r["sum_in_gamut"]
    assert 0.5 < r["display_floor"] < 2.0
    assert r["desaturate"] > r["clip"]  # greying out the emission is worse than clipping it


def test_under_uv_light_a_luminance_keeping_map_beats_clipping_at_display(rows):
    r = _row(rows, "lace-fwa", "white", "UV-A")
    assert r["display_floor"] > 2.0
    assert r["signed_display_desaturate"] < r["display_floor"]


def test_which_lights_need_fluorescence_for_the_lace(tables):
    needed = {r["light"]: r["needed"] for r in tables.intensity_rows()}
    for light in ("D65", "A", "FL2", "FL11", "UV-A", "sun:22"):
        assert needed[light], light
    for light in ("LED-B4", "LED-warm"):
        assert not needed[light], light
