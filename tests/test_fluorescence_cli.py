"""`catalog fluorescence`: --json matches the library, --plot writes a PNG atomically, bad
input is one line naming file and line, and nothing is written then."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from catalog.core.resources import FABRIC_DIR
from catalog.optics import fluorescence as fl
from catalog.commands.cli import main
from catalog.optics.lights import get_light
from catalog.optics.spectra import GRID_NM, read_spectrum

LACE = FABRIC_DIR / "measurements" / "lace-fwa"
ARGS = ["fluorescence", "--excitation", str(LACE / "excitation.csv"),
        "--emission", str(LACE / "emission.csv")]


def _json(capsys, *extra: str) -> dict:
    assert main([*ARGS, *extra, "--json"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1  # one JSON object, nothing else on stdout
    return json.loads(out)


@pytest.fixture(scope="module")
def spectra():
    return (read_spectrum(LACE / "excitation.csv", normalise=True),
            read_spectrum(LACE / "emission.csv", normalise=True))


@pytest.mark.parametrize("light", ["D65", "A", "LED-B4", "sun:22"])
def test_paper_mode_json_is_eq_1_to_4(capsys, spectra, light):
    result = _json(capsys, "--light", light, "--mode", "paper")
    xyz, rgb = fl.paper_colour(spectra[1])
    np.testing.assert_allclose(result["xyz"], xyz, rtol=1e-12)
    np.testing.assert_allclose(result["rgb"], rgb, rtol=1e-12)
    e = get_light(light).irradiance_w_m2_nm
    assert result["intensity"] == pytest.approx(
        fl.paper_intensity(e, spectra[0].resample(GRID_NM)), rel=1e-12)
    assert result["mode"] == "paper"
    assert "absorbed_photons_m2_s" not in result


def test_physical_mode_json_matches_the_library(capsys, spectra):
    result = _json(capsys, "--light", "D65", "--quantum-yield", "0.7",
                   "--peak-absorptance", "0.4", "--saturation", "inf")
    material = fl.material_from_spectra(*spectra, quantum_yield=0.7, peak_absorptance=0.4,
                                        saturation_photon_irradiance=float("inf"))
    e = get_light("D65").irradiance_w_m2_nm
    absorbed = fl.absorbed_photon_irradiance(material, e)
    exitance = fl.emitted_exitance_w_m2_nm(material, e)
    emission_xyz = fl.exitance_xyz(exitance)
    lux = get_light("D65").illuminance_lx
    assert result["mode"] == "physical"
    assert result["absorbed_photons_m2_s"] == pytest.approx(absorbed, rel=1e-12)
    assert result["emitted_photons_m2_s"] == pytest.approx(0.7 * absorbed, rel=1e-12)
    assert result["emitted_exitance_w_m2"] == pytest.approx(np.sum(exitance), rel=1e-12)
    assert result["emitted_radiance_w_m2_sr"] == pytest.approx(np.sum(exitance) / np.pi, rel=1e-12)
    np.testing.assert_allclose(result["emission_xyz_lm_m2"], emission_xyz, rtol=1e-12)
    assert result["intensity"] == pytest.approx(emission_xyz[1] / lux, rel=1e-9)
    assert result["light_illuminance_lx"] == pytest.approx(lux, rel=1e-12)
    assert result["paper_intensity"] == pytest.approx(
        fl.paper_intensity(e, spectra[0].resample(GRID_NM)), rel=1e-12)
    assert result["emission_rgb_linear"][1] < 0  # signed: the blue emission is out of gamut
    assert result["fluorescence_needed"] is True
    assert result["saturation_photon_irradiance"] is None  # inf is not JSON: null


def test_physical_intensity_scales_with_nothing_but_the_emission_grows_with_the_light(capsys):
    low = _json(capsys, "--light", "D65", "--illuminance", "1000")
    high = _json(capsys, "--light", "D65", "--illuminance", "100000")
    assert high["emitted_exitance_w_m2"] == pytest.approx(100 * low["emitted_exitance_w_m2"], rel=1e-6)
    assert high["intensity"] == pytest.approx(low["intensity"], rel=1e-6)


def test_led_b4_does_not_need_the_lace_brightener(capsys):
    assert _json(capsys, "--light", "LED-B4")["fluorescence_needed"] is False


@pytest.mark.slow
def test_plot_is_written(tmp_path, capsys):
    target = tmp_path / "figs" / "fig5_6.png"
    result = _json(capsys, "--light", "D65", "--plot", str(target))
    assert result["intensity"] > 0
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in target.parent.iterdir()) == ["fig5_6.png"]


def _bad_csv(tmp_path, body: str):
    path = tmp_path / "bad.csv"
    path.write_text(body)
    return path


@pytest.mark.parametrize("body,line,word", [
    ("300,0.1\n301,0.2\n", 1, "header"),
    ("wavelength_nm,intensity\n300,0.1\n301,nan\n", 3, "nan"),
    ("wavelength_nm,intensity\n300,0.1\n301,-1\n", 3, "negative"),
    ("wavelength_nm,intensity\n300,0.1\n302,0.2\n301,0.2\n", 4, "increasing"),
    ("wavelength_nm,intensity\n300,0.1\n300,0.2\n", 3, "duplicate"),
    ("wavelength_nm,intensity\n300,0.1\n", 1, "row"),
    ("", 1, "empty"),
])
@pytest.mark.parametrize("which", ["--excitation", "--emission"])
def test_bad_spectrum_is_refused_naming_file_and_line_and_nothing_is_written(
        tmp_path, capsys, body, line, word, which):
    bad = _bad_csv(tmp_path, body)
    argv = list(ARGS)
    argv[argv.index(which) + 1] = str(bad)
    plot = tmp_path / "plot.png"
    assert main([*argv, "--light", "D65", "--plot", str(plot), "--json"]) == 2
    captured = capsys.readouterr()
    message = captured.err.strip()
    # --json: stdout holds the same error as one JSON object, and nothing else
    assert json.loads(captured.out) == {"error": message.split("error: ", 1)[1], "exit_code": 2}
    assert "\n" not in message
    assert f"{bad}:{line}:" in message and word in message.lower(), message
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]


def test_unknown_light_is_refused(capsys, tmp_path):
    plot = tmp_path / "p.png"
    assert main([*ARGS, "--light", "D66", "--plot", str(plot)]) == 2
    err = capsys.readouterr().err
    assert "D66" in err and "D65" in err  # names the light and close names
    assert not plot.exists()


@pytest.mark.parametrize("option,value", [("--quantum-yield", "1.5"), ("--quantum-yield", "-0.1"),
                                          ("--peak-absorptance", "0"), ("--saturation", "-3"),
                                          ("--illuminance", "0")])
def test_out_of_range_options_are_refused(capsys, option, value):
    assert main([*ARGS, "--light", "D65", option, value]) == 2  # one line, no usage block
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and option in err[0]


@pytest.mark.slow
def test_console_script_prints_one_json_object():
    completed = subprocess.run(
        [sys.executable, "-m", "catalog", *ARGS, "--light", "sun:500", "--mode", "paper", "--json"],
        capture_output=True, text=True, timeout=120, check=True)
    result = json.loads(completed.stdout)
    assert set(result) >= {"xyz", "rgb", "intensity"}
    assert completed.stdout.count("\n") == 1
