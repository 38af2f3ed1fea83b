"""Load and check a room (.glb, the room format of docs/formats.md "Rooms").

``--room FILE.glb|NAME``: :func:`room_path` resolves a built-in name (``box``, ``living``,
shipped in catalog/room/data/) or a file; :func:`load_room` bounds the file before
decoding it (size, triangles from the accessors, texture sides from the image headers),
loads it through trimesh, and refuses a room that breaks a rule in one line naming the node
and the rule (:class:`catalog.core.errors.InputError`, exit 2):

- a node named ``window`` with one planar convex quad (two triangles, four corners) whose
  face normal (counter-clockwise winding, glTF's front face) points into the room;
- closed apart from the window: rays cast from inside the room (from the window into the
  room, then from where those land, in all directions) all meet a surface or leave through
  the window (:func:`leak_check`);
- at least one surface; at most MAX_TRIANGLES triangles and MAX_TEXTURE_SIDE texels a side.
"""

from __future__ import annotations

import hashlib
from io import BytesIO
from pathlib import Path

import numpy as np

from catalog.core.errors import InputError
from catalog.room import BUILTIN_ROOMS, glb  # noqa: F401  (BUILTIN_ROOMS: named here too)
from catalog.room.model import Camera, Room, Surface, Window

DATA_DIR = Path(__file__).resolve().parent / "data"
MAX_FILE_BYTES = 64 << 20
MAX_TRIANGLES = 200_000
MAX_TEXTURE_SIDE = 4096
#: Coplanarity of the window's corners, as a fraction of its diagonal.
PLANAR_TOLERANCE = 1e-4
#: Rays of the leak check: from the window into the room, then this many from each landing.
LEAK_SEED_RAYS = 1024
LEAK_RAYS_PER_SEED = 4


def room_path(spec: str | Path) -> Path:
    """The .glb for ``--room``: a built-in name or a file path."""
    text = str(spec)
    if text in BUILTIN_ROOMS:
        return DATA_DIR / f"{text}.glb"
    path = Path(text)
    if path.suffix.lower() != ".glb":
        raise InputError(f"unknown room {text!r}: give a built-in name ({', '.join(BUILTIN_ROOMS)}) "
                         "or a .glb file", field="--room")
    if not path.is_file():
        raise InputError("no such room file", path=path)
    return path


def load_room(spec: str | Path = "box", *, leak_rays: int = LEAK_SEED_RAYS) -> Room:
    """The checked :class:`Room` of ``spec`` (a built-in name or a .glb path)."""
    path = room_path(spec)
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise InputError(f"{size} bytes: a room file holds at most {MAX_FILE_BYTES >> 20} MiB", path=path)
    data = path.read_bytes()
    doc, binary = glb.split_glb(data, path)
    triangles = glb.triangle_count(doc)
    if triangles > MAX_TRIANGLES:
        raise InputError(f"{triangles} triangles: a room holds at most {MAX_TRIANGLES}", path=path)
    for width, height in glb.image_sizes(doc, binary):
        if max(width, height) > MAX_TEXTURE_SIDE:
            raise InputError(f"a {width}x{height} texture: at most {MAX_TEXTURE_SIDE} texels a side",
                             path=path)
    names = [n.get("name") for n in doc.get("nodes", [])]
    if "window" not in names:
        raise InputError("no node named 'window' (the aperture, one quad)", path=path)
    try:
        camera = glb.camera_of(doc)
    except InputError as exc:
        raise InputError(exc.problem, path=path, field="camera") from None
    surfaces, window_triangles = _decoded(data, doc, path)
    if not surfaces:
        raise InputError("no surfaces besides the window", path=path)
    window = window_from(window_triangles, path)
    room = Room(name=path.stem if str(spec) not in BUILTIN_ROOMS else str(spec), source=str(path),
                content_sha256=hashlib.sha256(data).hexdigest(), surfaces=tuple(surfaces),
                window=window,
                camera=None if camera is None else Camera(camera["position"], camera["forward"],
                                                          camera["up"], camera["yfov_deg"]))
    if leak_rays:
        leak_check(room, seeds=leak_rays)
    return room


