"""The light library: colour-science's illuminants at documented levels, our lamps, names."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from catalog.core.errors import CatalogError, InputError
from catalog.optics.lights import (
    DAYLIGHT_LX,
    LAMP_LX,
    UVA_TOTAL_W_M2,
    Light,
    get_light,
    illuminance_lx,
    light_names,
)
from catalog.optics.spectra import GRID_NM

colour = pytest.importorskip("colour")


def _colour_linear_on_grid(name: str) -> np.ndarray:
    """colour-science's own linear interpolation of its table at 1 nm, zero outside it."""
    sd = colour.SDS_ILLUMINANTS[name].copy()
    first, last = float(sd.wavelengths[0]), float(sd.wavelengths[-1])
    lo, hi = max(first, GRID_NM[0]), min(last, GRID_NM[-1])
    sd = sd.interpolate(colour.SpectralShape(lo, hi, 1), interpolator=colour.LinearInterpolator)
    out = np.zeros_like(GRID_NM)
    inside = (GRID_NM >= lo) & (GRID_NM <= hi)
    out[inside] = sd[GRID_NM[inside]]
    return out


def _is_daylight(name: str) -> bool:
    return name[0] == "D" or name.startswith("ID") or name in ("B", "C") or (
        name.startswith("ISO 7589") and "Daylight" in name)


@pytest.mark.parametrize("name", [str(k) for k in colour.SDS_ILLUMINANTS.keys()])
def test_every_cie_illuminant_is_colours_table_at_the_documented_level(name):
    light = get_light(name)
    reference = _colour_linear_on_grid(name)
    assert light.name == name
    assert light.irradiance_w_m2_nm.shape == GRID_NM.shape
    # zero exactly where colour has no data (FL/LED/HP below 380 nm, E below 360, ...)
    assert np.all(light.irradiance_w_m2_nm[reference == 0] == 0)
    # a single scale factor everywhere else
    positive = reference > 0
    ratio = light.irradiance_w_m2_nm[positive] / reference[positive]
    assert np.ptp(ratio) <= 1e-9 * ratio.mean()
    # ... the one that gives the documented illuminance
    expected_lx = DAYLIGHT_LX if _is_daylight(name) else LAMP_LX
    assert light.illuminance_lx == pytest.approx(expected_lx, rel=1e-12)


def test_d65_and_a_are_tabulated_from_300_nm():
    for name in ("D65", "A"):
        light = get_light(name)
        sd = colour.SDS_ILLUMINANTS[name]
        scale = light.irradiance_w_m2_nm[GRID_NM == 560.0][0] / sd[560.0]
        assert light.irradiance_w_m2_nm[0] > 0
        assert light.irradiance_w_m2_nm[0] == pytest.approx(sd[300.0] * scale, rel=1e-12)
    # and the lamps colour tabulates from 380 nm carry no UV at all
    for name in ("FL2", "FL11", "LED-B4"):
        assert not np.any(get_light(name).irradiance_w_m2_nm[GRID_NM < 380])


def test_illuminance_agrees_with_colour_luminous_flux():
    """Our 683 * sum ybar E dl against colour's luminous_flux (V(l) of 1924 = ybar of 1931)."""
    for name in ("D65", "A", "FL11", "LED-warm", "UV-A"):
        light = get_light(name)
        sd = colour.SpectralDistribution(dict(zip(GRID_NM, light.irradiance_w_m2_nm)))
        assert light.illuminance_lx == pytest.approx(colour.luminous_flux(sd), rel=2e-4)


def test_rescaling_is_exact_and_proportional():
    base = get_light("A")
    for target in (0.0, 1e-6, 250.0, 1e9):
        scaled = get_light("A", illuminance_lx=target)
        assert scaled.illuminance_lx == pytest.approx(target, rel=1e-12, abs=1e-300)
        np.testing.assert_allclose(scaled.irradiance_w_m2_nm,
                                   base.irradiance_w_m2_nm * (target / base.illuminance_lx),
                                   rtol=1e-12, atol=0)
    assert get_light("A").illuminance_lx == pytest.approx(LAMP_LX)  # cache not disturbed


