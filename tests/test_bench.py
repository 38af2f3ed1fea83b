"""catalog bench: the quick run's JSON, each section on a tiny input, the reduced
re-radiation matrices against closed forms, and the command's refusals."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from catalog.core.resources import data_missing_reason

from benchmarks import SECTIONS
from benchmarks import reduction as red
from catalog.optics.spectra import GRID_NM

LM_PER_W = 683.0


def _light(name: str) -> np.ndarray:
    from catalog.optics.lights import get_light

    return np.asarray(get_light(name).irradiance_w_m2_nm, dtype=np.float64)


def _numbers_all_finite(obj, path="") -> list[str]:
    """Paths of every number that is not finite, and of every null (print_json writes a
    non-finite float as null)."""
    bad = []
    if isinstance(obj, dict):
        for k, v in obj.items():
            bad += _numbers_all_finite(v, f"{path}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            bad += _numbers_all_finite(v, f"{path}[{i}]")
    elif obj is None:
        bad.append(path)
    elif isinstance(obj, float) and not math.isfinite(obj):
        bad.append(path)
    return bad


# --------------------------------------------------------------------------- the command

@pytest.mark.gl
@pytest.mark.slow
def test_quick_json_has_every_requested_section_with_finite_numbers(tmp_path):
    # colour and startup are smoked below on tiny inputs (together they take ~90 s here)
    sections = ["fluorescence", "fit", "cloth", "stability"]
    if data_missing_reason("bispectral") is not None:  # fluorescence reads the measured matrices
        sections.remove("fluorescence")
    out = tmp_path / "bench"
    result = subprocess.run([sys.executable, "-m", "catalog", "bench", "--quick", "--json",
                             "--sections", ",".join(sections), "--out", str(out)],
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    report = json.loads(result.stdout)  # one JSON object, nothing else on stdout
    assert report["quick"] is True and report["failed"] == {}
    assert list(report["sections"]) == sections
    for name in sections:
        section = report["sections"][name]
        assert section["rows"], name
        bad = [p for p in _numbers_all_finite({"rows": section["rows"], "summary": section["summary"]})
               if not p.endswith("synthetic_max_rel_param_error")]
        assert not bad, f"{name}: non-finite or null at {bad[:5]}"
    files = ["bench.md", "bench.json", "bench_fit.png", "bench_cloth.png"]
    files += ["bench_fluorescence_rgb.png"] if "fluorescence" in sections else []
    for name in files:
        assert (out / name).stat().st_size > 0, name
    assert json.loads((out / "bench.json").read_text())["sections"].keys() == set(sections)
    text = (out / "bench.md").read_text()
    assert "## Cloth" in text
    assert ("## Fluorescence in an RGB engine" in text) == ("fluorescence" in sections)
    # the synthetic fit has true parameters: LM on all points recovers them within 10 %
    fit = report["sections"]["fit"]["summary"]["per_method"]
    assert fit["LM, 4800 points"]["synthetic_max_rel_param_error"] < 0.1


def test_unknown_section_is_refused_in_one_line(tmp_path):
    result = subprocess.run([sys.executable, "-m", "catalog", "bench", "--sections", "colour,speed",
                             "--out", str(tmp_path / "b")], capture_output=True, text=True)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "--sections" in lines[0] and "speed" in lines[0]
    assert not (tmp_path / "b").exists()


def test_out_that_is_a_file_is_refused(tmp_path):
    target = tmp_path / "file.txt"
    target.write_text("keep me")
    result = subprocess.run([sys.executable, "-m", "catalog", "bench", "--sections", "fit",
                             "--out", str(target)], capture_output=True, text=True)
    assert result.returncode == 2 and "--out" in result.stderr
    assert target.read_text() == "keep me"


def test_every_section_module_has_run():
    import importlib

    for name, module in SECTIONS.items():
        assert callable(importlib.import_module(module).run), name


# --------------------------------------------------------------------------- sections, tiny

@pytest.mark.gl
@pytest.mark.slow
def test_colour_section_on_one_fabric_and_light(gl, tmp_path):
    from benchmarks import colour

    result = colour.run(ctx=gl, fabrics=["lace-fwa"], lights=["D65"], error_size=(40, 24),
                        time_size=(64, 36), repeats=1)
    rows = result["rows"]
    assert [r["variant"] for r in rows] == [v[0] for v in colour.VARIANTS]
    assert not _numbers_all_finite(rows)
    by = {r["variant"]: r for r in rows}
    # RGB mode pre-integrates light x cloth per pair: it equals the float64 reference
    assert by["physical rgb"]["mean_delta_e"] < 1e-3
    assert by["physical rgb"]["time_ratio"] == pytest.approx(1.0)
    assert by["physical rgb"]["shader_fluorescence"] == "physical"
    # the brightened lace under D65 glows: leaving it out is a visible error
    assert by["rgb, no fluorescence"]["mean_delta_e"] > 1.0
    for r in rows:
        assert r["p95_delta_e"] <= r["max_delta_e"] + 1e-12 and r["pixels"] > 100
    paths = colour.plot(result, tmp_path)
    assert all(p.stat().st_size > 0 for p in paths)


@pytest.mark.gl
@pytest.mark.slow
def test_truth_switches_on_the_emission_as_the_renderer_does(gl):
    """The bench's truth forces the emission on with the scene's with_physical_emission;
    the renderer's own physical mode must build the same terms."""
    from catalog.render.frame import FrameRenderer
    from catalog.render.scene import fluorescent_material, with_physical_emission

    renderer = FrameRenderer(gl, (16, 16))
    try:
        renderer.update(fabric="lace-fwa", light="D65", fluorescence="physical")
        kept = renderer.shading_inputs()
        assert kept.fluorescence_mode == "physical"
        renderer.update(fluorescence="off")
        forced = with_physical_emission(renderer.shading_inputs(),
                                        fluorescent_material(renderer.preset))
    finally:
        renderer.release()
    np.testing.assert_allclose(forced.absorbed_photons, kept.absorbed_photons, rtol=1e-12)
    np.testing.assert_allclose(forced.emission_per_photon, kept.emission_per_photon, rtol=1e-12)
    assert forced.saturation_photons == kept.saturation_photons


