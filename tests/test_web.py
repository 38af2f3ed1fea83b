"""The web catalog's Python side: the GLSL ES variant, the baked cloth codec, the recorded
frame, the site command and its refusals. The page itself is tested in test_web_browser.py."""

from __future__ import annotations

import base64
import json
import os
import stat
import subprocess
import sys

import numpy as np
import pytest

from catalog.gl import shaderlib


# ---------------------------------------------------------------- the ES variant
def test_es_variant_is_the_same_file_with_another_version_line():
    """Every line of the desktop source is in the ES source, in order; only the version line
    is replaced and the precision lines added after the defines."""
    defines = {"N_BANDS": 3, "NV4": 1, "FLUORESCENCE_PHYSICAL": True, "SEE_THROUGH": True}
    core = shaderlib.load_source("curtain.frag", defines).splitlines()
    es = shaderlib.load_source("curtain.frag", defines, dialect="es300").splitlines()
    assert core[0].startswith("#version 430") and es[0] == "#version 300 es"
    added = [line for line in es[1:] if line not in core]
    # (sampler2DShadow has no default precision in ES 3.00: the room's depth map needs one)
    assert added == ["precision highp float;", "precision highp int;", "precision highp sampler2D;",
                     "precision highp sampler2DShadow;"]
    assert [line for line in es[1:] if line not in added] == core[1:]
    # the precision lines follow the defines (so a define can never be hidden by them)
    assert es.index("#define N_BANDS 3") < es.index("precision highp float;")


def test_es_variant_of_every_frame_shader_has_no_include_left():
    for name in ("curtain.vert", "curtain.frag", "room_transport.vert", "room_transport.frag", "fullscreen.vert",
                 "background.frag", "tonemap.frag"):
        source = shaderlib.load_source(name, dialect="es300")
        directives = [line.strip() for line in source.splitlines() if line.strip().startswith("#")]
        assert not any(d.startswith("#include") for d in directives)
        assert [d for d in directives if d.startswith("#version")] == ["#version 300 es"]


def test_unknown_dialect_is_refused():
    from catalog.core.errors import CatalogError

    with pytest.raises(CatalogError, match="dialect"):
        shaderlib.load_source("room_transport.frag", dialect="es100")


# ---------------------------------------------------------------- baked cloth codec
def test_bake_codec_round_trip_within_its_quanta():
    """encode -> decode_frames gives back positions within half a quantum (0.05 mm) for a
    moving, folded grid (no simulation); the normals and tangents computed from them are
    within 0.005 rad of the mesh code's (catalog.cloth.mesh.grid_frames) on the exact positions
    (the earlier int8 storage allowed up to 1/127 per component); frames_of_grid is that
    mesh code, sums written out (same values within 1e-12)."""
    from catalog.cloth.mesh import grid_frames
    from catalog.web import bake

    cols, rows, f = 40, 30, 7
    u, v = np.meshgrid(np.arange(cols) * 0.04, np.arange(rows) * -0.04)
    frames = []
    for k in range(f):  # pleats swaying: z folds across, a wave down
        z = 0.05 * np.sin(u * 9.0 + 0.3 * k) + 0.02 * np.sin(v * 4.0 - 0.2 * k)
        frames.append(np.stack([u + 0.01 * np.sin(v * 3.0 + k), v, z], axis=-1).reshape(-1, 3))
    p = np.stack(frames) + np.array([-0.7, 0.2, 0.1])
    lo, payload = bake.encode(p)
    animation = bake.BakedAnimation(key="x", frames=f, fps=12.0, vertex_count=cols * rows,
                                    indices=np.arange(3, dtype=np.uint32),
                                    uv=np.zeros((cols * rows, 2)), offset_m=(0.1, -1.0, 0.2),
                                    lo_m=lo, payload=payload, grid=(cols, rows))
    positions, normals, tangents = bake.decode_frames(animation)
    assert positions.dtype == normals.dtype == np.float32
    offset = np.array([0.1, -1.0, 0.2])
    assert np.max(np.abs(positions - (p + offset))) <= 0.5 * bake.POSITION_STEP_M + 1e-6
    for k in range(f):
        want_n, want_t = grid_frames(p[k].reshape(rows, cols, 3))
        angle = lambda a, b: np.arccos(np.clip(np.sum(a * b, axis=-1), -1, 1))  # noqa: E731
        assert angle(normals[k].reshape(rows, cols, 3), want_n).max() <= 0.005
        assert angle(tangents[k].reshape(rows, cols, 3), want_t).max() <= 0.005
        ours = bake.frames_of_grid(p[k].reshape(rows, cols, 3))
        assert np.allclose(ours[0], want_n, atol=1e-12) and np.allclose(ours[1], want_t, atol=1e-12)
    assert len(payload) <= 0.6 * f * cols * rows * bake.BYTES_PER_VERTEX


