"""Pass 3 of the frame: the curtain, eq. 8 in N bands (curtain.vert/.frag), opaque or as OIT layers."""

from __future__ import annotations

import numpy as np

from catalog.gl.shaderlib import glsl_literal
from catalog.render import bands as band_lib
from catalog.render.curtain_frames import OCCLUSION_DIRECTIONS
from catalog.render.camera import gl_bytes
from catalog.render.passes.gl_common import ENVIRONMENT_UNIT, PATTERN_UNIT, Pass, set_uniform

def shared_division_safe(g_diff: float, g_spec: float) -> bool:
    """Whether curtain.frag may divide once for the key, the fill and the fluorescence
    (``SHARED_DIVISION``): the product of the two lights' HG denominators, each at least
    ((1 - |g_diff|)(1 - |g_spec|))^3, must stay a normal float32 (> 1.2e-38) in the worst case."""
    margin = (1.0 - abs(g_diff)) * (1.0 - abs(g_spec))
    return margin ** 6 > 1e-30


class CurtainPass(Pass):
    """The curtain (curtain.vert/.frag, eq. 8 in N bands, two-sided): its program variant
    for the scene (:meth:`variant_defines`, specialised constants or uniforms), the draw
    itself into the bound framebuffer, the patterned cloth's layers into the frame's OIT
    targets resolved over the room and background (oit_composite.frag, McGuire & Bavoil
    2013), the flat cloth the room's captures draw, and the G-buffer variant.

    In: the scene terms (frame.terms), the mesh (frame.mesh), the pattern texture, the room
    light's maps (shadow, occlusion, room side; frame.room_targets). Out: radiance into the
    HDR target (or the caller's framebuffer)."""

    def __init__(self, frame):
        super().__init__(frame)

    def variant_defines(self, gbuffer: bool = False) -> dict:
        """The switches of the curtain program this scene needs (not the specialised values)."""
        inputs = self.frame.terms.shading_inputs()
        defines = {"N_BANDS": self.frame.n_bands, "NV4": band_lib.chunks(self.frame.n_bands),
                   f"FLUORESCENCE_{inputs.fluorescence_mode.upper()}": True,
                   "SEE_THROUGH": inputs.direct > 0, "ANISOTROPIC": inputs.anisotropy != 0.0,
                   "GBUFFER": gbuffer, "SPECIALISED": self.frame.specialise,
                   "SHARED_DIVISION": shared_division_safe(inputs.g_diff, inputs.g_spec)}
        # the fill light's lobes where it lights the cloth (the room's solved light replaces
        # it: SceneTerms.curtain_inputs)
        defines["FILL_LIGHT"] = bool(np.any(self.frame.terms.curtain_inputs().fill_irradiance != 0))
        if self.frame.environment is not None and defines["SEE_THROUGH"]:
            defines["CURTAIN_ENVIRONMENT"] = True  # the see-through shows the image
        if self.frame.room_lamps:
            defines["N_ROOM_LAMPS"] = len(self.frame.room_lamps)   # the lamps light the cloth too
        if not self.frame.curtain_open:
            defines["KEY_SHADOW"] = True   # the wall's and the folds' shadow on the cloth
            defines["SKY_OCCLUSION"] = True   # the folds hide part of the outside
            defines["N_OCCLUSION"] = OCCLUSION_DIRECTIONS
        if self.frame.room_side_active():
            defines["ROOM_SIDE"] = True   # the room's own light on the cloth's room side (its transport)
            if defines.get("SKY_OCCLUSION"):
                defines["OCCLUSION_MAPS"] = True   # the folds' maps (the G-buffer's view continuation)
                defines["WALL_GRID"] = True   # the wall and its reveals where the outside is walled
        if self.frame.antialiasing == "msaa" and not gbuffer:
            defines["INTERPOLATION"] = "centroid"   # attributes from inside the triangle
        if self.frame.patterned and not gbuffer:
            # the holes are drawn by the OIT composite: no see-through term in the shader
            defines.update({"PATTERN": True, "OIT": True, "SEE_THROUGH": False,
                            "PATTERN_LOD_BIAS": glsl_literal(self.frame.fabric_pattern.lod_bias)})
            defines.update(self.frame.fabric_pattern.defines())
        return defines

    def _curtain_program(self, gbuffer: bool, overrides: dict | None = None, hem_band: bool = True):
        defines = self.variant_defines(gbuffer)
        if not hem_band:
            defines.pop("HEM_BORDER", None)   # triangles wholly above the hem's band
        if overrides:
            defines["ROOM_CAPTURE"] = True  # the transport's views of the window, not the frame's
            defines.pop("ROOM_SIDE", None)  # the transport reflects the room's light off the cloth
            defines.pop("OCCLUSION_MAPS", None)
            defines.pop("WALL_GRID", None)
        if self.frame.specialise:
            defines.update(self.frame.terms.scene_defines(overrides))
        return self.gl.program("curtain.vert", "curtain.frag", defines)

    def scene_uniforms(self, program, view_proj, inputs, camera_position=None) -> None:
        s = set_uniform
        s(program, "u_view_proj", gl_bytes(view_proj))
        eye = self.frame.camera.position if camera_position is None else camera_position
        s(program, "u_camera_position", tuple(float(v) for v in eye))
        s(program, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_fill_to_light", tuple(float(v) for v in inputs.fill_to_light))
        s(program, "u_sun_direction", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_sun_chord2", tuple(float(v) for v in inputs.sun_chord2))

    def draw_curtain(self, view_proj, fragment: str | None = None, gbuffer: bool = False,
                     camera_position=None, overrides: dict | None = None,
                     coarse: bool = False) -> None:
        """The curtain pass alone into the bound framebuffer.

        ``fragment``: draw the same mesh (same vertex shader and uniforms of the mesh and
        camera) with this fragment shader file instead of the curtain's: how a benchmark
        measures the rasteriser's floor with shaders of its own (benchmarks/shaders/).
        ``camera_position``: the eye for the view-dependent terms (default the camera's; the
        room's passes draw the curtain as seen from the key light or the room);
        ``overrides``: scene values replaced for this draw (the room transport's views)."""
        eye = tuple(float(v) for v in (self.frame.camera.position if camera_position is None
                                       else camera_position))
        if fragment is not None:
            program = self.gl.program("curtain.vert", fragment)
            set_uniform(program, "u_view_proj", gl_bytes(view_proj))
            set_uniform(program, "u_mesh_offset", self.frame.mesh.offset_m)
            set_uniform(program, "u_camera_position", eye)
        else:
            program = self._curtain_program(gbuffer, overrides)
            draws = [(program, None)]
            split = self._hem_band_split(program, coarse)
            if split is not None:
                # the hem's band (a lace's scallops) sampled only by the triangles that reach
                # it; the rest take the variant without it (one anisotropic lookup fewer a
                # fragment over most of the cloth; the same picture: above the band the shader
                # chose the all-over pattern's texel)
                above = self._curtain_program(gbuffer, overrides, hem_band=False)
                draws = [(program, split[0]), (above, split[1])]
            for one, _index in draws:
                self._bind_curtain(one, view_proj, eye, overrides, coarse)
        self.ctx.disable(self.mgl.CULL_FACE)  # two-sided cloth
        if fragment is not None:
            self.frame.mesh.curtain_vao(program, coarse).render(self.mgl.TRIANGLES)
            return
        for one, index in draws:
            self.frame.mesh.curtain_vao(one, coarse, index).render(self.mgl.TRIANGLES)

    def _hem_band_split(self, program, coarse: bool):
        """The index buffers' names (band, above) when ``program`` samples the hem's band and
        the mesh can be split at its top; else None."""
        pattern = self.frame.fabric_pattern
        if coarse or "u_border" not in program or pattern.border_repeats is None:
            return None
        v_band = pattern.border_repeats * pattern.repeat_m[1] / self.frame.mesh.fabric_size_m[1]
        return self.frame.mesh.hem_band_split(float(v_band))

    def _bind_curtain(self, program, view_proj, eye, overrides, coarse: bool) -> None:
        """The curtain program's inputs: the camera, the mesh, the pattern, the scene's values, the maps."""
        set_uniform(program, "u_view_proj", gl_bytes(view_proj))
        set_uniform(program, "u_camera_position", eye)
        set_uniform(program, "u_mesh_offset", self.frame.mesh.offset_m)
        if "u_pattern" in program:
            self.frame.fabric_pattern.bind(program, PATTERN_UNIT, self.frame.mesh.fabric_size_m)
            set_uniform(program, "u_inv_mean_coverage", 1.0 / max(self.frame.fabric_pattern.mean_coverage, 1e-6))
            set_uniform(program, "u_oit_depth_ref", self.oit_depth_reference_m())
        if not self.frame.specialise:
            for name, value in self.frame.terms.scene_values_with(overrides).items():
                set_uniform(program, name, value)
        if self.frame.room_lamps:
            for name, value in self.frame.terms.room_lamp_values().items():
                if overrides and name in overrides:
                    value = overrides[name]
                set_uniform(program, name, value)
        if "u_environment" in program:
            self.frame.environment[1].use(location=ENVIRONMENT_UNIT)
            set_uniform(program, "u_environment", ENVIRONMENT_UNIT)
            set_uniform(program, "u_environment_scale", self.frame.background.environment_scale(self.frame.terms.shading_inputs()))
        if "u_key_visibility" in program:
            self.frame.shadow.key_shadow_uniforms(program, self.frame.terms.shading_inputs(), coarse)
        if "u_room_side" in program:
            self.frame.room_transport.cloth_uniforms(program)
        if "u_vertex_occlusion" in program:
            self.frame.shadow.vertex_occlusion_uniforms(program)

    def draw_flat(self, view_proj, eye, overrides: dict, coarse: bool = False) -> None:
        """The room's captures draw the flat cloth (the pattern averaged, model.md section 9):
        each capture texel is a mean over a window patch anyway, and the flat variant draws in
        one pass. The whole mesh, not the coarse grid of the shadow map: under the UV lamp the
        grid's chords cut into the folds, which its front-layer map then shadowed, and the
        room's capture was 0.78x the path tracer's radiance along the same rays (0.93x with
        the mesh)."""
        drawing_flat = self.frame.drawing_flat
        self.frame.drawing_flat = True
        try:
            self.draw_curtain(view_proj, camera_position=eye, overrides=overrides,
                              coarse=coarse)
        finally:
            self.frame.drawing_flat = drawing_flat

    def oit_depth_reference_m(self) -> float:
        """The view distance (m) where the OIT depth weight is 1: just before the nearest
        the curtain can be (the camera's distance to its target less a metre)."""
        return max(0.0, self.frame.camera.distance_m - 1.0)

    def draw_oit(self, view_proj, vw: int, vh: int, msaa: dict | None = None) -> None:
        """The curtain's layers into the OIT targets (depth-tested against the room, not
        written), then resolved over the HDR target. ``msaa``: into the multisampled targets,
        each resolved (averaged over the samples) before the composite: at an edge pixel the
        composite takes the samples' mean layer colour, revealage and background."""
        mgl = self.mgl
        ctx = self.ctx
        (msaa["oit_fbo"] if msaa else self.frame.targets.oit_fbo).use()
        ctx.viewport = (0, 0, vw, vh)
        ctx.clear(0.0, 0.0, 0.0, 1.0, viewport=(0, 0, vw, vh))   # accum: revealage 1
        # clear() wrote (0, 0, 0, 1) into both targets: the weight target's alpha is unused
        ctx.enable(mgl.BLEND)
        ctx.blend_equation = mgl.FUNC_ADD
        ctx.blend_func = (mgl.ONE, mgl.ONE, mgl.ZERO, mgl.ONE_MINUS_SRC_ALPHA)
        self.draw_curtain(view_proj)
        if msaa:
            ctx.disable(mgl.BLEND)
            for src, dst in (("hdr_fbo", None), ("accum_src", "accum_dst"),
                             ("weight_src", "weight_dst")):
                ctx.copy_framebuffer(self.frame.targets.hdr_fbo if dst is None else msaa[dst], msaa[src])
            ctx.enable(mgl.BLEND)
            ctx.blend_equation = mgl.FUNC_ADD
        # resolve: average colour x (1 - revealage) + behind x revealage
        self.frame.targets.hdr_fbo.use()
        ctx.viewport = (0, 0, vw, vh)
        ctx.disable(mgl.DEPTH_TEST)
        ctx.blend_func = (mgl.ONE, mgl.SRC_ALPHA, mgl.ZERO, mgl.ONE)
        program = self.gl.program("fullscreen.vert", "oit_composite.frag")
        self.frame.targets.oit_accum.use(location=0)
        self.frame.targets.oit_weight.use(location=1)
        set_uniform(program, "u_accum", 0)
        set_uniform(program, "u_weight", 1)
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        ctx.disable(mgl.BLEND)
        ctx.blend_func = mgl.DEFAULT_BLENDING

    def render_gbuffer(self, refresh_light: bool = True) -> dict[str, np.ndarray]:
        """The curtain alone with the G-buffer variant: radiance and the per-pixel geometry the
        shader used (world position, unit normal, weft tangent), float32 (H, W, 3) each, a
        boolean mask of curtain pixels, and ``shadows`` (H, W, 4): the key's window mask, the
        coverage of the layer in front of the key and the outside's occlusion by the cloth and
        by the window wall (issue 11; 1, 0, 0, 0 where those are off). The reference shades these positions in float64.
        ``refresh_light`` False: the room's light and the shadow maps as the last frame drew them."""
        mgl = self.mgl
        w, h = self.frame.size
        if refresh_light and self.frame.room_side_active():   # the room's light on the cloth's room side (and its maps)
            self.frame.draw_room_light(self.frame.terms.shading_inputs())
        elif refresh_light:   # the cloth's shadow maps of this mesh
            self.frame.shadow.draw_cloth_shadow_maps(self.frame.terms.shading_inputs())
        if self.frame.targets.gbuffer is None:
            textures = [self.ctx.texture((w, h), 4, dtype="f4") for _ in range(8)]
            depth = self.ctx.depth_renderbuffer((w, h))
            self.frame.targets.gbuffer = (textures, self.ctx.framebuffer(textures, depth))
        textures, fbo = self.frame.targets.gbuffer
        fbo.use()
        self.ctx.viewport = (0, 0, w, h)
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        self.draw_curtain(self.frame.camera.view_projection(w / h), gbuffer=True)
        self.ctx.disable(mgl.DEPTH_TEST)
        out = {}
        for name, attachment in zip(("radiance", "position", "normal", "tangent", "shadows",
                                     "wall_light", "room_side_light", "window_side_light"), range(8)):
            data = fbo.read(viewport=(0, 0, w, h), components=4, dtype="f4", attachment=attachment)
            out[name] = np.frombuffer(data, dtype=np.float32).reshape(h, w, 4)[::-1].copy()
        out["mask"] = out["position"][..., 3] > 0.5
        out["second_coverage"] = out["wall_light"][..., 3].copy()   # curtain.frag: wall_light.w
        out["room_occlusion"] = out["normal"][..., 3].copy()        # curtain.frag: normal.w
        out["room_occlusion_view"] = out["tangent"][..., 3].copy()  # and tangent.w
        for name in ("radiance", "position", "normal", "tangent", "room_side_light", "window_side_light",
                     "wall_light"):
            out[name] = out[name][..., :3]
        return out
