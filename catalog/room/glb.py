"""The JSON chunk of a glTF 2.0 binary (.glb), read and written without decoding its buffers.

The loader reads it first to bound the work (triangle counts from the accessors, image
sizes from their headers) before trimesh decodes anything, and to find the optional
``camera`` node (trimesh drops camera nodes from its scene graph). tools/make_rooms.py
writes the camera through :func:`with_camera`. Layout: glTF 2.0 spec, section "GLB File
Format Specification" (12-byte header, then JSON and BIN chunks, 4-byte aligned).
"""

from __future__ import annotations

import json
import math
import struct

import numpy as np

from catalog.core.errors import InputError

GLB_MAGIC = 0x46546C67   # b"glTF"
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942


def split_glb(data: bytes, path) -> tuple[dict, bytes]:
    """(the JSON document, the BIN chunk's bytes) of a .glb; refuses anything else."""
    if len(data) < 20:
        raise InputError("not a glTF binary (shorter than its header)", path=path)
    magic, version, length = struct.unpack_from("<III", data, 0)
    if magic != GLB_MAGIC or version != 2:
        raise InputError("not a glTF 2.0 binary (.glb): bad magic or version", path=path)
    if length > len(data):
        raise InputError(f"truncated: the header says {length} bytes, the file has {len(data)}",
                         path=path)
    offset, doc, binary = 12, None, b""
    while offset + 8 <= length:
        size, kind = struct.unpack_from("<II", data, offset)
        body = data[offset + 8: offset + 8 + size]
        if kind == CHUNK_JSON:
            try:
                doc = json.loads(body.decode("utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError) as exc:
                raise InputError(f"the JSON chunk does not parse ({exc})", path=path) from None
        elif kind == CHUNK_BIN:
            binary = body
        offset += 8 + size + (-size % 4)
    if not isinstance(doc, dict):
        raise InputError("no JSON chunk", path=path)
    return doc, binary


def join_glb(doc: dict, binary: bytes) -> bytes:
    """A .glb from its JSON document and BIN chunk."""
    text = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary = binary + b"\0" * (-len(binary) % 4)
    chunks = struct.pack("<II", len(text), CHUNK_JSON) + text
    if binary:
        chunks += struct.pack("<II", len(binary), CHUNK_BIN) + binary
    return struct.pack("<III", GLB_MAGIC, 2, 12 + len(chunks)) + chunks


def node_local_matrix(node: dict) -> np.ndarray:
    """A node's local 4x4 transform (``matrix``, column-major, or T R S)."""
    if "matrix" in node:
        return np.asarray(node["matrix"], dtype=np.float64).reshape(4, 4).T
    t = np.asarray(node.get("translation", (0, 0, 0)), dtype=np.float64)
    x, y, z, w = (float(v) for v in node.get("rotation", (0, 0, 0, 1)))
    s = np.asarray(node.get("scale", (1, 1, 1)), dtype=np.float64)
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * s[None, :]
    m[:3, 3] = t
    return m


def world_matrices(doc: dict) -> dict[int, np.ndarray]:
    """Node index -> world transform, through the default scene's hierarchy."""
    nodes = doc.get("nodes", [])
    scenes = doc.get("scenes") or [{"nodes": list(range(len(nodes)))}]
    roots = scenes[int(doc.get("scene", 0))].get("nodes", [])
    out: dict[int, np.ndarray] = {}
    stack = [(int(i), np.eye(4)) for i in roots]
    while stack:
        index, parent = stack.pop()
        if index in out or not 0 <= index < len(nodes):
            continue
        world = parent @ node_local_matrix(nodes[index])
        out[index] = world
        stack += [(int(c), world) for c in nodes[index].get("children", [])]
    return out


def triangle_count(doc: dict) -> int:
    """Triangles the file's meshes hold, summed over the nodes that instance them (from the
    accessors' counts: nothing decoded)."""
    accessors = doc.get("accessors", [])
    per_mesh = []
    for mesh in doc.get("meshes", []):
        count = 0
        for primitive in mesh.get("primitives", []):
            if primitive.get("mode", 4) != 4:
                continue
            index = primitive.get("indices", primitive.get("attributes", {}).get("POSITION"))
            if index is not None and 0 <= int(index) < len(accessors):
                count += int(accessors[int(index)].get("count", 0)) // 3
        per_mesh.append(count)
    uses = [int(n["mesh"]) for n in doc.get("nodes", []) if "mesh" in n]
    return sum(per_mesh[m] for m in uses if 0 <= m < len(per_mesh))


def image_sizes(doc: dict, binary: bytes) -> list[tuple[int, int]]:
    """(width, height) of each embedded image, read from its header (PIL opens lazily)."""
    from io import BytesIO  # noqa: PLC0415

    from PIL import Image  # noqa: PLC0415

    views = doc.get("bufferViews", [])
    sizes = []
    for image in doc.get("images", []):
        view = views[int(image["bufferView"])] if "bufferView" in image else None
        if view is None:
            continue
        start = int(view.get("byteOffset", 0))
        with Image.open(BytesIO(binary[start:start + int(view["byteLength"])])) as img:
            sizes.append(img.size)
    return sizes


def camera_of(doc: dict) -> dict | None:
    """The node named ``camera`` with a perspective camera: {position, forward, up, yfov_deg},
    world space (glTF cameras look along their local -Z, +Y up); None when there is none."""
    nodes = doc.get("nodes", [])
    world = world_matrices(doc)
    for index, node in enumerate(nodes):
        if node.get("name") != "camera":
            continue
        cameras = doc.get("cameras", [])
        if "camera" not in node or not 0 <= int(node["camera"]) < len(cameras):
            raise InputError("node 'camera' carries no camera", field="camera")
        camera = cameras[int(node["camera"])]
        if camera.get("type") != "perspective" or "yfov" not in camera.get("perspective", {}):
            raise InputError("node 'camera' is not a perspective camera with a yfov", field="camera")
        m = world.get(index, node_local_matrix(node))
        forward = -m[:3, 2] / np.linalg.norm(m[:3, 2])
        up = m[:3, 1] / np.linalg.norm(m[:3, 1])
        return {"position": m[:3, 3].copy(), "forward": forward, "up": up,
                "yfov_deg": math.degrees(float(camera["perspective"]["yfov"]))}
    return None


def with_camera(data: bytes, position, target, yfov_deg: float) -> bytes:
    """``data`` (a .glb) with a root node named ``camera`` at ``position`` looking at ``target``."""
    doc, binary = split_glb(data, "<memory>")
    eye = np.asarray(position, dtype=np.float64)
    forward = np.asarray(target, dtype=np.float64) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, up, -forward, eye
    doc.setdefault("cameras", []).append({"type": "perspective", "perspective": {
        "yfov": math.radians(yfov_deg), "znear": 0.05, "zfar": 50.0}})
    doc.setdefault("nodes", []).append({"name": "camera", "camera": len(doc["cameras"]) - 1,
                                        "matrix": [float(v) for v in m.T.ravel()]})
    scene = int(doc.get("scene", 0))
    doc.setdefault("scenes", [{"nodes": []}])[scene].setdefault("nodes", []).append(len(doc["nodes"]) - 1)
    return join_glb(doc, binary)
