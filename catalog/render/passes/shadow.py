"""Pass 0a of the frame: the key light's maps and the outside's occlusion by the folds."""

from __future__ import annotations

import math

import numpy as np

from catalog.gl.shaderlib import glsl_literal
# the cloth's light-space frames (catalog.render.curtain_frames), under the old module's name
# until the key-shadow work in this file merges (then a rename)
from catalog.render import curtain_frames as room_light, scene as scene_lib
from catalog.render.camera import gl_bytes
from catalog.render.passes.gl_common import (KEY_FRONT_UNIT, KEY_SECOND_UNIT, OCCLUSION_UNIT, Pass,
                                             set_uniform)
from catalog.render.passes.targets import occlusion_grid

#: The key's second layer (room_shadow.frag SECOND_LAYER) lies behind the first by more than
#: KEY_SHADOW_BIAS_M plus the depth its own surface spans across this many texels: the
#: receiver's slope-scaled bias's KEY_SHADOW_SLOPE_TEXELS, set before measuring (0.5 was
#: better on the bench's voile and safety-yellow scenes afterwards: not taken, being chosen
#: on the scenes reported).
KEY_PEEL_SPAN_TEXELS = 1.5


#: How far (m, along the key's travel) a fragment must lie behind the cloth layer nearest the
#: key light to be in that layer's shadow, slope-scaled: KEY_SHADOW_BIAS_M plus
#: KEY_SHADOW_SLOPE_TEXELS front-map texels (room_light.shadow_texel_m, ~1 cm) times the
#: tangent of the angle between the cloth's normal and the key (at most KEY_SHADOW_SLOPE_CAP),
#: the depth a layer itself spans across that many texels, so a layer does not shade itself.
#: Issue 11: the constant 2 cm used before let a fold lying closer than that behind another
#: (the trough lines of the close-ups) escape the nearer fold's shadow.
KEY_SHADOW_BIAS_M = 0.004


#: The key light's map sides FrameSettings.shadow_map_size accepts (texels).
SHADOW_MAP_SIZES = (64, 128, 256, 512, 1024, 2048)


KEY_SHADOW_SLOPE_TEXELS = 1.5


KEY_SHADOW_SLOPE_CAP = 4.0


#: The front-layer map's lookup moved towards the light along the cloth's normal by this many
#: texels times sin(normal, key) (normal-offset shadows; 0: none).
KEY_SHADOW_NORMAL_OFFSET_TEXELS = 0.0


#: SKY_OCCLUSION's depth bias (m) and its lookup's offset off the surface (m): a texel and a
#: half of an occlusion map (room_light.OCCLUSION_TEXELS over ~2.4 m: 2 cm each).
OCCLUSION_BIAS_M = 0.01


OCCLUSION_OFFSET_M = 0.03


#: The key's visibility baked over the fabric's uv (curtain.frag KEY_SHADOW): a texel every
#: this many metres of the rest fabric, half the front-layer map's texel on the cloth
#: (room_light.shadow_texel_m: ~1 cm at 256), at most KEY_VISIBILITY_MAX_TEXELS a side. The
#: coarse grid's (the room's captures, a few texels a 16 cm patch) every COARSE_PITCH_M.
KEY_VISIBILITY_PITCH_M = 0.005


KEY_VISIBILITY_COARSE_PITCH_M = 0.02


KEY_VISIBILITY_MAX_TEXELS = 2048


#: Texels a row of the per-vertex occlusion texture (curtain.vert reads texel index % width).
VERTEX_OCCLUSION_WIDTH = 256


#: The mesh's buffers the maps are drawn from (CurtainMesh.buffers; not the index buffers
#: derived from them, e.g. the hem band's split, made during a frame).
_MESH_BUFFERS = ("position", "normal", "tangent", "uv", "index", "coarse_index", "interleaved")