def test_rescaling_refuses_a_dark_light_and_bad_levels():
    dark = Light("dark", "nothing", np.zeros_like(GRID_NM))
    with pytest.raises(InputError, match="'dark'.*0 lx"):
        dark.scaled_to(100.0)
    for bad in (-1.0, math.nan, math.inf):
        with pytest.raises(InputError, match="illuminance"):
            get_light("D65", illuminance_lx=bad)


def test_spectra_are_read_only():
    light = get_light("D65")
    with pytest.raises(ValueError):
        light.irradiance_w_m2_nm[0] = 1.0


def test_uva_lamp():
    light = get_light("UV-A")
    e = light.irradiance_w_m2_nm
    assert np.sum(e) * 1.0 == pytest.approx(UVA_TOTAL_W_M2, rel=1e-9)
    assert GRID_NM[np.argmax(e)] == 365.0
    # full width at half maximum of the main band, from the samples: 10 nm
    above = GRID_NM[(e >= e.max() / 2) & (GRID_NM < 390)]
    assert 9.0 <= above[-1] - above[0] + 1.0 <= 11.0
    assert light.uva_fraction == pytest.approx(0.985, abs=2e-3)
    # the documented mercury-line leak makes it faintly visible, not dark
    assert 0.1 < light.illuminance_lx < 5.0


def test_warm_led_is_warm_white_without_uv():
    light = get_light("LED-warm")
    assert not np.any(light.irradiance_w_m2_nm[GRID_NM <= 400])
    assert light.uva_fraction == 0.0
    visible = GRID_NM >= 360  # colour's CMFs start at 360 nm; the LED is dark below 400
    sd = colour.SpectralDistribution(dict(zip(GRID_NM[visible],
                                              light.irradiance_w_m2_nm[visible])))
    xyz = colour.sd_to_XYZ(sd)
    cct, duv = colour.uv_to_CCT(colour.xy_to_UCS_uv(colour.XYZ_to_xy(xyz)), method="Ohno 2013")
    assert 2700.0 <= cct <= 3000.0
    assert abs(duv) < 0.003
    assert light.illuminance_lx == pytest.approx(LAMP_LX, rel=1e-12)


def test_light_names_lists_the_whole_library_and_each_loads():
    names = light_names()
    assert len(names) == len(set(names))
    for cie in colour.SDS_ILLUMINANTS.keys():
        assert cie in names
    for ours in ("UV-A", "LED-warm", "sun:22", "sun:500"):
        assert ours in names
    for name in names:
        light = get_light(name)
        assert light.name == name
        assert np.all(np.isfinite(light.irradiance_w_m2_nm))
        assert np.all(light.irradiance_w_m2_nm >= 0)
        assert light.description


def test_names_are_matched_without_case_but_reported_as_colour_spells_them():
    assert get_light("d65").name == "D65"
    assert get_light(" led-b4 ").name == "LED-B4"


@pytest.mark.parametrize("bad, pattern", [
    ("D66", r"light 'D66': unknown light; close names: D65"),
    ("FL2x", r"light 'FL2x': unknown light.*FL2"),
    ("moon", r"light 'moon': unknown light"),
    ("", r"empty light name"),
])
def test_unknown_names_are_refused_with_close_names(bad, pattern):
    with pytest.raises(InputError, match=pattern):
        get_light(bad)


def test_illuminance_of_nothing_is_zero():
    assert illuminance_lx(np.zeros_like(GRID_NM)) == 0.0


