"""``catalog web``: write the static catalog site, whole or not at all.

The site (docs/web.md)::

    DIR/index.html     the page (assets/index.html)
    DIR/app.js         the WebGL2 replayer, camera, animation decoder and controls
    DIR/style.css
    DIR/data.js        window.CATALOG_PACKED: the page's data (shaders (GLSL ES variant),
                       recorded frame structures and per-scene uniform values, fabrics,
                       lights, swatches, pattern texels, buffers), deflated (pack_data)
    DIR/anim/KEY.js    one baked cloth animation per distinct cloth parameter set, loaded
                       by a <script> tag when a fabric is first shown

Everything is a plain file read with <script>/<link> tags: it works from ``file://`` (no
fetch of local files) and from any static host, with no network access at run time.
It is staged in a marked temporary folder on ``DIR``'s file system (catalog.core.atomic)
and moved in when complete; an existing ``DIR`` is written into only if it is an earlier
catalog site or empty, and of an earlier site only the files its manifest
(``catalog-web-site.json``, ``files``) lists are replaced or removed: a file the user
added (``CNAME``) survives.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import time
from importlib import resources
from pathlib import Path

import numpy as np

from catalog.core.errors import CatalogError, InputError
from catalog.web.deflated import DEFLATE_LEVEL, Deflated

#: The page's own files (catalog/web/assets), copied as they are.
ASSET_FILES = ("index.html", "app.js", "room_transport.js", "host_steps.js", "style.css")
#: A file every site has: marks a folder as ours (safe to replace).
MARKER = "catalog-web-site.json"
#: The room's transport pack (catalog.room.web_pack.PAGE_FILE).
ROOM_PACK_FILE = "room_pack.js"
FORMAT_VERSION = 2  # 2: data.js packed (pack_data)


#: The places in data.js that hold bytes (a Deflated, or base64, in the recorded data): packed
#: apart from the JSON (see :func:`pack_data`). (section, field); ``None``: every item of the list.
BINARY_FIELDS = (("textures", "data"), ("buffers", "data"), ("blobs", None))


def _json_length(value, depth: int = 2) -> int:
    """len(json.dumps(value, separators=(",", ":"))) of ``value`` with each
    :class:`~catalog.web.deflated.Deflated` as its bytes' base64 string (the plain form,
    :func:`plain_data_js`), without the whole text at once: the top ``depth`` levels of dicts
    and lists part by part (the scenes one at a time), a Deflated by its base64's length."""
    if isinstance(value, Deflated):
        return value.b64_length() + 2
    if depth and isinstance(value, dict) and value:
        return (2 + len(value) - 1
                + sum(len(json.dumps(str(key))) + 1 + _json_length(item, depth - 1)
                      for key, item in value.items()))
    if depth and isinstance(value, list) and value:
        return 2 + len(value) - 1 + sum(_json_length(item, depth - 1) for item in value)
    deeper: list[int] = []   # a Deflated below depth: "" in the text, its length added

    def stand_in(item):
        if not isinstance(item, Deflated):
            raise TypeError(f"{type(item).__name__} is not JSON serialisable")
        deeper.append(item.b64_length())
        return ""
    return len(json.dumps(value, separators=(",", ":"), default=stand_in)) + sum(deeper)


def _json_pieces(value, depth: int = 3):
    """json.dumps(value, separators=(",", ":")) in pieces: the top ``depth`` levels of dicts
    and lists part by part (joined, the same text)."""
    if depth and isinstance(value, dict) and value:
        for k, (key, item) in enumerate(value.items()):
            yield ("{" if k == 0 else ",") + json.dumps(str(key)) + ":"
            yield from _json_pieces(item, depth - 1)
        yield "}"
    elif depth and isinstance(value, list) and value:
        for k, item in enumerate(value):
            yield "[" if k == 0 else ","
            yield from _json_pieces(item, depth - 1)
        yield "]"
    else:
        yield json.dumps(value, separators=(",", ":"))


def _plain_length(data: dict) -> int:
    """:func:`_json_length` of ``data`` with its scenes' values as values, not indices into
    its ``value_pool`` (the plain form, :func:`plain_data_js`), when it has one."""
    pool = data.get("value_pool")
    if pool is None or "scenes" not in data:
        return _json_length(data)
    sizes = [len(json.dumps(v, separators=(",", ":"))) for v in pool]
    rest = {k: v for k, v in data.items() if k not in ("value_pool", "scenes")}
    scenes = data.get("scenes", {})

    def scene_length(scene: dict) -> int:
        values = scene["values"]
        return (len(json.dumps({**scene, "values": []}, separators=(",", ":")))
                + (sum(sizes[i] for i in values) + len(values) - 1 if values else 0))

    scenes_length = 2 + max(len(scenes) - 1, 0) + sum(
        len(json.dumps(str(key))) + 1 + scene_length(scene) for key, scene in scenes.items())
    return (_json_length(rest) + (1 if rest else 0) + len(json.dumps("scenes")) + 1
            + scenes_length)


