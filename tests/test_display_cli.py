"""`--ev`, `--white-balance` and the labelled sheet on the command line; the EXR's colour
metadata read back through OpenColorIO's built-in config (OpenImageIO's ColorConfig)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from catalog.render.snapshot import SnapshotRequest, read_metadata, render_snapshot

pytestmark = pytest.mark.gl


def _run(*args):
    return subprocess.run([sys.executable, "-m", "catalog", *args], capture_output=True,
                          text=True, timeout=180)


@pytest.mark.parametrize("option, value", [("--ev", "40"), ("--ev", "nan"), ("--ev", "bright"),
                                           ("--white-balance", "tungsten")])
def test_bad_display_options_are_refused_in_one_line(tmp_path, option, value):
    out = tmp_path / "x.png"
    result = _run("snapshot", "--fabric", "lace-fwa", "--light", "D65", "--size", "16x12",
                  "--out", str(out), option, value)
    assert result.returncode == 2 and result.stdout == ""
    assert len(result.stderr.strip().splitlines()) == 1 and option in result.stderr
    assert not out.exists()


@pytest.mark.slow
def test_fixed_ev_sets_the_exposure_and_one_stop_doubles_it(gl, tmp_path):
    reports = [render_snapshot(SnapshotRequest(fabric="voile-white", light="D65", size=(32, 24),
                                               out=tmp_path / f"ev{ev}.png", ev=ev), ctx=gl)
               for ev in (11.0, 12.0)]
    assert [r["ev100"] for r in reports] == [11.0, 12.0]
    assert reports[0]["exposure"] == pytest.approx(2 * reports[1]["exposure"], rel=1e-12)
    assert np.all(np.array(reports[0]["mean_srgb8"]) > np.array(reports[1]["mean_srgb8"]))
    meta = read_metadata(tmp_path / "ev11.0.png")
    assert meta["catalog:ev100"] == "11.0000" and meta["catalog:auto_exposure"] == "false"


@pytest.mark.slow
def test_camera_white_balance_leaves_a_lamp_warm(gl, tmp_path):
    room = render_snapshot(SnapshotRequest(fabric="voile-white", light="A", size=(32, 24),
                                           out=tmp_path / "room.png"), ctx=gl)
    camera = render_snapshot(SnapshotRequest(fabric="voile-white", light="A", size=(32, 24),
                                             out=tmp_path / "camera.png", white_balance="camera"),
                             ctx=gl)
    r_room, _, b_room = room["mean_srgb8"]
    r_cam, _, b_cam = camera["mean_srgb8"]
    # adapted (CAT16 with its degree of adaptation, D = 0.852): a warm residue, far less
    # orange than the camera's fixed D65 balance
    assert 0 < r_room - b_room < 0.4 * (r_cam - b_cam) and r_cam - b_cam > 30


@pytest.mark.slow
def test_exr_opens_in_ocio_with_a_standard_view(gl, tmp_path):
    import OpenImageIO as oiio

    from catalog.render.snapshot import OCIO_LINEAR_SPACE

    exr = tmp_path / "a.exr"
    report = render_snapshot(SnapshotRequest(fabric="lace-fwa", light="D65", size=(32, 24),
                                             out=exr), ctx=gl)
    buf = oiio.ImageBuf(str(exr))
    space = buf.spec().get_string_attribute("oiio:ColorSpace")
    assert space == OCIO_LINEAR_SPACE
    chroma = buf.spec().getattribute("chromaticities")
    np.testing.assert_allclose(chroma, [0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290], atol=1e-4)
    config = oiio.ColorConfig("ocio://default")
    assert config.resolve(space) == "Linear Rec.709 (sRGB)"
    # the EXR is radiance: a viewer applies our exposure, then the config's ACES 2.0 SDR view
    exposed = oiio.ImageBufAlgo.mul(buf, float(report["exposure"]))
    shown = oiio.ImageBufAlgo.ociodisplay(exposed, "sRGB - Display",
                                          "ACES 2.0 - SDR 100 nits (Rec.709)", fromspace=space,
                                          colorconfig="ocio://default")
    pixels = shown.get_pixels(oiio.FLOAT)
    assert not shown.has_error and np.all(np.isfinite(pixels))
    assert 0.1 < pixels.mean() < 0.9


@pytest.mark.slow
def test_sheet_grid_is_labelled(tmp_path):
    out = tmp_path / "sheet"
    result = _run("sheet", "--lights", "D65,UV-A", "--fabric", "lace-fwa,net-grey",
                  "--size", "40x30", "--out", str(out), "--json")
    assert result.returncode == 0, result.stderr
    import json

    import OpenImageIO as oiio

    report = json.loads(result.stdout)
    dx, dy = report["label_offset_px"]
    grid = oiio.ImageBuf(report["grid"]).get_pixels(oiio.UINT8)
    assert grid.shape == (2 * 30 + dy, 2 * 40 + dx, 3)
    header = grid[:dy, dx:].astype(int)
    for j in range(2):  # each column's name drawn above it
        assert header[:, j * 40:(j + 1) * 40].max() > 150
    names = grid[dy:, :dx].astype(int)
    for i in range(2):  # each row's name beside it
        assert names[i * 30:(i + 1) * 30].max() > 150
    unlabelled = _run("sheet", "--lights", "D65", "--fabric", "net-grey", "--size", "40x30",
                      "--out", str(tmp_path / "bare"), "--no-labels", "--json")
    assert json.loads(unlabelled.stdout)["label_offset_px"] == [0, 0]
