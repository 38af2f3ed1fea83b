"""Fabric patterns (catalog/presets/patterns.py, tools/make_patterns.py): every preset's coverage
agrees with its fitted LD, the generator reproduces the committed images, and bad pattern
images are refused naming the file and the problem."""

from __future__ import annotations

import importlib.util
import tomllib

import numpy as np
import pytest
from PIL import Image

from catalog.core.resources import FABRIC_DIR, PROJECT_ROOT
from catalog.core.errors import InputError
from catalog.presets.patterns import OPEN_AREA_TOLERANCE, load_pattern, pattern_from_images
from catalog.presets import list_presets, load_preset, save_preset_dict


def _make_patterns():
    spec = importlib.util.spec_from_file_location("make_patterns",
                                                  PROJECT_ROOT / "tools" / "make_patterns.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("path", list_presets(), ids=lambda p: p.stem)
def test_every_preset_has_a_pattern_whose_open_area_is_its_direct(path):
    """1 - mean(c) = LD within 1 % (relative), read with PIL (a reader independent of
    OpenImageIO) and through the loader."""
    preset = load_preset(path)
    table = preset.table("pattern")
    assert table, f"{path.name} has no [pattern]"
    pixels = np.asarray(Image.open(preset.resolve(table["coverage"])), dtype=np.float64)
    assert pixels.ndim == 2
    open_area = 1.0 - pixels.mean() / 65535.0
    direct = preset.btdf.direct
    assert abs(open_area - direct) <= OPEN_AREA_TOLERANCE * direct, (open_area, direct)
    pattern = load_pattern(preset)
    assert abs(pattern.open_area - open_area) < 1e-6
    assert pattern.height is not None and pattern.height.shape == pattern.coverage.shape


def test_jacquard_has_no_holes_and_lace_has_many():
    """The damask shows only as denser and lighter areas (c > 0.5 everywhere); the lace and
    the nets have real holes (c = 0 over much of their area)."""
    jacquard = load_pattern(load_preset(FABRIC_DIR / "jacquard-white.toml"))
    assert jacquard.coverage.min() > 0.5
    assert np.percentile(jacquard.coverage, 95) - np.percentile(jacquard.coverage, 5) > 0.05
    lace = load_pattern(load_preset(FABRIC_DIR / "lace-fwa.toml"))
    assert np.mean(lace.coverage == 0.0) > 0.2
    assert lace.repeat_m[0] == pytest.approx(0.1)


@pytest.mark.slow
def test_the_generator_reproduces_the_committed_patterns():
    make_patterns = _make_patterns()
    for name in sorted(make_patterns.PATTERNS):
        result = make_patterns.regenerate(name, write=False)
        pattern = load_pattern(load_preset(FABRIC_DIR / f"{name}.toml"))
        for new, old in ((result["coverage"], pattern.coverage), (result["height"], pattern.height)):
            # the same 16-bit codes
            np.testing.assert_array_equal(np.round(new * 65535.0), np.round(old * 65535.0),
                                          err_msg=name)
        table = tomllib.loads((FABRIC_DIR / f"{name}.toml").read_text())["pattern"]
        assert result["table"] == table, name


# --- user images and their refusals --------------------------------------------------------

def _png(path, array, mode=None):
    Image.fromarray(array, mode=mode).save(path)
    return path


def _exr(path, array):
    import OpenImageIO as oiio

    array = np.asarray(array, dtype=np.float32)
    if array.ndim == 2:
        array = array[..., None]
    spec = oiio.ImageSpec(array.shape[1], array.shape[0], array.shape[2], oiio.FLOAT)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(array)
    out.close()
    return path


def _tileable(n=32):
    x = np.arange(n)
    return (0.5 + 0.5 * np.cos(2 * np.pi * x / n))[None, :] * np.ones((n, 1))


def test_a_grey_png_and_an_exr_with_height_load_with_their_repeat(tmp_path):
    png = _png(tmp_path / "lace.png", (255 * _tileable()).astype(np.uint8))
    pattern = pattern_from_images(png, 0.05)
    assert pattern.repeat_m == (0.05, 0.05)
    assert pattern.coverage.max() == pytest.approx(1.0)
    exr = _exr(tmp_path / "lace.exr", np.stack([_tileable(), 0.5 * _tileable()], -1))
    pattern = pattern_from_images(exr, [0.04, 0.02])
    assert pattern.repeat_m == (0.04, 0.02)
    assert pattern.height.max() == pytest.approx(0.5)


@pytest.mark.parametrize("case,problem", [
    ("rgb", "1 channel (grey) or 2"),
    ("empty", "zero size"),
    ("nan", "NaN"),
    ("untileable", "not tileable"),
    ("range", "must lie in [0, 1]"),
    ("missing", "no such pattern image"),
])
def test_bad_pattern_images_are_refused_naming_file_and_problem(tmp_path, case, problem):
    path = tmp_path / f"{case}.exr"
    if case == "rgb":
        path = _png(tmp_path / "rgb.png", np.zeros((8, 8, 3), np.uint8))
    elif case == "empty":
        path.write_bytes(b"")
    elif case == "nan":
        values = _tileable()
        values[3, 4] = np.nan
        _exr(path, values)
    elif case == "untileable":
        _exr(path, np.linspace(0, 1, 32)[None, :] * np.ones((32, 1)))
    elif case == "range":
        _exr(path, 2.0 * _tileable())
    with pytest.raises(InputError) as info:
        pattern_from_images(path, 0.1)
    message = str(info.value)
    assert str(path) in message and problem in message


def test_a_bad_repeat_is_refused(tmp_path):
    png = _png(tmp_path / "ok.png", (255 * _tileable()).astype(np.uint8))
    for repeat in (0.0, -1.0, [0.1], "big", float("nan")):
        with pytest.raises(InputError, match="repeat_m"):
            pattern_from_images(png, repeat)


def test_a_preset_whose_pattern_misses_its_direct_is_not_written(tmp_path):
    """The write refuses (1 % rule) and leaves nothing behind."""
    doc = tomllib.loads((FABRIC_DIR / "voile-white.toml").read_text())
    (tmp_path / "patterns").mkdir()
    _png(tmp_path / "patterns" / "half.png", np.full((16, 16), 128, np.uint8))
    doc["pattern"] = {"coverage": "patterns/half.png", "repeat_m": 0.001}
    target = tmp_path / "voile-white.toml"
    with pytest.raises(InputError, match="mean open area 0.49804 differs from btdf.direct"):
        save_preset_dict(doc, target)
    assert not target.exists()
    doc["btdf"]["direct"] = 1 - 128 / 255
    save_preset_dict(doc, target)
    assert load_pattern(load_preset(target)).open_area == pytest.approx(1 - 128 / 255, abs=1e-6)


def test_three_distinct_laces_with_cords_and_a_half_drop():
    """At least three laces (kind "lace"); each has a hexagonal net ground (holes over >= 20 %
    of the repeat), cord relief (height 1 somewhere, the net's threads at most 0.3), dense
    cloth-stitch (c >= 0.8 over >= 8 %), and no two laces share a repeat or a coverage."""
    laces = [load_preset(p) for p in list_presets()
             if load_preset(p).table("pattern").get("kind") == "lace"]
    assert len(laces) >= 3
    seen = []
    for preset in laces:
        pattern = load_pattern(preset)
        c, h = pattern.coverage, pattern.height
        assert np.mean(c == 0.0) > 0.2, preset.name
        assert h.max() > 0.99 and np.mean(h > 0.9) > 0.003, preset.name
        assert np.mean(c >= 0.8) > 0.08, preset.name
        key = (tuple(round(r, 6) for r in pattern.repeat_m), c.shape)
        assert key not in seen, preset.name
        seen.append(key)
