"""The room lit through the curtain (issue 13, model.md section 9): the static room's geometry
as a light-map atlas, its precomputed ambient occlusion, the light-space frame of the key
light's transmittance shadow map and the window's luminaire grid. No GL here: numpy arrays
and matrices the renderer (:mod:`catalog.render.frame`) uploads.

The room is the box ``scene.ROOM_BOX`` with the window opening ``scene.WINDOW_RECT`` in its
wall z = WINDOW_Z. Its six inside faces are parametrised as
``P(s, t) = origin + s * axis_s + t * axis_t`` (s, t in [0, 1]); the light-map atlas holds
them side by side, FACE_TEXELS x FACE_TEXELS each (face k at columns k R .. (k + 1) R - 1).
Irradiance (linear sRGB, the renderer's cd m^-2 scale times pi) is stored per texel:

- direct: the curtain (and the sky through the window) as an area light, one patch per
  texel of the luminaire capture (:data:`LUMINAIRE_TEXELS`), ``E = sum L cos_p cos_r A / r^2``;
  the key light's beam through the window and the curtain (the transmittance shadow map);
  lamps placed in the room (isotropic points, ``E = I cos_r / r^2``);
- bounces, all of them: the coarse patches' total irradiance ``T = (I - K)^-1 S`` (the radiosity
  solve of model.md section 9, :func:`radiosity_operator`: S the direct light of each coarse patch, K
  the patch-to-patch transfer below, precomputed once as the matrix ``(I - K)^-1 - I``),
  then per texel ``E(x) = E_direct(x) + ao(x) / pi sum_j rho_j T_j F_j(x)`` (F_j pi times the
  exact form factor of patch j, :func:`rectangle_irradiance_factor`)
  over the coarse patches (rho_j the wall's albedo, or in the window opening the closed
  curtain's room-side reflectance: the cloth sends part of the room's light back) (the room is a convex box: every patch sees every other), with
  the ambient occlusion below. One bounce alone (issue 13's frame) left the walls 30 % and
  the floor 45 % darker than the path-traced reference (issue 11): with walls of albedo 0.6
  the bounces after the first double the first.

Ambient occlusion (precomputed once, the room is static): the cosine-weighted fraction of
the hemisphere over a texel that is free of the window's reveals and the rod within
AO_RADIUS_M (obscurance), by ray casting against their boxes in numpy. The room's faces are
not occluders: the bounce's form factors are exact (Lambert's polygon formula,
:func:`rectangle_irradiance_factor`), so a corner gets the light of the faces that meet there.
"""

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
#: ``room_bounce.frag``'s bounces: "all" (the radiosity solve) or "one" (issue 13's first).
ROOM_BOUNCES = ("all", "one")
#: The transmittance shadow map's side (texels).
SHADOW_TEXELS = 256
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
AO_TABLE_PATH = Path(__file__).resolve().parent / "data" / "room_ao.npz"


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


# --------------------------------------------------------------------------- the bounces

def coarse_patches(face_texels: int = FACE_TEXELS, level: int = BOUNCE_LEVEL) -> dict[str, np.ndarray]:
    """The bounce's coarse patches, in the order of their atlas texels (face f, row v,
    column u: index (f R + v) R + u, texel (f R + u, v) at mip ``level``): centre, normal,
    area (m^2), face, and the ambient occlusion and wall fraction averaged over each patch as
    the mip chain averages them (GL's box filter over 2^level x 2^level texels)."""
    rc = face_texels >> level
    block = face_texels // rc
    table = ao_and_mask_texture(face_texels)   # (R, 6R, 4), row = t

    def coarse(channel):
        values = table[..., channel].astype(np.float64)
        return values.reshape(rc, block, len(FACE_NAMES) * rc, block).mean(axis=(1, 3))

    ao, wall = coarse(0), coarse(1)
    centres, normals, areas, faces, ao_p, wall_p = [], [], [], [], [], []
    corners, edge_s, edge_t = [], [], []
    for f, face in enumerate(room_faces()):
        for v in range(rc):
            for u in range(rc):
                centres.append(face.origin + (u + 0.5) / rc * face.axis_s + (v + 0.5) / rc * face.axis_t)
                corners.append(face.origin + u / rc * face.axis_s + v / rc * face.axis_t)
                edge_s.append(face.axis_s / rc)
                edge_t.append(face.axis_t / rc)
                normals.append(face.normal)
                areas.append(face.area_m2 / rc ** 2)
                faces.append(f)
                ao_p.append(ao[v, f * rc + u])
                wall_p.append(wall[v, f * rc + u])
    return {"centre": np.array(centres), "normal": np.array(normals), "area": np.array(areas),
            "face": np.array(faces), "ao": np.array(ao_p), "wall": np.array(wall_p),
            "corner": np.array(corners), "s": np.array(edge_s), "t": np.array(edge_t)}