@pytest.fixture(scope="module")
def voile_bake():
    """bake() of voile-white in this process: one simulation of its loop for the module."""
    from catalog.presets import find_preset, load_preset
    from catalog.web import bake

    return bake.bake(load_preset(find_preset("voile-white")))


@pytest.fixture
def baked_voile(monkeypatch, voile_bake):
    """Site builds of voile-white take the module's bake instead of simulating the cloth again
    in a child (the child's bake is tested on its own: test_a_bake_in_the_child_process_..):
    for the tests about the site's files, which the bake does not change."""
    from catalog.web import bake

    def bake_apart(presets, on_baked=None):
        assert [p.name for p in presets] == ["voile-white"]
        if on_baked is not None:
            on_baked()
        return [voile_bake]

    monkeypatch.setattr(bake, "bake_apart", bake_apart)


@pytest.mark.slow
def test_baked_loop_is_seamless_and_small(voile_bake):
    """The last frame leads into the first: its step to frame 0 is no larger than the largest
    step inside the loop; and the encoding is at most 60 % of the raw 12 B per vertex."""
    from catalog.presets import find_preset, load_preset
    from catalog.web import bake

    from catalog.render import snapshot

    preset = load_preset(find_preset("voile-white"))
    animation = voile_bake
    positions, _, _ = bake.decode_frames(animation)
    # hung where the snapshot hangs its settled drape: the same rod offset (the loop's grid
    # plus the offset = the snapshot's mesh, both from the settled drape's grid), fabric size
    # (the pattern's scale) and rings
    still = snapshot.curtain_simulation(preset)
    on_rod, *_, size = snapshot.curtain_on_rod(still)
    assert np.allclose(still.positions().reshape(-1, 3) + np.array(animation.offset_m), on_rod,
                       atol=1e-6)
    assert animation.fabric_size_m == size
    assert animation.rings_x_m == tuple(snapshot.ring_xs_m(preset))
    steps = np.abs(np.diff(positions, axis=0)).max(axis=(1, 2))
    wrap = np.abs(positions[0] - positions[-1]).max()
    assert wrap <= steps.max()
    manifest = animation.manifest()
    assert manifest["encoded_bytes"] <= 0.6 * manifest["raw_bytes"]


@pytest.mark.slow
def test_a_bake_in_the_child_process_is_the_bake_here(voile_bake):
    """bake_apart (the site's bake, in a child Python) gives the animation bake() gives in
    this process, byte for byte, and counts it as it arrives."""
    from catalog.presets import find_preset, load_preset
    from catalog.web import bake

    preset = load_preset(find_preset("voile-white"))
    arrived = []
    (apart,) = bake.bake_apart([preset], on_baked=lambda: arrived.append(1))
    here = voile_bake
    assert arrived == [1] and apart.script() == here.script()
    assert bake.bake_apart([]) == []


def test_bake_hangs_the_desktops_settled_drape():
    """The baked loop's cloth is the curtain `catalog snapshot` shows: the drape's parameters
    (grid, fullness, rings) in the page's wind (test_baked_loop_... checks where it hangs)."""
    from catalog.cloth.drape import GRID, drape_params
    from catalog.presets import find_preset, load_preset
    from catalog.web import bake

    preset = load_preset(find_preset("voile-white"))
    params = bake.bake_params(preset)
    drape = drape_params(preset)
    assert (params.grid_w, params.grid_h) == GRID
    assert params == drape.with_changes(wind_speed_m_s=bake.WIND_M_S,
                                        gust_strength=bake.GUST_STRENGTH)
    assert bake.cloth_key(params) != bake.cloth_key(drape)


# ---------------------------------------------------------------- the recorded frame
@pytest.mark.gl
@pytest.mark.slow
def test_recording_context_changes_nothing_of_the_desktop_frame(gl):
    """The frame rendered through the recording proxy is bit-identical to the plain one, and
    the recorded programs are the frame's files with their defines."""
    from catalog.render.frame import FrameRenderer
    from catalog.web.record import RecordingContext

    images = []
    for ctx in (gl, RecordingContext(gl)):
        renderer = FrameRenderer(ctx, (48, 36), specialise=False)
        try:
            # the page's modes (catalog.web.export.DESKTOP_MODES: the constant room)
            renderer.update(fabric="lace-fwa", light="UV-A", room_lighting=False)
            renderer.render()
            images.append(renderer.read_srgb8())
        finally:
            renderer.release()
    assert np.array_equal(images[0], images[1])
    recipes = list(ctx.recording.programs.values())
    assert {(r["vertex"], r["fragment"]) for r in recipes} >= {
        ("curtain.vert", "curtain.frag"), ("room_transport.vert", "room_transport.frag"),
        ("fullscreen.vert", "background.frag"), ("fullscreen.vert", "tonemap.frag")}


