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
    # the height: normals out, slopes integrated back (Frankot-Chellappa): the same relief
    a, b = load_pattern(original), load_pattern(one)
    ha, hb = a.height * a.height_m, b.height * b.height_m
    ha, hb = ha - ha.mean(), hb - hb.mean()
    assert (ha * hb).sum() / np.sqrt((ha ** 2).sum() * (hb ** 2).sum()) > 0.95
    assert b.height_m == pytest.approx(np.ptp(a.height) * a.height_m, rel=0.15)
    # our own U3M carries the lobes: the same eq. 7 fabric
    assert first["lobes_from"] == "u3m custom.catalog.btdf"
    for key in ("k_d", "k_s", "tau", "rho", "g_diff", "g_spec"):
        assert getattr(one.btdf, key) == pytest.approx(getattr(original.btdf, key), rel=1e-5), key
    # and once more: U3M -> preset again is the same fabric (the upsampling a fixed point, 5e-4)
    status, _, err = _cli(capsys, "export", "--fabric", tmp_path / "a" / "one.toml",
                          "--out", tmp_path / "b" / "one.u3m")
    assert status == 0, err
    status, _, err = _cli(capsys, "import", tmp_path / "b" / "one.u3m", "--name", "two",
                          "--out", tmp_path / "c")
    assert status == 0, err
    two = load_preset(tmp_path / "c" / "two.toml")
    assert np.array_equal(load_pattern(two).coverage, load_pattern(one).coverage)
    assert np.max(np.abs(_dye_rgb(two) - _dye_rgb(one))) < 5e-4
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


def _grey_png(path: Path, values: np.ndarray):
    from PIL import Image

    Image.fromarray(np.asarray(np.round(values * 255), dtype=np.uint8), mode="L").save(path)


def test_a_u3m_10_from_another_tool(tmp_path, capsys):
    """U3M 1.0 (dpi a number, no physics), an alpha and a base colour texture: the coverage
    is the alpha, the dye's colour the mean sRGB-decoded base colour over the threads, the
    repeat the pixels over the dpi, the lobes the nearest catalog fabric's."""
    from PIL import Image

    from catalog.presets import load_preset

    folder = tmp_path / "m"
    (folder / "tex").mkdir(parents=True)
    stripes = np.tile((np.arange(64) % 4 != 0).astype(float), (64, 1))   # 25 % open
    _grey_png(folder / "tex" / "a.png", stripes)
    Image.new("RGB", (32, 32), (200, 60, 40)).save(folder / "tex" / "c.png")
    image = lambda p: {"width": 0, "height": 0, "dpi": 254.0, "path": p,
                       "repeat": {"rotation": 0, "mode": "normal"}}
    side = {k: {"constant": 0.0, "texture": None} for k in (
        "anisotropy_value", "anisotropy_rotation", "clearcoat_value", "clearcoat_normal",
        "clearcoat_roughness", "ior", "metalness", "normal", "displacement", "roughness",
        "sheen_value", "sheen_tint", "specular_value", "specular_tint", "subsurface_radius",
        "subsurface_value", "transmission")}
    side["alpha"] = {"constant": 1.0, "texture": {"factor": 1.0, "offset": 0.0,
                                                  "image": image("tex/a.png")}}
    side["basecolor"] = {"constant": {"r": 1, "g": 1, "b": 1}, "texture": {
        "factor": {"r": 1, "g": 1, "b": 1}, "mode": "multiply", "image": image("tex/c.png")}}
    side["subsurface_color"] = {"constant": {"r": 1, "g": 1, "b": 1}, "texture": None}
    side["shader"] = "principled"
    doc = {"schema": "1.0", "custom": None, "material": {
        "id": "{0f8fad5b-d9cb-469f-a165-70867728950e}", "name": "striped", "description": "",
        "created": "2020-01-01T00:00:00Z", "modified": "2020-01-01T00:00:00Z",
        "front": side, "back": None}}
    (folder / "striped.u3m").write_text(json.dumps(doc))
    status, report, err = _cli(capsys, "import", folder / "striped.u3m", "--name", "s",
                               "--out", tmp_path / "out")
    assert status == 0, err
    preset = load_preset(tmp_path / "out" / "s.toml")
    assert preset.btdf.direct == pytest.approx(0.25, abs=1e-4)
    assert preset.table("pattern")["repeat_m"][0] == pytest.approx(64 / 254 * 0.0254, rel=1e-6)
    srgb = np.array([200, 60, 40]) / 255.0
    linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
    assert np.max(np.abs(_dye_rgb(preset) - linear)) < 2e-3
    assert report["lobes_from"] in {p.stem for p in __import__("catalog.presets", fromlist=["x"]).list_presets()}