def rectangle_irradiance_factor(points: np.ndarray, normals: np.ndarray, corners: np.ndarray,
                                s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """pi times the form factor from points x (P, 3) with normals (P, 3) to rectangles
    ``corner + [0,1] s + [0,1] t`` (N, 3 each), (P, N) float64: Lambert's polygon formula, half
    the sum over the edges of the angle each subtends at x times the cosine between x's normal
    and the normal of the plane through x and the edge. A uniformly emitting rectangle of
    radiance L gives E(x) = L * factor, exactly. The float64 twin of common.glsl's
    ``rectangle_irradiance_factor``; the rectangle must lie on the normal's side of x's plane."""
    points = np.asarray(points, dtype=np.float64)[:, None, :]
    normals = np.asarray(normals, dtype=np.float64)
    vertices = [corners, corners + s, corners + s + t, corners + t]
    unit = []
    for vertex in vertices:
        v = np.asarray(vertex, dtype=np.float64)[None, :, :] - points
        unit.append(v / np.linalg.norm(v, axis=-1, keepdims=True))
    total = np.zeros(unit[0].shape[:2])
    for k in range(4):
        a, b = unit[k], unit[(k + 1) % 4]
        c = np.cross(a, b)
        sine = np.linalg.norm(c, axis=-1)
        angle = np.arctan2(sine, np.einsum("pjk,pjk->pj", a, b))
        cosine = np.einsum("pjk,pk->pj", c, normals) / np.maximum(sine, 1e-300)
        total += np.where(sine > 1e-9, angle * cosine, 0.0)
    return 0.5 * np.abs(total)


def patch_geometry(points: np.ndarray, normals: np.ndarray, point_faces: np.ndarray,
                   patches: dict) -> np.ndarray:
    """(P, N) pi times the form factor from points x (on faces ``point_faces``) to the coarse
    patches j (:func:`rectangle_irradiance_factor`: exact for a uniform patch, however near),
    0 on the point's own face (room_bounce.frag's geometry term). The point form of the
    patch's centre, cos_x cos_j A_j / max(r^2, A_j), which the frame used before, lost most of
    a patch's light near it: the wall's strip beside a sunlit floor was 3-5x too dark."""
    geometry = rectangle_irradiance_factor(points, normals, patches["corner"], patches["s"], patches["t"])
    geometry[point_faces[:, None] == patches["face"][None, :]] = 0.0
    return geometry


def patch_reflectance(albedo: float, window_albedo: float, wall: np.ndarray) -> np.ndarray:
    """Reflectance of patches whose wall fraction is ``wall``: the wall's ``albedo`` where it
    is wall, the closed curtain's room-side reflectance ``window_albedo`` in the opening
    (0 when it is open: the light leaves)."""
    return albedo * wall + window_albedo * (1.0 - wall)


@functools.lru_cache(maxsize=2)
def _patch_transfer(face_texels: int, level: int) -> tuple[np.ndarray, np.ndarray]:
    """ao_i / pi G_ij and the patches' wall fractions (the room's part of K, made once)."""
    patches = coarse_patches(face_texels, level)
    geometry = patch_geometry(patches["centre"], patches["normal"], patches["face"], patches)
    return patches["ao"][:, None] / math.pi * geometry, patches["wall"]


@functools.lru_cache(maxsize=16)
def radiosity_operator(albedo: float, window_albedo: float = 0.0, face_texels: int = FACE_TEXELS,
                       level: int = BOUNCE_LEVEL) -> np.ndarray:
    """(N, N) float64: the bounces the coarse patches add to their direct light,
    ``(I - K)^-1 - I`` with ``K_ij = ao_i / pi G_ij rho_j`` (the patch-to-patch form of
    room_bounce.frag's gather, a radiosity system as model.md section 9 names it; G from
    :func:`patch_geometry`, rho_j from :func:`patch_reflectance`: the wall's albedo, the closed
    curtain's reflectance in the window opening). T = S + op @ S is every patch's total
    irradiance. One colour channel: call it per channel when the curtain is dyed."""
    geometry, wall = _patch_transfer(face_texels, level)
    transfer = geometry * patch_reflectance(albedo, window_albedo, wall)[None, :]
    count = transfer.shape[0]
    return np.linalg.inv(np.eye(count) - transfer) - np.eye(count)


def radiosity_operator_rgb(albedo: float, window_albedo_rgb) -> np.ndarray:
    """(N, N, 3) float32: :func:`radiosity_operator` per colour channel (the window's
    reflectance rounded to 1e-4, so that a cache serves a fabric under a light)."""
    return np.stack([radiosity_operator(albedo, round(float(w), 4)) for w in window_albedo_rgb],
                    axis=-1).astype(np.float32)


#: The curtain's room side (issue 11, fourth round): the room's irradiance on it is gathered at
#: this many points across and down the window opening, in the window wall's plane (every
#: other face lies wholly in front of that plane, as Lambert's formula needs; the closed
#: curtain hangs 12 cm in front of it), and read bilinearly per vertex (curtain.vert
#: ROOM_SIDE). The room's light varies over metres: 12 x 12 points are 16 x 19 cm apart.
CURTAIN_SIDE_TEXELS = (12, 12)


def curtain_side_rect() -> tuple[float, float, float, float]:
    """The room-side grid's extent (x from, y from, width, height; metres): the opening."""
    x0, x1, y0, y1 = scene_lib.WINDOW_RECT
    return (x0, y0, x1 - x0, y1 - y0)


def curtain_side_points(texels: tuple[int, int] = CURTAIN_SIDE_TEXELS) -> np.ndarray:
    """(H, W, 3) the grid's points (texel centres, row 0 = the opening's bottom), in the window
    wall's plane."""
    x0, y0, w, h = curtain_side_rect()
    tw, th = texels
    xs = x0 + (np.arange(tw) + 0.5) / tw * w
    ys = y0 + (np.arange(th) + 0.5) / th * h
    gx, gy = np.meshgrid(xs, ys)
    return np.stack([gx, gy, np.full_like(gx, scene_lib.ROOM_BOX[2][0])], axis=-1)


def curtain_side_irradiance(total_rgb: np.ndarray, albedo: float, window_albedo_rgb,
                            texels: tuple[int, int] = CURTAIN_SIDE_TEXELS) -> np.ndarray:
    """The float64 twin of room_bounce.frag's CURTAIN_SIDE gather, (H, W, 3): at each grid point
    (facing the room), E = sum_j (rho_j / pi) T_j G_j over the coarse patches of every face but
    the window wall, with ``total_rgb`` (RC, 6 RC, 3) the patches' total irradiance (the
    radiosity pass's texture, row = v) and G_j from :func:`rectangle_irradiance_factor`."""
    patches = coarse_patches()
    rc = FACE_TEXELS >> BOUNCE_LEVEL
    total = np.asarray(total_rgb, dtype=np.float64)
    # patch (f, v, u), index (f rc + v) rc + u, is atlas texel (f rc + u, v)
    t_patch = total.reshape(rc, len(FACE_NAMES), rc, 3).transpose(1, 0, 2, 3).reshape(-1, 3)
    keep = patches["face"] != FACE_NAMES.index("window_wall")
    points = curtain_side_points(texels).reshape(-1, 3)
    normals = np.broadcast_to(np.array([0.0, 0.0, 1.0]), points.shape)
    geometry = rectangle_irradiance_factor(points, normals, patches["corner"][keep],
                                           patches["s"][keep], patches["t"][keep])
    out = np.zeros((points.shape[0], 3))
    for c in range(3):
        rho = patch_reflectance(albedo, float(np.asarray(window_albedo_rgb)[c]), patches["wall"][keep])
        out[:, c] = geometry @ (rho * t_patch[keep, c]) / math.pi
    return out.reshape(texels[1], texels[0], 3)


def sample_bilinear(texture: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """GL's LINEAR filter with clamp to edge: ``texture`` (H, W, C) read at ``uv`` (P, 2) in
    [0, 1] (texel centres at (i + 0.5) / W), float64 (P, C)."""
    tex = np.asarray(texture, dtype=np.float64)
    h, w = tex.shape[:2]
    uv = np.asarray(uv, dtype=np.float64)
    x = np.clip(uv[:, 0] * w - 0.5, 0.0, w - 1.0)
    y = np.clip(uv[:, 1] * h - 0.5, 0.0, h - 1.0)
    x0 = np.minimum(np.floor(x).astype(int), w - 2) if w > 1 else np.zeros(len(x), int)
    y0 = np.minimum(np.floor(y).astype(int), h - 2) if h > 1 else np.zeros(len(y), int)
    fx = (x - x0)[:, None]
    fy = (y - y0)[:, None]
    x1 = np.minimum(x0 + 1, w - 1)
    y1 = np.minimum(y0 + 1, h - 1)
    return ((1 - fy) * ((1 - fx) * tex[y0, x0] + fx * tex[y0, x1])
            + fy * ((1 - fx) * tex[y1, x0] + fx * tex[y1, x1]))


def curtain_side_uv(positions: np.ndarray) -> np.ndarray:
    """(P, 2) where fragments at ``positions`` (P, 3) read the room-side grid: their x, y over
    the opening (curtain.frag ROOM_SIDE; outside it, clamped to the edge)."""
    x0, y0, w, h = curtain_side_rect()
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    return np.stack([(p[:, 0] - x0) / w, (p[:, 1] - y0) / h], axis=-1)


# --------------------------------------------------------------------------- the key's shadow map

def light_view_projection(to_light: np.ndarray, margin_m: float = 0.05) -> np.ndarray:
    """Orthographic view-projection looking along the key light's travel (-to_light), framing
    the window opening and the curtain's space in front of it (what can cast a shadow)."""
    to_light = np.asarray(to_light, dtype=np.float64)
    to_light = to_light / np.linalg.norm(to_light)
    forward = -to_light
    helper = np.array([0.0, 1.0, 0.0]) if abs(forward[1]) < 0.95 else np.array([1.0, 0.0, 0.0])
    right = np.cross(forward, helper)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    z0 = scene_lib.ROOM_BOX[2][0]
    half_w = scene_lib.CURTAIN_WIDTH_M / 2 + 0.15
    corners = np.array([[x, y, z] for x in (min(wx0, -half_w), max(wx1, half_w))
                        for y in (wy0, max(wy1, scene_lib.CURTAIN_TOP_Y + 0.1))
                        for z in (z0 - 0.1, scene_lib.CURTAIN_Z + 0.35)])
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, up, -forward
    local = corners @ view[:3, :3].T
    lo, hi = local.min(axis=0) - margin_m, local.max(axis=0) + margin_m
    proj = np.eye(4)
    proj[0, 0], proj[0, 3] = 2 / (hi[0] - lo[0]), -(hi[0] + lo[0]) / (hi[0] - lo[0])
    proj[1, 1], proj[1, 3] = 2 / (hi[1] - lo[1]), -(hi[1] + lo[1]) / (hi[1] - lo[1])
    # view space looks down -z: depth from -hi.z (near) to -lo.z (far)
    near, far = -hi[2], -lo[2]
    proj[2, 2], proj[2, 3] = -2 / (far - near), -(far + near) / (far - near)
    return proj @ view


#: The cloth's own occlusion of the outside (issue 11, curtain.frag SKY_OCCLUSION): directions,
#: one front-layer depth map each (tiles of OCCLUSION_TEXELS, a square grid).
OCCLUSION_DIRECTIONS = 16
OCCLUSION_TEXELS = 128


@functools.lru_cache(maxsize=4)
def occlusion_directions(count: int = OCCLUSION_DIRECTIONS) -> np.ndarray:
    """(count, 3) unit directions towards the outside (-z), cosine-weighted about -z: the
    strata u = (j + 1/2) / count of a Fibonacci spiral, sin(theta) = sqrt(u), phi = j times
    the golden angle (their mean visibility estimates the cosine-weighted visible fraction)."""
    j = np.arange(count)
    u = (j + 0.5) / count
    r = np.sqrt(u)
    phi = j * math.pi * (3.0 - math.sqrt(5.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), -np.sqrt(1.0 - u)], -1)


def shadow_texel_m(to_light: np.ndarray, texels: int = SHADOW_TEXELS) -> float:
    """World size (m) of one texel of a ``texels``-wide shadow map (the larger of the two axes)."""
    m = light_view_projection(to_light)
    return float(2.0 / min(m[0, :3] @ m[0, :3], m[1, :3] @ m[1, :3]) ** 0.5 / texels)


# --------------------------------------------------------------------------- the luminaire capture

def window_view_projection(eye, plane_z: float, near: float = 0.05, far: float = 60.0) -> np.ndarray:
    """Off-axis perspective from ``eye`` whose frustum is exactly the window opening's
    rectangle in the plane z = ``plane_z``, looking towards that plane from either side: texel
    (i, j) of a capture is the radiance of window patch (i, j) towards the eye, i counting
    along +x and j along +y whichever side the eye is on (the clip space is written out, not
    a camera's view matrix, which would mirror x for an eye looking along +z)."""
    ex, ey, ez = (float(v) for v in eye)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    sign = 1.0 if ez < plane_z else -1.0         # the view axis: +z or -z
    to_plane = sign * (plane_z - ez)             # > 0
    if to_plane <= near:
        raise ValueError(f"eye {eye} is within {near} m of the plane z = {plane_z}")
    # w = sign (z - ez): the distance along the view axis
    w_row = np.array([0.0, 0.0, sign, -sign * ez])

    def lateral(axis, e, lo, hi):
        # clip = w ndc, ndc = 2 (crossing - lo) / (hi - lo) - 1, crossing = e + (q - e) D / w
        row = np.zeros(4)
        row[axis] = 2.0 * to_plane / (hi - lo)
        row[3] = -2.0 * to_plane * e / (hi - lo)
        return row + (2.0 * (e - lo) / (hi - lo) - 1.0) * w_row

    a, b = (far + near) / (far - near), -2.0 * far * near / (far - near)
    z_row = a * w_row + np.array([0.0, 0.0, 0.0, b])
    return np.stack([lateral(0, ex, wx0, wx1), lateral(1, ey, wy0, wy1), z_row, w_row])


#: The front of the box the room sees the closed curtain through (m): the drape's folds reach
#: from the window wall (z = WINDOW_Z) to about this far into the room; the room side's patches
#: lie in this plane and the box's sides join it to the opening's edges (issue 11, ninth round).
WINDOW_FRONT_Z = 0.02

#: room.frag takes the window's direct light on the window wall within this distance of the
#: opening (m; about two light-map texels), where it falls tenfold within one texel, from a
#: finer grid (room_window_near.frag) of this many texels a side.
WINDOW_NEAR_M = 0.6
WINDOW_NEAR_TEXELS = 64
#: ... fading into the light map over this much before WINDOW_NEAR_M (m): no seam there.
WINDOW_NEAR_FADE_M = 0.15


def window_near_rect() -> tuple[float, float, float, float]:
    """The window wall's rectangle round the opening that room_window_near.frag covers (x0, x1,
    y0, y1, m): the opening widened by WINDOW_NEAR_M, within the room's walls."""
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    (bx0, bx1), (by0, by1), _ = scene_lib.ROOM_BOX
    return (max(wx0 - WINDOW_NEAR_M, bx0), min(wx1 + WINDOW_NEAR_M, bx1),
            max(wy0 - WINDOW_NEAR_M, by0), min(wy1 + WINDOW_NEAR_M, by1))


def window_near_points(texels: int = WINDOW_NEAR_TEXELS) -> np.ndarray:
    """(texels, texels, 3): room_window_near.frag's points (row 0 = the rectangle's bottom):
    the texels' centres on the window wall, those inside the opening moved onto its nearest
    edge, 1 mm out on the wall."""
    x0, x1, y0, y1 = window_near_rect()
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    f = (np.arange(texels) + 0.5) / texels
    y, x = np.meshgrid(y0 + f * (y1 - y0), x0 + f * (x1 - x0), indexing="ij")
    q = np.stack([x, y], axis=-1).reshape(-1, 2)
    inside = np.minimum(q - [wx0, wy0], [wx1, wy1] - q)
    moved = inside.min(axis=1) > -1e-3
    along_x = moved & (inside[:, 0] < inside[:, 1])
    along_y = moved & ~along_x
    q[along_x, 0] = np.where(q[along_x, 0] - wx0 < wx1 - q[along_x, 0], wx0 - 1e-3, wx1 + 1e-3)
    q[along_y, 1] = np.where(q[along_y, 1] - wy0 < wy1 - q[along_y, 1], wy0 - 1e-3, wy1 + 1e-3)
    z = np.full((q.shape[0], 1), scene_lib.ROOM_BOX[2][0])
    return np.hstack([q, z]).reshape(texels, texels, 3)


#: Eyes by the window wall that capture the box's sides as the wall beside the opening sees
#: them (left, right; m): from behind the curtain's plane most ways through a side pass in
#: front of the folds into the room, and the side eyes' radiance, seen from the room, lit that
#: strip of wall 2-2.4x the path tracer's (issue 11, ninth round).
WALL_EYES = ((-1.5, 0.2, -0.15), (1.5, 0.2, -0.15))
#: The wall eyes' captures: a box side's 9 patch rows (one column) supersampled by 2^level.
WALL_EYE_LEVEL = 3


def wall_eye_capture_size() -> tuple[int, int]:
    """A wall eye's capture size: one column of the 9 patch rows supersampled by
    2^WALL_EYE_LEVEL."""
    return 1 << WALL_EYE_LEVEL, LUMINAIRE_TEXELS[1] << WALL_EYE_LEVEL


def rectangle_view_projection(eye, corner, s, t, near: float = 0.05, far: float = 60.0) -> np.ndarray:
    """Off-axis perspective from ``eye`` whose frustum is exactly the rectangle
    ``corner + [0,1] s + [0,1] t``: normalised device x runs along s and y along t, -1 to 1
    across it (a capture's texel (i, j) is the radiance of the rectangle's cell (i, j) towards
    the eye); the view axis is the rectangle's normal, away from the eye."""
    e, c = np.asarray(eye, dtype=np.float64), np.asarray(corner, dtype=np.float64)
    s, t = np.asarray(s, dtype=np.float64), np.asarray(t, dtype=np.float64)
    axis = np.cross(s, t)
    axis /= np.linalg.norm(axis)
    if (c - e) @ axis < 0.0:
        axis = -axis
    to_plane = float((c - e) @ axis)
    if to_plane <= near:
        raise ValueError(f"eye {tuple(e)} is within {near} m of the rectangle's plane")
    w_row = np.append(axis, -axis @ e)   # the distance along the view axis

    def lateral(edge):   # clip = w ndc, ndc = 2 (crossing - corner).edge / |edge|^2 - 1
        n2 = edge @ edge
        return (2.0 * ((e - c) @ edge) / n2 - 1.0) * w_row + (2.0 * to_plane / n2) * np.append(edge, -edge @ e)

    a, b = (far + near) / (far - near), -2.0 * far * near / (far - near)
    return np.stack([lateral(s), lateral(t), a * w_row + np.array([0.0, 0.0, 0.0, b]), w_row])


def wall_eye_view_projection(right: bool, front_z: float = None) -> np.ndarray:
    """The capture of the box's left (or right) side from its wall eye (:data:`WALL_EYES`):
    the side's rectangle (x = the opening's edge, y over the opening, z from the curtain's
    plane to the box's front ``front_z``), x along +z, y along +y."""
    front_z = WINDOW_FRONT_Z if front_z is None else front_z
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    corner = (wx1 if right else wx0, wy0, scene_lib.CURTAIN_Z)
    return rectangle_view_projection(WALL_EYES[1 if right else 0], corner, (0.0, 0.0, front_z - scene_lib.CURTAIN_Z),
                                     (0.0, wy1 - wy0, 0.0))


def luminaire_view_projection(eye=LUMINAIRE_EYE, plane_z: float | None = None) -> np.ndarray:
    """The room side's capture: the opening's rectangle in the plane ``plane_z`` (default the
    box's front, :data:`WINDOW_FRONT_Z`) seen from ``eye`` in the room, texel (i, j) the
    radiance of window patch (i, j) towards the room."""
    return window_view_projection(eye, WINDOW_FRONT_Z if plane_z is None else plane_z)


def back_luminaire_view_projection(eye=BACK_LUMINAIRE_EYE) -> np.ndarray:
    """The curtain's window side, captured from outside through the rod's plane
    (scene.CURTAIN_Z): texel (i, j) the radiance that patch (i, j) of that plane sends back
    towards the window wall."""
    return window_view_projection(eye, scene_lib.CURTAIN_Z)


def capture_eye_weights(points: np.ndarray, centres: np.ndarray,
                        side_eyes=CAPTURE_SIDE_EYES, middle_eye=LUMINAIRE_EYE) -> np.ndarray:
    """(P, N, 3): the weights of the left, middle and right captures for the radiance that
    window patch n (centre ``centres[n]``, in the opening) sends to point p: piecewise linear
    in the horizontal angle atan2(dx, dz) of the way from the patch to the point, between the
    angles at which the patch sees the three eyes, clamped beyond the side eyes (the float64
    twin of room_lightmap.frag's ``captured_towards``)."""
    points = np.asarray(points, dtype=np.float64)
    centres = np.asarray(centres, dtype=np.float64)

    def angle(at):   # of the way from every patch's centre to ``at`` ((3,) or (P, 1, 3))
        d = np.asarray(at, dtype=np.float64) - centres
        return np.arctan2(d[..., 0], np.maximum(d[..., 2], 1e-6))

    a = angle(points[:, None, :])
    a_left, a_mid, a_right = angle(side_eyes[0]), angle(middle_eye), angle(side_eyes[1])
    to_left = np.clip((a_mid - a) / (a_mid - a_left), 0.0, 1.0)
    to_right = np.clip((a - a_mid) / (a_right - a_mid), 0.0, 1.0)
    left = np.where(a <= a_mid, to_left, 0.0)
    right = np.where(a > a_mid, to_right, 0.0)
    return np.stack([left, 1.0 - left - right, right], axis=-1)


def luminaire_capture_size(level: int = LUMINAIRE_LEVEL) -> tuple[int, int]:
    """A capture's render size: LUMINAIRE_TEXELS supersampled by 2^level."""
    return LUMINAIRE_TEXELS[0] << level, LUMINAIRE_TEXELS[1] << level


#: room_lightmap.frag averages the window's light over 2 x 2 points of a texel within this
#: distance of the window's plane (m), its centre alone further away.
WINDOW_SUPERSAMPLE_M = 1.0


def window_patch_rectangles(plane_z: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The luminaire's patches in the plane z = ``plane_z``, in capture order (row j, column
    i: index j * 12 + i): corners (N, 3) and edges s, t (N, 3 each)."""
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    nx, ny = LUMINAIRE_TEXELS
    cx, cy = (wx1 - wx0) / nx, (wy1 - wy0) / ny
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    corners = np.stack([wx0 + i.ravel() * cx, wy0 + j.ravel() * cy,
                        np.full(i.size, float(plane_z))], axis=-1)
    s = np.broadcast_to([cx, 0.0, 0.0], corners.shape)
    t = np.broadcast_to([0.0, cy, 0.0], corners.shape)
    return corners, np.array(s), np.array(t)


def _smoothstep(edge0, edge1, x):
    t = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def window_beam_mask(points: np.ndarray, to_light, tan_radius: float = math.tan(scene_lib.SUN_RADIUS_RAD)) -> np.ndarray:
    """The float64 twin of common.glsl's ``room_window_beam``: the fraction of the key's beam
    that reaches ``points`` (P, 3) through the opening (its inner and outer planes, edges
    softened by the light's angular radius x the distance to each plane)."""
    p = np.asarray(points, dtype=np.float64)
    to_light = np.asarray(to_light, dtype=np.float64)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    z_in = scene_lib.ROOM_BOX[2][0]
    z_out = z_in - scene_lib.WALL_THICKNESS_M

    def soft_rect(q, half):
        lo_x = _smoothstep(wx0 - half, wx0 + half, q[:, 0])
        lo_y = _smoothstep(wy0 - half, wy0 + half, q[:, 1])
        hi_x = 1.0 - _smoothstep(wx1 - half, wx1 + half, q[:, 0])
        hi_y = 1.0 - _smoothstep(wy1 - half, wy1 + half, q[:, 1])
        return lo_x * lo_y * hi_x * hi_y

    s_in = (z_in - p[:, 2]) / to_light[2]
    s_out = (z_out - p[:, 2]) / to_light[2]
    q_in = p[:, :2] + s_in[:, None] * to_light[:2]
    q_out = p[:, :2] + s_out[:, None] * to_light[:2]
    inner = np.where(s_in > 0.0, soft_rect(q_in, s_in * tan_radius + 1e-3), 1.0)
    return (s_out >= 0.0) * inner * soft_rect(q_out, s_out * tan_radius + 1e-3)


def _key_lobe(points: np.ndarray, centres: np.ndarray, alpha: np.ndarray, lobe: dict | None) -> np.ndarray:
    """(P, N, 3): common.glsl ``key_lobe`` from rectangles centred at ``centres`` (N, 3) whose
    cloth the key reaches by ``alpha`` (N,) towards ``points`` (P, 3); 0 without ``lobe``
    (keywords lobe_rgb, g_spec, to_light)."""
    if lobe is None:
        return np.zeros((points.shape[0], centres.shape[0], 3))
    to_light = np.asarray(lobe["to_light"], dtype=np.float64)
    w = points[:, None, :] - centres[None, :, :]
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    chord2 = np.sum((w + to_light) ** 2, axis=-1)
    g = float(lobe["g_spec"])
    d = (1.0 - g) ** 2 + g * chord2
    phase = (1.0 - g) * (1.0 + g) / (4.0 * math.pi) / (d * np.sqrt(d))
    return (np.asarray(alpha, dtype=np.float64)[None, :] * phase)[..., None] \
        * np.asarray(lobe["lobe_rgb"], dtype=np.float64)


def window_box_rectangles(front_z: float = WINDOW_FRONT_Z) -> dict[str, tuple[np.ndarray, ...]]:
    """The box the room sees the closed curtain through (common.glsl ``window_irradiance``),
    each (corners, s, t) (N, 3): "front" the opening's 12 x 9 patches in the plane ``front_z``
    (capture order); "left" and "right" the sides x = x0, x1 from the curtain's plane to the
    front, a rectangle a patch row (9); "bottom" and "top" y = y0, y1, one a patch column
    (12); "left_gap" and "right_gap" the sides between the window wall and the curtain's
    plane (9 each); "back" the window side's patches in the curtain's plane."""
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    nx, ny = LUMINAIRE_TEXELS
    cx, cy = (wx1 - wx0) / nx, (wy1 - wy0) / ny
    wall_z, back_z = scene_lib.ROOM_BOX[2][0], scene_lib.CURTAIN_Z
    rows, cols = np.arange(ny), np.arange(nx)
    depth = np.array([0.0, 0.0, front_z - back_z])
    gap = np.array([0.0, 0.0, back_z - wall_z])

    def rects(corners, s, t):
        corners = np.asarray(corners, dtype=np.float64)
        return corners, np.broadcast_to(s, corners.shape).copy(), np.broadcast_to(t, corners.shape).copy()

    def side(x, z0, edge):
        return rects(np.stack([np.full(ny, x), wy0 + rows * cy, np.full(ny, z0)], -1), edge, [0.0, cy, 0.0])

    def cap(y):
        return rects(np.stack([wx0 + cols * cx, np.full(nx, y), np.full(nx, back_z)], -1), depth, [cx, 0.0, 0.0])

    return {"front": window_patch_rectangles(front_z), "back": window_patch_rectangles(back_z),
            "left": side(wx0, back_z, depth), "right": side(wx1, back_z, depth),
            "left_gap": side(wx0, wall_z, gap), "right_gap": side(wx1, wall_z, gap),
            "bottom": cap(wy0), "top": cap(wy1)}


def box_side_angle(centres: np.ndarray, points: np.ndarray, right: bool) -> np.ndarray:
    """common.glsl ``box_side_angle``: the angle (rad) of the way from ``centres`` on the box's
    side (right: x = x1, else x0) to ``points`` (broadcast), up from the side's outward normal
    towards +z."""
    d = np.asarray(points, dtype=np.float64) - np.asarray(centres, dtype=np.float64)
    return np.arctan2(d[..., 2], d[..., 0] if right else -d[..., 0])


def wall_eye_weight(centres: np.ndarray, points: np.ndarray, right: bool) -> np.ndarray:
    """The share of the box side's radiance (rows centred at ``centres`` (N, 3)) towards
    ``points`` (P, 3) taken from the room's side eye, the rest from the wall eye, (P, N):
    linear in :func:`box_side_angle` from the wall eye's angle (0) to level (1; a way level
    with the side's centre or falling crosses the folds, one rising from below it leaves by
    the box's front), clamped."""
    eye = np.asarray(WALL_EYES[1 if right else 0], dtype=np.float64)
    a_wall = box_side_angle(centres, eye, right)[None, :]
    a = box_side_angle(centres[None, :, :], np.asarray(points, dtype=np.float64)[:, None, :], right)
    return np.clip((a - a_wall) / (0.0 - a_wall), 0.0, 1.0)


def window_irradiance_at(points: np.ndarray, normals: np.ndarray, radiance_front: np.ndarray,
                         radiance_back: np.ndarray, radiance_sides: np.ndarray | None = None,
                         lobe: dict | None = None, alpha=None,
                         front_z: float = WINDOW_FRONT_Z, radiance_walls: np.ndarray | None = None) -> np.ndarray:
    """The float64 twin of common.glsl's ``window_irradiance``, (P, 3), at ``points`` (P, 3)
    of the room outside the opening with ``normals``: the front's patches (plane ``front_z``;
    ``radiance_front`` (9, 12, 3), the middle capture at its patch level, blended per point
    and patch with ``radiance_sides`` (2, 9, 12, 3), the side eyes' captures, by
    :func:`capture_eye_weights`) where the point lies before that plane; with a box
    (``front_z`` before the curtain's plane), its sides (the edge column of the side eye
    towards them), bottom and top (the blended edge row) and, for points before the curtain's
    plane, the sides' gaps (the window side's edge column); behind the curtain's plane, the
    window side's patches (``radiance_back``). ``radiance_walls`` (2, 9, 3): the wall eyes'
    captures of the sides, blended with the side eyes' by :func:`wall_eye_weight`. ``lobe``
    (keywords lobe_rgb, g_spec, to_light) adds the key's directional lobe to the room side's
    rectangles, scaled by ``alpha`` (9, 12), the middle capture's alpha. E = sum L F, F from
    :func:`rectangle_irradiance_factor`."""
    p = np.asarray(points, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    lf = np.asarray(radiance_front, dtype=np.float64).reshape(LUMINAIRE_TEXELS[1], LUMINAIRE_TEXELS[0], 3)
    lb = np.asarray(radiance_back, dtype=np.float64).reshape(-1, 3)
    a = (np.zeros(lf.shape[:2]) if alpha is None else np.asarray(alpha, dtype=np.float64).reshape(lf.shape[:2]))
    sides = None if radiance_sides is None else np.asarray(radiance_sides, dtype=np.float64).reshape((2,) + lf.shape)
    box = window_box_rectangles(front_z)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    back_z = scene_lib.CURTAIN_Z

    def blended(rows, cols, centres, at):   # (A, N, 3): captured_towards
        middle = lf[rows, cols]
        if sides is None:
            return np.broadcast_to(middle, (at.shape[0],) + middle.shape)
        w = capture_eye_weights(at, centres)
        return w[..., 0:1] * sides[0][rows, cols][None] + w[..., 1:2] * middle[None] + w[..., 2:3] * sides[1][rows, cols][None]

    def add(e, mask, rect, radiance, alpha_n):   # radiance (A, N, 3) or (N, 3)
        if not mask.any():
            return
        corners, s, t = rect
        at = p[mask]
        centres = corners + 0.5 * (s + t)
        factors = rectangle_irradiance_factor(at, n[mask], corners, s, t)
        total = np.broadcast_to(radiance, (at.shape[0],) + corners.shape) + _key_lobe(at, centres, alpha_n, lobe)
        e[mask] += np.einsum("pn,pnc->pc", factors, total)

    e = np.zeros(p.shape)
    ny, nx = lf.shape[:2]
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    front = box["front"]
    before_front = p[:, 2] > front_z + 1e-4
    if before_front.any():
        centres = front[0] + 0.5 * (front[1] + front[2])
        add(e, before_front, front, blended(j.ravel(), i.ravel(), centres, p[before_front]), a.ravel())
    if front_z > back_z:
        rows, cols = np.arange(ny), np.arange(nx)
        for name, col, mask in (("left", 0, p[:, 0] < wx0 - 1e-4), ("right", nx - 1, p[:, 0] > wx1 + 1e-4)):
            right = name == "right"
            edge = lf[rows, col] if sides is None else sides[1 if right else 0][rows, col]
            if radiance_walls is not None and mask.any():
                corners, s, t = box[name]
                weight = wall_eye_weight(corners + 0.5 * (s + t), p[mask], right)[..., None]
                walls = np.asarray(radiance_walls, dtype=np.float64).reshape(2, ny, 3)[1 if right else 0]
                edge = weight * edge[None] + (1.0 - weight) * walls[None]
            add(e, mask, box[name], edge, a[rows, col])
            gap_radiance = lb.reshape(ny, nx, 3)[rows, col]
            add(e, mask & (p[:, 2] > back_z), box[name + "_gap"], gap_radiance, np.zeros(ny))
        for name, row, mask in (("bottom", 0, p[:, 1] < wy0 - 1e-4), ("top", ny - 1, p[:, 1] > wy1 + 1e-4)):
            if mask.any():
                corners, s, t = box[name]
                centres = corners + 0.5 * (s + t)
                add(e, mask, box[name], blended(np.full(nx, row), cols, centres, p[mask]), a[row, cols])
    behind = p[:, 2] < back_z
    if behind.any():
        corners, s, t = box["back"]
        e[behind] += rectangle_irradiance_factor(p[behind], n[behind], corners, s, t) @ lb
    return e


def window_irradiance(radiance_front: np.ndarray, radiance_back: np.ndarray,
                      face_texels: int = FACE_TEXELS, lobe: dict | None = None,
                      radiance_sides: np.ndarray | None = None, alpha=None,
                      front_z: float = WINDOW_FRONT_Z, radiance_walls: np.ndarray | None = None) -> np.ndarray:
    """The float64 twin of room_lightmap.frag's window term, (R, 6R, 3): per atlas texel, the
    mean over its sample points on a wall (2 x 2 within WINDOW_SUPERSAMPLE_M of the window's
    plane, else the centre; none inside the opening) of :func:`window_irradiance_at` (its
    arguments)."""
    positions, _normals = texel_points(face_texels)
    wall_z = scene_lib.ROOM_BOX[2][0]
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    out = np.zeros(positions.shape[:2] + (3,))
    for k, face in enumerate(room_faces()):
        cols = slice(k * face_texels, (k + 1) * face_texels)
        centres = positions[:, cols].reshape(-1, 3)
        near = centres[:, 2] < wall_z + WINDOW_SUPERSAMPLE_M
        total = np.zeros((centres.shape[0], 3))
        count = np.zeros(centres.shape[0])
        offsets = [(0.0, 0.0, True)] + [((a - 0.5) * 0.5, (b - 0.5) * 0.5, False)
                                         for b in (0, 1) for a in (0, 1)]
        for ds, dt, is_centre in offsets:
            use = ~near if is_centre else near
            q = centres + (ds * face.axis_s + dt * face.axis_t) / face_texels
            in_opening = ((q[:, 2] < wall_z + 1e-4) & (q[:, 0] > wx0) & (q[:, 0] < wx1)
                          & (q[:, 1] > wy0) & (q[:, 1] < wy1))
            use = use & ~in_opening
            if not use.any():
                continue
            n = np.broadcast_to(face.normal, q[use].shape)
            total[use] += window_irradiance_at(q[use], n, radiance_front, radiance_back, radiance_sides,
                                               lobe=lobe, alpha=alpha, front_z=front_z,
                                               radiance_walls=radiance_walls)
            count[use] += 1
        mean = np.where(count[:, None] > 0, total / np.maximum(count, 1)[:, None], 0.0)
        out[:, cols] = mean.reshape(face_texels, face_texels, 3)
    return out


#: The room's shadow map and the occlusion maps draw the curtain from a grid with at most this many
#: vertices a side: on a CPU rasteriser a draw costs per triangle, and the beam's pattern
#: needs the folds (5.5 across), not every vertex.
COARSE_GRID_SIDE = 40


def coarse_grid_indices(uvs: np.ndarray, max_side: int = COARSE_GRID_SIDE) -> np.ndarray | None:
    """Triangles (int32, flat) over every k-th row and column of a row-major grid mesh, or
    None when the vertices are not such a grid (u running 0..1 along each row, v constant in
    it) or the grid is small already. The last row and column are always kept."""
    uvs = np.asarray(uvs, dtype=np.float64).reshape(-1, 2)
    n = uvs.shape[0]
    starts = np.flatnonzero(np.abs(uvs[:, 0]) < 1e-9)
    if starts.size < 2:
        return None
    columns = int(starts[1] - starts[0])
    if columns < 2 or n % columns:
        return None
    rows = n // columns
    grid = uvs.reshape(rows, columns, 2)
    if not (np.allclose(grid[:, :, 0], np.linspace(0.0, 1.0, columns)[None, :], atol=1e-6)
            and np.allclose(grid[:, :, 1], grid[:, :1, 1], atol=1e-9)):
        return None
    step = int(math.ceil(max(rows, columns) / max_side))
    if step <= 1:
        return None

    def keep(count):
        picks = list(range(0, count, step))
        return picks if picks[-1] == count - 1 else picks + [count - 1]

    r, c = np.array(keep(rows)), np.array(keep(columns))
    index = r[:, None] * columns + c[None, :]
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    cc, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    return np.concatenate([np.stack([a, cc, b], 1), np.stack([b, cc, d], 1)]).astype(np.int32).ravel()


@dataclass(frozen=True)
class RoomLamp:
    """A lamp in the room: a light of the library at ``position_m``, isotropic, its normal
    irradiance at 1 m equal to the light's spectrum (intensity = E(1 m) x 1 m^2)."""

    light: str
    position_m: tuple[float, float, float]


def check_lamp_position(position_m) -> tuple[float, float, float]:
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    p = tuple(float(v) for v in position_m)
    (x0, x1), (y0, y1), (z0, z1) = scene_lib.ROOM_BOX
    if len(p) != 3 or not (x0 < p[0] < x1 and y0 < p[1] < y1 and z0 < p[2] < z1):
        raise CatalogError(f"room lamp position {position_m!r} must lie inside the room "
                           f"x {x0}..{x1}, y {y0}..{y1}, z {z0}..{z1} m")
    return p


# --------------------------------------------------------------------------- regions of a view

#: Names of the regions :func:`view_regions` returns (the tests and the path-traced
#: comparison of the same scene use the same masks).
REGION_NAMES = ("floor_patch", "floor_away", "window_wall_strips")


def pixel_rays(view_projection: np.ndarray, eye, size) -> np.ndarray:
    """(H, W, 3) unit directions from ``eye`` through each pixel's centre (row 0 = top) of a
    view ``size`` = (W, H) pixels: the far plane's points unprojected."""
    w, h = size
    inv = np.linalg.inv(np.asarray(view_projection, dtype=np.float64))
    ys, xs = np.mgrid[0:h, 0:w]
    ndc = np.stack([(xs + 0.5) / w * 2 - 1, 1 - (ys + 0.5) / h * 2, np.ones((h, w)),
                    np.ones((h, w))], -1)
    far = ndc @ inv.T
    d = far[..., :3] / far[..., 3:] - np.asarray(eye, dtype=np.float64)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def view_regions(view_projection: np.ndarray, eye, size, to_light) -> dict[str, np.ndarray]:
    """Boolean (H, W) masks of a view (row 0 = top), found by geometry, not by shading:

    - ``floor_patch``: floor pixels the key's beam reaches through the hanging curtain
      (margins of 0.08 m inside the opening and 0.1-0.15 m inside the curtain);
    - ``floor_away``: floor pixels whose beam would cross the wall 0.3 m or more outside
      the opening;
    - ``window_wall_strips``: the outer fifths of the frame (the wall beside the window in
      the default view).
    """
    w, h = size
    eye = np.asarray(eye, dtype=np.float64)
    d = pixel_rays(view_projection, eye, size)
    (x0, x1), (y0, _), (z0, z1) = scene_lib.ROOM_BOX
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (y0 - eye[1]) / d[..., 1]
    p = eye + t[..., None] * d
    floor = (t > 0) & (p[..., 0] > x0 + 0.2) & (p[..., 0] < x1 - 0.2) & (p[..., 2] > z0 + 0.4) & (p[..., 2] < z1 - 0.2)
    to_light = np.asarray(to_light, dtype=np.float64)

    def crossing(z):
        s = (z - p[..., 2]) / to_light[2]
        return p[..., :2] + s[..., None] * to_light[:2]

    q = crossing(z0)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    m = 0.08
    in_window = (q[..., 0] > wx0 + m) & (q[..., 0] < wx1 - m) & (q[..., 1] > wy0 + m) & (q[..., 1] < wy1 - m)
    qc = crossing(scene_lib.CURTAIN_Z)
    half = scene_lib.CURTAIN_WIDTH_M / 2
    through = ((np.abs(qc[..., 0]) < half - 0.1) & (qc[..., 1] < scene_lib.CURTAIN_TOP_Y - 0.1)
               & (qc[..., 1] > scene_lib.CURTAIN_TOP_Y - scene_lib.CURTAIN_HEIGHT_M + 0.15))
    away = ((q[..., 0] < wx0 - 0.3) | (q[..., 0] > wx1 + 0.3) | (q[..., 1] < wy0 - 0.3)
            | (q[..., 1] > wy1 + 0.3))
    strips = np.zeros((h, w), dtype=bool)
    strips[:, : w // 5] = True
    strips[:, w - w // 5:] = True
    return {"floor_patch": floor & in_window & through, "floor_away": floor & away,
            "window_wall_strips": strips}



# --------------------------------------------------------------------------- the wall beside the cloth

@dataclass(frozen=True)
class WallLightSources:
    """What the window wall and its reveals show the cloth's window side (walled_radiance):
    the light map (irradiance, linear sRGB, (R, 6R, 3), row 0 = t = 0), the window-side
    capture at the reveals' level ((H, W, 3), row 0 = the opening's bottom), 0.5 pi x the
    sky's and the ground's radiance, the key's normal irradiance (linear sRGB) and its
    direction towards the light, the walls' albedo."""

    lightmap: np.ndarray
    back: np.ndarray
    reveal_sky: np.ndarray
    reveal_ground: np.ndarray
    key_rgb: np.ndarray
    to_light: np.ndarray
    albedo: float = scene_lib.ROOM_ALBEDO


def reveal_irradiance(points: np.ndarray, normals: np.ndarray, back: np.ndarray,
                      reveal_sky, reveal_ground) -> np.ndarray:
    """The float64 twin of common.glsl's ``reveal_irradiance`` (issue 11, fourth round): on a
    reveal (or the wall's outer face) the outside over the half of its hemisphere facing it
    (the sky above the horizon, the ground below) and the curtain's window side (``back``'s
    texel at the point's place in the opening) over the half facing the room, (P, 3)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    up = (0.5 + 0.5 * n[:, 1])[:, None]
    outside = (1.0 + np.maximum(-n[:, 2], 0.0))[:, None] * (
        up * np.asarray(reveal_sky, dtype=np.float64) + (1.0 - up) * np.asarray(reveal_ground, dtype=np.float64))
    fx = np.clip((p[:, 0] - wx0) / (wx1 - wx0), 0.0, 0.999)
    fy = np.clip((p[:, 1] - wy0) / (wy1 - wy0), 0.0, 0.999)
    h, w = back.shape[:2]
    seen = np.asarray(back, dtype=np.float64)[(fy * h).astype(int), (fx * w).astype(int)]
    return outside + (0.5 * math.pi * (1.0 - np.abs(n[:, 2])))[:, None] * seen


def wall_radiance_along(points: np.ndarray, directions: np.ndarray, sources: WallLightSources,
                        with_walled: bool = False):
    """(P, 3) the radiance met from ``points`` (P, 3) along ``directions`` (P, 3) (towards the
    window, d.z < 0) where they miss the opening, 0 where they pass it (``with_walled``: and
    the (P,) mask of the directions that miss it): the room's face where
    the ray leaves the room box (albedo / pi x the light map, bilinear), or, through the wall's
    inner plane inside the opening but not its outer one, the reveal it meets (albedo / pi x
    (:func:`reveal_irradiance` + the key, cos x the window's mask, undimmed: the reveals lie
    before the cloth)). The float64 twin of common.glsl's ``wall_radiance_along``."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    (x0, x1), (y0, y1), (z0, _) = scene_lib.ROOM_BOX
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    z_out = z0 - scene_lib.WALL_THICKNESS_M
    faces = room_faces()
    lightmap = np.asarray(sources.lightmap, dtype=np.float64)
    texels = lightmap.shape[0]
    to_light = np.asarray(sources.to_light, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        def plane_t(lo, hi, axis):
            t = (np.where(d[:, axis] > 0, hi, lo) - p[:, axis]) / d[:, axis]
            return np.where(np.abs(d[:, axis]) > 1e-12, t, np.inf)

        t_x, t_y = plane_t(x0, x1, 0), plane_t(y0, y1, 1)
        t_z = (z0 - p[:, 2]) / d[:, 2]
        q_in = p + t_z[:, None] * d
        q_out = p + ((z_out - p[:, 2]) / d[:, 2])[:, None] * d

        def inside(q):
            return (q[:, 0] >= wx0) & (q[:, 0] <= wx1) & (q[:, 1] >= wy0) & (q[:, 1] <= wy1)

        through_inner = (t_z <= np.minimum(t_x, t_y)) & inside(q_in)
        opening = through_inner & inside(q_out)
        reveal = through_inner & ~opening
        # the room's faces
        t_exit = np.minimum(np.minimum(t_x, t_y), t_z)
        q = p + t_exit[:, None] * d
        face = np.where(t_exit == t_z, 5, np.where(t_x <= t_y, np.where(d[:, 0] > 0, 3, 2),
                                                   np.where(d[:, 1] > 0, 1, 0)))
        out = np.zeros((p.shape[0], 3))
        edge = 0.5 / texels
        for k, f in enumerate(faces):
            on = (face == k) & ~through_inner
            if on.any():
                rel = q[on] - f.origin
                s = np.clip(rel @ f.axis_s / (f.axis_s @ f.axis_s), edge, 1 - edge)
                t = np.clip(rel @ f.axis_t / (f.axis_t @ f.axis_t), edge, 1 - edge)
                out[on] = sample_bilinear(lightmap, np.stack([(k + s) / len(faces), t], -1))
        # the reveals: where the ray leaves the opening's tunnel, between the wall's planes
        if reveal.any():
            pr, dr = p[reveal], d[reveal]
            tx_r = np.where(np.abs(dr[:, 0]) > 1e-12, (np.where(dr[:, 0] > 0, wx1, wx0) - pr[:, 0]) / dr[:, 0], np.inf)
            ty_r = np.where(np.abs(dr[:, 1]) > 1e-12, (np.where(dr[:, 1] > 0, wy1, wy0) - pr[:, 1]) / dr[:, 1], np.inf)
            side_x = (tx_r <= ty_r)[:, None]
            hit = pr + np.minimum(tx_r, ty_r)[:, None] * dr
            zero = np.zeros(len(pr))
            normal = np.where(side_x, np.stack([-np.sign(dr[:, 0]), zero, zero], -1),
                              np.stack([zero, -np.sign(dr[:, 1]), zero], -1))
            e = reveal_irradiance(hit, normal, sources.back, sources.reveal_sky, sources.reveal_ground)
            if to_light[2] < 0.0:
                cos_key = np.maximum(normal @ to_light, 0.0)
                e = e + (cos_key * window_beam_mask(hit, to_light))[:, None] * np.asarray(sources.key_rgb, dtype=np.float64)
            out[reveal] = e
        out[opening] = 0.0
    radiance = sources.albedo / math.pi * out
    return (radiance, ~opening) if with_walled else radiance


def walled_radiance(points: np.ndarray, sources: WallLightSources,
                    directions: np.ndarray | None = None) -> np.ndarray:
    """(P, 3) the float64 twin of common.glsl's ``walled_radiance``: over the occlusion's
    directions (cosine-weighted about -z, :func:`occlusion_directions`), the mean of
    :func:`wall_radiance_along` (0 where a direction passes the opening). The cloth's own folds
    along a walled direction are not looked for."""
    d_all = occlusion_directions() if directions is None else np.asarray(directions, dtype=np.float64)
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    total = np.zeros((p.shape[0], 3))
    for d in d_all:
        total += wall_radiance_along(p, np.broadcast_to(d, p.shape), sources)
    return total / len(d_all)


#: The directional lobe's samples about the view's continuation (curtain.vert WALL_LIGHT).
WALL_LOBE_SAMPLES = 16


@functools.lru_cache(maxsize=8)
def wall_lobe_directions(g: float, count: int = WALL_LOBE_SAMPLES) -> np.ndarray:
    """(count, 3) directions about +z drawn from Henyey-Greenstein's phase function with
    asymmetry ``g`` (model.md eq. 6) by its closed-form inverse at stratified u = (k + 1/2) /
    count, the azimuth k times the golden ratio's fraction of a turn (|g| < 1e-3: uniform
    over the sphere)."""
    u = (np.arange(count) + 0.5) / count
    phi = 2.0 * math.pi * ((np.arange(count) * 0.6180339887498949) % 1.0)
    if abs(g) < 1e-3:
        cos = 1.0 - 2.0 * u
    else:
        s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u)
        cos = np.clip((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0)
    sin = np.sqrt(np.maximum(0.0, 1.0 - cos * cos))
    return np.stack([sin * np.cos(phi), sin * np.sin(phi), cos], -1)


def wall_lobe_radiance(points: np.ndarray, views: np.ndarray, sources: WallLightSources,
                       lobe: np.ndarray) -> np.ndarray:
    """(P, 3) the float64 twin of curtain.vert WALL_LIGHT's directional sum: over ``lobe``'s
    directions (:func:`wall_lobe_directions`) turned about each unit view continuation
    ``views`` (P, 3) (the shader's frame: across = normalize(cross(x or y, view)), up = cross(
    view, across)), the mean over all of them of the wall's radiance less the outside's (sky
    above the horizon, ground below) where one towards the window meets the wall."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    v = np.asarray(views, dtype=np.float64).reshape(-1, 3)
    axis = np.where((np.abs(v[:, 0]) < 0.9)[:, None], np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    across = np.cross(axis, v)
    across /= np.linalg.norm(across, axis=-1, keepdims=True)
    up = np.cross(v, across)
    sky = np.asarray(sources.reveal_sky, dtype=np.float64) / (0.5 * math.pi)
    ground = np.asarray(sources.reveal_ground, dtype=np.float64) / (0.5 * math.pi)
    total = np.zeros((p.shape[0], 3))
    for local in np.asarray(lobe, dtype=np.float64):
        d = local[0] * across + local[1] * up + local[2] * v
        towards = d[:, 2] < -1e-6
        safe = np.where(towards[:, None], d, np.array([0.0, 0.0, -1.0]))
        radiance, walled = wall_radiance_along(p, safe, sources, with_walled=True)
        outside = np.where(safe[:, 1:2] > 0.0, sky, ground)
        total += np.where((towards & walled)[:, None], radiance - outside, 0.0)
    return total / len(lobe)