@pytest.mark.gl
def test_recording_context_refuses_what_the_page_cannot_replay(gl):
    """A context call the page has no command for fails loudly (never a silent difference);
    texels a frame gives a texture are kept for the page."""
    from catalog.core.errors import CatalogError
    from catalog.web.record import RecordingContext

    ctx = RecordingContext(gl)
    with pytest.raises(CatalogError, match="copy_framebuffer"):
        ctx.copy_framebuffer(None, None)
    with pytest.raises(CatalogError, match="wireframe"):
        ctx.wireframe = True
    texels = bytes(range(16))
    texture = ctx.texture((2, 2), 4, texels)
    assert ctx.recording.texture_data[texture.rid] == texels
    # a framebuffer's depth mask is noted (moderngl applies it at use and clear: the OIT
    # layers write no depth and their clear keeps the room's); other framebuffer state refused
    fbo = ctx.framebuffer([texture], ctx.depth_renderbuffer((2, 2)))
    assert "depth_mask" not in ctx.recording.framebuffers[fbo.rid]
    fbo.depth_mask = False
    assert ctx.recording.framebuffers[fbo.rid]["depth_mask"] is False
    assert fbo.depth_mask is False
    with pytest.raises(CatalogError, match="color_mask"):
        fbo.color_mask = (True, False, True, True)
    fbo.release()
    texture.release()


@pytest.mark.gl
@pytest.mark.slow   # a recorded lit frame (1.1-1.7 s under -n 2)
def test_the_room_transport_is_recorded_as_a_host_step(gl):
    """The lit room (room_lighting on) through the recorder: the frame and the receivers'
    irradiance are bit-identical to the plain context's; the recording holds one host step
    ``room_transport`` after the views it reads are drawn (the captures' framebuffer) and
    before the room is drawn, whose commands are only writes to the outputs its inputs name
    (the light map's buffer, the room-side, wall and cloth textures); the room's depth map is
    a depth texture with its compare func; a dry recording of it is refused (it reads pixels)."""
    from catalog.core.errors import CatalogError
    from catalog.render.frame import FrameRenderer
    from catalog.web.record import RecordingContext

    images, irradiance = [], []
    rec_ctx = RecordingContext(gl)
    for ctx in (gl, rec_ctx):
        renderer = FrameRenderer(ctx, (48, 36), specialise=False)
        try:
            renderer.update(fabric="linen-dense", light="D65", room_lighting=True)
            if ctx is rec_ctx:
                renderer.render()   # the programs and targets made before the recorded frame
                renderer.invalidate_room_light()
                with pytest.raises(CatalogError, match="host step 'room_transport' reads pixels"):
                    ctx.recording.start(dry=True)
                    renderer.render()
                ctx.recording.stop()
                renderer.invalidate_room_light()
                ctx.recording.start(dry=False)
            renderer.render()
            if ctx is rec_ctx:
                commands = ctx.recording.stop()
            images.append(renderer.read_srgb8())
            irradiance.append(renderer.room_transport.irradiance.copy())
        finally:
            renderer.release()
    assert np.array_equal(images[0], images[1])
    assert np.array_equal(irradiance[0], irradiance[1]) and irradiance[0].max() > 0
    rec = rec_ctx.recording
    ops = [c["op"] for c in commands]
    assert ops.count("host") == 1 and ops.count("host_end") == 1
    start, end = ops.index("host"), ops.index("host_end")
    step = commands[start]
    assert step["name"] == "room_transport"
    inputs = step["inputs"]
    outputs = inputs["outputs"]
    written = {outputs["light_map"]["object"]} | {outputs[k]["object"] for k in ("room_side", "wall_grid")} \
        | {t["object"] for t in outputs["cloth"]}
    inside = commands[start + 1:end]
    assert inside and {c["op"] for c in inside} <= {"buffer_write", "texture_write"}
    assert {c.get("buffer", c.get("texture")) for c in inside} <= written
    capture = inputs["captures"]["texture"]["object"]
    capture_fbos = {rid for rid, f in rec.framebuffers.items() if capture in f["colour"]}
    drawn_into = None
    views = 0
    for c in commands[:start]:
        if c["op"] == "framebuffer":
            drawn_into = c["framebuffer"]
        elif c["op"] == "draw" and drawn_into in capture_fbos:
            views += 1
    assert views >= len(inputs["captures"]["weights"])   # a view a direction at least
    room_program = {rid for rid, r in rec.programs.items() if r["vertex"] == "room_transport.vert"}
    room_draws = [i for i, c in enumerate(commands) if c["op"] == "draw"
                  and rec.vertex_arrays[c["vertex_array"]]["program"] in room_program
                  and rec.vertex_arrays[c["vertex_array"]]["content"][0]["buffer"] == outputs["light_map"]["object"]]
    assert room_draws and min(room_draws) > end
    depth = rec.textures[inputs["room_depth"]["texture"]["object"]]
    assert depth["dtype"] == "depth" and depth["compare_func"] == "<="


