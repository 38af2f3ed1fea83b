"""`catalog snapshot` and `catalog sheet`: files, metadata, and one-line refusals with no file."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from catalog.core.errors import CatalogError
from catalog.render.snapshot import SnapshotRequest, read_metadata, render_snapshot

pytestmark = pytest.mark.gl


def _request(preset, out, **changes):
    values = dict(fabric=str(preset), light="D65", size=(48, 32), out=out)
    values.update(changes)
    return SnapshotRequest(**values)


@pytest.mark.slow
def test_exr_and_png_with_metadata(gl, make_preset, tmp_path):
    import OpenImageIO as oiio

    preset = make_preset()
    exr = tmp_path / "a.exr"
    png = tmp_path / "a.png"
    report_exr = render_snapshot(_request(preset, exr, light="sun:100"), ctx=gl)
    report_png = render_snapshot(_request(preset, png, light="sun:100", fluorescence="paper",
                                          bands=6), ctx=gl)
    for path, report, kind in ((exr, report_exr, "float"), (png, report_png, "uint8")):
        meta = read_metadata(path)
        assert meta["catalog:fabric"] == "lace-test"
        assert meta["catalog:light"] == "sun:100"
        assert meta["catalog:mode"] == report["mode"]
        buf = oiio.ImageBuf(str(path))
        assert (buf.spec().width, buf.spec().height, buf.spec().nchannels) == (48, 32, 3)
        assert buf.spec().format.basetype == (oiio.FLOAT if kind == "float" else oiio.UINT8)
    pixels = oiio.ImageBuf(str(exr)).get_pixels(oiio.FLOAT)
    assert np.all(np.isfinite(pixels)) and pixels.max() > 100.0  # cd m^-2, scene-referred
    assert read_metadata(png)["catalog:bands"] == "6"
    assert not list(tmp_path.glob(".*"))  # no temporaries left


@pytest.mark.parametrize("bad", ["missing-key", "out-of-range", "bad-toml", "no-file"])
def test_bad_preset_is_refused_without_a_file(gl, make_preset, tmp_path, bad):
    preset = make_preset()
    text = preset.read_text()
    if bad == "missing-key":
        preset.write_text(text.replace("g_spec = 0.97\n", ""))
    elif bad == "out-of-range":
        preset.write_text(text.replace("g_spec = 0.97", "g_spec = 1.5"))
    elif bad == "bad-toml":
        preset.write_text(text + "[[[\n")
    else:
        preset = tmp_path / "absent.toml"
    out = tmp_path / "x.png"
    with pytest.raises(CatalogError) as err:
        render_snapshot(_request(preset, out), ctx=gl)
    assert "\n" not in str(err.value) and str(preset.name) in str(err.value)
    assert not out.exists() and not list(tmp_path.glob(".x*"))


@pytest.mark.parametrize("field,value,needle", [
    ("light", "D66", "D66"),
    ("size", (0, 10), "impossible"),
    ("size", (100000, 10), "impossible"),
    ("out", "x.jpg", ".exr"),
    ("bands", 5, "--bands"),
    ("frame", -1, "--frame"),
])
def test_bad_options_are_refused_without_a_file(gl, make_preset, tmp_path, field, value, needle):
    out = tmp_path / (value if field == "out" else "x.png")
    changes = {} if field == "out" else {field: value}
    request = _request(make_preset(), out, **changes)
    with pytest.raises(CatalogError) as err:
        render_snapshot(request, ctx=gl)
    assert "\n" not in str(err.value) and needle in str(err.value)
    assert not any(tmp_path.glob("x*")) and not any(tmp_path.glob(".x*"))


def test_no_egl_device_is_one_line(monkeypatch):
    import moderngl

    from catalog.gl.context import create_headless_context

    def refuse(*args, **kwargs):
        raise Exception("eglGetDisplay failed\nno device")

    monkeypatch.setattr(moderngl, "create_standalone_context", refuse)
    with pytest.raises(CatalogError) as err:
        create_headless_context()
    assert str(err.value).startswith("no EGL device") and "\n" not in str(err.value)


@pytest.mark.slow
def test_cli_json_and_one_line_error(make_preset, tmp_path):
    out = tmp_path / "c.png"
    ok = subprocess.run([sys.executable, "-m", "catalog", "snapshot", "--fabric",
                         str(make_preset()), "--light", "A", "--size", "40x30", "--frame", "0",
                         "--out", str(out), "--no-fluorescence", "--json"],
                        capture_output=True, text=True, timeout=120)
    assert ok.returncode == 0, ok.stderr
    import json

    report = json.loads(ok.stdout)
    assert report["fluorescence_variant"] == "off" and report["light"] == "A" and out.exists()
    bad = subprocess.run([sys.executable, "-m", "catalog", "snapshot", "--fabric",
                          str(make_preset()), "--light", "A", "--size", "40x",
                          "--out", str(tmp_path / "d.png")],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stdout == ""
    assert len(bad.stderr.strip().splitlines()) == 1 and "--size" in bad.stderr
    assert not (tmp_path / "d.png").exists()


@pytest.mark.slow
def test_sheet_every_fabric_and_light(gl, make_preset, tmp_path):
    from catalog.render.sheet import render_sheet

    fabrics = [str(make_preset("one")), str(make_preset("two", fluorescent=False))]
    report = render_sheet(["D65", "LED-B4"], tmp_path / "sheet", (24, 16), fabrics=fabrics,
                          progress=False, ctx=gl)
    assert len(report["images"]) == 4
    import OpenImageIO as oiio

    grid = oiio.ImageBuf(report["grid"])
    dx, dy = report["label_offset_px"]
    assert dx > 0 and dy > 0  # labelled by default
    assert (grid.spec().width, grid.spec().height) == (48 + dx, 32 + dy)
    for image in report["images"]:
        assert oiio.ImageBuf(image["path"]).spec().width == 24


@pytest.mark.slow
def test_frame_n_renders_the_simulated_cloth(gl, make_preset, tmp_path):
    """--frame 0 is the settled drape, --frame N > 0 the simulation started from it."""
    preset = make_preset()
    still = render_snapshot(_request(preset, tmp_path / "f0.exr"), ctx=gl)
    moved = render_snapshot(_request(preset, tmp_path / "f3.exr", frame=3), ctx=gl)
    assert still["mesh"] == "settled drape" and moved["mesh"].startswith("cloth simulation")
    assert still["mean_linear_rgb"] != moved["mean_linear_rgb"]
    assert all(v > 0 for v in moved["mean_linear_rgb"])
