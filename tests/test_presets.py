"""Fabric presets: the committed catalog (fabrics/*.toml), its regeneration from
fabrics/measurements/ by tools/make_presets.py, and the preset loader's validation
(catalog/presets/__init__.py)."""

from __future__ import annotations

import copy
import importlib.util
import math
import tomllib

import numpy as np
import pytest

from catalog.core.resources import FABRIC_DIR, PROJECT_ROOT
from catalog.core.errors import InputError
from catalog.presets import list_presets, load_preset, preset_from_dict, save_preset_dict

REQUIRED_FABRICS = {"lace-fwa", "voile-white", "linen-dense", "sheer-teal", "safety-yellow",
                    "fluoro-pink"}
FLUORESCENT = {"lace-fwa", "safety-yellow", "fluoro-pink"}


def _make_presets_module():
    spec = importlib.util.spec_from_file_location("make_presets",
                                                  PROJECT_ROOT / "tools" / "make_presets.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# --- the committed catalog --------------------------------------------------------------

def test_catalog_has_a_preset_for_every_measurement():
    presets = {p.stem for p in list_presets()}
    measured = {p.parent.name for p in (FABRIC_DIR / "measurements").glob("*/gonio.csv")}
    assert len(presets) >= 8
    assert REQUIRED_FABRICS <= presets
    assert presets == measured


@pytest.mark.parametrize("path", list_presets(), ids=lambda p: p.stem)
def test_every_preset_loads_and_is_consistent(path):
    preset = load_preset(path)
    b = preset.btdf
    assert 0 <= b.direct <= 1 and 0 < b.rho <= 1
    assert b.g_spec > b.g_diff
    ident = preset.fit["identifiable"]
    assert b.a_diff == pytest.approx(ident["a_diff"], rel=1e-4, abs=1e-7)
    assert b.a_spec == pytest.approx(ident["a_spec"], rel=1e-4, abs=1e-7)
    assert preset.fit["points"] == 4800
    assert preset.fit["rmse"] < preset.fit["cook_torrance"]["rmse"]
    assert preset.resolve(preset.fit["source"]).is_file()
    assert preset.has_fluorescence == (preset.name in FLUORESCENT)
    if preset.has_fluorescence:
        fl = preset.fluorescence
        assert fl.excitation.is_file() and fl.emission.is_file()
        assert fl.xyz[1] == pytest.approx(100.0)
        assert 0 < fl.extra["quantum_yield"] <= 1
    cloth = preset.table("cloth")
    assert cloth["areal_density_kg_m2"] > 0 and cloth["stretch_stiffness_n_m"] > 0


@pytest.mark.parametrize("path", list_presets(), ids=lambda p: p.stem)
def test_cloth_table_is_what_the_simulator_reads(path):
    from catalog.cloth.params import ClothParams

    preset = load_preset(path)
    params = ClothParams.from_preset(preset)
    assert params.areal_density_kg_m2 == pytest.approx(preset.table("cloth")["areal_density_kg_m2"])


@pytest.mark.filterwarnings("ignore:Aligning")   # colour-science reshaping E and the dye to its CMFs
def test_dyed_sheer_is_coloured_per_channel_and_spectrally():
    from catalog.optics.spectra import read_spectrum

    preset = load_preset(FABRIC_DIR / "sheer-teal.toml")
    rgb = preset.raw["btdf"]["rgb"]
    a_spec = np.array(rgb["a_spec"])
    assert len(rgb["direct"]) == len(rgb["a_diff"]) == 3
    assert a_spec.max() / a_spec.min() > 1.5                      # not grey
    dye = read_spectrum(preset.resolve(preset.raw["dye"]["transmittance"]))
    assert np.all((dye.values >= 0) & (dye.values <= 1))
    assert dye.values.max() - dye.values.min() > 0.5              # spectral, not flat
    red = dye.values[(dye.wavelength_nm > 600) & (dye.wavelength_nm < 680)].mean()
    green = dye.values[(dye.wavelength_nm > 480) & (dye.wavelength_nm < 540)].mean()
    assert red < 0.5 * green                                      # teal absorbs the red
    # tau is the dye's luminance-weighted absorption: colour-science's Y of the dye's
    # transmittance under the equal-energy illuminant
    import colour

    sd = colour.SpectralDistribution(dict(zip(dye.wavelength_nm, dye.values)))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    y = colour.sd_to_XYZ(sd, cmfs, colour.SDS_ILLUMINANTS["E"])[1] / 100.0
    assert preset.btdf.tau == pytest.approx(-math.log(y), rel=0.01)


def test_direct_is_close_to_the_open_area_of_the_weave():
    """The fitted see-through recovers the generator's open area for the open fabrics."""
    for name in ("lace-fwa", "voile-white", "net-grey", "safety-yellow", "sheer-teal"):
        preset = load_preset(FABRIC_DIR / f"{name}.toml")
        comments = (FABRIC_DIR / "measurements" / name / "gonio.csv").read_text().splitlines()
        open_area = next(float(c.split(":")[1]) for c in comments
                         if c.startswith("# open_area_normal:"))
        assert preset.btdf.direct == pytest.approx(open_area, abs=0.06), name


def _assert_same_document(new, old, where=""):
    assert type(new) is type(old) or (isinstance(new, (int, float))
                                      and isinstance(old, (int, float))), where
    if isinstance(old, dict):
        assert set(new) == set(old), where
        for key in old:
            _assert_same_document(new[key], old[key], f"{where}.{key}")
    elif isinstance(old, list):
        assert len(new) == len(old), where
        for i, (a, b) in enumerate(zip(new, old)):
            _assert_same_document(a, b, f"{where}[{i}]")
    elif isinstance(old, float):
        # six significant digits are written; allow the last one to move with the BLAS
        assert new == pytest.approx(old, rel=2e-5, abs=1e-12), where
    else:
        assert new == old, where


@pytest.mark.slow
def test_regenerating_reproduces_the_committed_presets(tmp_path):
    """tools/make_presets.py (catalog fit on every measurement) into a scratch folder
    beside a link to the same measurements gives the committed files."""
    (tmp_path / "measurements").symlink_to(FABRIC_DIR / "measurements")
    make_presets = _make_presets_module()
    summaries = make_presets.make_presets(tmp_path / "measurements", tmp_path)
    assert len(summaries) == len(list_presets())
    for path in list_presets():
        new = tomllib.loads((tmp_path / path.name).read_text())
        old = tomllib.loads(path.read_text())
        _assert_same_document(new, old, path.stem)


# --- the loader's validation (catalog/presets/__init__.py) -------------------------------------------

def _valid_doc():
    return tomllib.loads((FABRIC_DIR / "lace-fwa.toml").read_text())


@pytest.mark.parametrize("key", ["schema", "name", "display_name", "btdf"])
def test_missing_top_level_key_is_refused(key, tmp_path):
    doc = _valid_doc()
    del doc[key]
    with pytest.raises(InputError, match=key):
        preset_from_dict(doc, tmp_path / "lace-fwa.toml")


@pytest.mark.parametrize("key", ["direct", "k_d", "k_s", "tau", "rho", "g_diff", "g_spec"])
def test_missing_btdf_key_is_refused(key, tmp_path):
    doc = _valid_doc()
    del doc["btdf"][key]
    with pytest.raises(InputError, match=f"btdf.{key}"):
        preset_from_dict(doc, tmp_path / "lace-fwa.toml")


@pytest.mark.parametrize("key,value", [("direct", -0.1), ("direct", 1.2), ("rho", 0.0),
                                       ("rho", 1.5), ("g_spec", 1.0), ("g_diff", -1.0),
                                       ("k_d", -0.5), ("tau", -1.0), ("g_spec", float("nan")),
                                       ("k_s", "big")])
def test_out_of_range_values_are_refused_naming_file_and_key(key, value, tmp_path):
    doc = _valid_doc()
    doc["btdf"][key] = value
    path = tmp_path / "lace-fwa.toml"
    with pytest.raises(InputError) as excinfo:
        save_preset_dict(doc, path)
    assert str(path) in str(excinfo.value) and f"btdf.{key}" in str(excinfo.value)
    assert not path.exists() and not any(tmp_path.iterdir())


def test_name_must_match_the_file_stem(tmp_path):
    with pytest.raises(InputError, match="stem"):
        preset_from_dict(_valid_doc(), tmp_path / "other.toml")


def test_bad_fluorescence_colour_is_refused(tmp_path):
    doc = _valid_doc()
    doc["fluorescence"]["rgb"] = [1.0, 2.0]
    with pytest.raises(InputError, match="fluorescence.rgb"):
        preset_from_dict(doc, tmp_path / "lace-fwa.toml")


def test_unknown_keys_survive_a_round_trip(tmp_path):
    doc = _valid_doc()
    doc["btdf"]["anisotropy"] = 0.1
    doc["notes"] = {"weaver": "test"}
    path = tmp_path / "lace-fwa.toml"
    (tmp_path / "measurements").symlink_to(FABRIC_DIR / "measurements")
    (tmp_path / "patterns").symlink_to(FABRIC_DIR / "patterns")
    save_preset_dict(copy.deepcopy(doc), path)
    back = load_preset(path)
    assert back.raw["btdf"]["anisotropy"] == 0.1 and back.raw["notes"] == {"weaver": "test"}
    assert back.table("cloth") == doc["cloth"]
    assert back.fluorescence.excitation.is_file()


def test_broken_toml_is_refused(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("schema = 1\nname = \n")
    with pytest.raises(InputError, match="not valid TOML"):
        load_preset(path)