@pytest.mark.gl
@pytest.mark.slow   # a recorded lit frame (1.1-1.7 s under -n 2)
def test_a_scene_with_the_room_transport_exports_its_host_step(lit_recording):
    """SiteExporter.record of a lit-room scene: its host step's in-frame writes carry their
    bytes as the scene's blobs (slots, not in the shared structure); objects() gives the page
    the room's depth map as a depth texture (with its compare func), not a renderbuffer, and
    every texture a host step writes."""
    exporter, recorded, structure = lit_recording
    writes = [c for c in structure if c["op"] == "texture_write"]
    assert writes and all("data" not in c for c in writes)
    for c in writes:
        blob = exporter.value_pool[recorded["values"][c["slot"]]]["blob"]
        size = exporter.ctx.recording.textures[c["texture"]]["size"]
        assert len(exporter.blobs[blob].raw()) == size[0] * size[1] * 4 * 4
    objects = exporter.objects()
    depth = [rid for rid, t in objects["textures"].items() if t["dtype"] == "depth"]
    assert len(depth) == 1 and objects["textures"][depth[0]]["compare_func"] == "<="
    assert depth[0] not in objects["renderbuffers"]
    assert {c["texture"] for c in writes} <= set(objects["textures"])


@pytest.mark.gl
@pytest.mark.slow
def test_split_commands_keeps_every_uniform_value_in_order(gl):
    from catalog.render.frame import FrameRenderer
    from catalog.web.export import split_commands
    from catalog.web.record import RecordingContext

    ctx = RecordingContext(gl)
    renderer = FrameRenderer(ctx, (16, 12), specialise=False)
    try:
        # the page's modes (catalog.web.export.DESKTOP_MODES: the constant room)
        renderer.update(fabric="fluoro-pink", light="D65", room_lighting=False)
        ctx.recording.start()
        renderer.render()
        commands = ctx.recording.stop()
    finally:
        renderer.release()
    structure, values = split_commands(commands)
    moved = ("uniform", "buffer_write")  # values of the scene: uniforms, bytes written
    scene = [c for c in commands if c["op"] in moved]
    assert len(values) == len(scene) > 20
    assert [c["slot"] for c in structure if c["op"] in moved] == list(range(len(values)))
    for command, value in zip(scene, values):
        if command["op"] == "uniform":  # float32-exact: 9 significant digits give it back
            assert np.array_equal(np.float32(command["value"]), np.float32(value))
        else:  # the bytes written, as they are
            assert value == command["data"]
    # every other command kept as it was, in order (room, curtain, background, display ...)
    assert [c for c in structure if c["op"] not in moved] == \
        [c for c in commands if c["op"] not in moved]
    assert sum(c["op"] == "draw" for c in structure) >= 4


# ---------------------------------------------------------------- the command
def _run_web(*args, env=None):
    return subprocess.run([sys.executable, "-m", "catalog", "web", *args], capture_output=True,
                          text=True, env=env, timeout=600)


def test_unknown_fabric_one_line_exit_2_nothing_written(tmp_path):
    out = tmp_path / "site"
    result = _run_web("--out", str(out), "--fabric", "no-such-cloth")
    assert result.returncode == 2
    assert len(result.stderr.strip().splitlines()) == 1
    assert "no-such-cloth" in result.stderr and "--fabric" in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_unknown_light_one_line_exit_2_nothing_written(tmp_path):
    out = tmp_path / "site"
    result = _run_web("--out", str(out), "--fabric", "voile-white", "--lights", "D65,D99")
    assert result.returncode == 2
    assert len(result.stderr.strip().splitlines()) == 1
    assert "D99" in result.stderr and "--lights" in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_unwritable_folder_one_line_exit_2(tmp_path):
    parent = tmp_path / "ro"
    parent.mkdir()
    parent.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        result = _run_web("--out", str(parent / "site"), "--fabric", "voile-white")
    finally:
        parent.chmod(stat.S_IRWXU)
    assert result.returncode == 2
    assert len(result.stderr.strip().splitlines()) == 1 and "not writable" in result.stderr
    assert list(parent.iterdir()) == []


