"""The draped curtain as glTF 2.0 binary (``.glb``), for any standard viewer.

Geometry: the curtain the snapshot draws at that frame (catalog.render.snapshot's
``simulated_curtain``: the settled drape, then the cloth simulation), in the scene's
coordinates (metres, +Y up, glTF's convention): positions, unit normals, and UVs counted in
pattern repeats (u = metres across / repeat_u), so the texture tiles with a REPEAT sampler
at the fabric's physical scale.

Material (a standard viewer's approximation of eq. 7; the fabric's own data rides along):

- ``baseColorFactor``: the yarn's colour (the dye's linear sRGB under D65, else a white);
  ``baseColorTexture``: the pattern as RGBA, alpha = the coverage, ``alphaMode`` BLEND,
  double-sided: the holes are holes;
- ``KHR_materials_diffuse_transmission``: the thread's diffuse see-through, the diffuse
  lobe's weight per thread area (a_diff / rho = e^-tau k_d, eq. 7), clamped to [0, 1];
- ``KHR_materials_sheen``: the grazing glow of fibres, coloured like the yarn;
- ``extras.catalog`` on the scene: the preset (every table), the light, the frame and the
  room, so the file round-trips to the fabric it came from.
"""

from __future__ import annotations

import json
import math
import struct
import tempfile
from pathlib import Path

import numpy as np

GLB_MAGIC = 0x46546C67
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
FLOAT, UNSIGNED_INT = 5126, 5125
REPEAT, LINEAR, LINEAR_MIPMAP_LINEAR = 10497, 9729, 9987
#: Sheen of a matte yarn (KHR_materials_sheen): roughness, and the colour's share of the yarn's.
SHEEN_ROUGHNESS = 0.5
SHEEN_SHARE = 0.5


def _pad(data: bytes, fill: bytes = b"\x00") -> bytes:
    return data + fill * (-len(data) % 4)


def _png_bytes(rgba: np.ndarray) -> bytes:
    """RGBA 8-bit PNG bytes of an (H, W, 4) 0..1 array (through OpenImageIO)."""
    import OpenImageIO as oiio  # noqa: PLC0415

    from catalog.core.errors import CatalogError  # noqa: PLC0415

    h, w, _ = rgba.shape
    data = np.round(np.clip(rgba, 0, 1) * 255).astype(np.uint8)
    with tempfile.TemporaryDirectory(prefix="catalog-gltf-") as folder:
        path = Path(folder) / "pattern.png"
        out = oiio.ImageOutput.create(str(path))
        spec = oiio.ImageSpec(w, h, 4, oiio.UINT8)
        if out is None or not (out.open(str(path), spec) and out.write_image(data)):
            raise CatalogError(f"cannot encode the pattern texture: {oiio.geterror()}")
        out.close()
        return path.read_bytes()


