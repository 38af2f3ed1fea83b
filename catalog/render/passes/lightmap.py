"""Pass 0c of the frame: the room's light map, its bounces and the curtain's room-side light."""

from __future__ import annotations

import math

import numpy as np

from catalog.render import room_light, scene as scene_lib
from catalog.render.camera import gl_bytes
from catalog.render.passes.gl_common import (OCCLUSION_MAPS_UNIT, ROOM_SIDE_CLOTH_UNIT, ROOM_SIDE_UNIT,
                                             VERTEX_WALL_LIGHT_UNIT, WALL_LIGHTMAP_UNIT,
                                             WINDOW_SIDE_CLOTH_UNIT, Pass, set_uniform)


class LightmapPass(Pass):
    """The room's light map (room_lightmap.frag: the window as an area light from its
    captures, the key's beam through the shadow map, the lamps; room_window_near.frag: the
    window wall beside the opening, finer), every bounce (room_radiosity.frag's solve,
    room_bounce.frag's gather with ambient occlusion), the room's irradiance on the curtain's
    room side and each vertex's walled light (WALL_LIGHT); and when the room's light is stale.

    In: the shadow and window-capture passes' maps, the scene terms. Out: ``direct``,
    ``beam``, ``lightmap``, ``total``, ``room_side``, ``window_near`` and ``vertex_wall_light``
    of frame.room_targets (read by the room and curtain passes)."""

    def __init__(self, frame):
        super().__init__(frame)
        self._room_key = None
        self._room_frames = 0
        self._room_mesh_version = None

    def room_common_uniforms(self, program, inputs) -> None:
        s = set_uniform
        for name, value in room_light.face_uniforms().items():
            s(program, name, value)
        wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
        z0 = scene_lib.ROOM_BOX[2][0]
        s(program, "u_window_rect", (wx0, wx1, wy0, wy1))
        s(program, "u_wall_z", (z0, z0 - scene_lib.WALL_THICKNESS_M))
        s(program, "u_light_view_proj", gl_bytes(room_light.light_view_projection(inputs.key_to_light, placement=self.frame.placement)))
        s(program, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_key_rgb", self.frame.terms.room_colours(inputs)["u_key_rgb"])
        s(program, "u_tan_sun_radius", math.tan(scene_lib.SUN_RADIUS_RAD))
        s(program, "u_albedo", scene_lib.ROOM_ALBEDO)

    def _radiosity_operator(self, window_albedo) -> None:
        """Upload room_light.radiosity_operator_rgb for this window reflectance (when it changed)."""
        key = tuple(round(v, 4) for v in window_albedo)
        if key != self.frame.room_targets.operator_albedo:
            operator = room_light.radiosity_operator_rgb(scene_lib.ROOM_ALBEDO, key)
            self.frame.room_targets.get()["radiosity_operator"].write(np.ascontiguousarray(operator).tobytes())
            self.frame.room_targets.operator_albedo = key

    def draw_room_lightmap(self, inputs) -> None:
        """Passes R3 and R4: the light map's direct part (area light, beam, lamps), then (R3b,
        with every bounce) the coarse patches' total irradiance, then the bounces gathered
        with ambient occlusion into the light map the room reads."""
        mgl, gl = self.mgl, self.frame.room_targets.get()
        aw, ah = room_light.atlas_size()
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        gl["direct_fbo"].use()
        self.ctx.viewport = (0, 0, aw, ah)
        program = self.gl.program("fullscreen.vert", "room_lightmap.frag",
                                {"BEAM_SAMPLES": room_light.BEAM_SAMPLES, **self.frame.capture.window_light_defines()})
        self.room_common_uniforms(program, inputs)
        self.frame.capture.window_light_uniforms(program, inputs)
        set_uniform(program, "u_face_texels", float(room_light.FACE_TEXELS))
        set_uniform(program, "u_supersample_m", room_light.WINDOW_SUPERSAMPLE_M)
        gl["shadow"].use(location=2)
        set_uniform(program, "u_shadow", 2)
        (x0, x1), _, _ = scene_lib.ROOM_BOX
        spacing_m = (x1 - x0) / room_light.FACE_TEXELS / room_light.BEAM_SAMPLES   # the beam's samples'
        set_uniform(program, "u_beam_shadow_lod",
                  max(0.0, math.log2(spacing_m / room_light.shadow_texel_m(inputs.key_to_light, self.frame.shadow_texels, placement=self.frame.placement))))
        set_uniform(program, "u_key_on", 1.0)
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        if self.frame.capture.window_near():   # the window wall beside the opening, finer (room_window_near.frag)
            gl["window_near_fbo"].use()
            self.ctx.viewport = (0, 0, room_light.WINDOW_NEAR_TEXELS, room_light.WINDOW_NEAR_TEXELS)
            near = self.gl.program("fullscreen.vert", "room_window_near.frag", self.frame.capture.window_light_defines())
            self.frame.capture.window_light_uniforms(near, inputs)
            set_uniform(near, "u_near_rect", room_light.window_near_rect())
            set_uniform(near, "u_window_rect", scene_lib.WINDOW_RECT)
            set_uniform(near, "u_wall_z", scene_lib.ROOM_BOX[2][0])
            set_uniform(near, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
            self.gl.fullscreen_vao(near).render(mgl.TRIANGLES, vertices=3)
            gl["direct_fbo"].use()
            self.ctx.viewport = (0, 0, aw, ah)
        gl["direct"].build_mipmaps()
        gl["beam"].build_mipmaps()
        rc = room_light.FACE_TEXELS >> room_light.BOUNCE_LEVEL
        window_albedo = self.frame.terms.window_albedo_rgb(inputs)
        # the coarse patches' total irradiance (room_radiosity.frag)
        self._radiosity_operator(window_albedo)
        gl["total_fbo"].use()
        self.ctx.viewport = (0, 0, len(room_light.FACE_NAMES) * rc, rc)
        program = self.gl.program("fullscreen.vert", "room_radiosity.frag")
        self._bind_bounce_sources(program)
        gl["radiosity_operator"].use(location=4)
        set_uniform(program, "u_operator", 4)
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        self.ctx.viewport = (0, 0, aw, ah)

        gl["lightmap_fbo"].use()
        program = self._bounce_gather_program(window_albedo)
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        if self.frame.room_side_active():
            self._draw_room_side(window_albedo)
            if not self.frame.curtain_open:
                self._draw_vertex_wall_light(inputs)

    def _bounce_gather_program(self, window_albedo, defines: dict | None = None):
        """room_bounce.frag (with ``defines``) and its inputs bound: the coarse patches' totals
        (every bounce), the faces, the obscurance and wall fraction, the albedos; for pass R4
        and R4b."""
        gl = self.frame.room_targets.get()
        program = self.gl.program("fullscreen.vert", "room_bounce.frag", defines)
        gl["total"].use(location=4)
        set_uniform(program, "u_total", 4)
        for name, value in room_light.face_uniforms().items():
            set_uniform(program, name, value)
        self._bind_bounce_sources(program)
        gl["ao"].use(location=2)
        set_uniform(program, "u_ao_mask", 2)
        set_uniform(program, "u_albedo", scene_lib.ROOM_ALBEDO)
        set_uniform(program, "u_window_albedo", window_albedo)
        return program

    def _draw_room_side(self, window_albedo) -> None:
        """Pass R4b (issue 11, fourth round): the room's irradiance on the curtain's room side,
        room_bounce.frag's gather at CURTAIN_SIDE_TEXELS points over the opening."""
        mgl, gl = self.mgl, self.frame.room_targets.get()
        gl["room_side_fbo"].use()
        self.ctx.viewport = (0, 0, *room_light.CURTAIN_SIDE_TEXELS)
        program = self._bounce_gather_program(window_albedo, {"CURTAIN_SIDE": True})
        set_uniform(program, "u_side_rect", room_light.curtain_side_rect())
        set_uniform(program, "u_side_z", scene_lib.ROOM_BOX[2][0])
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)

    def room_side_uniforms(self, program) -> None:
        """curtain.frag's ROOM_SIDE: the room-side irradiance grid, its extent, the cloth's
        reflectance of the room's light."""
        gl = self.frame.room_targets.get()
        gl["room_side"].use(location=ROOM_SIDE_UNIT)
        set_uniform(program, "u_room_side", ROOM_SIDE_UNIT)
        x0, y0, w, h = room_light.curtain_side_rect()
        set_uniform(program, "u_room_side_rect", (x0, y0, 1.0 / w, 1.0 / h))
        set_uniform(program, "u_room_side_reflectance", self.frame.terms.curtain_room_reflectance_rgb(self.frame.terms.shading_inputs()))
        gl["luminaire"].use(location=ROOM_SIDE_CLOTH_UNIT)
        set_uniform(program, "u_room_side_cloth", ROOM_SIDE_CLOTH_UNIT)
        set_uniform(program, "u_room_side_cloth_level", room_light.LUMINAIRE_LEVEL)
        set_uniform(program, "u_room_side_cloth_size", room_light.LUMINAIRE_TEXELS)
        gl["luminaire_back"].use(location=WINDOW_SIDE_CLOTH_UNIT)
        set_uniform(program, "u_window_side_cloth", WINDOW_SIDE_CLOTH_UNIT)
        set_uniform(program, "u_window_side_cloth_level", room_light.BACK_LUMINAIRE_LEVEL)
        diffuse, directional = self.frame.terms.curtain_forward_rgb(self.frame.terms.shading_inputs())
        set_uniform(program, "u_window_side_diffuse", diffuse)
        set_uniform(program, "u_window_side_directional", directional)
        if "u_occlusion_maps" in program:   # beside the per-vertex occlusion (OCCLUSION_UNIT)
            self.frame.shadow.occlusion_uniforms(program, OCCLUSION_MAPS_UNIT)
        if "u_wall_grid" in program:   # the room's transport's (WALL_GRID)
            self.frame.room_transport.wall_grid_texture().use(location=VERTEX_WALL_LIGHT_UNIT)
            set_uniform(program, "u_wall_grid", VERTEX_WALL_LIGHT_UNIT)
        if "u_vertex_wall_light" in program:
            self._wall_light_uniforms(program, self.frame.terms.shading_inputs())
            set_uniform(program, "u_wall_lobe", np.asarray(
                room_light.wall_lobe_directions(float(self.frame.terms.shading_inputs().g_spec)), dtype="f4"))
            texture = gl.get("vertex_wall_light")
            if texture is None:   # not drawn yet (a mesh bound after the last update): none
                texture = self.frame.shadow.vertex_target("vertex_wall_light", 1)
            texture.use(location=VERTEX_WALL_LIGHT_UNIT)
            set_uniform(program, "u_vertex_wall_light", VERTEX_WALL_LIGHT_UNIT)

    def _wall_light_uniforms(self, program, inputs) -> None:
        """common.glsl's WALL_LIGHT inputs: the light map (WALL_LIGHTMAP_UNIT), the room's faces
        and box, the opening and the wall's planes, the reveals' outside and the window-side
        capture (bound at WINDOW_SIDE_CLOTH_UNIT, read at the reveals' level), the key."""
        gl = self.frame.room_targets.get()
        s = set_uniform
        gl["lightmap"].use(location=WALL_LIGHTMAP_UNIT)
        s(program, "u_wall_lightmap", WALL_LIGHTMAP_UNIT)
        faces = room_light.face_uniforms()
        for name in ("origin", "s", "t"):
            s(program, f"u_wall_face_{name}", faces[f"u_face_{name}"])
        s(program, "u_wall_face_texels", float(room_light.FACE_TEXELS))
        (x0, x1), (y0, y1), (z0, z1) = scene_lib.ROOM_BOX
        s(program, "u_wall_box_lo", (x0, y0, z0))
        s(program, "u_wall_box_hi", (x1, y1, z1))
        s(program, "u_wall_opening", tuple(scene_lib.WINDOW_RECT))
        s(program, "u_wall_planes", (z0, z0 - scene_lib.WALL_THICKNESS_M))
        reveals = self.frame.terms.reveal_inputs(inputs)
        s(program, "u_wall_sky_half", reveals["sky_half"])
        s(program, "u_wall_ground_half", reveals["ground_half"])
        gl["luminaire_back"].use(location=WINDOW_SIDE_CLOTH_UNIT)
        s(program, "u_wall_back", WINDOW_SIDE_CLOTH_UNIT)
        s(program, "u_wall_back_level", reveals["back_level"])
        s(program, "u_wall_back_size", reveals["back_size"])
        s(program, "u_wall_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_wall_key_rgb", self.frame.terms.room_colours(inputs)["u_key_rgb"])
        s(program, "u_wall_tan_sun", math.tan(scene_lib.SUN_RADIUS_RAD))
        s(program, "u_wall_albedo", scene_lib.ROOM_ALBEDO)

    def _draw_vertex_wall_light(self, inputs) -> None:
        """Each vertex's walled radiance (occlusion_points.* with WALL_LIGHT): what the window
        wall and its reveals show its window side, from the light map just drawn."""
        self.frame.shadow.draw_vertex_points("vertex_wall_light", {"WALL_LIGHT": True},
                                 lambda program: self._wall_light_uniforms(program, inputs))

    def read_room_total(self) -> np.ndarray:
        """The coarse patches' last total irradiance (radiosity pass), float32 (RC, 6 RC, 3)."""
        rc = room_light.FACE_TEXELS >> room_light.BOUNCE_LEVEL
        data = self.frame.room_targets.get()["total"].read()
        return np.frombuffer(data, dtype="f4").reshape(rc, len(room_light.FACE_NAMES) * rc, 4)[..., :3].copy()

    def read_room_side(self) -> np.ndarray:
        """The last room-side irradiance grid, float32 (H, W, 3), row 0 = the opening's bottom."""
        tw, th = room_light.CURTAIN_SIDE_TEXELS
        data = self.frame.room_targets.get()["room_side"].read()
        return np.frombuffer(data, dtype="f4").reshape(th, tw, 4)[..., :3].copy()

    def _bind_bounce_sources(self, program) -> None:
        """The bounces' sources for room_radiosity.frag and room_bounce.frag: the direct map and
        the beam (units 1 and 3), read at the coarse level BOUNCE_LEVEL."""
        gl = self.frame.room_targets.get()
        gl["direct"].use(location=1)
        set_uniform(program, "u_direct", 1)
        gl["beam"].use(location=3)
        set_uniform(program, "u_beam", 3)
        set_uniform(program, "u_bounce_level", room_light.BOUNCE_LEVEL)
        set_uniform(program, "u_coarse_texels", room_light.FACE_TEXELS >> room_light.BOUNCE_LEVEL)

    def draw_room_light(self, inputs) -> None:
        """All the room lighting's passes before the frame (R1-R4)."""
        self.frame.shadow.draw_room_shadow(inputs)
        self.frame.capture.draw_room_luminaire(inputs)
        self.draw_room_lightmap(inputs)

    def read_room_shadow(self) -> np.ndarray:
        """The last transmittance shadow map, float32 (N, N, 3), row 0 = the map's bottom."""
        gl = self.frame.room_targets.get()
        n = self.frame.shadow_texels
        data = gl["shadow"].read(level=0)
        return np.frombuffer(data, dtype=np.float16).reshape(n, n, 4)[..., :3].astype(np.float32)

    def read_room_lightmap(self) -> np.ndarray:
        """The last light map (irradiance, linear sRGB), float32 (R, 6R, 3), row 0 = t = 0."""
        gl = self.frame.room_targets.get()
        aw, ah = room_light.atlas_size()
        data = gl["lightmap_fbo"].read(viewport=(0, 0, aw, ah), components=4, dtype="f4")
        return np.frombuffer(data, dtype=np.float32).reshape(ah, aw, 4)[..., :3].copy()

    def stale(self) -> bool:
        """Whether the room's light must be redrawn this frame (see room_update_every)."""
        key = (self.frame.terms.inputs_key, self.frame.curtain_open, self.frame.room_lighting,
               self.frame.room_side_active(), self.frame.key_second_layer, self.frame.patterned,
               self.frame.fabric_pattern.key,
               tuple((light.name, position) for light, position in self.frame.room_lamps))
        self._room_frames += 1
        # a cloth on the GPU moves unseen: its owner calls frame.cloth_moved() after each step
        moved = self.frame.mesh.version != self._room_mesh_version
        due = moved and self._room_frames >= self.frame.room_update_every
        if key != self._room_key or due or self.frame.room_targets.objects is None:
            self._room_key = key
            self._room_mesh_version = self.frame.mesh.version
            self._room_frames = 0
            return True
        return False

    def invalidate(self) -> None:
        """Redraw the room's light at the next frame (e.g. after the cloth moved on the GPU)."""
        self._room_key = None
        self.frame.room.invalidate_order()  # and sort the room's triangles toward the light again
