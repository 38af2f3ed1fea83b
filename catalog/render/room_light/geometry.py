"""The room box: its faces, the light-map atlas, texel points and the ambient occlusion table."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.render import scene as scene_lib


#: Light-map texels per side of each room face.
FACE_TEXELS = 16
#: Faces of the room, in atlas order.
FACE_NAMES = ("floor", "ceiling", "left", "right", "back", "window_wall")
#: Coarse mip level of the direct light map used as the bounce's sources (16 -> 8 per side:
#: 384 patches). Issue 11 went from 4 per side: a patch 1.1 m across gathers as if all its
#: light sat at its centre, so a sunlit strip by the window wall lit that wall as if from
#: half a metre out (the noon room's window wall was 1.5-2x the reference's).
BOUNCE_LEVEL = 1
#: The luminaire capture: patches across and down the window opening, each the mean of
#: 2^LUMINAIRE_LEVEL x 2^LUMINAIRE_LEVEL samples (the capture's mip level), so that a fold
#: moving across a patch changes its radiance smoothly (no shimmer in the room's light; 8 x 8
#: since issue 11's sixth round drew the captures from the whole mesh: 4 x 4 moved a texel of
#: the light map by 5 % a 2 cm step).
LUMINAIRE_TEXELS = (12, 9)
LUMINAIRE_LEVEL = 3
#: Where the luminaire capture looks from (metres): the middle of the room, eye height.
LUMINAIRE_EYE = (0.0, 0.2, 2.0)
#: Two more captures of the room side (issue 11, sixth round), from eyes towards the side walls
#: (metres): the folds' flanks face either way, and the lit ones glow about three times the
#: shadowed under a low UV lamp, so a wall that sees the window obliquely sees mostly one kind;
#: from the room's middle alone the left wall got 0.68x the path tracer's direct light and the
#: right 0.98x. room_lightmap.frag blends the three by the horizontal angle from each window
#: patch to the receiving point (:func:`capture_eye_weights`). Left first.
CAPTURE_SIDE_EYES = ((-1.7, 0.2, 0.8), (1.7, 0.2, 0.8))
#: Their samples per patch side, 2^level (as the middle's: 4 x 4 samples moved a floor texel
#: by 5.1 % a 2 cm step, over the room's stability bound).
SIDE_LUMINAIRE_LEVEL = 3
#: The closed curtain's window side (issue 11): its radiance is captured from outside, from the
#: room eye mirrored through the rod's plane, and sent from patches in that plane
#: (scene.CURTAIN_Z, the drape's mean depth) to what lies behind it: the window wall beside
#: the opening, in the gap between the wall and the cloth.
BACK_LUMINAIRE_EYE = (LUMINAIRE_EYE[0], LUMINAIRE_EYE[1],
                      2.0 * scene_lib.CURTAIN_Z - LUMINAIRE_EYE[2])
#: Its samples per patch side, 2^level: the window wall beside the opening sees the nearest
#: patches from a few centimetres, so a fold sliding through one of 4 x 4 samples changed a
#: texel there by 6 % a 2 cm step; 8 x 8 keeps it under 5 % (the room's stability test).
BACK_LUMINAIRE_LEVEL = 3
#: room_lightmap.frag's beam (the bounces' source): the mean over BEAM_SAMPLES x BEAM_SAMPLES
#: points of a light-map texel (issue 11, sixth round; frame.py passes it to the shader as a define).
BEAM_SAMPLES = 8
#: The transmittance shadow map's side (texels): 1024, about 2.5 mm a texel over the curtain's
#: space. At 256 (1 cm) the folds' shadows on the floor stepped in one-texel stairs (issue 34:
#: the hem's light patches at 1280x720); the room's lookups take the mip level of the sun's
#: penumbra, whose texels a finer map has box-filtered (antialiased) instead of point-sampled.
SHADOW_TEXELS = 1024
#: Ambient occlusion: rays per texel and the distance within which geometry occludes.
AO_RAYS = 96
AO_RADIUS_M = 0.6
#: What the obscurance counts, part of the stored table's key: 1 the room's faces and the
#: occluder boxes (issue 13), 2 the occluder boxes alone (issue 11: the form factors are exact).
AO_METHOD = 2
#: Room lamps: at most this many (uniform arrays in room_lightmap.frag).
MAX_ROOM_LAMPS = 4


@dataclass(frozen=True)
class Face:
    name: str
    origin: np.ndarray
    axis_s: np.ndarray
    axis_t: np.ndarray
    normal: np.ndarray   # into the room

    @property
    def area_m2(self) -> float:
        return float(np.linalg.norm(np.cross(self.axis_s, self.axis_t)))


@functools.lru_cache(maxsize=1)
def room_faces() -> tuple[Face, ...]:
    """The six inside faces of the room box (normals into the room), in FACE_NAMES order."""
    (x0, x1), (y0, y1), (z0, z1) = scene_lib.ROOM_BOX
    a = np.array
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    return (
        Face("floor", a([x0, y0, z0]), a([dx, 0, 0]), a([0, 0, dz]), a([0.0, 1, 0])),
        Face("ceiling", a([x0, y1, z0]), a([dx, 0, 0]), a([0, 0, dz]), a([0.0, -1, 0])),
        Face("left", a([x0, y0, z0]), a([0, 0, dz]), a([0, dy, 0]), a([1.0, 0, 0])),
        Face("right", a([x1, y0, z0]), a([0, 0, dz]), a([0, dy, 0]), a([-1.0, 0, 0])),
        Face("back", a([x0, y0, z1]), a([dx, 0, 0]), a([0, dy, 0]), a([0.0, 0, -1])),
        Face("window_wall", a([x0, y0, z0]), a([dx, 0, 0]), a([0, dy, 0]), a([0.0, 0, 1])),
    )


def face_uniforms() -> dict[str, np.ndarray]:
    """The face table as the shaders' uniform arrays (float32 (6, 3) each)."""
    faces = room_faces()
    return {"u_face_origin": np.array([f.origin for f in faces], dtype="f4"),
            "u_face_s": np.array([f.axis_s for f in faces], dtype="f4"),
            "u_face_t": np.array([f.axis_t for f in faces], dtype="f4"),
            "u_face_normal": np.array([f.normal for f in faces], dtype="f4")}


