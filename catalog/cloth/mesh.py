"""The curtain as a triangle mesh for the renderer, and exports through trimesh.

Vertex order is the particle order (row-major, row 0 on the rod). Per vertex:

- ``positions`` (N, 3) float32, metres (y up, room side +z, see params.py);
- ``normals`` (N, 3) float32, unit, towards the room (+z) at rest;
- ``uv`` (N, 2) float32: u = 0..1 left to right (along the weft), v = 0..1 bottom to top;
- ``uv_m`` (N, 2) float32: the same in metres of rest fabric (for weave-scale textures);
- ``tangents`` (N, 4) float32: xyz = the weft direction (increasing u) made orthogonal
  to the normal, w = +1, the handedness: the warp direction (increasing v) is
  cross(normal, tangent.xyz) * w (the glTF convention);
- ``indices`` (T, 3) uint32, counter-clockwise seen from the room side at rest.

The interleaved layouts the GPU backend writes (and :meth:`CurtainMesh.vertex_data`
returns for the CPU backends) are documented in docs/cloth.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Iterable

import numpy as np

from catalog.core.atomic import atomic_path
from catalog.cloth.params import ClothParams
from catalog.cloth.state import rest_pose
from catalog.cloth.topology import triangle_indices
from catalog.core.errors import InputError

#: Floats per vertex of the dynamic buffer: position vec4, normal vec4, tangent vec4.
DYNAMIC_FLOATS = 12
#: Floats per vertex of the static buffer: uv vec2, uv_m vec2.
STATIC_FLOATS = 4
EXPORT_SUFFIXES = (".obj", ".ply", ".glb")


def _unit(v: np.ndarray) -> np.ndarray:
    length = np.sqrt(np.sum(v * v, axis=-1, keepdims=True))
    return v / np.where(length > 0.0, length, 1.0)


def grid_frames(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Normals and weft tangents (H, W, 3) of a grid of positions (central differences)."""
    from catalog.cloth.backend_numpy import grid_normals

    normals = grid_normals(x)
    across = np.empty_like(x)
    across[:, 1:-1] = x[:, 2:] - x[:, :-2]
    across[:, 0] = x[:, 1] - x[:, 0]
    across[:, -1] = x[:, -1] - x[:, -2]
    across -= np.sum(across * normals, axis=-1, keepdims=True) * normals  # Gram-Schmidt
    return normals, _unit(across)


@dataclass(frozen=True)
class CurtainMesh:
    positions: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    uv_m: np.ndarray
    tangents: np.ndarray
    indices: np.ndarray
    grid_w: int
    grid_h: int

    @classmethod
    def from_grid(cls, positions_m: np.ndarray, params: ClothParams) -> "CurtainMesh":
        x = np.asarray(positions_m, dtype=np.float64).reshape(params.grid_h, params.grid_w, 3)
        normals, weft = grid_frames(x)
        h, w = params.grid_h, params.grid_w
        u = np.broadcast_to(np.linspace(0.0, 1.0, w)[None, :], (h, w))
        v = np.broadcast_to(np.linspace(1.0, 0.0, h)[:, None], (h, w))
        uv = np.stack([u, v], axis=-1).reshape(-1, 2)
        tangents = np.concatenate([weft, np.ones((h, w, 1))], axis=-1)
        return cls(
            positions=x.reshape(-1, 3).astype(np.float32),
            normals=normals.reshape(-1, 3).astype(np.float32),
            uv=uv.astype(np.float32),
            uv_m=(uv * [params.width_m, params.height_m]).astype(np.float32),
            tangents=tangents.reshape(-1, 4).astype(np.float32),
            indices=triangle_indices(w, h),
            grid_w=w, grid_h=h)

    @property
    def warp_directions(self) -> np.ndarray:
        """(N, 3): cross(normal, tangent) * w, the direction of increasing v."""
        return np.cross(self.normals, self.tangents[:, :3]) * self.tangents[:, 3:4]

    def vertex_data(self) -> np.ndarray:
        """(N, 12) float32 [x y z 1 | nx ny nz 0 | tx ty tz w]: the dynamic buffer layout."""
        n = len(self.positions)
        out = np.empty((n, DYNAMIC_FLOATS), dtype=np.float32)
        out[:, 0:3] = self.positions
        out[:, 3] = 1.0
        out[:, 4:7] = self.normals
        out[:, 7] = 0.0
        out[:, 8:12] = self.tangents
        return out

    def static_data(self) -> np.ndarray:
        """(N, 4) float32 [u v | u_m v_m]: the static buffer layout."""
        return np.concatenate([self.uv, self.uv_m], axis=1).astype(np.float32)

    def to_trimesh(self):
        import trimesh

        visual = trimesh.visual.TextureVisuals(uv=self.uv)
        return trimesh.Trimesh(vertices=self.positions, faces=self.indices,
                               vertex_normals=self.normals, visual=visual, process=False)


def curtain_mesh(params: ClothParams | None = None, opening: float | None = None) -> CurtainMesh:
    """The curtain hanging at rest (straight pleats below the rings), no simulation needed.

    ``opening`` (0, 1]: the fraction of the rest width the rings span; below 1 the rings
    fold into zig-zag pleats that run down the fabric.
    """
    params = params or ClothParams(opening=0.8)
    return CurtainMesh.from_grid(rest_pose(params, opening), params)


def export_mesh(mesh: CurtainMesh, path: str | Path) -> Path:
    """Write one frame as OBJ, PLY or GLB (by suffix), atomically."""
    path = Path(path)
    if path.suffix.lower() not in EXPORT_SUFFIXES:
        raise InputError(f"unsupported mesh format {path.suffix!r}; use one of "
                         f"{', '.join(EXPORT_SUFFIXES)}", path=path)
    suffix = path.suffix.lower()
    if suffix == ".obj":
        # positions, normals and uv only: no material file beside it (it has no texture)
        from trimesh.exchange.obj import export_obj

        text = export_obj(mesh.to_trimesh(), include_normals=True, include_texture=True,
                          write_texture=False)
        text = "\n".join(line for line in text.splitlines()
                         if not line.startswith(("mtllib", "usemtl"))) + "\n"
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
        return path
    with atomic_path(path) as tmp:
        mesh.to_trimesh().export(tmp, file_type=suffix.lstrip("."))
    return path


def export_sequence(meshes: Iterable[CurtainMesh], pattern: str | Path) -> list[Path]:
    """Write frames to ``pattern`` with ``{frame}`` in it (e.g. ``out/curtain_{frame:04d}.ply``)."""
    pattern = str(pattern)
    if "{frame" not in pattern:
        raise InputError("sequence pattern needs a {frame} field, e.g. curtain_{frame:04d}.obj",
                         path=pattern)
    return [export_mesh(mesh, pattern.format(frame=i)) for i, mesh in enumerate(meshes)]
