"""U3M: preset -> U3M 1.1 -> preset -> U3M -> preset keeps the coverage, dye and repeat;
a .u3ma (zipped) reads the same; a U3M that breaks its schema, a missing texture, a texture
that is not an image and an absurd dpi are refused in one line naming the file and the
field, exit 2, nothing written."""

from __future__ import annotations

import json
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest

from catalog.commands.cli import main


def _cli(capsys, *args):
    status = main([*map(str, args), "--json"])
    out = capsys.readouterr()
    return status, (json.loads(out.out) if out.out.strip() else None), out.err


@pytest.fixture(scope="module")
def teal_u3m(tmp_path_factory):
    """sheer-teal (dyed, patterned) exported as U3M 1.1."""
    folder = tmp_path_factory.mktemp("u3m")
    assert main(["export", "--fabric", "sheer-teal", "--out", str(folder / "teal.u3m")]) == 0
    return folder / "teal.u3m"


def _dye_rgb(preset):
    from catalog.exchange.u3m import rgb_of_spectrum
    from catalog.optics.spectra import read_spectrum

    spectrum = read_spectrum(preset.resolve(preset.raw["dye"]["transmittance"]))
    return rgb_of_spectrum(spectrum.wavelength_nm, spectrum.values)


@pytest.mark.slow
def test_u3m_round_trip_keeps_coverage_dye_and_repeat(teal_u3m, tmp_path, capsys):
    from catalog.presets import find_preset, load_preset
    from catalog.presets.bundle import outside_paths
    from catalog.presets.patterns import load_pattern

    original = load_preset(find_preset("sheer-teal"))
    doc = json.loads(teal_u3m.read_text())
    assert doc["schema"] == "1.1" and doc["material"]["front"]["alpha"]["texture"]["image"]["dpi"]["x"] > 0
    status, first, err = _cli(capsys, "import", teal_u3m, "--name", "one", "--out", tmp_path / "a")
    assert status == 0, err
    one = load_preset(tmp_path / "a" / "one.toml")
    assert outside_paths(one.raw) == []
    # coverage: the 16-bit alpha is the 16-bit coverage, exactly
    assert np.array_equal(load_pattern(one).coverage, load_pattern(original).coverage)
    assert one.btdf.direct == pytest.approx(original.btdf.direct, abs=1e-5)
    assert load_pattern(one).repeat_m == pytest.approx(load_pattern(original).repeat_m, rel=1e-6)
    # dye: the same colour under D65 (the original's clipped to the sRGB gamut), within 2e-3
    want = np.clip(_dye_rgb(original), 0, 1)
    assert np.max(np.abs(_dye_rgb(one) - want)) < 2e-3
    assert one.table("import")["dye_upsampling"].startswith("Mallett")
    assert one.table("cloth")["areal_density_kg_m2"] == original.table("cloth")["areal_density_kg_m2"]
    # and once more: U3M -> preset again is the same fabric (the upsampling is a fixed point)
    status, _, err = _cli(capsys, "export", "--fabric", tmp_path / "a" / "one.toml",
                          "--out", tmp_path / "b" / "one.u3m")
    assert status == 0, err
    status, _, err = _cli(capsys, "import", tmp_path / "b" / "one.u3m", "--name", "two",
                          "--out", tmp_path / "c")
    assert status == 0, err
    two = load_preset(tmp_path / "c" / "two.toml")
    assert np.array_equal(load_pattern(two).coverage, load_pattern(one).coverage)
    assert np.max(np.abs(_dye_rgb(two) - _dye_rgb(one))) < 1e-4
    assert two.btdf.direct == one.btdf.direct


@pytest.mark.slow
def test_u3ma_reads_like_the_u3m(teal_u3m, tmp_path, capsys):
    archive = tmp_path / "teal.u3ma"
    with zipfile.ZipFile(archive, "w") as z:
        z.write(teal_u3m, "teal.u3m")
        for f in (teal_u3m.parent / "teal").iterdir():
            z.write(f, f"teal/{f.name}")
    status, report, err = _cli(capsys, "import", archive, "--name", "z", "--out", tmp_path / "z")
    assert status == 0, err
    status, plain, err = _cli(capsys, "import", teal_u3m, "--name", "p", "--out", tmp_path / "p")
    assert report["open_area"] == plain["open_area"] and report["repeat_m"] == plain["repeat_m"]


def _break(doc, case):
    front = doc["material"]["front"]
    image = front["alpha"]["texture"]["image"]
    if case == "no material name":
        del doc["material"]["name"]
        return "material.name"
    if case == "no alpha":
        del front["alpha"]
        return "material.front.alpha"
    if case == "dpi not an object":
        image["dpi"] = "300"
        return "material.front.alpha.texture.image.dpi"
    if case == "climbing path":
        image["path"] = "../secret.png"
        return "material.front.alpha.texture.image.path"
    if case == "missing texture":
        image["path"] = "teal/gone.png"
        return "material.front.alpha.texture.image.path"
    if case == "not an image":
        image["path"] = "teal/physics.json"
        return "material.front.alpha.texture.image.path"
    if case == "absurd dpi":
        image["dpi"] = {"x": 1e9, "y": 1e9}
        return "material.front.alpha.texture.image.dpi"
    if case == "unknown schema":
        doc["schema"] = "9.9"
        return "schema"
    raise AssertionError(case)


@pytest.mark.slow
@pytest.mark.parametrize("case", ["no material name", "no alpha", "dpi not an object",
                                  "climbing path", "missing texture", "not an image",
                                  "absurd dpi", "unknown schema"])
def test_bad_u3m_is_refused_naming_file_and_field(teal_u3m, tmp_path, capsys, case):
    folder = tmp_path / "in"
    shutil.copytree(teal_u3m.parent, folder)
    path = folder / "teal.u3m"
    doc = json.loads(path.read_text())
    field = _break(doc, case)
    path.write_text(json.dumps(doc))
    before = path.read_bytes()
    out = tmp_path / "out"
    status, report, err = _cli(capsys, "import", path, "--name", "x", "--out", out)
    assert status == 2, err
    line = err.strip()
    assert "\n" not in line and str(path) in line and field in line, line
    assert report["exit_code"] == 2 and not out.exists()
    assert path.read_bytes() == before                         # the input is untouched