def test_unwritable_folder_refused_before_any_work(tmp_path, monkeypatch):
    """The same refusal through the library, where the test runs as root: the writability
    check is made (os.access says no) before anything is baked or written."""
    from catalog.core.errors import InputError
    from catalog.web import site

    real_access = os.access
    monkeypatch.setattr(site.os, "access",
                        lambda p, mode: False if str(p) == str(tmp_path) else real_access(p, mode))
    with pytest.raises(InputError, match="not writable"):
        site.build_site(tmp_path / "site", fabrics="voile-white", lights="D65")
    assert list(tmp_path.iterdir()) == []


def test_foreign_folder_is_not_replaced(tmp_path):
    out = tmp_path / "photos"
    out.mkdir()
    (out / "holiday.jpg").write_bytes(b"x")
    result = _run_web("--out", str(out), "--fabric", "voile-white", "--lights", "D65")
    assert result.returncode == 2 and "not a catalog site" in result.stderr
    assert [p.name for p in out.iterdir()] == ["holiday.jpg"]


@pytest.mark.gl
@pytest.mark.slow
def test_failure_midway_leaves_no_site_and_no_stage(tmp_path, monkeypatch, baked_voile):
    """An error after the work began (here: while recording) leaves neither DIR, nor the
    staging folder beside it, nor the missing folders above DIR that the build made."""
    from catalog.core.errors import CatalogError
    from catalog.web import export, site

    def broken(*args, **kw):
        raise CatalogError("recording failed")

    monkeypatch.setattr(export.SiteExporter, "record", broken)
    with pytest.raises(CatalogError, match="recording failed"):
        site.build_site(tmp_path / "made" / "for it" / "site", fabrics="voile-white",
                        lights="D65")
    assert list(tmp_path.iterdir()) == []  # the folders made above DIR are gone too


@pytest.mark.gl
@pytest.mark.slow
def test_a_second_build_replaces_only_what_the_first_wrote(tmp_path, baked_voile):
    """The second build replaces the first's files and removes those its manifest lists and
    the new site lacks; a file the user added (CNAME) survives."""
    from catalog.web import site

    out = tmp_path / "site"
    site.build_site(out, fabrics="voile-white", lights="D65")
    manifest = json.loads((out / site.MARKER).read_text())
    assert set(manifest["files"]) == {p.relative_to(out).as_posix() for p in out.rglob("*")
                                      if p.is_file()}
    (out / "anim" / "old-cloth.js").write_text("from the first build")  # listed: ours
    manifest["files"].append("anim/old-cloth.js")
    (out / site.MARKER).write_text(json.dumps(manifest))
    (out / "CNAME").write_text("fabrics.example.org\n")  # the user's
    report = site.build_site(out, fabrics="voile-white", lights="A")
    assert not (out / "anim" / "old-cloth.js").exists()
    assert (out / "CNAME").read_text() == "fabrics.example.org\n"
    assert json.loads((out / site.MARKER).read_text())["lights"] == ["A"] == report["lights"]
    assert [p.name for p in tmp_path.iterdir()] == ["site"]  # no stage or old copy left
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == []


@pytest.mark.gl
@pytest.mark.slow
def test_site_is_whole(web_site):
    """index.html, app.js, data.js, one animation per cloth parameter set; data.js holds
    every fabric x light x fluorescence scene and only ES shaders."""
    out, report = web_site
    names = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    assert {"index.html", "app.js", "style.css", "data.js", "catalog-web-site.json"} <= names
    from catalog.web.browser import site_data

    text = (out / "data.js").read_text()
    assert text.startswith("window.CATALOG_PACKED = ")
    data = site_data(out)
    from catalog.web.export import FLUORESCENCE, GLARE, ROOM_LAMPS

    switches = len(FLUORESCENCE) * len(GLARE) * len(ROOM_LAMPS)
    assert len(data["scenes"]) == len(report["fabrics"]) * len(report["lights"]) * switches
    for shader in data["shaders"]:
        assert shader["vertex"].startswith("#version 300 es")
        assert shader["fragment"].startswith("#version 300 es")
    for fabric in data["fabrics"]:
        assert (out / "anim" / f"{fabric['animation']}.js").is_file()
    # no reference to the network or to fetch in the page's code
    page = (out / "app.js").read_text() + (out / "index.html").read_text()
    assert "http://" not in page and "https://" not in page and "fetch(" not in page