def pack_data(data: dict) -> tuple[str, int]:
    """data.js's text, and the bytes a plain ``window.CATALOG_DATA = JSON`` would take
    (:func:`packed_pieces`, joined)."""
    pieces, plain = packed_pieces(data)
    return "".join(pieces), plain


def packed_pieces(data: dict):
    """(data.js's text in pieces, the bytes a plain ``window.CATALOG_DATA = JSON`` would
    take): the pieces an iterator that makes each binary item's base64 as it comes, so that
    data.js is written without its whole text (or all its base64) in memory.

    data.js sets ``window.CATALOG_PACKED = {"json": Z, "binary": [Z, ..]}``: Z is base64 of zlib
    (the page inflates it with the browser's DecompressionStream; a script, not a fetch, so
    that file:// works). The bulky bytes (:data:`BINARY_FIELDS`: the fabrics' pattern texels,
    vertex buffers, bytes a frame writes) leave the JSON: each becomes ``{"binary": i}``, its
    bytes deflated on their own (deflate does much better on bytes than on their base64), and
    the rest of the JSON (uniform values, frame structures, shaders) is deflated as text, each
    distinct uniform value once (``value_pool``; a scene's ``values`` index it)."""
    import base64  # noqa: PLC0415
    import zlib  # noqa: PLC0415

    # The whole catalog's data is hundreds of MB as Python objects: no deep copy of it and no
    # plain JSON text of it whole. The plain size is counted part by part (_json_length), and
    # only what packing changes is copied (the scenes' value lists, the entries whose bytes
    # move out).
    plain = len(plain_data_js({})) - 2 + _plain_length(data)
    data = dict(data)
    binary: list[bytes] = []   # deflated
    # every distinct uniform value once ("values": [0.5, ..] -> "values": [i, ..] into
    # "value_pool"): scenes of one fabric or light share most of theirs. Data that comes
    # pooled (the exporter pools as it records) is kept as it is.
    pool: dict[str, int] = {}
    if "scenes" in data and "value_pool" not in data:
        data["scenes"] = {key: {**scene, "values": [
            pool.setdefault(json.dumps(v, separators=(",", ":")), len(pool))
            for v in scene["values"]]} for key, scene in data["scenes"].items()}
        data["value_pool"] = [json.loads(text) for text in pool]

    def move(value: str | Deflated) -> dict:
        # a Deflated (as the exporter holds them) as it is; base64 deflated here
        deflated = value if isinstance(value, Deflated) else Deflated.of(base64.b64decode(value))
        binary.append(deflated.data)
        return {"binary": len(binary) - 1}

    for section, field in BINARY_FIELDS:
        if field is None:
            data[section] = [move(v) for v in data[section]]
            continue
        data[section] = {key: ({**entry, field: move(entry[field])}
                               if isinstance(entry.get(field), (str, Deflated)) else entry)
                         for key, entry in data[section].items()}
    # deflated part by part (the scenes and the pool an item at a time): the same bytes as
    # zlib.compress of the whole text, without the whole text in memory
    deflate = zlib.compressobj(DEFLATE_LEVEL)
    deflated = [deflate.compress(piece.encode("utf-8")) for piece in _json_pieces(data)]
    deflated.append(deflate.flush())
    del data
    packed_json = base64.b64encode(b"".join(deflated)).decode("ascii")
    del deflated

    def pieces():
        # json.dumps({"format": .., "json": .., "binary": [..]}, separators=(",", ":")), each
        # binary item's base64 made as it is written
        yield (f'window.CATALOG_PACKED = {{"format":{json.dumps(FORMAT_VERSION)},"json":'
               f'{json.dumps(packed_json)},"binary":[')
        for k, item in enumerate(binary):
            yield ("," if k else "") + json.dumps(base64.b64encode(item).decode("ascii"))
        yield "]};\n"
    return pieces(), plain


def plain_data_js(data: dict) -> str:
    """data.js as plain JSON (``window.CATALOG_DATA``, bytes as base64, a Deflated's too): the
    form before :func:`pack_data`, which the page still reads (the benchmark loads both)."""
    return "window.CATALOG_DATA = " + json.dumps(data, separators=(",", ":"),
                                                 default=Deflated.b64) + ";\n"


