"""The curtain's mesh on the device, shared by every pass that draws the cloth."""

from __future__ import annotations

import math

import numpy as np

from catalog.core.errors import CatalogError
from catalog.render import curtain_frames, scene as scene_lib
from catalog.render.passes.gl_common import Pass

def fabric_size_from_mesh(positions, uvs, indices) -> tuple[float, float]:
    """The rest fabric's (width, length) in metres that uv 0..1 spans, measured on a grid
    mesh: the median of |dP| / |du| over triangle edges along u (dv = 0), likewise along v."""
    tri = np.asarray(indices).reshape(-1, 3)
    a = np.concatenate([tri[:, 0], tri[:, 1], tri[:, 2]])
    b = np.concatenate([tri[:, 1], tri[:, 2], tri[:, 0]])
    dp = np.linalg.norm(positions[a].astype(np.float64) - positions[b], axis=1)
    duv = np.abs(uvs[a].astype(np.float64) - uvs[b])
    size = []
    for along, across in ((0, 1), (1, 0)):
        sel = (duv[:, along] > 1e-9) & (duv[:, across] < 1e-6 * duv[:, along] + 1e-12)
        size.append(float(np.median(dp[sel] / duv[sel, along])) if sel.any() else 1.0)
    return size[0], size[1]


class CurtainMesh(Pass):
    """The curtain's mesh on the device: its vertex buffers (our own from :meth:`set_mesh`,
    or the cloth simulation's bound with :meth:`bind_cloth_buffers` /
    :meth:`bind_cloth_vertex_buffer`), the coarse grid the room's maps draw, the offset into
    the scene, the rest fabric's size (the pattern's scale), and the vertex arrays that draw
    it with a program (:meth:`curtain_vao`, :meth:`shadow_vao`)."""

    def __init__(self, frame):
        super().__init__(frame)
        self.buffers = None
        self._own_buffers = []
        self.format = "3f"
        self.offset_m = (0.0, 0.0, 0.0)
        self.vertex_count = 0
        self.version = 0
        self.mesh_arrays = None
        self.fabric_size_m = (scene_lib.CURTAIN_WIDTH_M, scene_lib.CURTAIN_HEIGHT_M)

    def set_mesh(self, positions, normals, uvs, tangents, indices, fabric_size_m=None) -> None:
        """The curtain: float32 (V, 3) positions, normals, tangents (weft), (V, 2) uvs and
        int32 triangle indices ((T, 3) or flat). ``fabric_size_m``: the rest fabric's width and
        length (m) that uv 0..1 spans (the pattern's scale); default: measured on the mesh
        (:func:`fabric_size_from_mesh`)."""
        positions = np.ascontiguousarray(positions, dtype="f4").reshape(-1, 3)
        count = positions.shape[0]
        normals = np.ascontiguousarray(normals, dtype="f4").reshape(-1, 3)
        tangents = np.ascontiguousarray(tangents, dtype="f4").reshape(-1, 3)
        uvs = np.ascontiguousarray(uvs, dtype="f4").reshape(-1, 2)
        indices = np.ascontiguousarray(indices, dtype="i4").ravel()
        if not (normals.shape[0] == tangents.shape[0] == uvs.shape[0] == count):
            raise CatalogError("curtain mesh arrays differ in vertex count")
        if indices.size == 0 or indices.size % 3 or indices.min() < 0 or indices.max() >= count:
            raise CatalogError("curtain mesh indices must be triangles of existing vertices")
        if fabric_size_m is None:
            fabric_size_m = fabric_size_from_mesh(positions, uvs, indices)
        self.fabric_size_m = tuple(float(v) for v in fabric_size_m)
        self.release()
        self.buffers = {
            "position": self.ctx.buffer(positions.tobytes()),
            "normal": self.ctx.buffer(normals.tobytes()),
            "tangent": self.ctx.buffer(tangents.tobytes()),
            "uv": self.ctx.buffer(uvs.tobytes()),
            "index": self.ctx.buffer(indices.tobytes()),
        }
        coarse = curtain_frames.coarse_grid_indices(uvs)
        if coarse is not None:  # the room's shadow map and occlusion maps draw this coarser grid
            self.buffers["coarse_index"] = self.ctx.buffer(coarse.tobytes())
        self._own_buffers = list(self.buffers.values())  # the cloth's are not ours
        self.format = "3f"
        self.offset_m = (0.0, 0.0, 0.0)
        self.vertex_count = count
        self.gl.release_vaos()
        self.mesh_arrays = (positions, normals, tangents)
        self._triangle_v_min = uvs[:, 1][indices.reshape(-1, 3)].min(axis=1)   # the hem band's split
        self._band_split = None
        self.version += 1

    def hem_band_split(self, v_band: float) -> tuple[str, str] | None:
        """The names of two index buffers that split the triangles at the hem band's top,
        ``v_band`` in uv (the band's rows from the hem at v = 0): those reaching below it, and
        the rest, which lie wholly above it; None where the mesh's uvs are not known (the
        cloth's own index buffer) or one side would be empty."""
        v_min = getattr(self, "_triangle_v_min", None)
        if v_min is None or self.buffers is None:
            return None
        if self._band_split is None or self._band_split[0] != v_band:
            tri = np.frombuffer(self.buffers["index"].read(), dtype="i4").reshape(-1, 3)
            low = v_min < v_band
            if low.all() or not low.any():
                self._band_split = (v_band, None)
            else:
                for name, rows in (("band_index", tri[low]), ("above_index", tri[~low])):
                    if name in self.buffers:
                        self.buffers[name].release()
                        self._own_buffers.remove(self.buffers[name])
                    self.buffers[name] = self.ctx.buffer(np.ascontiguousarray(rows).tobytes())
                    self._own_buffers.append(self.buffers[name])
                self.gl.release_vaos()
                self._band_split = (v_band, ("band_index", "above_index"))
        return self._band_split[1]

    def set_fabric_size(self, fabric_size_m) -> None:
        """The rest fabric's width and length (m) that uv 0..1 spans (the pattern's scale) for
        the current mesh, e.g. when another fabric hangs in the same grid."""
        size = tuple(float(v) for v in fabric_size_m)
        if len(size) != 2 or not all(math.isfinite(v) and v > 0 for v in size):
            raise CatalogError(f"fabric size {fabric_size_m!r} must be two positive lengths (m)")
        self.fabric_size_m = size

    def update_positions(self, positions, normals, tangents=None) -> None:
        """New positions and normals (and tangents: another cloth on the same grid) for the
        same vertices (a simulation frame), in the same buffers."""
        positions = np.ascontiguousarray(positions, dtype="f4").reshape(-1, 3)
        normals = np.ascontiguousarray(normals, dtype="f4").reshape(-1, 3)
        if tangents is not None:
            tangents = np.ascontiguousarray(tangents, dtype="f4").reshape(-1, 3)
            if tangents.shape[0] != self.vertex_count:
                raise CatalogError(f"update_positions: expected {self.vertex_count} tangents, "
                                   f"got {tangents.shape[0]}")
        if positions.shape[0] != self.vertex_count or normals.shape[0] != self.vertex_count:
            raise CatalogError(f"update_positions: expected {self.vertex_count} vertices, "
                               f"got {positions.shape[0]}")
        if self.format != "3f":
            raise CatalogError("update_positions after bind_cloth_buffers / bind_cloth_vertex_buffer: "
                               "the cloth owns the buffers")
        self.buffers["position"].write(positions.tobytes())
        self.buffers["normal"].write(normals.tobytes())
        if tangents is not None:
            self.buffers["tangent"].write(tangents.tobytes())
        self.mesh_arrays = (positions, normals,
                            self.mesh_arrays[2] if tangents is None else tangents)
        self.version += 1

    def bind_cloth_buffers(self, position_buffer, normal_buffer) -> None:
        """Read positions and normals straight from GPU buffers (vec4 per vertex, xyz used),
        e.g. written by the cloth's compute shader; same vertex order as :meth:`set_mesh`."""
        expected = 16 * self.vertex_count
        if position_buffer.size < expected or normal_buffer.size < expected:
            raise CatalogError(f"cloth buffers hold fewer than {self.vertex_count} vec4 vertices")
        self.buffers["position"] = position_buffer
        self.buffers["normal"] = normal_buffer
        self.buffers.pop("interleaved", None)
        self.format = "3f 4x"
        self.gl.release_vaos()

    def bind_cloth_vertex_buffer(self, vertex_buffer, index_buffer=None,
                                 offset_m=(0.0, 0.0, 0.0)) -> None:
        """Draw the cloth's interleaved dynamic buffer directly (docs/cloth.md: 48 bytes per
        vertex, [x y z 1 | nx ny nz 0 | tx ty tz w]), as the GPU backend writes it.

        ``index_buffer``: its uint32 triangles (default: those of the last :meth:`set_mesh`,
        which must then have the same vertex count). ``offset_m`` moves the cloth's frame into
        the scene (e.g. ``(0, scene.CURTAIN_TOP_Y - params.rod_y_m, scene.CURTAIN_Z)``).
        """
        count = vertex_buffer.size // 48
        if index_buffer is None and count != self.vertex_count:
            raise CatalogError(f"cloth vertex buffer holds {count} vertices, the mesh "
                               f"{self.vertex_count}: pass its index_buffer")
        self.buffers["interleaved"] = vertex_buffer
        if index_buffer is not None:
            self.buffers["index"] = index_buffer
            self.buffers.pop("coarse_index", None)  # another mesh: no coarse grid
            self._triangle_v_min = None               # nor the hem band's split
        self.vertex_count = count
        self.format = "interleaved"
        self.set_mesh_offset(offset_m)
        self.gl.release_vaos()

    def set_mesh_offset(self, offset_m) -> None:
        """Translate the curtain mesh (metres) in the vertex shader."""
        offset = tuple(float(v) for v in offset_m)
        if len(offset) != 3 or not all(math.isfinite(v) for v in offset):
            raise CatalogError(f"mesh offset {offset_m!r} must be three finite numbers (m)")
        self.offset_m = offset

    def release(self) -> None:
        for buffer in self._own_buffers:
            buffer.release()
        self._own_buffers = []

    @property
    def has_coarse_grid(self) -> bool:
        """Whether the mesh has the coarse grid the room's maps and captures draw."""
        return self.buffers is not None and "coarse_index" in self.buffers

    def curtain_vao(self, program, coarse: bool = False, index_name: str | None = None):
        """The mesh drawn with ``program``; ``coarse``: the coarse grid's triangles (where the
        mesh has one), for the room's views of the aperture, a few texels a patch;
        ``index_name``: those of that index buffer (:meth:`hem_band_split`)."""
        key = ("curtain", id(program), coarse, index_name)
        if key not in self.gl.vaos:
            b = self.buffers
            if self.format == "interleaved":
                names = [n for n in ("in_position", "in_normal", "in_tangent") if n in program]
                layout = " ".join("3f 4x" if n in program else "16x"
                                  for n in ("in_position", "in_normal", "in_tangent"))
                content = [(b["interleaved"], layout, *names)]
            else:
                content = [(b["position"], self.format, "in_position")]
                if "in_normal" in program:
                    content.append((b["normal"], self.format, "in_normal"))
                if "in_tangent" in program:
                    content.append((b["tangent"], "3f", "in_tangent"))
            if "in_uv" in program:
                content.append((b["uv"], "2f", "in_uv"))
            index = b.get("coarse_index", b["index"]) if coarse else b["index"]
            if index_name is not None:
                index = b[index_name]
            self.gl.vaos[key] = self.ctx.vertex_array(
                program, content, index_buffer=index, index_element_size=4)
        return self.gl.vaos[key]

    def shadow_vao(self, program, fine: bool = False):
        """The curtain from the key light (coarse grid; ``fine``: the drawn mesh itself, for
        the cloth's own shadow, whose depth must match the shaded surface's)."""
        key = ("shadow", id(program), fine)
        if key not in self.gl.vaos:
            b = self.buffers
            if self.format == "interleaved":
                content = [(b["interleaved"], "3f 36x", "in_position")]
            else:
                content = [(b["position"], self.format, "in_position")]
            if "in_uv" in program and "uv" in b and self.format != "interleaved":
                content.append((b["uv"], "2f", "in_uv"))
            self.gl.vaos[key] = self.ctx.vertex_array(
                program, content, index_buffer=b["index"] if fine else b.get("coarse_index", b["index"]),
                index_element_size=4)
        return self.gl.vaos[key]