def test_float_texels_quantised_within_half_a_step():
    """encode_texels -> the page's decoding (decode_texels does the page's arithmetic): every
    float32 texel within half a quantum of its channel's range (+ float32 rounding), 8-bit
    textures unchanged, a constant channel exact; 16 bits take half the bytes of float32."""
    from catalog.web.export import decode_texels, encode_texels

    rng = np.random.default_rng(3)
    texels = np.stack([rng.uniform(-0.7, 0.7, 500), rng.uniform(-1, 1, 500),
                       np.full(500, 0.25), rng.uniform(0, 1, 500)], axis=1).astype("f4")
    for bits in (8, 16):
        desc = {"dtype": "f4", "components": 4}
        enc = encode_texels(texels.tobytes(), desc, bits=bits)
        back = decode_texels({**desc, **enc}).reshape(-1, 4)
        step = (texels.max(axis=0) - texels.min(axis=0)) / ((1 << bits) - 1)
        err = np.abs(back.astype(np.float64) - texels)
        assert np.all(err <= step / 2 + 1e-6), (bits, err.max(axis=0), step)
        assert np.all(back[:, 2] == np.float32(0.25))
        assert enc["data"].size == texels.nbytes * bits // 32
    raw = bytes(range(256))
    assert decode_texels({"dtype": "f1", "components": 4, **encode_texels(raw, {"dtype": "f1", "components": 4})}).tobytes() == raw


def test_given_mip_levels_travel_after_level_0():
    """A texture the frame filled and whose levels 1..n it wrote: one quantised block, level 0
    then each level (w >> k by h >> k), ``levels`` n; no levels without them; a gap refused."""
    from catalog.core.errors import CatalogError
    from catalog.web.export import decode_texels, given_texels
    from catalog.web.record import Recording

    rng = np.random.default_rng(5)
    levels = [rng.uniform(0, 1, (8 >> k, 4 >> k, 4)).astype("f4") for k in range(3)]
    rec = Recording()
    rec.textures[7] = {"dtype": "f4", "components": 4, "size": [4, 8], "mipmaps": True}
    rec.texture_data[7] = levels[0].tobytes()
    assert "levels" not in given_texels(rec, 7) and given_texels(rec, 8) == {}
    rec.texture_levels[7] = {1: levels[1].tobytes(), 2: levels[2].tobytes()}
    entry = given_texels(rec, 7)
    assert entry["levels"] == 2
    back = decode_texels({**rec.textures[7], **entry})
    want = np.concatenate([lv.ravel() for lv in levels])
    assert back.shape == want.shape and np.max(np.abs(back - want)) <= 0.5 / 255 + 1e-6
    rec.texture_levels[7] = {2: levels[2].tobytes()}
    with pytest.raises(CatalogError, match="levels 1..n"):
        given_texels(rec, 7)


@pytest.mark.gl
@pytest.mark.slow
def test_site_carries_each_fabrics_pattern(web_site):
    """The page shows the desktop's patterned cloth (issue 12): the curtain program is built
    with PATTERN and OIT, and each fabric's pattern texture reaches data.js quantised
    (TEXEL_BITS), decoding to the desktop's texels within half a quantum per channel."""
    from catalog.presets import load_preset
    from catalog.core.resources import FABRIC_DIR
    from catalog.presets.patterns import load_pattern, mip_chain
    from catalog.web.export import DESKTOP_MODES, decode_texels

    assert DESKTOP_MODES["patterned"] is True
    out, report = web_site
    from catalog.web.browser import site_data

    data = site_data(out)
    assert any(s["defines"].get("PATTERN") and s["defines"].get("OIT") for s in data["shaders"])
    # and the room (its file, under the constant room's light until the page applies its
    # transport) with the cloth's own shadow maps
    files = {f for s in data["shaders"] for f in s["files"]}
    assert {"room_shadow.frag", "room_transport.frag"} <= files
    quantised = [t for t in data["textures"].values() if t.get("quantised")]
    for name in report["fabrics"]:
        texels = load_pattern(load_preset(FABRIC_DIR / f"{name}.toml")).normal_map()
        h, w = texels.shape[:2]
        match = [t for t in quantised if t["size"] == [w, h] and t.get("mipmaps")]
        assert match, f"no {w}x{h} pattern texture for {name}"
        q = match[0]["quantised"]
        half_step = (np.array(q["hi"]) - np.array(q["lo"])) / (2 * ((1 << q["bits"]) - 1))
        assert min(np.max(np.abs(decode_texels(t)[:h * w * 4].reshape(h, w, 4) - texels)
                          - half_step) for t in match) <= 1e-6
        # and the desktop's prefiltered levels after level 0 (the page writes them over its chain)
        chain = mip_chain(texels)
        level_1 = decode_texels(match[0])[h * w * 4:][:(h >> 1) * (w >> 1) * 4]
        assert match[0]["levels"] == len(chain) - 1
        assert np.max(np.abs(level_1.reshape(h >> 1, w >> 1, 4) - chain[1]) - half_step) <= 1e-5