def test_pareto_front_and_default_choice():
    from benchmarks import colour

    points = [(1.0, 0.1, "a"), (0.9, 0.5, "b"), (1.2, 0.05, "c"), (1.3, 0.2, "d")]
    assert colour.pareto_front(points) == ["a", "b", "c"]  # d is beaten by a on both
    rows = []
    for label, _, _ in colour.VARIANTS:
        ratio = {"physical rgb": 1.0, "physical 16 bands": 2.0}.get(label, 1.05)
        error = {"physical rgb": 0.2, "physical 16 bands": 0.1}.get(label, 3.0)
        rows.append({"variant": label, "light": "D65", "mean_delta_e": error, "p95_delta_e": error,
                     "frame_ms": 10 * ratio, "time_ratio": ratio})
    summary = colour.summarise(rows)
    assert summary["default"] == "physical rgb" and summary["goal_met"]
    # 16 bands is more accurate but twice as slow: on the front, not the default
    assert "physical 16 bands" in summary["pareto_front"]


def test_fit_errors_are_zero_for_the_true_parameters():
    from benchmarks import fit
    from catalog.optics.btdf import eq7_transmittance

    data = fit.synthetic_gonio()
    t = fit.SYNTHETIC_TRUTH
    clean = data.with_values(eq7_transmittance(data.one_minus_cos, t["direct"], t["a_diff"],
                                               t["a_spec"], t["g_diff"], t["g_spec"],
                                               data.straight_through))
    e = fit.errors(clean, t, t)
    assert e["rmse_4800"] == 0.0 and e["max_rel_param_error"] == 0.0 and e["finite"]
    # the noisy set is 2 % off in RMS relative terms
    assert fit.errors(data, t, t)["weighted_rms_4800"] == pytest.approx(0.02, rel=0.15)