def test_cie_light_does_not_import_pvlib():
    """A CIE light costs colour-science's import and nothing more (pvlib/pandas are the
    sun's): checked by what is imported, since timings belong in benchmarks."""
    code = ("import sys; from catalog.optics.lights import get_light; get_light('D65'); "
            "get_light('UV-A'); get_light('LED-warm'); print('pvlib' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "False"


def test_cli_lights_json_parses(capsys):
    from catalog.commands.cli import main

    assert main(["lights", "--json", "--names", "D65,UV-A,sun:22"]) == 0
    out = json.loads(capsys.readouterr().out)
    rows = {r["name"]: r for r in out["lights"]}
    assert set(rows) == {"D65", "UV-A", "sun:22"}
    assert rows["D65"]["illuminance_lx"] == pytest.approx(DAYLIGHT_LX)
    assert rows["UV-A"]["uva_fraction"] > 0.9
    assert all(r["description"] for r in rows.values())


def test_cli_lights_lists_everything_as_json(capsys):
    from catalog.commands.cli import main

    assert main(["lights", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [r["name"] for r in out["lights"]] == light_names()


@pytest.mark.slow
def test_cli_lights_plot_is_written_atomically(tmp_path, capsys):
    from catalog.commands.cli import main

    target = tmp_path / "lights.png"
    assert main(["lights", "--plot", str(target), "--names", "D65,A,UV-A", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["plot"] == str(target)
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["lights.png"]


def test_cli_lights_bad_name_is_one_line_exit_2(tmp_path, capsys):
    from catalog.commands.cli import main

    target = tmp_path / "x.png"
    assert main(["lights", "--plot", str(target), "--names", "D65,nope"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "'nope'" in err
    assert not target.exists()


def test_errors_are_catalog_errors():
    assert issubclass(InputError, CatalogError)


def test_every_light_knows_its_kind_when_the_library_makes_it():
    """The light's kind and, for the sun, its model and elevation are resolved once by the
    library (issue 31: nothing below reads them from the name): CIE tables are illuminants,
    the blacklight and the 385 nm LED UV lamps, the 405 nm and white LEDs lamps; a sun by path
    stands at 90 deg less the zenith its path implies (sun.model), one by date where
    sun_position puts it; rescaling keeps both; a path with no zenith has no elevation."""
    from catalog.optics.lights import SunSource, _make, get_light
    from catalog.optics.sun.model import sun_position, zenith_deg_from_path

    kinds = {name: get_light(name).kind for name in ("D65", "A", "FL2", "UV-A", "UV-385", "LED-405",
                                                     "LED-warm", "LED-violet-white", "sun:60")}
    assert kinds == {"D65": "illuminant", "A": "illuminant", "FL2": "illuminant", "UV-A": "uv",
                     "UV-385": "uv", "LED-405": "lamp", "LED-warm": "lamp", "LED-violet-white": "lamp",
                     "sun:60": "sun"}
    assert get_light("D65").sun is None and not get_light("UV-A").is_sun
    paper, clear = get_light("sun:60").sun, get_light("sun-clear:60").sun
    assert paper.model == "paper" and clear.model == "clear"
    assert paper.elevation_deg == pytest.approx(90.0 - zenith_deg_from_path(60.0), abs=1e-12)
    assert clear.elevation_deg == paper.elevation_deg
    dated = get_light("sun@2026-06-21T12:00,34.7,135.5").sun
    assert dated.model == "date"
    assert dated.elevation_deg == pytest.approx(90.0 - sun_position("2026-06-21T12:00", 34.7, 135.5).zenith_deg)
    assert get_light("sun:10").sun.elevation_deg is None   # shorter than the 22 km layer
    scaled = get_light("sun:60", illuminance_lx=500.0)
    assert scaled.kind == "sun" and scaled.sun == paper
    with pytest.raises(ValueError, match="SunSource"):
        _make("x", "a sun without a position", np.zeros_like(GRID_NM), "sun")
    with pytest.raises(ValueError, match="kind"):
        _make("x", "a lamp with one", np.zeros_like(GRID_NM), "lamp", SunSource("paper", 30.0))