def unpack_data(text: str) -> dict:
    """The data of a data.js written by :func:`pack_data`, bytes back as base64 (as recorded)."""
    import base64  # noqa: PLC0415
    import zlib  # noqa: PLC0415

    packed = json.loads(text[text.index("= ") + 2:].rstrip().rstrip(";"))
    data = json.loads(zlib.decompress(base64.b64decode(packed["json"])))
    pool = data.pop("value_pool", None)
    if pool is not None:
        for scene in data["scenes"].values():
            scene["values"] = [pool[i] for i in scene["values"]]

    def back(ref):
        raw = zlib.decompress(base64.b64decode(packed["binary"][ref["binary"]]))
        return base64.b64encode(raw).decode("ascii")

    for section, field in BINARY_FIELDS:
        if field is None:
            data[section] = [back(v) for v in data[section]]
            continue
        for entry in data[section].values():
            if isinstance(entry.get(field), dict):
                entry[field] = back(entry[field])
    return data


def _check_out(out: Path) -> Path:
    out = Path(out)
    parent = out.resolve().parent
    existing = parent
    while not existing.exists():  # missing folders above DIR are made (and removed on failure)
        existing = existing.parent
    if not existing.is_dir():
        raise InputError(f"{str(existing)!r} is a file, not a folder", field="--out")
    if out.exists():
        if not out.is_dir():
            raise InputError(f"{str(out)!r} is a file, not a folder", field="--out")
        if any(out.iterdir()) and not (out / MARKER).is_file():
            raise InputError(f"{str(out)!r} exists and is not a catalog site; refusing to "
                             "replace it", field="--out")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise InputError(f"folder {str(existing)!r} is not writable", field="--out")
    return out


