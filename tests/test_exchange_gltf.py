"""``catalog export --out FILE.glb``: the draped curtain as glTF 2.0, read back by trimesh
and by our own GLB parse, checked by the Khronos glTF-Validator (npm, tools/node)."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

from catalog.commands.cli import main

ROOT = Path(__file__).resolve().parent.parent
NODE_TOOLS = ROOT / "tools" / "node"


@pytest.fixture(scope="module")
def lace_glb(tmp_path_factory):
    path = tmp_path_factory.mktemp("glb") / "lace.glb"
    assert main(["export", "--fabric", "lace-fwa", "--light", "D65", "--frame", "0",
                 "--out", str(path)]) == 0
    return path


def _chunks(path: Path):
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<III", data)
    assert (magic, version, length) == (0x46546C67, 2, len(data))
    json_len, _ = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20:20 + json_len])
    bin_len, _ = struct.unpack_from("<II", data, 20 + json_len)
    return doc, data[28 + json_len:28 + json_len + bin_len]


@pytest.mark.slow
def test_glb_loads_in_trimesh_with_the_curtains_mesh_uvs_and_pattern(lace_glb):
    import trimesh

    from catalog.presets import find_preset, load_preset
    from catalog.render.snapshot import simulated_curtain

    preset = load_preset(find_preset("lace-fwa"))
    positions, normals, uv, _t, indices, size = simulated_curtain(preset, 0)
    scene = trimesh.load(lace_glb, force="scene")
    (mesh,) = scene.geometry.values()
    assert len(mesh.vertices) == len(positions)                       # one vertex per node
    assert len(mesh.faces) == len(np.asarray(indices).reshape(-1)) // 3
    assert np.allclose(np.sort(mesh.vertices, axis=0), np.sort(positions, axis=0), atol=1e-6)
    # UVs count pattern repeats: the fabric's width over the repeat's
    repeat = preset.table("pattern")["repeat_m"]
    assert mesh.visual.uv[:, 0].max() == pytest.approx(size[0] / repeat[0], rel=1e-5)
    image = mesh.visual.material.baseColorTexture
    assert image is not None and image.mode == "RGBA"
    alpha = np.asarray(image, dtype=np.float64)[..., 3] / 255.0
    assert 1.0 - alpha.mean() == pytest.approx(preset.btdf.direct, abs=0.01)  # the pattern


@pytest.mark.slow
def test_glb_carries_the_fabric_under_extras(lace_glb):
    doc, binary = _chunks(lace_glb)
    extras = doc["scenes"][0]["extras"]["catalog"]
    assert extras["light"] == "D65" and extras["frame"] == 0 and extras["room"] == "box"
    assert extras["preset"]["name"] == "lace-fwa"
    from catalog.presets import find_preset, load_preset

    assert extras["preset"] == json.loads(json.dumps(load_preset(find_preset("lace-fwa")).raw))
    assert extras["preset"]["btdf"]["direct"] == pytest.approx(0.383842)
    material = doc["materials"][0]
    assert material["alphaMode"] == "BLEND" and material["doubleSided"]
    assert "KHR_materials_sheen" in material["extensions"]
    normals = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"]]
    view = doc["bufferViews"][normals["bufferView"]]
    n = np.frombuffer(binary, np.float32, normals["count"] * 3, view["byteOffset"]).reshape(-1, 3)
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)   # unit normals


@pytest.mark.slow
def test_khronos_validator_reports_no_errors(lace_glb):
    if shutil.which("node") is None:
        pytest.skip("node is not installed (tools/setup.sh installs the validator with npm)")
    if not (NODE_TOOLS / "node_modules" / "gltf-validator").is_dir():
        pytest.skip("gltf-validator is not installed: run tools/setup.sh (npm install in tools/node)")
    result = subprocess.run(["node", str(NODE_TOOLS / "validate.js"), str(lace_glb)],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    issues = json.loads(result.stdout)["issues"]
    assert issues["numErrors"] == 0, issues["messages"]
    assert issues["numWarnings"] == 0, issues["messages"]


@pytest.mark.parametrize("args, field", [
    (["--out", "x.obj"], "--out"), (["--frame", "-1"], "--frame"),
    (["--room", "castle"], "--room"), (["--light", "no-such-light"], "no-such-light"),
])
def test_bad_export_options_get_one_line(tmp_path, capsys, args, field):
    args = [a if a != "x.obj" else str(tmp_path / "x.obj") for a in args]
    if "--out" not in args:
        args += ["--out", str(tmp_path / "c.glb")]
    status = main(["export", "--fabric", "lace-fwa", *args])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err and field in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.browser
@pytest.mark.slow
def test_glb_renders_in_chromium_through_threejs(lace_glb, tmp_path):
    """The .glb in a standard viewer: three.js's GLTFLoader in headless chromium (WebGL2 by
    SwiftShader), served from loopback. The curtain's mesh, UVs, normals, the pattern
    texture and the sheen arrive; the frame shows a lit curtain with its holes (not one
    colour)."""
    import base64
    import functools
    import http.server
    import io
    import threading

    from catalog.web import browser as web_browser

    reason = web_browser.missing_reason()
    three = NODE_TOOLS / "node_modules" / "three"
    if reason:
        pytest.skip(reason)
    if not three.is_dir():
        pytest.skip("three.js is not installed: run tools/setup.sh (npm install in tools/node)")
    site = tmp_path / "site"
    site.mkdir()
    (site / "index.html").write_text((ROOT / "tests" / "web" / "gltf_viewer.html").read_text())
    (site / "three").symlink_to(three)
    (site / "lace.glb").write_bytes(lace_glb.read_bytes())
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(site))
    handler.log_message = lambda *a, **k: None
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    page = web_browser.Browser(400, 320)
    try:
        page.driver.get(f"http://127.0.0.1:{server.server_port}/index.html?file=lace.glb")
        assert web_browser.wait_until(
            lambda: page.driver.execute_script("return window.result") is not None, 60.0)
        result = page.driver.execute_script("return window.result")
        url = page.driver.execute_script("return document.getElementById('view').toDataURL('image/png')")
        errors = page.console_errors()
    finally:
        page.close()
        server.shutdown()
    assert "error" not in result, result
    doc, _ = _chunks(lace_glb)
    position = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    assert result["vertices"] == position["count"] and result["uv"] and result["normals"]
    assert result["map"] is not None and result["transparent"] and result["sheen"] > 0
    assert result["type"] == "MeshPhysicalMaterial"
    assert [e for e in errors if "favicon" not in e] == []
    from PIL import Image

    pixels = np.asarray(Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))).convert("RGB"),
                        dtype=np.float64)
    lit = pixels.max(axis=2) > 40
    assert 0.2 < lit.mean() < 0.95                   # the curtain fills the view, not all of it
    grey = pixels.mean(axis=2)
    row = grey[grey.shape[0] // 2]
    assert np.abs(np.diff(row)).mean() > 3           # the lace's holes: not one flat colour


@pytest.mark.slow
def test_the_export_records_the_room_it_was_asked_for(tmp_path, capsys):
    """``--room living`` (a built-in) and a room file are read and checked like every command's
    room (catalog.room.load), and the file's extras name the room."""
    import shutil

    from catalog.room.load import room_path

    own = tmp_path / "client-room.glb"
    shutil.copyfile(room_path("living"), own)
    for room, recorded in (("living", "living"), (str(own), "client-room.glb")):
        out = tmp_path / f"{recorded}.glb"
        assert main(["export", "--fabric", "voile-white", "--room", room, "--out", str(out)]) == 0
        capsys.readouterr()
        doc, _binary = _chunks(out)
        assert doc["scenes"][0]["extras"]["catalog"]["room"] == recorded
