"""Pass 1 of the frame: the room's props, lit by the light map (room.vert/.frag)."""

from __future__ import annotations

import numpy as np

from catalog.render import room_light, scene as scene_lib
from catalog.render.passes.gl_common import Pass, set_uniform


class RoomPass(Pass):
    """The room's props (room.vert/.frag): the walls around the window, the rod and the
    curtain's rings, lit by the light map and the key's beam through the window and curtain
    (the triangles facing the key drawn first, with KEY_BEAM), or the constant room when the
    room lighting is off.

    In: the scene terms, frame.room_targets' maps. Out: radiance and depth into the HDR target."""

    def __init__(self, frame):
        super().__init__(frame)
        positions, normals = scene_lib.room_props()
        self._room_vbo = self.ctx.buffer(np.hstack([positions, normals]).astype("f4").tobytes())
        self._ring_vbo = None
        self.ring_arrays = (np.zeros((0, 3), "f4"), np.zeros((0, 3), "f4"))
        self._room_order_key = None
        self._room_facing = 0

    def _room_order(self, to_light) -> int:
        """Reorder the room's triangles so that those facing the key light come first;
        returns their vertex count (cached per key direction)."""
        key = tuple(float(v) for v in to_light)
        if self._room_order_key != key:
            positions, normals = scene_lib.room_props()
            facing = (normals[0::3] @ np.asarray(to_light, dtype=np.float32)) > 0.0
            order = np.concatenate([np.flatnonzero(facing), np.flatnonzero(~facing)])
            tri_p = positions.reshape(-1, 3, 3)[order].reshape(-1, 3)
            tri_n = normals.reshape(-1, 3, 3)[order].reshape(-1, 3)
            self._room_vbo.write(np.hstack([tri_p, tri_n]).astype("f4").tobytes())
            self._room_order_key = key
            self._room_facing = 3 * int(facing.sum())
        return self._room_facing

    def draw(self, view_proj, inputs) -> None:
        lit = self.frame.room_lighting
        if lit:
            facing = self._room_order(inputs.key_to_light)
            total = self._room_vbo.size // 24
            self.ctx.enable(self.mgl.CULL_FACE)
            for beam, first, count in ((True, 0, facing), (False, facing, total - facing)):
                if count:
                    program = self.gl.program("room.vert", "room.frag",
                                            {"ROOM_LIGHTING": True, "KEY_BEAM": beam,
                                             **self.frame.capture.window_light_defines(),
                                             **({"WINDOW_NEAR": True} if self.frame.capture.window_near() else {})})
                    self._room_lit_uniforms(program, view_proj, inputs)
                    self._room_vao(program).render(self.mgl.TRIANGLES, vertices=count,
                                                   first=first)
            self.ctx.disable(self.mgl.CULL_FACE)
            self._draw_rings(program)  # the last (beam-free) program
            return
        program = self.gl.program("room.vert", "room.frag", {"ROOM_LIGHTING": False})
        self.frame.curtain.scene_uniforms(program, view_proj, inputs)
        colours = self.frame.terms.display_colours(inputs)
        set_uniform(program, "u_room_rgb", colours["u_room_rgb"])
        set_uniform(program, "u_fill_rgb", colours["u_fill_rgb"])
        self.ctx.enable(self.mgl.CULL_FACE)
        self._room_vao(program).render(self.mgl.TRIANGLES)
        self.ctx.disable(self.mgl.CULL_FACE)
        self._draw_rings(program)

    def _draw_rings(self, program) -> None:
        """The curtain's rings on the rod (issue 12), with the room's program (no culling)."""
        if self._ring_vbo is None:
            return
        key = ("rings", id(program))
        if key not in self.gl.vaos:
            self.gl.vaos[key] = self.ctx.vertex_array(
                program, [(self._ring_vbo, "3f 3f", "in_position", "in_normal")])
        self.gl.vaos[key].render(self.mgl.TRIANGLES)

    def _room_lit_uniforms(self, program, view_proj, inputs) -> None:
        self.frame.curtain.scene_uniforms(program, view_proj, inputs)
        gl = self.frame.room_targets.objects
        self.frame.lightmap.room_common_uniforms(program, inputs)
        set_uniform(program, "u_face_texels", float(room_light.FACE_TEXELS))
        gl["lightmap"].use(location=1)
        set_uniform(program, "u_lightmap", 1)
        gl["shadow"].use(location=2)
        set_uniform(program, "u_shadow", 2)
        set_uniform(program, "u_shadow_texel_m", room_light.shadow_texel_m(inputs.key_to_light, self.frame.shadow_texels, placement=self.frame.placement))
        set_uniform(program, "u_curtain_z", scene_lib.CURTAIN_Z)
        reveals = self.frame.terms.reveal_inputs(inputs)
        set_uniform(program, "u_reveal_sky", reveals["sky_half"])
        set_uniform(program, "u_reveal_ground", reveals["ground_half"])
        self.frame.capture.window_light_uniforms(program, inputs)   # the window side on unit 3 (the reveals)
        if self.frame.capture.window_near():
            gl["direct"].use(location=6)
            set_uniform(program, "u_lightmap_direct", 6)
            gl["window_near"].use(location=8)
            set_uniform(program, "u_window_near", 8)
            set_uniform(program, "u_near_rect", room_light.window_near_rect())
            set_uniform(program, "u_near_m", room_light.WINDOW_NEAR_M)
            set_uniform(program, "u_near_fade_m", room_light.WINDOW_NEAR_FADE_M)
        set_uniform(program, "u_reveal_back_level", reveals["back_level"])
        set_uniform(program, "u_reveal_back_size", reveals["back_size"])

    def _room_vao(self, program):
        key = ("room", id(program))
        if key not in self.gl.vaos:
            self.gl.vaos[key] = self.ctx.vertex_array(
                program, [(self._room_vbo, "3f 3f", "in_position", "in_normal")])
        return self.gl.vaos[key]

    def set_rings(self, xs_m, placement=None) -> None:
        """Curtain rings on the rod (of ``placement``; None: the box's) at these x positions
        (m, scene frame); empty: none."""
        positions, normals = scene_lib.ring_mesh(xs_m, placement)
        self.ring_arrays = (positions, normals)   # the transport's room light draws them too
        if self._ring_vbo is not None:
            self._ring_vbo.release()
            self._ring_vbo = None
            self.gl.release_vaos("rings")
        if len(positions):
            self._ring_vbo = self.ctx.buffer(np.hstack([positions, normals]).astype("f4").tobytes())

    def release(self) -> None:
        self._room_vbo.release()
        if self._ring_vbo is not None:
            self._ring_vbo.release()
            self._ring_vbo = None

    def invalidate_order(self) -> None:
        """Sort the room's triangles toward the key light again at the next draw."""
        self._room_order_key = None