@pytest.mark.slow
def test_cloth_runs_are_deterministic_and_deviation_is_a_distance():
    from benchmarks import cloth

    backend = cloth.fastest_backend()
    a, _, finite, used = cloth.trajectory((5, 6), 4, backend, 3)
    b, _, _, _ = cloth.trajectory((5, 6), 4, backend, 3)
    assert finite and used == 4
    assert cloth.deviation(a, b) == (0.0, 0.0)
    shifted = a.copy()
    shifted[..., 0] += 0.003
    rms, worst = cloth.deviation(shifted, a)
    assert rms == pytest.approx(0.003) and worst == pytest.approx(0.003)


@pytest.mark.slow
def test_startup_section_without_first_frames():
    from benchmarks import startup

    result = startup.run(quick=True, first_frames=False, repeats=1)
    assert not _numbers_all_finite(result["rows"])
    heavy = result["summary"]["heavy_imports"]
    assert heavy["catalog.commands.cli"] == [] and "scipy" not in heavy["catalog.viewer"]
    assert result["summary"]["help_s"] > 0
    tables = startup.markdown_tables(result)  # the docs' tables also say when a part is missing
    assert set(tables) == {"startup", "startup_brief"}
    assert "The viewer was not timed (first frames not timed" in tables["startup"]


# --------------------------------------------------------------------------- reductions

def test_grey_material_reduces_to_a_scaled_identity():
    sensors = red.cmf_sensors(False)
    grey = red.reduce_operator(lambda light: 0.37 * light, sensors, sensors)
    np.testing.assert_allclose(grey, 0.37 * np.eye(3), atol=1e-12)
    # with the UV band as a fourth input channel: XYZ out = 0.37 [I | 0]
    with_uv = red.reduce_operator(lambda light: 0.37 * light, sensors, red.cmf_sensors(True))
    np.testing.assert_allclose(with_uv, 0.37 * np.hstack([np.eye(3), np.zeros((3, 1))]), atol=1e-12)


@pytest.mark.parametrize("light_name", ["D65", "A", "FL2", "UV-A", "sun:500"])
def test_per_light_basis_is_exact_for_a_non_fluorescent_cloth(light_name):
    """A coloured (not grey) reflectance: the per-light reduction returns exactly the XYZ of
    R E, the per-light RGB a pre-integrating renderer uses (closed form: sum cmf R E)."""
    reflectance = 0.2 + 0.6 * np.exp(-0.5 * ((GRID_NM - 600.0) / 40.0) ** 2)
    light = _light(light_name)
    sensors = red.cmf_sensors(False)
    reduced = red.reduce_operator(lambda e: reflectance * e, sensors, sensors,
                                  basis=red.light_boxes(light))
    got = red.apply_reduced(reduced, sensors, light)
    expected = (reflectance * light) @ sensors
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12 * np.max(expected))
    # the light-independent reduction is not exact for this coloured cloth in general
    dual = red.apply_reduced(red.reduce_operator(lambda e: reflectance * e, sensors, sensors),
                             sensors, light)
    if light_name in ("FL2", "A"):
        assert np.max(np.abs(dual - expected) / expected) > 1e-4


def test_dual_basis_is_exact_for_a_light_in_the_cmf_span_even_when_fluorescent():
    # a fluorescent operator: reflectance plus an emission driven by absorbed UV-blue
    emission = np.exp(-0.5 * ((GRID_NM - 450.0) / 20.0) ** 2)
    absorption = np.exp(-0.5 * ((GRID_NM - 370.0) / 25.0) ** 2)

    def operator(light):
        return 0.8 * light + 0.01 * emission * float(absorption @ light)

    sensors = red.cmf_sensors(False)
    reduced = red.reduce_operator(operator, sensors, sensors)
    light = sensors @ np.array([0.5, 1.0, 0.8])  # a light the three CMFs span
    np.testing.assert_allclose(red.apply_reduced(reduced, sensors, light), operator(light) @ sensors,
                               rtol=1e-10)