class ShadowPass(Pass):
    """The key light's maps, drawn from the light (room_shadow.vert/.frag): the room's
    transmittance map through the curtain (the pattern's holes projected), the cloth's own
    front-layer map and its peeled second layer (curtain.frag KEY_SHADOW), the occlusion maps
    of the outside by the folds (SKY_OCCLUSION) and each vertex's occlusion from them
    (occlusion_points.*).

    In: the scene terms, the mesh, the pattern texture. Out: ``shadow``, ``key_front``,
    ``key_second``, ``occlusion`` and ``vertex_occlusion`` of frame.room_targets."""

    def __init__(self, frame):
        super().__init__(frame)

    def key_shadow_uniforms(self, program, inputs, coarse: bool = False) -> None:
        """curtain.frag's KEY_SHADOW: the key's visibility baked over the fabric's uv, of the
        mesh or (``coarse``) of the coarse grid the room's captures draw (its chords lie off
        the cloth, so their shadow is their own)."""
        name = "key_visibility_coarse" if coarse and self.frame.mesh.has_coarse_grid else "key_visibility"
        texture = self.frame.room_targets.get().get(name)
        if texture is None:   # not drawn yet (a mesh bound after the last update): none
            texture = self._key_visibility_target(name)
        texture.use(location=KEY_FRONT_UNIT)
        set_uniform(program, "u_key_visibility", KEY_FRONT_UNIT)

    def _key_lookup_uniforms(self, program, inputs) -> None:
        """key_visibility.frag's inputs: the front-layer maps, their frame and depth bias, the opening."""
        gl = self.frame.room_targets.get()
        gl["key_front"].use(location=KEY_FRONT_UNIT)
        gl["key_second"].use(location=KEY_SECOND_UNIT)
        s = set_uniform
        s(program, "u_key_front", KEY_FRONT_UNIT)
        s(program, "u_key_second", KEY_SECOND_UNIT)
        matrix = room_light.light_view_projection(inputs.key_to_light, placement=self.frame.placement)
        s(program, "u_light_view_proj", gl_bytes(matrix))
        metre = self.frame.terms.key_depth_per_metre(inputs)
        slope_m = KEY_SHADOW_SLOPE_TEXELS * room_light.shadow_texel_m(inputs.key_to_light, self.frame.room_targets.key_texels, placement=self.frame.placement)
        s(program, "u_key_depth_bias", (KEY_SHADOW_BIAS_M * metre, slope_m * metre, KEY_SHADOW_SLOPE_CAP))
        s(program, "u_key_normal_offset", KEY_SHADOW_NORMAL_OFFSET_TEXELS
          * room_light.shadow_texel_m(inputs.key_to_light, self.frame.room_targets.key_texels, placement=self.frame.placement))
        wx0, wx1, wy0, wy1 = self.frame.placement.window_rect   # the frame's room's window
        z0 = self.frame.placement.window_z
        s(program, "u_window_rect", (wx0, wx1, wy0, wy1))
        s(program, "u_wall_z", (z0, z0 - scene_lib.WALL_THICKNESS_M))
        s(program, "u_tan_sun_radius", math.tan(scene_lib.SUN_RADIUS_RAD))

    def vertex_occlusion_uniforms(self, program) -> None:
        """curtain.vert's SKY_OCCLUSION: the per-vertex occlusion texture."""
        texture = self.frame.room_targets.get().get("vertex_occlusion")
        if texture is None:   # not drawn yet (a mesh bound after the last update): none
            texture = self.vertex_target("vertex_occlusion", 1)
        texture.use(location=OCCLUSION_UNIT)
        set_uniform(program, "u_vertex_occlusion", OCCLUSION_UNIT)
        set_uniform(program, "u_vertex_occlusion_width", VERTEX_OCCLUSION_WIDTH)

    def vertex_target(self, name: str, vertices: int):
        """A per-vertex texture ``name`` (the room's resources: "vertex_occlusion",
        "vertex_wall_light") for ``vertices`` (VERTEX_OCCLUSION_WIDTH a row), made or remade
        when the count needs more rows (its texels are written by :meth:`draw_vertex_points`,
        which clears it first)."""
        mgl, gl = self.mgl, self.frame.room_targets.get()
        rows = max(1, -(-int(vertices) // VERTEX_OCCLUSION_WIDTH))
        texture = gl.get(name)
        if texture is None or texture.size[1] < rows:
            if texture is not None:
                gl[name + "_fbo"].release()
                texture.release()
            texture = self.ctx.texture((VERTEX_OCCLUSION_WIDTH, rows), 4, dtype="f4")
            texture.filter = (mgl.NEAREST, mgl.NEAREST)
            gl[name] = texture
            gl[name + "_fbo"] = self.ctx.framebuffer([texture])
        return texture

    def draw_vertex_points(self, name: str, defines: dict, bind) -> None:
        """occlusion_points.* with ``defines`` into the per-vertex texture ``name``, one point
        a vertex of the curtain's mesh; ``bind(program)`` sets the pass's own inputs."""
        mgl = self.mgl
        texture = self.vertex_target(name, self.frame.mesh.vertex_count)
        fbo = self.frame.room_targets.objects[name + "_fbo"]
        fbo.use()
        self.ctx.viewport = (0, 0, *texture.size)
        fbo.clear(0.0, 0.0, 0.0, 0.0)
        program = self.gl.program("occlusion_points.vert", "occlusion_points.frag",
                                {"OCCLUSION_MAPS": True, "N_OCCLUSION": room_light.OCCLUSION_DIRECTIONS,
                                 **defines})
        self.occlusion_uniforms(program)
        bind(program)
        set_uniform(program, "u_mesh_offset", self.frame.mesh.offset_m)
        set_uniform(program, "u_target_size", tuple(int(v) for v in texture.size))
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        self.frame.mesh.curtain_vao(program).render(mgl.POINTS)

    def _draw_vertex_occlusion(self) -> None:
        """Each vertex's outside occlusion (occlusion_points.*) from the occlusion maps."""
        self.draw_vertex_points("vertex_occlusion", {}, lambda program: None)

    def occlusion_uniforms(self, program, unit: int = OCCLUSION_UNIT) -> None:
        """common.glsl's outside_occlusion: the occlusion maps (at texture ``unit``) and each
        direction's frame."""
        gl = self.frame.room_targets.get()
        gl["occlusion"].use(location=unit)
        s = set_uniform
        s(program, "u_occlusion_maps", unit)
        directions = room_light.occlusion_directions()
        matrices = [room_light.light_view_projection(d, placement=self.frame.placement) for d in directions]
        s(program, "u_occlusion_view_proj", b"".join(gl_bytes(m) for m in matrices))
        s(program, "u_occlusion_depth_bias",
          tuple(OCCLUSION_BIAS_M * abs(float(m[2, 2])) / 2 for m in matrices))
        s(program, "u_occlusion_direction", np.asarray(directions, dtype="f4"))
        s(program, "u_occlusion_grid", float(occlusion_grid()))
        s(program, "u_occlusion_offset_m", OCCLUSION_OFFSET_M)
        wx0, wx1, wy0, wy1 = self.frame.placement.window_rect   # the frame's room's window
        z0 = self.frame.placement.window_z
        s(program, "u_occlusion_window", (wx0, wx1, wy0, wy1))
        s(program, "u_occlusion_wall_z", (z0, z0 - scene_lib.WALL_THICKNESS_M))


    def _border(self, patterned: bool) -> dict:
        """The hem band's define (the scallops' holes cast their shadow) when patterned."""
        return self.frame.fabric_pattern.defines() if patterned else {}

    def draw_room_shadow(self, inputs) -> None:
        """Pass R1: the key light's transmittance through the curtain (room_shadow.frag)."""
        mgl, gl = self.mgl, self.frame.room_targets.get()
        n = self.frame.shadow_texels
        gl["shadow_fbo"].use()
        self.ctx.viewport = (0, 0, n, n)
        gl["shadow_fbo"].clear(1.0, 1.0, 1.0, 1.0)
        if not self.frame.curtain_open:
            # the fabric's pattern (issue 12's texture and scale, when this renderer has them
            # and the mesh carries uvs) projects its holes; else the uniform mean coverage
            pattern = self.frame.fabric_pattern.texture
            patterned = (pattern is not None and self.frame.patterned
                         and self.frame.mesh.format != "interleaved")
            program = self.gl.program("room_shadow.vert", "room_shadow.frag",
                                    {"HAS_UV": True, "PATTERN": patterned, **self._border(patterned)})
            if patterned:
                self.frame.fabric_pattern.bind(program, 3, self.frame.mesh.fabric_size_m)
            colours = self.frame.terms.room_colours(inputs)
            set_uniform(program, "u_light_view_proj",
                      gl_bytes(room_light.light_view_projection(inputs.key_to_light, placement=self.frame.placement)))
            set_uniform(program, "u_mesh_offset", self.frame.mesh.offset_m)
            set_uniform(program, "u_mean_coverage", colours["u_mean_coverage"])
            set_uniform(program, "u_thread_beam_rgb", (0.0, 0.0, 0.0))
            self.ctx.disable(mgl.DEPTH_TEST)
            self.ctx.disable(mgl.CULL_FACE)
            self.ctx.enable(mgl.BLEND)
            self.ctx.blend_func = (mgl.ZERO, mgl.SRC_COLOR)   # dst *= this layer's transmittance
            self.frame.mesh.shadow_vao(program).render(mgl.TRIANGLES)
            self.ctx.blend_func = mgl.DEFAULT_BLENDING
            self.ctx.disable(mgl.BLEND)
        gl["shadow"].build_mipmaps()
        self.draw_cloth_shadow_maps(inputs)

    def draw_cloth_shadow_maps(self, inputs) -> None:
        """The maps of the cloth's own shadows (issue 11): the key's front layer (KEY_SHADOW)
        and the occlusion maps (SKY_OCCLUSION), when they are on and the curtain is drawn."""
        if self.frame.curtain_open:
            return
        pattern = self.frame.fabric_pattern.texture
        patterned = (pattern is not None and self.frame.patterned
                     and self.frame.mesh.format != "interleaved")
        colours = self.frame.terms.room_colours(inputs)
        mesh = self._mesh_key()
        key_maps = (mesh, self.frame.mesh.fabric_size_m, tuple(float(v) for v in inputs.key_to_light),
                    patterned, self._pattern_key() if patterned else None,
                    colours["u_mean_coverage"], colours["u_thread_beam_rgb"],
                    bool(self.frame.key_second_layer), self.frame.room_targets.key_texels)
        if not self._kept("key", key_maps):
            self._draw_key_front(inputs, patterned, colours)
            self._draw_key_visibility(inputs, "key_visibility")
            if self.frame.mesh.has_coarse_grid:
                self._draw_key_visibility(inputs, "key_visibility_coarse", coarse=True)
        if not self._kept("occlusion", mesh):   # the outside's occlusion: the cloth's alone
            self._draw_occlusion_maps()
            self._draw_vertex_occlusion()

    def _mesh_key(self) -> tuple:
        """What the cloth's maps take of the mesh and the room: its buffers, their version
        (bumped by set_mesh, update_positions and cloth_moved), format, count and offset,
        and the frame's placement."""
        mesh = self.frame.mesh
        return (mesh.version, mesh.format, mesh.vertex_count, mesh.offset_m,
                tuple((name, id(b)) for name, b in (mesh.buffers or {}).items()
                      if name in _MESH_BUFFERS), self.frame.placement)

    def _pattern_key(self) -> tuple:
        """What the maps take of the pattern: its texture (the fabric's key, the texture
        object and its filtering) and the hem's band."""
        fp = self.frame.fabric_pattern
        texture = fp.texture
        return (fp.key, id(texture), tuple(texture.filter), float(texture.anisotropy),
                id(fp.border), fp.border_repeats, fp.repeat_m)

    def _kept(self, group: str, key) -> bool:
        """Whether the maps of ``group`` hold what ``key`` draws (drawn for real with it since
        the maps were made): then they are kept, not drawn again (a frame per light of the
        web export's meter and whites drew the same occlusion maps each time). A context that
        notes commands (catalog.web.record: the page replays the maps every frame) draws them
        each time; a dry recording draws no pixels, so the maps hold what they held."""
        drawn = self.frame.room_targets.drawn
        recording = getattr(self.ctx, "recording", None)
        if recording is not None and recording.commands is not None:
            if not recording.skipping:
                drawn[group] = key
            return False
        if drawn.get(group) == key:
            return True
        drawn[group] = key
        return False

    def _draw_occlusion_maps(self) -> None:
        """SKY_OCCLUSION's maps: per direction of room_light.occlusion_directions, the depth
        of the layer of cloth nearest the outside along it (one tile each)."""
        mgl, gl = self.mgl, self.frame.room_targets.get()
        n = room_light.OCCLUSION_TEXELS
        grid = occlusion_grid()
        gl["occlusion_fbo"].use()
        self.ctx.viewport = (0, 0, grid * n, grid * n)   # the whole atlas (use() restores the last tile's)
        gl["occlusion_fbo"].clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        program = self.gl.program("room_shadow.vert", "room_shadow.frag",
                                {"HAS_UV": True, "PATTERN": False, "FRONT_LAYER": True,
                                 "BOTH_LAYERS": True})
        set_uniform(program, "u_mesh_offset", self.frame.mesh.offset_m)
        set_uniform(program, "u_mean_coverage", 1.0)
        set_uniform(program, "u_thread_beam_rgb", (0.0, 0.0, 0.0))
        # the nearest layer (alpha, MIN) and the farthest (g, MAX) in one pass, no depth test
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.enable(mgl.BLEND)
        self.ctx.blend_func = (mgl.ONE, mgl.ONE)
        self.ctx.blend_equation = (mgl.MAX, mgl.MIN)
        self.ctx.disable(mgl.CULL_FACE)
        vao = self.frame.mesh.shadow_vao(program)   # the coarse grid: the occlusion is a fold's, not a pixel's
        for j, direction in enumerate(room_light.occlusion_directions()):
            self.ctx.viewport = ((j % grid) * n, (j // grid) * n, n, n)
            set_uniform(program, "u_light_view_proj", gl_bytes(room_light.light_view_projection(direction, placement=self.frame.placement)))
            vao.render(mgl.TRIANGLES)
        self.ctx.viewport = (0, 0, grid * n, grid * n)
        self.ctx.blend_equation = mgl.FUNC_ADD
        self.ctx.blend_func = mgl.DEFAULT_BLENDING
        self.ctx.disable(mgl.BLEND)

    def _draw_key_front(self, inputs, patterned: bool, colours: dict) -> None:
        """The key light's front-layer map (curtain.frag KEY_SHADOW): per texel the layer of
        cloth nearest the light, its transmittance (as the room's map, one layer) and depth."""
        mgl, gl = self.mgl, self.frame.room_targets.get()
        n = self.frame.room_targets.key_texels
        gl["key_front_fbo"].use()
        self.ctx.viewport = (0, 0, n, n)
        gl["key_front_fbo"].clear(1.0, 1.0, 1.0, 1.0, depth=1.0)
        program = self.gl.program("room_shadow.vert", "room_shadow.frag",
                                {"HAS_UV": True, "PATTERN": patterned, "FRONT_LAYER": True,
                                 **self._border(patterned)})
        self._front_layer_uniforms(program, inputs, patterned, colours)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.depth_func = "<"
        self.ctx.disable(mgl.CULL_FACE)
        self.frame.mesh.shadow_vao(program, fine=True).render(mgl.TRIANGLES)
        # the second layer (issue 11, seventh round): the map peeled; cleared to coverage 0
        gl["key_second_fbo"].use()
        gl["key_second_fbo"].clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        if self.frame.key_second_layer:
            program = self.gl.program("room_shadow.vert", "room_shadow.frag",
                                      {"HAS_UV": True, "PATTERN": patterned, "SECOND_LAYER": True,
                                       **self._border(patterned),
                                       "PEEL_SPAN_TEXELS": glsl_literal(KEY_PEEL_SPAN_TEXELS)})
            self._front_layer_uniforms(program, inputs, patterned, colours)
            gl["key_front"].use(location=KEY_FRONT_UNIT)
            set_uniform(program, "u_first_layer", KEY_FRONT_UNIT)
            set_uniform(program, "u_peel_bias", KEY_SHADOW_BIAS_M * self.frame.terms.key_depth_per_metre(inputs))
            self.frame.mesh.shadow_vao(program, fine=True).render(mgl.TRIANGLES)
        self.ctx.disable(mgl.DEPTH_TEST)

    def _key_visibility_target(self, name: str):
        """The texture ``name`` of the key's visibility over the fabric's uv (key_visibility.frag),
        one texel every KEY_VISIBILITY_PITCH_M of the rest fabric (``*_coarse``: the coarse
        grid's, every KEY_VISIBILITY_COARSE_PITCH_M; at most KEY_VISIBILITY_MAX_TEXELS a side),
        made or remade when the fabric's size asks for another; cleared to fully lit."""
        mgl, gl = self.mgl, self.frame.room_targets.get()
        pitch = KEY_VISIBILITY_COARSE_PITCH_M if name.endswith("_coarse") else KEY_VISIBILITY_PITCH_M
        size = tuple(int(min(KEY_VISIBILITY_MAX_TEXELS, max(16, math.ceil(m / pitch))))
                     for m in self.frame.mesh.fabric_size_m)
        texture = gl.get(name)
        if texture is None or tuple(texture.size) != size:
            if texture is not None:
                gl[name + "_fbo"].release()
                texture.release()
            texture = self.ctx.texture(size, 4, dtype="f4")
            texture.filter = (mgl.LINEAR, mgl.LINEAR)
            texture.repeat_x = texture.repeat_y = False
            gl[name] = texture
            gl[name + "_fbo"] = self.ctx.framebuffer([texture])
            gl[name + "_fbo"].clear(1.0, 0.0, 0.0, 1.0)
        return texture

    def _draw_key_visibility(self, inputs, name: str, coarse: bool = False) -> None:
        """The key's visibility on the cloth (key_visibility.vert/.frag: the window's mask and
        the two layers' coverage in front), baked over the fabric's uv from the front-layer
        maps just drawn: none of it depends on the camera, so the frame reads it with one
        lookup (curtain.frag KEY_SHADOW). ``coarse``: on the coarse grid's triangles."""
        mgl = self.mgl
        texture = self._key_visibility_target(name)
        fbo = self.frame.room_targets.objects[name + "_fbo"]
        fbo.use()
        self.ctx.viewport = (0, 0, *texture.size)
        fbo.clear(1.0, 0.0, 0.0, 1.0)
        program = self.gl.program("key_visibility.vert", "key_visibility.frag")
        self._key_lookup_uniforms(program, inputs)
        set_uniform(program, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        set_uniform(program, "u_mesh_offset", self.frame.mesh.offset_m)
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        self.ctx.disable(mgl.CULL_FACE)
        self.frame.mesh.curtain_vao(program, coarse).render(mgl.TRIANGLES)

    def _front_layer_uniforms(self, program, inputs, patterned: bool, colours: dict) -> None:
        """room_shadow.frag's FRONT_LAYER and SECOND_LAYER inputs: the light's frame, the
        pattern's coverage."""
        if patterned:
            self.frame.fabric_pattern.bind(program, 3, self.frame.mesh.fabric_size_m)
        set_uniform(program, "u_light_view_proj",
                  gl_bytes(room_light.light_view_projection(inputs.key_to_light, placement=self.frame.placement)))
        set_uniform(program, "u_mesh_offset", self.frame.mesh.offset_m)
        set_uniform(program, "u_mean_coverage", colours["u_mean_coverage"])
        set_uniform(program, "u_thread_beam_rgb", colours["u_thread_beam_rgb"])
