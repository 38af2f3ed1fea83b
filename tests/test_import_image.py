"""``catalog import IMAGE``: a lace from a backlit scan the project draws itself
(tools/make_lace_scan.py), checked against an independent decode of the image (Pillow +
colour-science's sRGB decoding), and the bad inputs refused in one line, nothing written."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from catalog.commands.cli import main

ROOT = Path(__file__).resolve().parent.parent


def _scan_module():
    spec = importlib.util.spec_from_file_location("make_lace_scan", ROOT / "tools" / "make_lace_scan.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    path = tmp_path_factory.mktemp("scan") / "lace-scan.png"
    _scan_module().write_scan(path, size=256)
    return path


def _independent_open_area(path: Path) -> float:
    import colour
    from PIL import Image

    rgb = np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0
    linear = colour.cctf_decoding(rgb, function="sRGB")
    return float(np.mean(linear @ np.array([0.2126, 0.7152, 0.0722])))


def _run(capsys, *args):
    status = main(["import", *map(str, args), "--json"])
    out = capsys.readouterr()
    return status, (json.loads(out.out) if out.out.strip() else None), out.err


@pytest.mark.slow
def test_scan_becomes_a_preset_with_the_images_open_area(scan, tmp_path, capsys):
    from catalog.presets import load_preset
    from catalog.presets.bundle import outside_paths
    from catalog.presets.patterns import load_pattern

    status, report, err = _run(capsys, scan, "--name", "scanned", "--out", tmp_path / "out")
    assert status == 0, err
    expected = _independent_open_area(scan)
    preset = load_preset(tmp_path / "out" / "scanned.toml")
    assert preset.btdf.direct == pytest.approx(expected, rel=0.01)          # within 1 %
    assert abs(report["direct"] - expected) <= 0.01                          # formats.md
    assert load_pattern(preset).open_area == pytest.approx(preset.btdf.direct, rel=0.01)
    # the size from the header's dpi: 256 px at the scan's dpi is the lace's 80 mm repeat
    assert preset.table("pattern")["repeat_m"][0] == pytest.approx(0.08, rel=1e-3)
    # the lobes' lender is named, and it is the nearest in openness
    assert preset.table("import")["lobes_from"] == report["lobes_from"] == "lace-fwa"
    assert outside_paths(preset.raw) == []
    assert (tmp_path / "out" / "scanned" / "source" / scan.name).read_bytes() == scan.read_bytes()


def test_artwork_with_threshold_and_polarity(scan, tmp_path, capsys):
    from PIL import Image

    grey = np.asarray(Image.open(scan).convert("L"), dtype=np.float64) / 255.0
    status, light, err = _run(capsys, scan, "--name", "a", "--out", tmp_path, "--threshold", "0.5",
                              "--repeat-m", "0.1")
    assert status == 0, err
    # Pillow's grey of sRGB values: > 0.5 encoded is > 0.214 linear; the drawing is crisp
    assert light["open_area"] == pytest.approx(float(np.mean(grey > 0.7354)), abs=0.01)
    status, dark, err = _run(capsys, scan, "--name", "b", "--out", tmp_path, "--threshold", "0.5",
                             "--polarity", "dark-open", "--repeat-m", "0.1")
    assert status == 0, err
    assert light["open_area"] + dark["open_area"] == pytest.approx(1.0, abs=1e-3)
    # --repeat-m is the width; the height follows the pixels' aspect (square pixels)
    assert light["repeat_m"] == pytest.approx([0.1, 0.1 * grey.shape[0] / grey.shape[1]], abs=1e-6)


def _write_grey(path: Path, values: np.ndarray, dpi: float | None = 300.0):
    from PIL import Image

    image = Image.fromarray(np.asarray(values * 255, dtype=np.uint8), mode="L")
    image.save(path, dpi=(dpi, dpi)) if dpi else image.save(path)


@pytest.mark.parametrize("case, field", [
    ("all open", "open area"), ("all thread", "open area"), ("absurd dpi", "dpi"),
    ("absurd repeat", "--repeat-m"), ("no resolution", "--repeat-m"), ("not an image", "not an image"),
])
def test_bad_images_are_refused_in_one_line_and_nothing_is_written(tmp_path, capsys, case, field):
    path = tmp_path / "in.png"
    extra = []
    stripes = np.tile((np.arange(64) % 8 < 4).astype(float), (64, 1))
    if case == "all open":
        _write_grey(path, np.ones((64, 64)))
    elif case == "all thread":
        _write_grey(path, np.zeros((64, 64)))
    elif case == "absurd dpi":
        _write_grey(path, stripes, dpi=1.0)
    elif case == "absurd repeat":
        _write_grey(path, stripes)
        extra = ["--repeat-m", "1e-6"]
    elif case == "no resolution":
        _write_grey(path, stripes, dpi=None)
    else:
        path.write_text("this is not a PNG")
    out = tmp_path / "out"
    status, report, err = _run(capsys, path, "--name", "x", "--out", out, *extra)
    assert status == 2
    line = err.strip()
    assert "\n" not in line and str(path) in line and field in line, line
    assert report["exit_code"] == 2
    assert not out.exists()


@pytest.mark.slow
def test_gonio_gives_the_lobes_and_travels_with_the_preset(scan, tmp_path, capsys):
    """With --gonio the lobes are the fit's (eq. 7 a_diff, a_spec, g's), direct stays the
    image's open area, and the gonio file is copied into the preset's folder."""
    from catalog.core.resources import FABRIC_DIR
    from catalog.fit.gonio import read_gonio
    from catalog.fit.preset_build import fit_measurement
    from catalog.presets import load_preset
    from catalog.presets.bundle import outside_paths

    gonio = FABRIC_DIR / "measurements" / "lace-fwa" / "gonio.csv"
    status, report, err = _run(capsys, scan, "--name", "g", "--out", tmp_path, "--gonio", gonio)
    assert status == 0, err
    assert report["lobes_from"] == "gonio"
    preset = load_preset(tmp_path / "g.toml")
    fit = fit_measurement(read_gonio(gonio), "relative")["hg"].params
    for key in ("a_diff", "a_spec", "g_diff", "g_spec"):
        assert getattr(preset.btdf, key) == pytest.approx(fit[key], rel=1e-4), key
    assert preset.btdf.direct == pytest.approx(_independent_open_area(scan), rel=0.01)
    assert outside_paths(preset.raw) == []
    assert preset.resolve(preset.fit["source"]).read_bytes() == gonio.read_bytes()


@pytest.mark.slow
def test_the_docs_figures_come_from_the_committed_scan_and_record():
    """docs/exchange.md's source image is what tools/make_lace_scan.py draws (byte for byte)
    and the numbers it quotes are those of docs/img/exchange.json."""
    import io

    from PIL import Image

    record = json.loads((ROOT / "docs" / "img" / "exchange.json").read_text())
    assert len(record["commit"]) >= 7
    committed = np.asarray(Image.open(ROOT / "docs" / "img" / record["source"]).convert("RGB"))
    drawn, dpi, _ = _scan_module().draw_scan(512)
    assert np.array_equal(committed, drawn)
    text = (ROOT / "docs" / "exchange.md").read_text()
    assert f"{record['import']['open_area']:.4f}" in text
    assert f"{dpi:.2f} dpi" in text and record["import"]["lobes_from"] in text


def test_reimporting_a_presets_own_image_into_itself_is_refused(tmp_path, capsys):
    folder = tmp_path / "x" / "patterns"
    folder.mkdir(parents=True)
    path = folder / "coverage.png"
    _write_grey(path, np.tile((np.arange(64) % 8 < 4).astype(float), (64, 1)))
    before = path.read_bytes()
    status, report, err = _run(capsys, path, "--name", "x", "--out", tmp_path)
    assert status == 2 and "--out" in err and "never overwritten" in err
    assert path.read_bytes() == before and not (tmp_path / "x.toml").exists()