@pytest.mark.data
def test_fichet_reduction_matches_the_bispectral_studys_implementation():
    from catalog.optics.bispectral import study
    from catalog.optics.bispectral.matrix import find_bfc, read_bfc

    matrix = read_bfc(find_bfc("TEXTYELL"))
    ours = red.fichet_reduced(matrix)
    theirs = study.reduced_matrix(matrix, with_uv=False)
    np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-12 * np.max(np.abs(theirs)))


@pytest.mark.data
@pytest.mark.parametrize("light_name", ["D65", "UV-A"])
def test_per_light_reduction_of_a_measured_matrix_is_the_exact_colour(light_name):
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid, find_bfc, read_bfc

    matrix = read_bfc(find_bfc("CIBA12"))
    light = _light(light_name)
    reduced = red.per_light_reduced(matrix, light)
    got = red.apply_reduced(reduced, red.cmf_sensors(False), light)
    expected = exact_exitance_on_grid(matrix, light) @ red.cmf_sensors(False)
    np.testing.assert_allclose(got, expected, rtol=1e-9)


@pytest.mark.parametrize("n_bands", [6, 9, 16])
def test_n_bands_are_exact_for_a_grey_non_fluorescent_material(n_bands):
    """bands_xyz on a flat reflectance and no emission: the band colours are the key light's
    own, so the N-band colour equals the spectral one (closed form: 683 r sum cmf E)."""
    from types import SimpleNamespace

    from benchmarks.fluorescence_rgb import bands_xyz
    from catalog.optics.fluorescence import FluorescentMaterial

    dark = FluorescentMaterial(absorptance=np.full(GRID_NM.size, 0.5),  # absorbs, emits nothing
                               emission_pdf_per_nm=np.full(GRID_NM.size, 1.0 / GRID_NM.size),
                               quantum_yield=0.0, saturation_photon_irradiance=math.inf)
    models = SimpleNamespace(reflectance_fit=np.full(GRID_NM.size, 0.45),
                             fit=SimpleNamespace(material=lambda: dark))
    for light_name in ("D65", "FL2"):
        light = _light(light_name)
        expected = LM_PER_W * 0.45 * (light @ red.cmf_sensors(False))
        np.testing.assert_allclose(bands_xyz(models, light, n_bands), expected, rtol=2e-6)


def test_a_section_run_alone_without_its_data_says_so_in_one_line(tmp_path, monkeypatch, capsys):
    """python -m benchmarks.fluorescence_rgb without the measured matrices: exit 2, one line
    naming --data, no JSON written (the committed one is never half-replaced)."""
    from benchmarks.results import section_main
    from catalog.core import resources

    monkeypatch.setattr(resources, "_user_data", None)
    monkeypatch.setenv(resources.DATA_ENV, str(tmp_path / "nowhere"))
    out = tmp_path / "result.json"
    assert section_main("fluorescence", ["--quick", "--json-out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--data" in err[0] and "nowhere" in err[0]
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.gl
def test_render_shaders_bench_runs_every_variant(tmp_path):
    """The shader benchmark end to end at a small size: it broke twice unseen (a constant
    moved to core.constants without its import; a variant that changed LD under a pattern)."""
    from benchmarks import render_shaders

    out = tmp_path / "render.json"
    assert render_shaders.main(["--quick", "--size", "96x64", "--repeats", "1", "--draws", "1",
                                "--json", str(out)]) == 0
    result = json.loads(out.read_text())
    labels = json.dumps(result)
    for needed in ("trivial", "rgb physical", "rgb off, no see-through", "16 bands physical"):
        assert needed in labels