def _exact_factors(doc: dict) -> dict[str, np.ndarray]:
    """Node name -> its material's baseColorFactor (linear RGB, as written: trimesh rounds
    it to 8 bits), where the node's mesh has one material."""
    materials, meshes = doc.get("materials", []), doc.get("meshes", [])
    out = {}
    for node in doc.get("nodes", []):
        if "mesh" not in node or "name" not in node or not 0 <= int(node["mesh"]) < len(meshes):
            continue
        used = {p.get("material") for p in meshes[int(node["mesh"])].get("primitives", [])}
        if len(used) != 1:
            continue
        index = used.pop()
        factor = (0.5, 0.5, 0.5) if index is None else \
            materials[int(index)].get("pbrMetallicRoughness", {}).get("baseColorFactor", (1, 1, 1, 1))[:3]
        out[node["name"]] = np.asarray(factor, dtype=np.float64)
    return out


def srgb_to_linear(values: np.ndarray) -> np.ndarray:
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


def _decoded(data: bytes, doc: dict, path) -> tuple[list[Surface], np.ndarray | None]:
    import trimesh  # noqa: PLC0415  (imports scipy: only when a room is loaded)

    try:
        scene = trimesh.load(BytesIO(data), file_type="glb", force="scene", process=False)
    except Exception as exc:  # noqa: BLE001  (trimesh raises many kinds on a broken file)
        raise InputError(f"trimesh cannot read it ({type(exc).__name__}: {exc})", path=path) from None
    factors = _exact_factors(doc)
    surfaces, window = [], None
    for node in scene.graph.nodes_geometry:
        matrix, geometry_name = scene.graph[node]
        mesh = scene.geometry[geometry_name]
        if not hasattr(mesh, "faces"):
            continue
        faces = np.asarray(mesh.faces, dtype=np.int64)
        vertices = np.asarray(mesh.vertices, dtype=np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
        if np.linalg.det(matrix[:3, :3]) < 0:      # a mirroring transform flips the winding
            faces = faces[:, ::-1]
        triangles = vertices[faces]
        if not np.all(np.isfinite(triangles)):
            raise InputError(f"node {node!r}: non-finite vertex positions", path=path)
        if node == "window":
            window = triangles
            continue
        material = getattr(mesh.visual, "material", None)
        uv = getattr(mesh.visual, "uv", None)
        factor = factors.get(node)
        texture = None
        if material is not None:
            if factor is None:
                raw = getattr(material, "baseColorFactor", None)
                factor = (np.asarray(raw[:3], dtype=np.float64) / 255.0 if raw is not None
                          else np.ones(3))
            image = getattr(material, "baseColorTexture", None)
            if image is not None and uv is not None:
                texture = srgb_to_linear(np.asarray(image.convert("RGB"), dtype=np.float64) / 255.0)
        if factor is None:
            factor = np.full(3, 0.5)
        uvs = np.asarray(uv, dtype=np.float64)[faces] if texture is not None else None
        surfaces.append(Surface(str(node), triangles, uvs, np.asarray(factor, dtype=np.float64), texture))
    return surfaces, window


def window_from(triangles: np.ndarray | None, path) -> Window:
    """The aperture of the ``window`` node's two triangles (world space), or a refusal."""
    rule = "node 'window': must be one planar quad (two triangles, four corners)"
    if triangles is None or triangles.shape[0] != 2:
        count = 0 if triangles is None else triangles.shape[0]
        raise InputError(f"{rule}; it has {count} triangles", path=path)
    points = triangles.reshape(-1, 3)
    scale = float(np.linalg.norm(points.max(0) - points.min(0)))
    if not scale > 0:
        raise InputError(f"{rule}; it is degenerate", path=path)
    unique = []
    for p in points:
        if not any(np.linalg.norm(p - q) <= 1e-6 * scale for q in unique):
            unique.append(p)
    if len(unique) != 4:
        raise InputError(f"{rule}; its triangles have {len(unique)} distinct corners", path=path)
    n0 = np.cross(triangles[0, 1] - triangles[0, 0], triangles[0, 2] - triangles[0, 0])
    n1 = np.cross(triangles[1, 1] - triangles[1, 0], triangles[1, 2] - triangles[1, 0])
    if np.linalg.norm(n0) <= 1e-12 * scale ** 2 or np.linalg.norm(n1) <= 1e-12 * scale ** 2:
        raise InputError(f"{rule}; a triangle has no area", path=path)
    normal = n0 + n1
    normal /= np.linalg.norm(normal)
    if float(n0 @ n1) <= 0:
        raise InputError("node 'window': its two triangles face opposite ways", path=path)
    unique = np.array(unique)
    offset = (unique - unique.mean(0)) @ normal
    if np.max(np.abs(offset)) > PLANAR_TOLERANCE * scale:
        raise InputError(f"node 'window': not planar (a corner {np.max(np.abs(offset)):.3g} m off "
                         "its plane); it must be one planar quad", path=path)
    # order the corners around the centre, counter-clockwise seen from the room (along -normal)
    u = unique[1] - unique[0]
    u -= (u @ normal) * normal
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    rel = unique - unique.mean(0)
    order = np.argsort(np.arctan2(rel @ v, rel @ u))
    corners = unique[order]
    edges = np.roll(corners, -1, axis=0) - corners
    turns = np.cross(edges, np.roll(edges, -1, axis=0)) @ normal
    if not np.all(turns > 0):
        raise InputError("node 'window': not a convex quad; it must be one planar quad", path=path)
    # the shared diagonal must be one of the quad's diagonals (two triangles covering it)
    area = 0.5 * (np.linalg.norm(n0) + np.linalg.norm(n1))
    quad_area = 0.5 * abs(float(np.cross(corners[2] - corners[0], corners[3] - corners[1]) @ normal))
    if abs(area - quad_area) > 1e-6 * quad_area:
        raise InputError(f"{rule}; its triangles overlap instead of tiling it", path=path)
    return Window(corners=corners, normal=normal)


def _hemisphere(normal: np.ndarray, count: int, rng) -> np.ndarray:
    d = rng.normal(size=(count, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.where((d @ normal)[:, None] < 0, -d, d)


def leak_check(room: Room, seeds: int = LEAK_SEED_RAYS, seed: int = 0) -> None:
    """Refuse a room that is not closed apart from its window, or whose window faces out.

    From points on the window (just inside it) rays go into the room; each must meet a
    surface (else the window's normal points out of the room, or the room is open). From
    each landing point (just before it), LEAK_RAYS_PER_SEED rays go in all directions; each
    must meet a surface or leave through the window. A ray that does neither is a leak."""
    from catalog.room.rays import NumpyRays, ray_caster  # noqa: PLC0415

    rng = np.random.default_rng(seed)
    triangles = room.triangles()
    work = triangles.shape[0] * seeds * (1 + LEAK_RAYS_PER_SEED)
    rays = NumpyRays(triangles) if work < 4e7 else ray_caster(triangles)
    w = room.window
    size = float(np.linalg.norm(np.ptp(room.bounds(), axis=0)))
    eps = 1e-4 * size
    s, t = rng.random((2, seeds))
    origins = w.origin + s[:, None] * w.u_edge + t[:, None] * w.v_edge
    inside = origins[_in_quad(w, origins)] + eps * w.normal
    directions = _hemisphere(w.normal, inside.shape[0], rng)
    dist, _ = rays.intersect(inside, directions)
    escaped = ~np.isfinite(dist)
    if escaped.mean() > 0.5:
        raise InputError("node 'window': its normal must point into the room (rays along it "
                         f"from the window meet nothing in {escaped.mean():.0%} of cases)",
                         path=room.source)
    if escaped.any():
        d = directions[escaped][0]
        raise InputError(f"the room leaks: {int(escaped.sum())} of {escaped.size} rays from the window "
                         f"into the room meet no surface (e.g. towards {np.round(d, 3).tolist()}); "
                         "apart from the window it must be closed", path=room.source)
    landing = inside + (dist - eps)[:, None] * directions
    origins = np.repeat(landing, LEAK_RAYS_PER_SEED, axis=0)
    d = rng.normal(size=origins.shape)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    dist, _ = rays.intersect(origins, d)
    open_ = ~np.isfinite(dist)
    if open_.any():
        through = np.isfinite(NumpyRays(_grown(w)).intersect(origins[open_], d[open_])[0])
        leaks = np.flatnonzero(open_)[~through]
        if leaks.size:
            i = leaks[0]
            raise InputError(f"the room leaks: {leaks.size} of {d.shape[0]} rays from inside leave it "
                             f"away from the window (e.g. from {np.round(origins[i], 3).tolist()} towards "
                             f"{np.round(d[i], 3).tolist()}); apart from the window it must be closed",
                             path=room.source)


def _in_quad(w: Window, points: np.ndarray) -> np.ndarray:
    """Which points (on the window's plane) lie inside the convex quad."""
    inside = np.ones(points.shape[0], dtype=bool)
    for i in range(4):
        a, b = w.corners[i], w.corners[(i + 1) % 4]
        inside &= (np.cross(b - a, points - a) @ w.normal) >= 0
    return inside


def _grown(w: Window, by: float = 1e-5) -> np.ndarray:
    """The window's triangles grown by ``by`` of its size (rounding at its edges)."""
    c = w.centre + (w.corners - w.centre) * (1 + by)
    return np.array([[c[0], c[1], c[2]], [c[0], c[2], c[3]]])