def atlas_size(face_texels: int = FACE_TEXELS) -> tuple[int, int]:
    return len(FACE_NAMES) * face_texels, face_texels


def texel_points(face_texels: int = FACE_TEXELS) -> tuple[np.ndarray, np.ndarray]:
    """World positions and normals of every atlas texel centre, (R, 6R, 3) each (row = t)."""
    r = face_texels
    centres = (np.arange(r) + 0.5) / r
    s, t = np.meshgrid(centres, centres)  # (R rows = t, R cols = s)
    positions, normals = [], []
    for face in room_faces():
        positions.append(face.origin + s[..., None] * face.axis_s + t[..., None] * face.axis_t)
        normals.append(np.broadcast_to(face.normal, s.shape + (3,)))
    return np.concatenate(positions, axis=1), np.concatenate(normals, axis=1)


def surface_mask(positions: np.ndarray) -> np.ndarray:
    """1 where a texel lies on a wall, 0 inside the window opening (no surface there)."""
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    p = positions
    on_window_wall = np.isclose(p[..., 2], scene_lib.ROOM_BOX[2][0])
    in_opening = (p[..., 0] > wx0) & (p[..., 0] < wx1) & (p[..., 1] > wy0) & (p[..., 1] < wy1)
    return np.where(on_window_wall & in_opening, 0.0, 1.0)


def _occluder_boxes() -> np.ndarray:
    """Axis-aligned boxes (B, 2, 3) that occlude inside the room: the window wall's parts
    around the opening (its reveals) and the rod's bounding box; the room's own faces are
    handled as the box the rays leave."""
    (x0, x1), (y0, y1), (z0, z1) = scene_lib.ROOM_BOX
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    t = 0.1
    rod_y = scene_lib.CURTAIN_TOP_Y + 0.03
    half = (scene_lib.CURTAIN_WIDTH_M + 0.4) / 2
    return np.array([
        [[x0, y0, z0 - t], [wx0, y1, z0]], [[wx1, y0, z0 - t], [x1, y1, z0]],
        [[wx0, y0, z0 - t], [wx1, wy0, z0]], [[wx0, wy1, z0 - t], [wx1, y1, z0]],
        [[-half, rod_y - 0.015, scene_lib.CURTAIN_Z - 0.015],
         [half, rod_y + 0.015, scene_lib.CURTAIN_Z + 0.015]],
    ])


def _cosine_directions(count: int, seed: int = 13) -> np.ndarray:
    """Cosine-distributed unit directions around +z (stratified, fixed seed: reproducible)."""
    rng = np.random.default_rng(seed)
    side = int(math.ceil(math.sqrt(count)))
    i, j = np.meshgrid(np.arange(side), np.arange(side))
    u1 = ((i.ravel() + rng.random(side * side)) / side)[:count]
    u2 = ((j.ravel() + rng.random(side * side)) / side)[:count]
    r, phi = np.sqrt(u1), 2 * math.pi * u2
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)], axis=-1)