def _plain(value):
    """A TOML document as JSON (paths and numbers as they are)."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    return str(value)


def curtain_arrays(preset, frame: int, placement=None):
    """(positions, unit normals, uv in repeats, indices, fabric size m, repeat m), the curtain
    on the rod of ``placement`` (catalog.render.placement; None: the box's)."""
    from catalog.presets.patterns import load_pattern  # noqa: PLC0415
    from catalog.render.snapshot import simulated_curtain  # noqa: PLC0415

    positions, normals, uv, _tangents, indices, fabric_size = simulated_curtain(preset, frame, placement)
    pattern = load_pattern(preset)
    repeat = pattern.repeat_m if pattern is not None else fabric_size
    normals = np.asarray(normals, dtype=np.float64)
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    uv_repeats = np.asarray(uv, dtype=np.float64) * np.array(fabric_size) / np.array(repeat)
    # glTF's v runs down the texture; the mesh's v = 1 is the top of the curtain
    uv_repeats[:, 1] = (1.0 - np.asarray(uv, dtype=np.float64)[:, 1]) * fabric_size[1] / repeat[1]
    return (np.asarray(positions, dtype=np.float32), normals.astype(np.float32),
            uv_repeats.astype(np.float32), np.asarray(indices, dtype=np.uint32).reshape(-1),
            fabric_size, repeat, pattern)


def gltf_document(preset, light: str, frame: int, room: str, placement=None):
    """(glTF JSON dict, binary buffer bytes)."""
    from catalog.exchange.u3m_export import base_colour_of  # noqa: PLC0415

    positions, normals, uv, indices, fabric_size, repeat, pattern = curtain_arrays(preset, frame, placement)
    colour = base_colour_of(preset)
    blobs, views, accessors = [], [], []

    def add(data: bytes, target: int | None) -> int:
        offset = sum(len(b) for b in blobs)
        blobs.append(_pad(data))
        view = {"buffer": 0, "byteOffset": offset, "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        views.append(view)
        return len(views) - 1

    def accessor(array: np.ndarray, kind: str, component: int, target: int, bounds=False) -> int:
        entry = {"bufferView": add(array.tobytes(), target), "componentType": component,
                 "count": int(array.shape[0]), "type": kind}
        if bounds:
            entry["min"] = [float(v) for v in array.min(axis=0)]
            entry["max"] = [float(v) for v in array.max(axis=0)]
        accessors.append(entry)
        return len(accessors) - 1

    attributes = {"POSITION": accessor(positions, "VEC3", FLOAT, ARRAY_BUFFER, bounds=True),
                  "NORMAL": accessor(normals, "VEC3", FLOAT, ARRAY_BUFFER),
                  "TEXCOORD_0": accessor(uv, "VEC2", FLOAT, ARRAY_BUFFER)}
    index_accessor = accessor(indices, "SCALAR", UNSIGNED_INT, ELEMENT_ARRAY_BUFFER)
    accessors[index_accessor].update(min=[int(indices.min())], max=[int(indices.max())])
    b = preset.btdf
    transmission = min(max(math.exp(-b.tau) * b.k_d, 0.0), 1.0)
    material = {
        "name": preset.display_name,
        "pbrMetallicRoughness": {"baseColorFactor": colour + [1.0], "metallicFactor": 0.0,
                                 "roughnessFactor": 0.85},
        "doubleSided": True,
        "extensions": {
            "KHR_materials_sheen": {"sheenColorFactor": [SHEEN_SHARE * c for c in colour],
                                    "sheenRoughnessFactor": SHEEN_ROUGHNESS},
            "KHR_materials_diffuse_transmission": {
                "diffuseTransmissionFactor": round(transmission, 6),
                "diffuseTransmissionColorFactor": colour},
        },
    }
    doc = {"asset": {"version": "2.0", "generator": "catalog export (fabric catalog)"},
           "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_diffuse_transmission"],
           "scene": 0, "nodes": [{"name": "curtain", "mesh": 0}],
           "meshes": [{"name": preset.name,
                       "primitives": [{"attributes": attributes, "indices": index_accessor,
                                       "material": 0, "mode": 4}]}],
           "materials": [material]}
    if pattern is not None:
        rgba = np.ones(pattern.coverage.shape + (4,), dtype=np.float32)
        rgba[..., 3] = pattern.coverage
        image_view = add(_png_bytes(rgba), None)
        doc["images"] = [{"name": "pattern", "mimeType": "image/png", "bufferView": image_view}]
        doc["samplers"] = [{"magFilter": LINEAR, "minFilter": LINEAR_MIPMAP_LINEAR,
                            "wrapS": REPEAT, "wrapT": REPEAT}]
        doc["textures"] = [{"sampler": 0, "source": 0}]
        material["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
        material["alphaMode"] = "BLEND"
    doc["accessors"] = accessors
    doc["bufferViews"] = views
    binary = b"".join(blobs)
    doc["buffers"] = [{"byteLength": len(binary)}]
    doc["scenes"] = [{"name": "catalog", "nodes": [0], "extras": {"catalog": {
        "preset": _plain(preset.raw), "light": light, "frame": frame, "room": room,
        "fabric_size_m": [float(v) for v in fabric_size],
        "pattern_repeat_m": [float(v) for v in repeat],
        "uv": "TEXCOORD_0 counts pattern repeats (u across, v down from the rod)"}}}]
    return doc, binary


def glb_bytes(doc: dict, binary: bytes) -> bytes:
    text = _pad(json.dumps(doc, separators=(",", ":")).encode("utf-8"), b" ")
    body = _pad(binary)
    total = 12 + 8 + len(text) + 8 + len(body)
    return (struct.pack("<III", GLB_MAGIC, 2, total) + struct.pack("<II", len(text), CHUNK_JSON)
            + text + struct.pack("<II", len(body), CHUNK_BIN) + body)


def write_glb(preset, out: str | Path, light: str = "D65", frame: int = 0,
              room: str = "box", placement=None) -> dict:
    """Write the curtain as ``out`` (.glb) atomically, hung on the rod of ``placement`` (the
    room's window: catalog.render.placement; None: the box's); a JSON report."""
    from catalog.core.atomic import write_bytes_atomic  # noqa: PLC0415

    doc, binary = gltf_document(preset, light, frame, room, placement)
    data = glb_bytes(doc, binary)
    write_bytes_atomic(out, data, inputs=[preset.path] if preset.path else [])
    accessor = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    return {"out": str(out), "format": "glTF 2.0 binary", "fabric": preset.name, "light": light,
            "frame": frame, "room": room, "vertices": accessor["count"],
            "triangles": doc["accessors"][doc["meshes"][0]["primitives"][0]["indices"]]["count"] // 3,
            "bytes": len(data), "texture": "images" in doc,
            "extensions": doc["extensionsUsed"]}