def test_packed_data_round_trips_and_is_smaller():
    """pack_data -> unpack_data gives back the page's data exactly (bytes as base64, as the
    recorder writes them); repetitive bytes and JSON shrink under deflate."""
    import base64

    from catalog.web.site import pack_data, unpack_data

    b64 = lambda raw: base64.b64encode(raw).decode("ascii")  # noqa: E731
    data = {"format": 2, "scenes": {f"s{i}": {"values": [0.125 * i, [1.0, 2.0, 3.0]]} for i in range(200)},
            "textures": {"1": {"size": [64, 64], "data": b64(bytes(range(256)) * 64)},
                         "2": {"size": [1, 1]}},
            "buffers": {"3": {"data": b64(np.arange(300, dtype="<f4").tobytes())}, "4": {"curtain": "uv"}},
            "blobs": [b64(b"\x00" * 1000), b64(b"xy")]}
    text, plain = pack_data(data)
    assert text.startswith("window.CATALOG_PACKED = ")
    assert unpack_data(text) == data
    assert len(text) < 0.5 * plain


def test_deflated_bytes_round_trip_and_count_as_their_base64():
    """A Deflated gives its bytes back (zlib at DEFLATE_LEVEL: zlib.compress's own bytes) and
    its base64 (lengths 0, 1, 2 and 3 mod 3); _json_length of data holding Deflated values in
    dicts, in lists of lists and below its depth equals len(json.dumps) of the same data with
    each as its base64 string; pack_data writes the same data.js from either form."""
    import base64
    import json
    import zlib

    from catalog.web.deflated import DEFLATE_LEVEL, Deflated
    from catalog.web.site import _json_length, pack_data, plain_data_js

    rng = np.random.default_rng(7)
    raws = [b"", b"a", b"ab", b"abc", bytes(1000),
            rng.integers(0, 256, 4099, dtype=np.uint8).tobytes()]
    for raw in raws:
        d = Deflated.of(raw)
        assert d.raw() == raw and d.size == len(raw)
        assert d.data == zlib.compress(raw, DEFLATE_LEVEL)
        assert d.b64() == base64.b64encode(raw).decode("ascii") and d.b64_length() == len(d.b64())
    # in pieces: zlib.compress's bytes of their concatenation; texels given in pieces (level
    # 0, its mip levels) encode as their concatenation does
    cuts = [0, 1, 700, 701, 4099]
    pieces = [raws[5][i:j] for i, j in zip(cuts, cuts[1:])] + [b"", bytes(3000)]
    assert Deflated.of_pieces(iter(pieces)) == Deflated.of(b"".join(pieces))
    from catalog.web.export import encode_texels
    levels = [rng.uniform(-1, 1, (n, 4)).astype("f4").tobytes() for n in (64, 16, 4, 1)]
    levels[2] = np.full((4, 4), 9.0, dtype="f4").tobytes()   # the greatest texel in a level
    desc = {"dtype": "f4", "components": 4}
    assert encode_texels(levels, desc) == encode_texels(b"".join(levels), desc)
    assert encode_texels(levels, desc)["quantised"]["hi"] == [9.0] * 4
    as_b64 = lambda v: (v.b64() if isinstance(v, Deflated) else  # noqa: E731
                        {k: as_b64(x) for k, x in v.items()} if isinstance(v, dict) else
                        [as_b64(x) for x in v] if isinstance(v, list) else v)
    blobs = [Deflated.of(r) for r in raws]
    data = {"format": 2, "blobs": blobs, "nested": [[blobs[1], [blobs[5], 0.5, "é"]], []],
            "textures": {1: {"size": [4, 4], "data": blobs[4], "deep": {"x": [{"y": blobs[3]}]}}},
            "empty": {}, "scenes": {"s0": {"values": [0, 1]}}, "value_pool": [0.125, [1.0, 2.0]]}
    plain = as_b64(data)
    for depth in (0, 1, 2, 3, 6):
        assert _json_length(data, depth) == len(json.dumps(plain, separators=(",", ":"))), depth
    assert plain_data_js(data) == plain_data_js(plain)
    packable = {k: v for k, v in data.items() if k not in ("nested",)}
    packable["textures"] = {1: {"size": [4, 4], "data": blobs[4]}}
    packable["buffers"] = {3: {"data": blobs[5]}, 4: {"curtain": "uv"}}
    assert pack_data(packable) == pack_data(as_b64(packable))


def test_frame_comparison_reports_a_frame_wide_shift():
    """compare_frames' signed mean per channel: a shift of the whole frame (another white
    balance) reads as itself, sign included; a moved edge counts by its share of the frame
    (a column of 200/255 lost from 40: -5/255 in each channel)."""
    from catalog.web.browser import compare_frames, frames_match

    rng = np.random.default_rng(3)
    desktop = rng.integers(40, 200, size=(30, 40, 3), dtype=np.uint8)
    shifted = desktop.astype(np.int16) + np.array([1, -1, 0], dtype=np.int16)
    figures = compare_frames(shifted.astype(np.uint8), desktop)
    assert figures["signed_mean_8bit"] == [1.0, -1.0, 0.0]
    assert figures["unmatched"] == 0 and not frames_match(figures)  # mean 0.67 > 0.5
    edge = np.zeros((30, 40, 3), dtype=np.uint8)
    edge[:, 20:] = 200
    moved = np.roll(edge, 1, axis=1)
    moved[:, 0] = 0
    figures = compare_frames(moved, edge)
    assert figures["edge_shift"] == 30 and figures["signed_mean_8bit"] == [-5.0] * 3


