"""The room drawn with its light map from the precomputed transport (room_transport.vert/.frag).

Input: a room's runtime bundle (:class:`catalog.render.room_operators.RoomOperators`) and
the receivers' irradiance (E, 3). The pass draws each receiver's triangle with the
light map of catalog.room.lightmap (corners welded on each plane, linear inside each
receiver) times the surface's albedo (base colour x texture, at the texture coordinates the
receiver's corners take in their triangle) / pi; with ``key`` uniforms, the key's beam per
pixel (KEY_BEAM: the curtain's transmittance map, the room's depth map from the key). The
frame's room light (catalog/render/passes/room_transport_light.py) drives it.
"""

from __future__ import annotations

import numpy as np

from catalog.render.camera import gl_bytes
from catalog.room.lightmap import corner_irradiance


def look_at_view_projection(position, forward, up, fov_y_deg: float, aspect: float,
                            near_m: float = 0.05, far_m: float = 50.0) -> np.ndarray:
    """The 4x4 view-projection of a camera (a room's ``camera`` node)."""
    f = np.asarray(forward, dtype=np.float64) / np.linalg.norm(forward)
    right = np.cross(f, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, true_up, -f
    view[:3, 3] = -view[:3, :3] @ np.asarray(position, dtype=np.float64)
    t = 1.0 / np.tan(np.radians(fov_y_deg) / 2)
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = t / aspect, t
    proj[2, 2] = (far_m + near_m) / (near_m - far_m)
    proj[2, 3] = 2 * far_m * near_m / (near_m - far_m)
    proj[3, 2] = -1.0
    return proj @ view


class FlatTransportRoom:
    """A bare transport (no room file) as :class:`RoomTransportPass` draws it: each
    receiver's mean albedo, no textures."""

    def __init__(self, transport):
        from catalog.render.room_operators import SurfaceData  # noqa: PLC0415

        rec = transport.receivers
        self.transport = transport
        self.corners, self.normal, self.count = rec.corners, rec.normal, rec.count
        self.surface = np.zeros(rec.count, dtype=np.int64)
        self.uvs = np.zeros((rec.count, 3, 2))
        self.surfaces = (SurfaceData("flat", np.ones(3), None),)
        self.flat_albedo = rec.albedo
        self.triangles = rec.triangles

    def corner_irradiance(self, irradiance):
        return corner_irradiance(self.transport, irradiance)


class RoomTransportPass:
    """Owns its programs, vertex buffer and the surfaces' textures; :meth:`update` uploads a
    new light map (the curtain moved, the sun moved), :meth:`draw` draws it depth-tested,
    :meth:`draw_depth` the room's geometry alone (the key's depth map). ``room``: a
    :class:`catalog.render.room_operators.RoomOperators`, or a bare
    :class:`catalog.room.transport.Transport` (each receiver's mean albedo)."""

    def __init__(self, ctx, room):
        import moderngl  # noqa: PLC0415

        from catalog.gl.shaderlib import create_program  # noqa: PLC0415

        if not hasattr(room, "corner_irradiance"):
            room = FlatTransportRoom(room)
        self.ctx = ctx
        self.room = room
        self._programs = {}
        self._create_program = create_program
        self._key = ()
        self.set_key(None)
        self._buffer = ctx.buffer(reserve=self._positions.shape[0] * 11 * 4)
        # the key's depth map: the room's own triangles (not the receivers': fewer)
        self._depth_buffer = ctx.buffer(np.asarray(room.triangles, dtype="f4").reshape(-1, 3).tobytes())
        self._vaos = {}
        self._textures = {}
        white = ctx.texture((1, 1), 3, data=np.ones(3, dtype="f4").tobytes(), dtype="f4")
        for s_index in np.unique(room.surface):
            s_index = int(s_index)
            texture = room.surfaces[s_index].texture
            if texture is None:
                self._textures[s_index] = white
                continue
            h, w = texture.shape[:2]
            t = ctx.texture((w, h), 3, data=np.ascontiguousarray(texture[::-1], dtype="f4").tobytes(),
                            dtype="f4")
            t.build_mipmaps()
            t.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            self._textures[s_index] = t
        self._white = white
        self.update(np.zeros((room.count, 3)))

    @property
    def buffer(self):
        """The room's vertex buffer (positions, the light map, normals, uvs: :meth:`update`)."""
        return self._buffer

    def program(self, defines: dict):
        key = tuple(sorted(defines.items()))
        if key not in self._programs:
            self._programs[key] = self._create_program(self.ctx, "room_transport.vert",
                                                       "room_transport.frag", defines)
        return self._programs[key]

    def _vao(self, program, depth: bool = False):
        key = (id(program), depth)
        if key not in self._vaos:
            if depth:
                self._vaos[key] = self.ctx.vertex_array(program, [(self._depth_buffer, "3f", "in_position")])
            else:
                # attributes a variant optimised away are skipped in the interleaved buffer
                fields = [("in_position", "3f", "12x"), ("in_irradiance", "3f", "12x"),
                          ("in_normal", "3f", "12x"), ("in_uv", "2f", "8x")]
                layout = " ".join(fmt if name in program else skip for name, fmt, skip in fields)
                names = [name for name, _f, _s in fields if name in program]
                self._vaos[key] = self.ctx.vertex_array(program, [(self._buffer, layout, *names)])
        return self._vaos[key]

    def set_key(self, to_light) -> None:
        """Order the receivers by surface, those facing the key light first (None: all taken
        as facing it): only those are drawn with KEY_BEAM (a CPU rasteriser runs both sides of
        a branch). Takes effect at the next :meth:`update`."""
        room = self.room
        key = None if to_light is None else tuple(round(float(v), 6) for v in to_light)
        if key == self._key:
            return
        self._key = key
        facing = (np.ones(room.count, dtype=bool) if key is None
                  else room.normal @ np.asarray(key, dtype=np.float64) > 0.0)
        order = np.lexsort((~facing, room.surface))
        self._order = order
        self._ranges = []   # (surface index, facing the key, first vertex, count)
        surface, lit = room.surface[order], facing[order]
        for s_index in np.unique(surface):
            for side in (True, False):
                sel = np.flatnonzero((surface == s_index) & (lit == side))
                if sel.size:
                    self._ranges.append((int(s_index), side, 3 * int(sel[0]), 3 * int(sel.size)))
        self._positions = room.corners[order].reshape(-1, 3).astype("f4")
        self._normals = np.repeat(room.normal[order], 3, axis=0).astype("f4")
        self._uvs = room.uvs[order].reshape(-1, 2).astype("f4")
        flat = getattr(room, "flat_albedo", None)
        self._flat_albedo = None if flat is None else flat[order]

    def update(self, irradiance: np.ndarray) -> None:
        """Upload the receivers' irradiance (E, 3)."""
        corner = self.room.corner_irradiance(np.asarray(irradiance, dtype=np.float64))[self._order]
        if self._flat_albedo is not None:   # no room: each receiver's mean albedo, factor 1
            corner = corner * self._flat_albedo[:, None, :]
        data = np.concatenate([self._positions, corner.reshape(-1, 3).astype("f4"), self._normals,
                               self._uvs], axis=1)
        self._buffer.write(np.ascontiguousarray(data, dtype="f4").tobytes())

    def draw(self, view_proj: np.ndarray, beam_uniforms=None) -> None:
        """Draw into the bound framebuffer, depth-tested. ``beam_uniforms``: a callable that
        sets KEY_BEAM's inputs on the program (None: the light map alone)."""
        import moderngl  # noqa: PLC0415

        programs = {}
        for beam in {beam_uniforms is not None and side for _s, side, _f, _c in self._ranges}:
            program = self.program({"KEY_BEAM": beam})
            program["u_view_proj"].write(gl_bytes(view_proj))
            if beam:
                beam_uniforms(program)
            programs[beam] = program
        self.ctx.enable(moderngl.DEPTH_TEST)
        self.ctx.disable(moderngl.CULL_FACE)
        for s_index, side, first, count in self._ranges:
            program = programs[beam_uniforms is not None and side]
            factor = self.room.surfaces[s_index].factor
            program["u_albedo_factor"].value = tuple(float(v) for v in factor)
            self._textures[s_index].use(location=0)
            program["u_albedo_texture"].value = 0
            self._vao(program).render(moderngl.TRIANGLES, vertices=count, first=first)

    def draw_props(self, view_proj: np.ndarray, positions, normals, irradiance, albedo,
                   beam_uniforms=None) -> None:
        """Props outside the room's file (the curtain's rod and rings), grey Lambertian, with
        an irradiance per vertex (N, 3), drawn as :meth:`draw` draws the room."""
        import moderngl  # noqa: PLC0415

        count = len(positions)
        if count == 0:
            return
        data = np.concatenate([np.asarray(positions, "f4"), np.asarray(irradiance, "f4"),
                               np.asarray(normals, "f4"), np.zeros((count, 2), "f4")], axis=1)
        raw = np.ascontiguousarray(data).tobytes()
        # one buffer and vertex array kept between draws (a recorded frame's objects must be
        # the same from frame to frame), grown when the props grow
        if getattr(self, "_props_buffer", None) is None or self._props_buffer.size < len(raw):
            if getattr(self, "_props_buffer", None) is not None:
                self._props_buffer.release()
                for vao in self._props_vaos.values():
                    vao.release()
            self._props_buffer = self.ctx.buffer(reserve=len(raw))
            self._props_vaos = {}
        self._props_buffer.write(raw)
        buffer = self._props_buffer
        program = self.program({"KEY_BEAM": beam_uniforms is not None})
        program["u_view_proj"].write(gl_bytes(view_proj))
        if beam_uniforms is not None:
            beam_uniforms(program)
        fields = [("in_position", "3f", "12x"), ("in_irradiance", "3f", "12x"),
                  ("in_normal", "3f", "12x"), ("in_uv", "2f", "8x")]
        layout = " ".join(fmt if name in program else skip for name, fmt, skip in fields)
        names = [name for name, _f, _s in fields if name in program]
        if id(program) not in self._props_vaos:
            self._props_vaos[id(program)] = self.ctx.vertex_array(program, [(buffer, layout, *names)])
        vao = self._props_vaos[id(program)]
        program["u_albedo_factor"].value = tuple(float(albedo) for _ in range(3))
        self._white.use(location=0)
        program["u_albedo_texture"].value = 0
        self.ctx.enable(moderngl.DEPTH_TEST)
        self.ctx.disable(moderngl.CULL_FACE)
        vao.render(moderngl.TRIANGLES, vertices=count)

    def draw_depth(self, view_proj: np.ndarray) -> None:
        """The room's triangles' depth alone into the bound framebuffer (no culling)."""
        import moderngl  # noqa: PLC0415

        program = self.program({"DEPTH_ONLY": True})
        program["u_view_proj"].write(gl_bytes(view_proj))
        self.ctx.enable(moderngl.DEPTH_TEST)
        self.ctx.disable(moderngl.CULL_FACE)
        self._vao(program, depth=True).render(moderngl.TRIANGLES)

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        for t in {id(t): t for t in self._textures.values()}.values():
            t.release()
        if self._white not in self._textures.values():
            self._white.release()
        for program in self._programs.values():
            program.release()
        self._buffer.release()
        self._depth_buffer.release()
        if getattr(self, "_props_buffer", None) is not None:
            for vao in self._props_vaos.values():
                vao.release()
            self._props_buffer.release()
            self._props_buffer = None