def site_files(out: Path) -> list[str]:
    """The files an earlier site in ``out`` wrote (its manifest's ``files``; a site written
    before the manifest listed them: the page's fixed names and anim/*.js)."""
    try:
        manifest = json.loads((out / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    files = manifest.get("files") if isinstance(manifest, dict) else None
    if isinstance(files, list) and all(isinstance(f, str) for f in files):
        return files
    return [*ASSET_FILES, "data.js", MARKER,
            *(f"anim/{p.name}" for p in sorted((out / "anim").glob("*.js")))]


def _replace_listed(new_files: list[str]):
    """Before the new site's files are moved in: remove the earlier site's files that the
    new one does not write. Only files the manifest lists, inside the site, are touched:
    a file the user added (a CNAME) survives."""
    def remove(out: Path) -> None:
        root = out.resolve()
        for name in site_files(out):
            target = (out / name)
            if name in new_files or not target.resolve().is_relative_to(root):
                continue
            with contextlib.suppress(OSError):
                if target.is_file() and not target.is_symlink():
                    target.unlink()
    return remove


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _asset(name: str) -> bytes:
    return resources.files("catalog.web").joinpath("assets", name).read_bytes()


def _return_large_blocks(threshold_bytes: int = 1 << 20) -> None:
    """Let glibc's malloc give blocks of ``threshold_bytes`` or more back to the system when
    they are freed (mallopt M_MMAP_THRESHOLD; elsewhere nothing). Its default threshold grows
    to the largest block freed (up to 32 MB), after which the pattern's float64 temporaries
    (catalog.presets.patterns.Pattern.normal_map, some 50 MB for the lace, made by each of
    the build's renderers) came from the heap and stayed in the process after use: the
    whole catalog's build peaked at 641 MB. A fixed threshold also keeps it from growing."""
    import ctypes  # noqa: PLC0415
    import ctypes.util  # noqa: PLC0415

    m_mmap_threshold = -3   # malloc.h
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.mallopt(m_mmap_threshold, int(threshold_bytes))
    except (OSError, AttributeError):   # not glibc
        pass


class StagePeaks:
    """The peak resident set (MB) of each stage of a build (:data:`STAGES`): Linux's VmHWM,
    reset at each stage's start (``/proc/self/clear_refs`` 5). Opt-in (build_site's
    ``stage_peaks``): the reset also lowers what the process's own peak reads afterwards
    (getrusage, /usr/bin/time), so the whole run's peak is then the largest stage's. Where
    the files cannot be used (not Linux) nothing is measured ({})."""

    def __init__(self, enabled: bool):
        self.peaks: dict[str, int] = {}
        self._stage = None
        self._on = enabled and self._reset()

    @staticmethod
    def _reset() -> bool:
        try:
            Path("/proc/self/clear_refs").write_text("5")
            return True
        except OSError:
            return False

    def start(self, name: str) -> None:
        """End the running stage (its peak noted) and start ``name``."""
        self.end()
        if self._on:
            self._stage = name
            self._reset()

    def end(self) -> None:
        if self._stage is not None:
            with open("/proc/self/status", encoding="ascii") as status:
                kb = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
            self.peaks[self._stage] = round(kb / 1024)
        self._stage = None


#: The stages of a build, as StagePeaks names them: the cloths' bake (its child process's
#: peak is the child's own), the swatches' renderer, the exporter's two renderers made and
#: checked, the scenes recorded, the GL objects collected (and the renderers released), the
#: data pooled, packed and written with the room's pack.
STAGES = ("bake", "swatches", "exporter", "recording", "GL collect", "packing")


def build_site(out: str | Path, fabrics: str | None = None, lights: str | None = None,
               ctx=None, progress: bool = False, room="box",
               stage_peaks: bool = False) -> dict:
    """Write the site into ``out``; returns a report (sizes, counts, seconds). ``progress``:
    the bake's and the recording's progress on stderr (catalog.core.progress). ``room``: a
    built-in name or a .glb path (``--room``): the scenes are drawn in it and its transport's
    web pack is written (export.room_pack_script). ``stage_peaks``: measure each stage's
    peak resident set (:class:`StagePeaks`; the report's ``stage_peak_mb``)."""
    import base64  # noqa: PLC0415

    from catalog.core.progress import progress as progress_bar  # noqa: PLC0415

    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415
    from catalog.web import bake as bake_lib  # noqa: PLC0415
    from catalog.web import export  # noqa: PLC0415

    start = time.perf_counter()
    _return_large_blocks()
    stages = StagePeaks(stage_peaks)
    out = Path(out)
    names = export.parse_fabrics(fabrics)
    choices = export.parse_lights(lights)
    out = _check_out(out)
    presets = [load_preset(find_preset(n)) for n in names]
    from catalog.room.load import load_room  # noqa: PLC0415

    room = load_room(room)   # a bad room is refused in one line before any work
    for preset in presets:  # refuse a bad preset before any work
        scene_lib.dye_transmittance(preset)
        scene_lib.fluorescent_material(preset)

    from catalog.core.atomic import STAGE_MARKER, staged_folder  # noqa: PLC0415

    new_files: list[str] = []
    with staged_folder(out, replace_listed=_replace_listed(new_files)) as stage:
        timings = {}
        t = time.perf_counter()
        stages.start("bake")
        fabric_animation = {}
        keys = {preset.name: bake_lib.cloth_key(bake_lib.bake_params(preset)) for preset in presets}
        firsts = {}   # one preset per distinct cloth
        for preset in presets:
            firsts.setdefault(keys[preset.name], preset)
        with progress_bar("catalog web: bake", total=len(firsts), unit="cloths",
                          enabled=progress) as bar:
            animations = dict(zip(firsts, bake_lib.bake_apart(list(firsts.values()),
                                                              on_baked=bar.advance)))
        for preset in presets:
            fabric_animation[preset.name] = animations[keys[preset.name]]
        first = next(iter(animations.values()))
        for animation in animations.values():  # the page swaps the curtain's buffers only
            if not (np.array_equal(animation.indices, first.indices)
                    and np.array_equal(animation.uv, first.uv)):
                raise CatalogError("the baked curtains differ in their grids; the page's "
                                   "recorded frame has one")
        timings["bake_s"] = time.perf_counter() - t

        t = time.perf_counter()
        from catalog.gl.context import headless_context  # noqa: PLC0415

        # without ctx, a context of its own, released at the end of the block (its programs,
        # textures and the driver's compiled shaders go before the data is packed) and the
        # caller's current context current again
        stages.start("swatches")
        with headless_context(ctx) as own:
            # the swatches first, their renderer released before the recording's two are made
            swatches = {name: base64.b64encode(png).decode("ascii")
                        for name, png in export.swatch_pngs(own, presets, room=room).items()}
            stages.start("exporter")
            exporter = export.SiteExporter(own, room=room)
            try:
                positions, normals, tangents = bake_lib.decode_frame(first, 0)
                exporter.use_mesh(positions, normals, first.uv, tangents, first.indices)
                exporter.use_drape(fabric_animation[presets[0].name])
                exporter.check_camera_uniforms(exporter.scene(presets[0], choices[0]))
                scenes = {}
                stages.start("recording")
                variants = list(itertools.product(export.FLUORESCENCE, export.GLARE,
                                                  export.ROOM_LAMPS))
                with progress_bar("catalog web: record", total=len(presets) * len(choices)
                                  * len(variants), unit="scenes", enabled=progress) as bar:
                    for preset in presets:
                        exporter.use_drape(fabric_animation[preset.name])
                        for choice in choices:
                            scene = exporter.scene(preset, choice)   # resolved once, drawn 8 ways
                            metered = exporter.record(scene, "on")
                            # the switches keep the exposure metered with fluorescence on, no
                            # glare, no lamp: they show the brightener's, the glare's and the
                            # lamp's light
                            for fluorescence, glare, lamp in variants:
                                key = export.scene_key(preset.name, choice.id, fluorescence, glare,
                                                       lamp)
                                scenes[key] = (
                                    metered if (fluorescence, glare, lamp) == ("on", "off", "none")
                                    else exporter.record(scene, fluorescence,
                                                         ev100=metered["ev100"], glare=glare,
                                                         lamp=lamp))
                                bar.advance()
                stages.start("GL collect")
                objects = exporter.objects()
            finally:
                exporter.release()
        timings["record_s"] = time.perf_counter() - t
        stages.start("packing")
        scenes, value_pool = exporter.pooled_scenes(scenes)

        camera = exporter.renderer.camera
        data = {
            "format": FORMAT_VERSION,
            "record_size": list(export.RECORD_SIZE),
            "camera": {"target": list(camera.target), "fov_y_deg": camera.fov_y_deg,
                       "near_m": camera.near_m, "far_m": camera.far_m,
                       "yaw_deg": camera.yaw_deg, "pitch_deg": camera.pitch_deg,
                       "distance_m": camera.distance_m, "limits": export.ORBIT_LIMITS},
            "camera_uniforms": export.CAMERA_UNIFORMS,
            **objects,
            "structures": exporter.structures,
            "blobs": exporter.blobs,
            "scenes": scenes,
            "value_pool": value_pool,   # the scenes' values index it
            "fabrics": [{"name": p.name, "display_name": p.display_name,
                         "facts": export.fabric_facts(p), "swatch": swatches[p.name],
                         "animation": fabric_animation[p.name].key} for p in presets],
            "lights": [{"id": c.id, "label": c.label, "kind": c.kind, "hour": c.hour}
                       for c in choices],
            "fluorescence": list(export.FLUORESCENCE),
            "glare": list(export.GLARE),
            "room_lamps": [{"id": k, "label": v} for k, v in export.ROOM_LAMPS.items()],
            "animations": {k: a.manifest() for k, a in animations.items()},
        }
        t = time.perf_counter()
        room_text, room_report = export.room_pack_script(room)
        (stage / ROOM_PACK_FILE).write_text(room_text, encoding="utf-8")
        del room_text
        data["room"] = {"name": room_report["name"], "pack": ROOM_PACK_FILE}
        timings["room_pack_s"] = time.perf_counter() - t
        pieces, plain_bytes = packed_pieces(data)
        del data
        with open(stage / "data.js", "w", encoding="utf-8") as packed:
            packed.writelines(pieces)
        del pieces
        (stage / "anim").mkdir()
        for animation in animations.values():
            (stage / "anim" / f"{animation.key}.js").write_text(animation.script(), encoding="utf-8")
        for name in ASSET_FILES:
            (stage / name).write_bytes(_asset(name))
        sizes = {p.relative_to(stage).as_posix(): p.stat().st_size
                 for p in sorted(stage.rglob("*")) if p.is_file() and p.name != STAGE_MARKER}
        report = {"out": str(out), "fabrics": names, "lights": [c.id for c in choices],
                  "scenes": len(scenes), "structures": len(exporter.structures),
                  "shader_programs": len(objects["shaders"]),
                  "animations": {k: a.manifest() for k, a in animations.items()},
                  "bytes": sizes, "total_bytes": sum(sizes.values()),
                  "first_view_bytes": sum(v for k, v in sizes.items()   # (the room pack: after it)
                                          if not k.startswith("anim/") and k != ROOM_PACK_FILE)
                  + max(a.stat().st_size for a in (stage / "anim").iterdir()),
                  "data_js_plain_bytes": plain_bytes, "room": room_report,
                  **{k: round(v, 3) for k, v in timings.items()}}
        stages.end()
        if stages.peaks:
            report["stage_peak_mb"] = dict(stages.peaks)
        new_files.extend([*sizes, MARKER])
        (stage / MARKER).write_text(json.dumps({"format": FORMAT_VERSION, "fabrics": names,
                                                "lights": report["lights"],
                                                "files": sorted(new_files)}, indent=1) + "\n",
                                    encoding="utf-8")
    report["build_s"] = round(time.perf_counter() - start, 3)
    if not (out / "index.html").is_file():
        raise CatalogError(f"{out}: the site was not written")
    return report