@pytest.mark.slow   # 200 MB held and let go (0.7 s here)
def test_stage_peaks_reset_at_each_stage(tmp_path):
    """StagePeaks (the per-stage column of benchmarks/web_build.py): a stage that holds 200 MB for a
    moment peaks at least 190 MB above the resident set before it; the stage after it, which
    holds nothing more, peaks below that (the peak is reset at each stage's start). Linux
    only (VmHWM, /proc/self/clear_refs); elsewhere nothing is measured."""
    from catalog.web.site import StagePeaks

    stages = StagePeaks(True)
    if not stages._on:
        assert stages.peaks == {}
        pytest.skip("no /proc/self/clear_refs here")
    stages.start("quiet")
    stages.start("big")
    block = np.ones(200 * 2 ** 20 // 8)   # written: resident
    del block
    stages.start("after")
    stages.end()
    assert set(stages.peaks) == {"quiet", "big", "after"}
    assert stages.peaks["big"] >= stages.peaks["quiet"] + 190, stages.peaks
    assert stages.peaks["after"] < stages.peaks["big"] - 150, stages.peaks
    assert StagePeaks(False).peaks == {} and not StagePeaks(False)._on


def _grid_animation(amplitude_m: float, key: str):
    """A one-frame BakedAnimation of a 9 x 7 grid hanging in a sine of ``amplitude_m`` (the
    same grid, uv and triangles whatever the amplitude: two fabrics of one site)."""
    from catalog.web import bake

    cols, rows = 9, 7
    u, v = np.meshgrid(np.linspace(0.0, 1.0, cols), np.linspace(0.0, 1.0, rows))
    grid = np.stack([1.2 * u - 0.6, 1.6 * v, amplitude_m * np.sin(4 * np.pi * u)], axis=-1)
    quads = [(r * cols + c, r * cols + c + 1, (r + 1) * cols + c, (r + 1) * cols + c + 1)
             for r in range(rows - 1) for c in range(cols - 1)]
    indices = np.array([[a, c, b, b, c, d] for a, b, c, d in quads], dtype=np.uint32).ravel()
    lo, payload = bake.encode(grid.reshape(1, -1, 3))
    return bake.BakedAnimation(key=key, frames=1, fps=12.0, vertex_count=cols * rows,
                               indices=indices, uv=np.stack([u, v], -1).reshape(-1, 2).astype("f4"),
                               offset_m=(0.0, 0.0, 0.1), lo_m=lo, payload=payload,
                               fabric_size_m=(1.2, 1.6), rings_x_m=(-0.5, 0.0, 0.5),
                               grid=(cols, rows))


@pytest.mark.gl
def test_use_drape_puts_each_fabrics_cloth_in_the_recorded_frame(gl):
    """The site's exporter is given the first fabric's mesh once (use_mesh: the page's curtain
    buffers); use_drape of another fabric then puts that fabric's own baked frame 0 into the
    recorded renderer's buffers (what its host steps read back is drawn from it), in the same
    buffers (the page's curtain tags still name them), as into the meter's."""
    from catalog.web import bake, export

    first, second = _grid_animation(0.02, "first"), _grid_animation(0.08, "second")
    exporter = export.SiteExporter(gl)
    try:
        p, n, t = bake.decode_frame(first, 0)
        exporter.use_mesh(p, n, first.uv, t, first.indices.astype(np.int32))
        exporter.use_drape(first)
        tags = dict(exporter.curtain_tags)
        exporter.use_drape(second)
        want = dict(zip(("position", "normal", "tangent"), bake.decode_frame(second, 0)))
        assert not np.allclose(want["position"], p, atol=1e-3)   # the cloths differ
        buffers = exporter.ctx.recording.buffers
        for rid, tag in tags.items():
            if tag in want:
                assert buffers[rid] == np.ascontiguousarray(want[tag], dtype="f4").tobytes(), tag
        for arrays in (exporter.renderer.mesh_arrays, exporter.meter.mesh_arrays):
            for got, tag in zip(arrays, ("position", "normal", "tangent")):
                np.testing.assert_array_equal(got, want[tag])
        assert exporter.curtain_tags == tags
    finally:
        exporter.release()