def _frame(normal: np.ndarray) -> np.ndarray:
    """(3, 3) rows (tangent, bitangent, normal) for a unit normal."""
    helper = np.array([0.0, 1.0, 0.0]) if abs(normal[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    tangent = np.cross(helper, normal)
    tangent /= np.linalg.norm(tangent)
    return np.stack([tangent, np.cross(normal, tangent), normal])


@functools.lru_cache(maxsize=2)
def ambient_occlusion(face_texels: int = FACE_TEXELS, rays: int = AO_RAYS,
                      radius_m: float = AO_RADIUS_M) -> np.ndarray:
    """Obscurance per atlas texel, (R, 6R) float32 in [0, 1]: the cosine-weighted fraction of
    rays that travel ``radius_m`` without meeting the occluder boxes (the window's reveals and
    the rod). The room's own faces are not occluders: the gather's exact form factors
    (:func:`patch_geometry`) already give each face the light of the faces beside it, and
    counting them again (issue 13's obscurance did) left every edge texel of the room at
    0.3-0.6x the path-traced irradiance (issue 11)."""
    positions, _ = texel_points(face_texels)
    boxes = _occluder_boxes()
    local = _cosine_directions(rays)
    out = np.empty(positions.shape[:2], dtype=np.float32)
    for k, face in enumerate(room_faces()):
        cols = slice(k * face_texels, (k + 1) * face_texels)
        p = positions[:, cols].reshape(-1, 1, 3) + 1e-4 * face.normal
        d = (local @ _frame(face.normal))[None, :, :]  # (1, rays, 3)
        d = np.where(np.abs(d) < 1e-9, 1e-9, d)
        hit = np.full((p.shape[0], rays), np.inf)
        for lo, hi in boxes:
            t_near = np.max(np.minimum((lo - p) / d, (hi - p) / d), axis=-1)
            t_far = np.min(np.maximum((lo - p) / d, (hi - p) / d), axis=-1)
            enters = (t_far >= np.maximum(t_near, 0.0)) & (t_far > 0)
            hit = np.where(enters, np.minimum(hit, np.maximum(t_near, 0.0)), hit)
        free = (hit >= radius_m).mean(axis=-1)
        out[:, cols] = free.reshape(face_texels, face_texels)
    return out


#: The precomputed occlusion (tools/make_room_ao.py writes it; the room is static).
AO_TABLE_PATH = Path(__file__).resolve().parent.parent / "data" / "room_ao.npz"


def ao_table_key(face_texels: int = FACE_TEXELS) -> np.ndarray:
    """What the stored table was computed for: texels, rays, radius, the room's geometry."""
    return np.array([face_texels, AO_RAYS, AO_RADIUS_M, AO_METHOD, *np.ravel(scene_lib.ROOM_BOX),
                     *scene_lib.WINDOW_RECT, scene_lib.CURTAIN_TOP_Y, scene_lib.CURTAIN_Z,
                     scene_lib.CURTAIN_WIDTH_M], dtype=np.float64)


def write_ao_table(path: Path = AO_TABLE_PATH) -> None:
    from catalog.core.atomic import atomic_path  # noqa: PLC0415

    with atomic_path(path, suffix=".npz") as tmp:
        np.savez_compressed(tmp, key=ao_table_key(), ao=ambient_occlusion())


def stored_ambient_occlusion(face_texels: int = FACE_TEXELS) -> np.ndarray:
    """The stored table when it was made for this room and these settings, else computed
    (~1 s of numpy; the table spares the first frame that)."""
    if face_texels == FACE_TEXELS and AO_TABLE_PATH.is_file():
        with np.load(AO_TABLE_PATH, allow_pickle=False) as data:
            if np.array_equal(data["key"], ao_table_key(face_texels)):
                return data["ao"].astype(np.float32)
    return ambient_occlusion(face_texels)


def ao_and_mask_texture(face_texels: int = FACE_TEXELS) -> np.ndarray:
    """(R, 6R, 4) float32: AO, surface mask, 0, 1 (row 0 = t = 0, as GL stores it)."""
    positions, _ = texel_points(face_texels)
    out = np.zeros(positions.shape[:2] + (4,), dtype=np.float32)
    out[..., 0] = stored_ambient_occlusion(face_texels)
    out[..., 1] = surface_mask(positions)
    out[..., 3] = 1.0
    return out
