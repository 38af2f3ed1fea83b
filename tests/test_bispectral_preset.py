"""``catalog bispectral FILE --preset BASE --export DIR``: a fabric carrying a measured
matrix's fluorescence as the renderer carries it (issue 15)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.commands.cli import main


def _export(tmp_path, *extra):
    return main(["bispectral", "CIBA12", "--preset", "lace-fwa", "--export", str(tmp_path),
                 *extra])


@pytest.mark.data
@pytest.mark.slow
def test_exported_fabric_renders_the_bands_and_the_residual(tmp_path, capsys):
    """The exported preset, loaded as a user's fabric, gives the shader under the key the
    fit's own emission: bands + residual (float64 sum of the fit), relative 1e-4 (the CSV
    files' digits); with --residual none, the bands alone and no residual file."""
    from catalog.optics.bispectral.bands import fit_banded
    from catalog.optics.bispectral.matrix import find_bfc, fit_separable, read_bfc
    from catalog.optics.lights import get_light
    from catalog.presets import find_preset, load_preset
    from catalog.render import scene

    matrix = read_bfc(find_bfc("CIBA12"))
    base = fit_separable(matrix)
    for residual, folder in ((True, tmp_path / "whole"), (False, tmp_path / "none")):
        args = [] if residual else ["--residual", "none"]
        assert _export(folder, *args) == 0
        assert "wrote preset" in capsys.readouterr().out
        preset = load_preset(find_preset("lace-fwa-ciba12-banded", fabric_dir=folder))
        files = folder / "lace-fwa-ciba12-banded"
        assert (files / "residual.csv").is_file() == residual
        assert ("residual" in preset.fluorescence.extra) == residual
        assert len(preset.fluorescence.extra["bands"]) >= 10
        assert (files / "patterns" / "lace-fwa.png").is_file()  # the folder stands alone
        fit = fit_banded(matrix, base=base, residual=residual)
        for name in ("LED-405", "UV-A", "D65"):
            key = get_light(name).irradiance_w_m2_nm
            inputs, decision = scene.build_shading_inputs(
                preset, key, np.array([0.0, 0.0, -1.0]), is_sun=False)
            assert decision.used == "physical"
            n_key = inputs.absorbed_photons[0]
            effective = n_key / (1.0 + n_key / inputs.saturation_photons)
            got = inputs.emission_per_photon * effective * 2 * math.pi
            want = fit.emitted_w_m2_nm(key)
            if residual:
                want = want + fit.residual_exitance_w_m2_nm(key)
            assert np.max(np.abs(got - want)) <= 1e-4 * np.max(np.abs(want)), name


@pytest.mark.data
@pytest.mark.slow
def test_two_fabrics_exported_into_one_folder_keep_their_own_files(tmp_path, capsys):
    from catalog.presets import find_preset, load_preset

    assert _export(tmp_path) == 0
    assert main(["bispectral", "TEXTYELL", "--preset", "voile-white", "--export",
                 str(tmp_path)]) == 0
    capsys.readouterr()
    first = load_preset(find_preset("lace-fwa-ciba12-banded", fabric_dir=tmp_path))
    second = load_preset(find_preset("voile-white-textyell-banded", fabric_dir=tmp_path))
    assert first.fluorescence.emission != second.fluorescence.emission
    assert "ciba12" in str(first.fluorescence.emission)
    # the paper mode's eq. 1-3 colour is the matrix's glow, not the base's: the brightened
    # white glows blue (z/y above 3), the yellow textile's dye fluoresces yellow-green
    # (z/y below 0.5); voile-white itself has no fluorescence table
    assert first.fluorescence.xyz[2] / first.fluorescence.xyz[1] > 3.0
    assert second.fluorescence.xyz[2] / second.fluorescence.xyz[1] < 0.5


@pytest.mark.data
@pytest.mark.parametrize("args, field", [
    (["--preset", "lace-fwa"], "--preset"),                       # no --export
    (["--residual", "none", "--export", "{out}"], "--residual"),  # no --preset
    (["--preset", "no-such-fabric", "--export", "{out}"], "no-such-fabric"),
])
def test_bad_preset_options_get_one_line_and_write_nothing(tmp_path, capsys, args, field):
    out = tmp_path / "out"
    args = [a.replace("{out}", str(out)) for a in args]
    assert main(["bispectral", "CIBA12", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert field in err and "\n" not in err
    assert not out.exists()


@pytest.mark.data
@pytest.mark.slow
def test_json_describes_the_model_the_export_carries(tmp_path, capsys):
    """With --residual none the report's model and its per-light XYZ are the bands alone,
    the model the exported fabric carries, not the default one with the residual."""
    import json

    from catalog.optics.bispectral.bands import BANDS_CHOSEN, CHOSEN

    models = {}
    for choice in ("whole", "none"):
        assert _export(tmp_path / choice, "--residual", choice, "--json",
                       "--lights", "LED-405") == 0
        models[choice] = json.loads(capsys.readouterr().out)
    assert models["whole"]["model"]["name"] == CHOSEN
    assert models["whole"]["model"]["measured_residual"] == "whole"
    assert models["none"]["model"]["name"] == BANDS_CHOSEN
    assert models["none"]["model"]["measured_residual"] is None
    assert (models["none"]["lights"]["LED-405"]["xyz_model"]
            != models["whole"]["lights"]["LED-405"]["xyz_model"])
