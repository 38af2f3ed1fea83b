"""The room's bounces: coarse patches, exact form factors and the radiosity operator (model.md section 9)."""

from __future__ import annotations

import functools
import math

import numpy as np

from catalog.render.room_light.geometry import (BOUNCE_LEVEL, FACE_NAMES, FACE_TEXELS,
                                                ao_and_mask_texture, room_faces)


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
