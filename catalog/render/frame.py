"""FrameRenderer: one frame of the curtain scene into an HDR target, tone-mapped to sRGB.

The viewer and the snapshot command both drive this class (docs/render.md has the API).
It never creates a GL context: it is handed one (:mod:`catalog.gl.context`).

Passes, into an RGBA32F target of linear sRGB radiance (Y in cd m^-2):

0. the room's light (issue 13, docs/room.md; when the scene, cloth or lamps changed): the key
   light's transmittance shadow map through the curtain (room_shadow.*, the pattern's holes
   projected), the window as the room sees it (the flat curtain's capture), the light map of
   the room box (room_lightmap.frag: area light, lamps; room_radiosity.frag and room_bounce.frag:
   every bounce, ambient occlusion);
1. room props (room.vert/.frag): walls around the window, the curtain rod, lit by the light
   map and the key's beam through the window and the curtain (or, switched off, the earlier
   constant room);
2. background (shaders/fullscreen.vert + background.frag), on the far plane so the depth test
   shades only the pixels nothing covers: the outside through the window (the clear sky by
   direction of catalog/optics/sun/sky.py or an environment image, the ground, the sun's
   disc) or the room, per camera ray;
3. the curtain (curtain.vert/.frag): eq. 8 in N bands, two-sided, no face culling, with the
   fabric's pattern (catalog/presets/patterns.py): the threads' radiance (the fitted lobes over the
   mean coverage) and coverage c into weighted blended OIT targets (McGuire & Bavoil 2013),
   resolved over the room and background drawn in 1-2 (oit_composite.frag): the holes show
   what is really behind, undimmed, and overlapping folds multiply their open fractions;
   ``patterned = False`` draws the paper's flat cloth instead (opaque, LD times the
   background by ray direction: the frame before issue 12, kept for comparison);
3b. glare (bloom_down/glow/bloom.frag), energy-preserving, when on;
4. display (fullscreen.vert + tonemap.frag) into the caller's framebuffer (or our RGBA8
   target): exposure (EV100, fixed or metered from a luminance histogram of this frame),
   white balance (CAT16), tone curve, gamut compression in OKLab, the sRGB curve
   (:mod:`catalog.render.display`, docs/display.md); then FXAA (fxaa.frag, issue 12) on
   the display image; ``set_antialiasing("off")`` displays straight into the target.

Anti-aliasing (:meth:`FrameRenderer.set_antialiasing`, default ``auto``): FXAA (step 4), or
MSAA where the context has MSAA_SAMPLES samples and is a GPU (:func:`choose_antialiasing`):
steps 1-3 then draw into multisampled targets (the OIT targets too), resolved before the
OIT composite.
"""

from __future__ import annotations

import math

import numpy as np

from catalog.core.constants import FLUORESCENCE_MODES
from catalog.core.errors import CatalogError, InputError
from catalog.render import bands as band_lib
from catalog.render import display as display_lib
from catalog.render import room_light
from catalog.render import scene as scene_lib
from catalog.render.camera import OrbitCamera, gl_bytes
from catalog.gl.shaderlib import create_program, glsl_literal

#: Auto exposure meters a copy of the frame at most this many pixels wide (a mip level).
METER_MAX_SIDE_PX = 96
#: Glare (bloom.frag): the fraction of the frame's radiance spread into the blurs, and the
#: blurs' weights (mip levels 1..6, wider blurs weighted less; normalised to sum 1).
BLOOM_STRENGTH = 0.04
BLOOM_LEVEL_WEIGHTS = (0.30, 0.24, 0.18, 0.13, 0.09, 0.06)
#: Anti-aliasing: a post-process on the display image (shaders/fxaa.frag), multisampling of
#: the HDR passes (the OIT targets too, resolved before the composite), none, or ``auto``
#: (:func:`choose_antialiasing`: by the context's GL_MAX_SAMPLES and the cost rule).
ANTIALIASING_MODES = ("auto", "fxaa", "msaa", "off")
#: Samples per pixel of the MSAA path.
MSAA_SAMPLES = 4
#: Renderer strings of CPU rasterisers: there MSAA multiplies the HDR passes' cost (each
#: sample shaded and blended in float: 3.5x the flat frame's HDR passes on llvmpipe, where
#: FXAA costs a fifth of the frame; benchmarks/bench_pattern.json), so ``auto`` takes FXAA.
SOFTWARE_RASTERISERS = ("llvmpipe", "softpipe", "swrast", "swr", "lavapipe", "swiftshader")
#: Specialised curtain programs kept compiled (one per light/fabric/mode/bands seen lately).
MAX_SPECIALISED = 8
#: Texture unit of the fabric's pattern, and its anisotropic filtering (samples, at most).
PATTERN_UNIT = 3
#: Texture unit of the environment image (background and the curtain's see-through).
ENVIRONMENT_UNIT = 5
#: Texture unit of the key light's front-layer map (the curtain's KEY_SHADOW), and of its
#: second layer's (issue 11, seventh round).
KEY_FRONT_UNIT = 6
KEY_SECOND_UNIT = 14
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
#: The key light's map sides set_shadow_map_size accepts (texels).
SHADOW_MAP_SIZES = (64, 128, 256, 512, 1024, 2048)
KEY_SHADOW_SLOPE_TEXELS = 1.5
KEY_SHADOW_SLOPE_CAP = 4.0
#: The front-layer map's lookup moved towards the light along the cloth's normal by this many
#: texels times sin(normal, key) (normal-offset shadows; 0: none).
KEY_SHADOW_NORMAL_OFFSET_TEXELS = 0.0
#: Texture unit of the occlusion maps (the curtain's SKY_OCCLUSION).
OCCLUSION_UNIT = 7
#: Texture unit of the room's irradiance on the curtain's room side (the curtain's ROOM_SIDE).
ROOM_SIDE_UNIT = 8
#: Texture unit of the room's capture of the cloth's room side (ROOM_SIDE: what a fold sees of
#: its neighbours where they hide the room).
ROOM_SIDE_CLOTH_UNIT = 9
#: Texture unit of the capture of the cloth's window side (ROOM_SIDE: the folds in front of
#: the outside light the cloth behind them).
WINDOW_SIDE_CLOTH_UNIT = 10
#: Texture unit of the occlusion maps in the curtain pass (ROOM_SIDE: the view's continuation).
OCCLUSION_MAPS_UNIT = 11
#: Texture units of the room's light map and the per-vertex walled radiance in the curtain pass
#: (WALL_LIGHT: what the window wall and its reveals show the cloth's window side).
WALL_LIGHTMAP_UNIT = 12
VERTEX_WALL_LIGHT_UNIT = 13
#: SKY_OCCLUSION's depth bias (m) and its lookup's offset off the surface (m): a texel and a
#: half of an occlusion map (room_light.OCCLUSION_TEXELS over ~2.4 m: 2 cm each).
OCCLUSION_BIAS_M = 0.01
OCCLUSION_OFFSET_M = 0.03
#: Texels a row of the per-vertex occlusion texture (curtain.vert reads texel index % width).
VERTEX_OCCLUSION_WIDTH = 256
PATTERN_ANISOTROPY = 4.0
#: The pattern's LOD bias (common.glsl thread_texel; issue 11, eighth round): the reference
#: averages a pixel's box (variance 1/12 px^2), the hardware's trilinear filter at its level
#: (texel side T about a pixel) is the mip's box and the bilinear tent, T^2/12 + T^2/6 = T^2/4:
#: three times too wide, which blurs the lace's motifs; the level with T = 1/sqrt(3) px matches
#: the box's variance. 0: the hardware's level (before).
PATTERN_LOD_BIAS = math.log2(1.0 / math.sqrt(3.0))
#: The largest image side we accept (also limited by the context's GL_MAX_TEXTURE_SIZE).
MAX_SIDE_PX = 16384


def shared_division_safe(g_diff: float, g_spec: float) -> bool:
    """Whether curtain.frag may divide once for the key, the fill and the fluorescence
    (``SHARED_DIVISION``): the product of the two lights' HG denominators, each at least
    ((1 - |g_diff|)(1 - |g_spec|))^3, must stay a normal float32 (> 1.2e-38) in the worst case."""
    margin = (1.0 - abs(g_diff)) * (1.0 - abs(g_spec))
    return margin ** 6 > 1e-30


#: Bytes one pixel of a frame costs: on the device the HDR target (RGBA32F, 16), its depth
#: (4) and the display target (RGBA8, 4); on the host a linear read-back (RGB float32, 12).
FRAME_BYTES_PER_PIXEL = 36


def frame_memory_limit_bytes() -> int:
    """The most memory one frame may take: a quarter of the machine's physical memory (a
    software rasteriser's targets live there; a GPU's are smaller still, and GL has no
    portable query of its memory)."""
    import os  # noqa: PLC0415

    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 4
    except (ValueError, OSError, AttributeError):
        return 4 << 30


def gl_size_limit(ctx) -> int:
    """The largest image side the context can render: the least of its texture,
    renderbuffer and viewport limits (queried)."""
    limit = MAX_SIDE_PX
    for key in ("GL_MAX_TEXTURE_SIZE", "GL_MAX_RENDERBUFFER_SIZE"):
        value = ctx.info.get(key)
        if value:
            limit = min(limit, int(value))
    dims = ctx.info.get("GL_MAX_VIEWPORT_DIMS")
    if dims:
        limit = min(limit, *(int(d) for d in dims))
    return limit


def software_rasteriser(info: dict) -> bool:
    """True for a CPU rasteriser (llvmpipe, SwiftShader, ...), from ``ctx.info``'s GL_RENDERER."""
    renderer = str(info.get("GL_RENDERER", "")).lower()
    return any(name in renderer for name in SOFTWARE_RASTERISERS)


def choose_specialise(info: dict) -> bool:
    """Whether a renderer compiles the scene's values into the curtain shader as constants.

    On a CPU rasteriser yes: it runs every operation per fragment, so folded constants and no
    uniform loads are measured savings (docs/render.md). On a GPU no: uniforms cost it
    nothing, a light change then compiles nothing, and NVIDIA's compiler was measured to fold
    the see-through constants (model.md eq. 8's LD terms) with a relative error up to 1.1e-3
    against the float64 reference, where the uniform program stays within 1.2e-6
    (docs/gpu.md)."""
    return software_rasteriser(info)


def choose_antialiasing(info: dict) -> str:
    """``auto``'s choice for a context (``ctx.info`` plus ``GL_RENDERER``): ``msaa`` where
    the context multisamples float targets with at least MSAA_SAMPLES samples
    (GL_MAX_SAMPLES) on a GPU, where multisampling is paid in bandwidth, not shading;
    ``fxaa`` on CPU rasterisers (the measured cost rule) and where samples are lacking."""
    samples = int(info.get("GL_MAX_SAMPLES", 0) or 0)
    if samples < MSAA_SAMPLES or software_rasteriser(info):
        return "fxaa"
    return "msaa"


def check_size(size, ctx=None) -> tuple[int, int]:
    """(width, height) in pixels, refused with a one-line error when impossible: a side
    outside 1..the context's limit (:func:`gl_size_limit`), or a frame larger than
    :func:`frame_memory_limit_bytes`."""
    try:
        width, height = (int(v) for v in size)
    except (TypeError, ValueError):
        raise CatalogError(f"image size {size!r} must be two whole numbers (width, height)") from None
    limit = MAX_SIDE_PX if ctx is None else gl_size_limit(ctx)
    if not (1 <= width <= limit and 1 <= height <= limit):
        raise CatalogError(f"image size {width}x{height} is impossible: each side must lie in "
                           f"1..{limit} px (this GL context's limit)")
    need = width * height * FRAME_BYTES_PER_PIXEL
    budget = frame_memory_limit_bytes()
    if need > budget:
        raise CatalogError(f"image size {width}x{height} needs about {need >> 20} MiB for one "
                           f"frame, more than the {budget >> 20} MiB this machine allows; "
                           "choose a smaller --size")
    return width, height


def gl_bytes_mat3(matrix: np.ndarray) -> bytes:
    """A 3x3 matrix (column-vector convention) as GLSL's column-major mat3."""
    return np.ascontiguousarray(np.asarray(matrix, dtype=np.float32).T).tobytes()


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


class FrameRenderer:
    """Renders the curtain scene with a given moderngl context at a given size (w, h)."""

    def __init__(self, ctx, size: tuple[int, int], specialise: bool | None = None):
        """``specialise``: compile the scene's values into the curtain shader as constants
        (recompiled when the light, fabric, mode or band count changes; a CPU rasteriser then
        loads no uniforms per fragment) rather than passing them as uniforms; None (default):
        :func:`choose_specialise` for this context (constants on a CPU rasteriser only)."""
        import moderngl  # noqa: PLC0415

        self._moderngl = moderngl
        self.ctx = ctx
        self.size = check_size(size, ctx)
        w, h = self.size
        self._hdr = ctx.texture((w, h), 4, dtype="f4")
        self._hdr.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._depth = ctx.depth_renderbuffer((w, h))
        self._hdr_fbo = ctx.framebuffer([self._hdr], self._depth)
        self._ldr = ctx.texture((w, h), 4)
        self._ldr_fbo = ctx.framebuffer([self._ldr])
        # the tone-mapped image before FXAA (fxaa.frag reads texels; LINEAR for the
        # benchmark's earlier FXAA of filtered reads, FXAA_SHADER)
        self._pre = ctx.texture((w, h), 4)
        self._pre.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self._pre.repeat_x = self._pre.repeat_y = False
        self._pre_fbo = ctx.framebuffer([self._pre])
        self.antialiasing = "fxaa"
        self.fxaa_shader = "fxaa.frag"   # the benchmark swaps in its earlier version
        self._msaa = None                # the multisampled targets, made on first use
        self.set_antialiasing("auto")
        self._gbuffer = None
        # weighted blended OIT: sum C a w | prod (1 - a), and sum a w; the scene's depth
        self._oit_accum = ctx.texture((w, h), 4, dtype="f4")
        self._oit_weight = ctx.texture((w, h), 1, dtype="f4")
        for texture in (self._oit_accum, self._oit_weight):
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._oit_fbo = ctx.framebuffer([self._oit_accum, self._oit_weight], self._depth)
        self._oit_fbo.depth_mask = False  # the layers are tested against the room, not each other
        self.patterned = True
        self._pattern_texture = None
        self._pattern_key = None
        self._pattern = None
        self._fabric_size_m = (scene_lib.CURTAIN_WIDTH_M, scene_lib.CURTAIN_HEIGHT_M)
        self._programs: dict[tuple, object] = {}
        self.specialise = (choose_specialise(dict(ctx.info)) if specialise is None
                           else bool(specialise))
        self._vaos: dict[tuple, object] = {}

        self.preset = None
        self.light = None
        self._key_to_light = scene_lib.key_direction(scene_lib.LAMP_ELEVATION_DEG)
        self._is_sun = False
        self.mode = "physical"
        self.n_bands = 3
        self.camera = OrbitCamera()
        self.exposure = 1.0              # a multiplier on top of the EV (compensation)
        self.ev100 = None                # None: metered per frame (auto exposure)
        self.white_balance = display_lib.DEFAULT_WHITE_BALANCE
        self.metered_ev100 = None        # the auto exposure's current EV100 (adapted)
        self.display_stages = 3          # tonemap.frag's DISPLAY_STAGES (benchmark variants)
        self._wb_cache = None
        self._inputs = None
        self._inputs_key = None
        self._decision = None
        self._uniforms = None
        self._uniforms_key = None
        self._last = None  # (vw, vh, fbo, viewport)
        #: issue 13: the room lit through the curtain (False: the earlier constant room)
        self.room_lighting = True
        #: issue 11: the key light on the cloth shaded by the window wall and by the folds
        #: nearer the light (curtain.frag KEY_SHADOW; False: the key reaches every fragment)
        self.key_shadow = True
        #: issue 11: the cloth's own folds hide part of the outside from its ambient term
        #: (curtain.frag SKY_OCCLUSION; False: every fragment sees the whole outside)
        self.sky_occlusion = True
        #: issue 11: the ambient term by view (False: the normal view's at every angle)
        self.ambient_by_view = True
        #: issue 11: the outside through the lobes by the view's height, the sky above the
        #: view's line and the ground below (False: the outside averaged)
        self.outside_by_view = True
        #: issue 11: the room's bounces, "all" (radiosity, room_radiosity.frag) or "one"
        self.room_bounces = "all"
        #: issue 11: the key's directional lobe through the cloth reaches the room spread over
        #: its HG lobe, from the window's patches (room_lightmap.frag); False: collimated in
        #: the beam, a_spec forward(g_spec) per thread (issue 13's frame)
        self.room_lobe = True
        #: issue 11 (fourth round): the curtain's room side lit by the room's solved light
        #: (curtain.frag ROOM_SIDE, with the room lighting and the viewer inside); False: by
        #: the stand-ins, the fill light and the room's share of the ambient term
        self.room_side_solved = True
        self.wall_light = True     # the window wall and its reveals light the cloth (WALL_LIGHT)
        #: issue 11 (sixth round): the room's capture of the window from three eyes, blended
        #: per receiving point (room_lightmap.frag SIDE_EYES); False: from the middle alone
        self.side_eyes = True
        #: the room sees the closed curtain through a box around its folds (set_window_box)
        self.window_box = True
        #: the box's sides also captured from eyes by the window wall (set_wall_eyes)
        self.wall_eyes = True
        #: the window wall beside the opening takes the window's light per pixel (set_window_near)
        self.window_near_field = True
        #: issue 11 (sixth round): the room's captures see the folds behind through the holes
        #: (curtain.frag FOLDS_BEHIND); False: the outside there
        self.capture_folds = True
        #: the room's and the folds' light passed by the dye of the lit cloth's own light
        #: (set_secondary_dye)
        self.secondary_dye = True
        #: the key's shadow on the cloth through two layers, not one (set_key_second_layer)
        self.key_second_layer = True
        #: the pattern's LOD bias (set_pattern_lod_bias)
        self.pattern_lod_bias = PATTERN_LOD_BIAS
        #: the side (texels) of the key light's maps: the room's transmittance map and the
        #: cloth's front-layer map (set_shadow_map_size)
        self.shadow_texels = room_light.SHADOW_TEXELS
        self.curtain_open = False
        self.room_lamps: list[tuple] = []   # (catalog.optics.lights.Light, (x, y, z) m)
        self._room_gl = None
        #: the room's light (shadow map, capture, light map) is redrawn at once when the light,
        #: fabric, curtain or lamps change, and every ``room_update_every`` frames while the
        #: cloth moves (a cloth drawn from GPU buffers is taken as moving); 1: every frame
        self.room_update_every = 1
        self._room_key = None
        self._room_frames = 0
        self._mesh_version = 0
        self.sky_model = True      # the clear sky of catalog/optics/sun/sky.py behind the window (a sun)
        self.bloom = True          # glare before the tone map (bloom.frag)
        self.environment = None    # (path, texture, upper-hemisphere illuminance) or None
        self._bloom_gl = None

        positions, normals = scene_lib.room_props()
        self._room_vbo = ctx.buffer(np.hstack([positions, normals]).astype("f4").tobytes())
        self._curtain_buffers = None
        self._ring_vbo = None
        default = scene_lib.draped_curtain()
        self.set_mesh(default.positions, default.normals, default.uvs, default.tangents,
                      default.indices)

    # ------------------------------------------------------------------ state
    def set_fabric(self, preset) -> None:
        """A preset object, a preset name (fabrics/NAME.toml) or a path to a .toml."""
        from catalog.presets import Preset, find_preset, load_preset  # noqa: PLC0415

        if not isinstance(preset, Preset):
            preset = load_preset(find_preset(preset))
        scene_lib.dye_transmittance(preset)  # refuse a bad dye file now, not at render
        scene_lib.fluorescent_material(preset)
        self._set_pattern(preset)
        self.preset = preset

    def set_rings(self, xs_m) -> None:
        """Curtain rings on the rod at these x positions (m, scene frame); empty: none."""
        positions, normals = scene_lib.ring_mesh(xs_m)
        if self._ring_vbo is not None:
            self._ring_vbo.release()
            self._ring_vbo = None
            for key in [k for k in self._vaos if k[0] == "rings"]:
                self._vaos.pop(key).release()
        if len(positions):
            self._ring_vbo = self.ctx.buffer(np.hstack([positions, normals]).astype("f4").tobytes())

    def set_patterned(self, patterned: bool) -> None:
        """True (default): the fabric's pattern, holes and layers (OIT); False: the flat,
        opaque cloth of eq. 8 with LD times the background by ray direction."""
        self.patterned = bool(patterned)

    def _set_pattern(self, preset) -> None:
        """The preset's pattern as a mipmapped RGBA32F texture (thread normal, coverage);
        without a [pattern] a uniform coverage 1 - LD (one texel)."""
        from catalog.presets.patterns import load_pattern  # noqa: PLC0415

        table = preset.table("pattern")
        key = (str(preset.path), repr(sorted(table.items())), preset.btdf.direct)
        if key == self._pattern_key:
            return
        pattern = load_pattern(preset)
        if pattern is None:
            texels = np.array([[[0.0, 0.0, 1.0, 1.0 - preset.btdf.direct]]], dtype=np.float32)
            repeat = self._fabric_size_m
        else:
            texels = pattern.normal_map()
            repeat = pattern.repeat_m
        mgl = self._moderngl
        if self._pattern_texture is not None:
            self._pattern_texture.release()
        h, w = texels.shape[:2]
        texture = self.ctx.texture((w, h), 4, np.ascontiguousarray(texels).tobytes(), dtype="f4")
        texture.repeat_x = texture.repeat_y = True
        texture.filter = (mgl.LINEAR_MIPMAP_LINEAR, mgl.LINEAR)
        texture.build_mipmaps()
        max_aniso = float(self.ctx.info.get("GL_MAX_TEXTURE_MAX_ANISOTROPY", 1.0) or 1.0)
        texture.anisotropy = min(PATTERN_ANISOTROPY, max_aniso)
        self._pattern_texture = texture
        self._pattern = pattern
        self._pattern_repeat_m = tuple(float(v) for v in repeat)
        self._pattern_mean_coverage = float(np.mean(texels[..., 3], dtype=np.float64))
        self._pattern_key = key

    def set_pattern_filtering(self, filtered: bool) -> None:
        """True (default): trilinear mipmapped, anisotropic; False: nearest texel, no mips
        (for measuring what the filtering buys: shimmer, the far limit)."""
        mgl = self._moderngl
        texture = self._pattern_texture
        if filtered:
            texture.filter = (mgl.LINEAR_MIPMAP_LINEAR, mgl.LINEAR)
            max_aniso = float(self.ctx.info.get("GL_MAX_TEXTURE_MAX_ANISOTROPY", 1.0) or 1.0)
            texture.anisotropy = min(PATTERN_ANISOTROPY, max_aniso)
        else:
            texture.filter = (mgl.NEAREST, mgl.NEAREST)
            texture.anisotropy = 1.0

    @property
    def pattern(self):
        """The current fabric's :class:`catalog.presets.patterns.Pattern` (None: uniform coverage)."""
        return self._pattern

    def pattern_mip_level(self, level: int) -> np.ndarray:
        """Level ``level`` of the pattern texture's mip chain as GL built it, (H, W, 4)."""
        texture = self._pattern_texture
        w = max(1, texture.width >> level)
        h = max(1, texture.height >> level)
        data = texture.read(level=level)
        return np.frombuffer(data, dtype=np.float32).reshape(h, w, 4).copy()

    def set_light(self, light) -> None:
        """A light name of the library (``D65``, ``sun:22``, ...) or a catalog.optics.lights.Light.

        The sun stands behind the window at the elevation its path length implies; a lamp at
        scene.LAMP_ELEVATION_DEG. :meth:`set_sun_hour` and :meth:`set_key_direction` move it.
        """
        from catalog.optics.lights import get_light  # noqa: PLC0415

        if isinstance(light, str):
            light = get_light(light)
        self.light = light
        self._is_sun = light.name.startswith(("sun:", "sun-clear:", "sun@"))
        try:
            elevation = scene_lib.key_elevation_for(light.name)
        except (ValueError, CatalogError):
            elevation = scene_lib.LAMP_ELEVATION_DEG
        self._key_to_light = scene_lib.key_direction(elevation)

    def set_sun_hour(self, hour: float) -> dict:
        """The sun at ``hour`` (local solar time, summer solstice, 34.7 N) behind the window."""
        from catalog.optics.lights import get_light  # noqa: PLC0415

        sun = scene_lib.sun_at_hour(hour)
        self.light = get_light(sun.light_name)
        self._is_sun = True
        self._key_to_light = scene_lib.key_direction(90.0 - sun.zenith_deg, sun.azimuth_deg)
        return {"hour": hour, "zenith_deg": sun.zenith_deg, "path_km": sun.path_km,
                "light": sun.light_name}

    def set_key_direction(self, elevation_deg: float, azimuth_deg: float = scene_lib.KEY_AZIMUTH_DEG) -> None:
        """Move the key light: azimuth 0 = straight behind the window, 180 = behind the viewer."""
        self._key_to_light = scene_lib.key_direction(elevation_deg, azimuth_deg)

    def set_fluorescence(self, mode: str) -> None:
        if mode not in FLUORESCENCE_MODES:
            raise CatalogError(f"fluorescence mode {mode!r}: choose one of {', '.join(FLUORESCENCE_MODES)}")
        self.mode = mode

    def set_room_lighting(self, on: bool) -> None:
        """Light the room through the curtain (shadow map, area light, bounce: issue 13) or
        keep the earlier constant room (a fraction of the key light plus the fill light)."""
        self.room_lighting = bool(on)

    def set_key_shadow(self, on: bool) -> None:
        """Shade the key light on the cloth by the window wall and the folds nearer the light
        (issue 11; curtain.frag KEY_SHADOW), or let it reach every fragment (the earlier frame)."""
        self.key_shadow = bool(on)

    def set_ambient_by_view(self, on: bool) -> None:
        """The cloth's ambient term by view (issue 11; the lobes integrated for the view's
        angle to the normal), or the normal view's at every angle (the earlier frame)."""
        self.ambient_by_view = bool(on)

    def set_room_bounces(self, bounces: str) -> None:
        """The room's diffuse bounces: "all" (the radiosity solve of
        :func:`catalog.render.room_light.radiosity_operator`, issue 11) or "one" (issue 13's
        single bounce, which left the walls and the floor too dark)."""
        if bounces not in room_light.ROOM_BOUNCES:
            raise InputError(f"{bounces!r}: choose one of {', '.join(room_light.ROOM_BOUNCES)}",
                             field="room bounces")
        self.room_bounces = bounces

    def set_room_lobe(self, on: bool) -> None:
        """The key's directional lobe in the room: spread over its HG lobe from the window's
        patches (True, issue 11: the path-traced floor by a voile under a low key was 1.5x the
        collimated beam's light) or kept in the collimated beam (False, issue 13's frame)."""
        self.room_lobe = bool(on)

    def set_room_side(self, solved: bool) -> None:
        """Light the curtain's room side by the room's solved light (True, issue 11's fourth
        round: the stand-ins were 1.6-3x the room's light under daylight and 1 % of it under
        UV-A, where the room is lit by the glow) or by the stand-ins (False: the fill light
        and the room's share of the ambient term, the earlier frame)."""
        self.room_side_solved = bool(solved)

    def set_wall_light(self, on: bool) -> None:
        """Light the cloth's window side by the window wall and its reveals where they hide
        the outside (True, issue 11's fifth round: the sunlit sill seen through the
        directional lobe was 40-57 % of the path-traced lace noon room's curtain bottom) or
        count those directions dark (False, before). Needs the room side's solved light and
        the outside's occlusion."""
        self.wall_light = bool(on)

    def window_front_z(self) -> float:
        """The plane of the room side's window patches (m): the front of the box around the
        closed curtain's folds (room_light.WINDOW_FRONT_Z), or the opening's when the curtain
        is open or ``window_box`` is off (before issue 11's ninth round)."""
        if self.window_box and not self.curtain_open:
            return room_light.WINDOW_FRONT_Z
        return scene_lib.ROOM_BOX[2][0]

    def box_active(self) -> bool:
        """Whether the room sees the curtain through the box round its folds (its front before
        the opening's plane: ``window_box`` on and the curtain closed)."""
        return self.window_front_z() > scene_lib.ROOM_BOX[2][0]

    def window_near(self) -> bool:
        """Whether room.frag takes the window's light per pixel on the window wall beside the
        opening (WINDOW_NEAR): with the box (its sides stand on that wall)."""
        return self.window_near_field and self.box_active()

    def set_window_near(self, on: bool) -> None:
        """The window wall within room_light.WINDOW_NEAR_M of the opening takes the window's
        light per pixel (True: it falls tenfold within a light-map texel there) or from the
        light map (False)."""
        self.window_near_field = bool(on)

    def wall_eyes_active(self) -> bool:
        """Whether the box's sides are captured from the wall eyes too (WALL_EYES)."""
        return self.wall_eyes and self.box_active()

    def set_wall_eyes(self, on: bool) -> None:
        """Capture the box's sides also from eyes by the window wall (room_light.WALL_EYES) and
        blend the two by the angle of the way to each receiving point (True); off: the side
        eyes' edge columns alone."""
        self.wall_eyes = bool(on)

    def set_window_box(self, on: bool) -> None:
        """The room sees the closed curtain through a box around its folds (the patches at the
        folds' front, the box's sides at the opening's edges: a wall seeing the window edge-on
        gets the flanks' light); off: through the opening's plane alone (before issue 11's
        ninth round)."""
        self.window_box = bool(on)

    def set_side_eyes(self, on: bool) -> None:
        """Capture the window for the room's direct light from the middle and two eyes towards
        the side walls, blended by the angle to each receiving point (True, issue 11's sixth
        round: under the UV lamp the folds' lit flanks, facing one way, glow about three times
        the shadowed, and the path-traced left wall got 1.3x the right's direct light while the
        one capture from the middle lit both alike) or from the middle alone (False, before)."""
        self.side_eyes = bool(on)

    def set_capture_folds(self, on: bool) -> None:
        """Let the room's captures of the window see, through the cloth's holes, the folds
        behind where they hide the outside (True, issue 11's sixth round: the frame's own
        patterned curtain composites them, the captures draw the flat cloth and showed the
        outside there, dark under the UV lamp) or the outside (False, before)."""
        self.capture_folds = bool(on)

    def set_secondary_dye(self, on: bool) -> None:
        """Pass the room's light and the folds' light through the cloth by the dye of what the
        key-lit cloth sends on, its forward share of the key and its glow (True, issue 11's
        seventh round, catalog.optics.dye_colour) or by the key's dye (False, before)."""
        self.secondary_dye = bool(on)

    def set_key_second_layer(self, on: bool) -> None:
        """Shade the cloth behind two layers of its folds with the key's beam through both (True,
        issue 11's seventh round: the front-layer map peeled into a second map, each layer
        passing the beam by its own coverage) or through the nearest alone (False, before: a
        point of voile behind two folds was 1.15-1.55x the path tracer's)."""
        self.key_second_layer = bool(on)

    def set_pattern_lod_bias(self, bias: float | bool) -> None:
        """The pattern's mip level bias (log2 of the filter's texel side): PATTERN_LOD_BIAS or
        True, the level whose filter has the pixel's box's variance (issue 11's eighth round);
        0 or False, the hardware's level (before: the lace's motifs blurred); any float in
        [-4, 4]."""
        bias = PATTERN_LOD_BIAS if bias is True else 0.0 if bias is False else float(bias)
        if not -4.0 <= bias <= 4.0:
            raise InputError(f"{bias}: a LOD bias in [-4, 4]", field="pattern LOD bias")
        self.pattern_lod_bias = bias

    def room_side_active(self) -> bool:
        """Whether the curtain's room side takes the room's solved light this frame: with the
        room lighting, the option on and the viewer in the room (from outside, the room lies
        behind the cloth and the stand-ins stay)."""
        return bool(self.room_lighting and self.room_side_solved and self.viewer_inside)

    def curtain_inputs(self):
        """The :class:`ShadingInputs` the curtain program shades with: :meth:`shading_inputs`,
        without the stand-ins for the room's light when :meth:`room_side_active`
        (:func:`catalog.render.scene.with_room_solved`). The float64 twin of a frame takes these."""
        inputs = self.shading_inputs()
        if not self.room_side_active():
            return inputs
        key = (self._inputs_key, "room_solved")
        if getattr(self, "_curtain_inputs_key", None) != key:
            self._curtain_inputs = scene_lib.with_room_solved(inputs)
            self._curtain_inputs_key = key
        return self._curtain_inputs

    def set_shadow_map_size(self, texels: int) -> None:
        """The side of the key light's maps (the room's transmittance map and the cloth's
        front-layer map): a power of two in SHADOW_MAP_SIZES' range (issue 11's Pareto)."""
        texels = int(texels)
        if texels not in SHADOW_MAP_SIZES:
            raise InputError(f"{texels}: choose one of {', '.join(map(str, SHADOW_MAP_SIZES))}",
                             field="shadow map size")
        if texels != self.shadow_texels:
            self.shadow_texels = texels
            self._release_room_resources()

    def _release_room_resources(self) -> None:
        """Free the room lighting's GL objects (made again on next use, e.g. at a new size)."""
        if self._room_gl is None:
            return
        if self.ctx.fbo in [obj for name, obj in self._room_gl.items() if name.endswith("_fbo")]:
            (self.ctx.screen or self.ctx.detect_framebuffer(0)).use()
        for obj in self._room_gl.values():
            obj.release()
        self._room_gl = None
        self._room_key = None

    def set_outside_by_view(self, on: bool) -> None:
        """The outside the lobes bring by the view's height (issue 11: the sky above the view's
        line, the ground below; u_ambient_tilt), or the outside averaged (the earlier frame)."""
        self.outside_by_view = bool(on)

    def set_sky_occlusion(self, on: bool) -> None:
        """Let the cloth's own folds hide part of the outside from its ambient term (issue 11;
        curtain.frag SKY_OCCLUSION), or let every fragment see the whole outside."""
        self.sky_occlusion = bool(on)

    def set_curtain_open(self, open_: bool) -> None:
        """Open: the curtain is drawn aside (not drawn, casts nothing, lights nothing)."""
        self.curtain_open = bool(open_)

    def set_room_lamps(self, lamps) -> None:
        """Lamps placed in the room: (light name or Light, (x, y, z) m) pairs, at most
        room_light.MAX_ROOM_LAMPS; each an isotropic point whose normal irradiance at 1 m is
        the light's spectrum. They light the room (not the curtain's shading)."""
        from catalog.optics.lights import get_light  # noqa: PLC0415

        lamps = list(lamps)
        if len(lamps) > room_light.MAX_ROOM_LAMPS:
            raise CatalogError(f"at most {room_light.MAX_ROOM_LAMPS} room lamps, got {len(lamps)}")
        self.room_lamps = [(get_light(light) if isinstance(light, str) else light,
                            room_light.check_lamp_position(position)) for light, position in lamps]

    def set_sky_model(self, on: bool) -> None:
        """The clear sky by direction (catalog/optics/sun/sky.py) or the earlier flat sky and ground."""
        self.sky_model = bool(on)
        self._room_key = None  # the window's capture sees the sky

    def set_environment(self, path) -> None:
        """An HDR latitude-longitude image (EXR, ...) as the view behind the window, scaled to
        the light's sky (catalog/render/environment.py); None: the procedural clear sky."""
        from catalog.render import environment as env  # noqa: PLC0415

        if self.environment is not None:
            self.environment[1].release()
            self.environment = None
        self._room_key = None  # the window's capture sees the outside
        if path is None:
            return
        pixels = env.load_environment(path)
        h, w = pixels.shape[:2]
        texture = self.ctx.texture((w, h), 3, data=np.ascontiguousarray(pixels[::-1]).tobytes(),
                                   dtype="f4")
        texture.filter = (self._moderngl.LINEAR, self._moderngl.LINEAR)
        texture.repeat_x, texture.repeat_y = True, False
        self.environment = (str(path), texture, env.upper_illuminance(pixels))
        self._room_key = None

    def set_bloom(self, on: bool) -> None:
        """Glare before the tone map (energy-preserving, bloom.frag) on or off."""
        self.bloom = bool(on)

    def set_bands(self, n_bands: int) -> None:
        self.n_bands = band_lib.check_band_count(n_bands)

    def set_camera(self, yaw_deg: float, pitch_deg: float, distance_m: float) -> None:
        self.camera = OrbitCamera(yaw_deg=float(yaw_deg), pitch_deg=float(pitch_deg),
                                  distance_m=float(distance_m))

    def set_exposure(self, multiplier: float) -> None:
        if not (math.isfinite(multiplier) and multiplier > 0):
            raise CatalogError(f"exposure {multiplier!r} must be a positive number")
        self.exposure = float(multiplier)

    def set_ev(self, ev100: float | None) -> None:
        """A fixed exposure (EV100, as a camera's), or None for the automatic exposure."""
        self.ev100 = None if ev100 is None else display_lib.check_ev(ev100)

    def set_white_balance(self, white_balance: str) -> None:
        """"room" (adapt to the light's white) or "camera" (fixed D65), see display.py."""
        if white_balance not in display_lib.WHITE_BALANCES:
            raise CatalogError(f"white balance {white_balance!r}: choose one of "
                               f"{', '.join(display_lib.WHITE_BALANCES)}")
        self.white_balance = white_balance

    # ------------------------------------------------------------------ mesh
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
        self._fabric_size_m = tuple(float(v) for v in fabric_size_m)
        self._release_own_buffers()
        self._curtain_buffers = {
            "position": self.ctx.buffer(positions.tobytes()),
            "normal": self.ctx.buffer(normals.tobytes()),
            "tangent": self.ctx.buffer(tangents.tobytes()),
            "uv": self.ctx.buffer(uvs.tobytes()),
            "index": self.ctx.buffer(indices.tobytes()),
        }
        coarse = room_light.coarse_grid_indices(uvs)
        if coarse is not None:  # the room's shadow map and occlusion maps draw this coarser grid
            self._curtain_buffers["coarse_index"] = self.ctx.buffer(coarse.tobytes())
        self._own_buffers = list(self._curtain_buffers.values())  # the cloth's are not ours
        self._curtain_format = "3f"
        self._mesh_offset = (0.0, 0.0, 0.0)
        self._vertex_count = count
        self._release_vaos()
        self.mesh_arrays = (positions, normals, tangents)
        self._mesh_version = getattr(self, "_mesh_version", 0) + 1

    def set_fabric_size(self, fabric_size_m) -> None:
        """The rest fabric's width and length (m) that uv 0..1 spans (the pattern's scale) for
        the current mesh, e.g. when another fabric hangs in the same grid."""
        size = tuple(float(v) for v in fabric_size_m)
        if len(size) != 2 or not all(math.isfinite(v) and v > 0 for v in size):
            raise CatalogError(f"fabric size {fabric_size_m!r} must be two positive lengths (m)")
        self._fabric_size_m = size

    def update_positions(self, positions, normals) -> None:
        """New positions and normals for the same vertices (a simulation frame)."""
        positions = np.ascontiguousarray(positions, dtype="f4").reshape(-1, 3)
        normals = np.ascontiguousarray(normals, dtype="f4").reshape(-1, 3)
        if positions.shape[0] != self._vertex_count or normals.shape[0] != self._vertex_count:
            raise CatalogError(f"update_positions: expected {self._vertex_count} vertices, "
                               f"got {positions.shape[0]}")
        if self._curtain_format != "3f":
            raise CatalogError("update_positions after bind_cloth_buffers / bind_cloth_vertex_buffer: "
                               "the cloth owns the buffers")
        self._curtain_buffers["position"].write(positions.tobytes())
        self._curtain_buffers["normal"].write(normals.tobytes())
        self.mesh_arrays = (positions, normals, self.mesh_arrays[2])
        self._mesh_version += 1

    def bind_cloth_buffers(self, position_buffer, normal_buffer) -> None:
        """Read positions and normals straight from GPU buffers (vec4 per vertex, xyz used),
        e.g. written by the cloth's compute shader; same vertex order as :meth:`set_mesh`."""
        expected = 16 * self._vertex_count
        if position_buffer.size < expected or normal_buffer.size < expected:
            raise CatalogError(f"cloth buffers hold fewer than {self._vertex_count} vec4 vertices")
        self._curtain_buffers["position"] = position_buffer
        self._curtain_buffers["normal"] = normal_buffer
        self._curtain_buffers.pop("interleaved", None)
        self._curtain_format = "3f 4x"
        self._release_vaos()

    def bind_cloth_vertex_buffer(self, vertex_buffer, index_buffer=None,
                                 offset_m=(0.0, 0.0, 0.0)) -> None:
        """Draw the cloth's interleaved dynamic buffer directly (docs/cloth.md: 48 bytes per
        vertex, [x y z 1 | nx ny nz 0 | tx ty tz w]), as the GPU backend writes it.

        ``index_buffer``: its uint32 triangles (default: those of the last :meth:`set_mesh`,
        which must then have the same vertex count). ``offset_m`` moves the cloth's frame into
        the scene (e.g. ``(0, scene.CURTAIN_TOP_Y - params.rod_y_m, scene.CURTAIN_Z)``).
        """
        count = vertex_buffer.size // 48
        if index_buffer is None and count != self._vertex_count:
            raise CatalogError(f"cloth vertex buffer holds {count} vertices, the mesh "
                               f"{self._vertex_count}: pass its index_buffer")
        self._curtain_buffers["interleaved"] = vertex_buffer
        if index_buffer is not None:
            self._curtain_buffers["index"] = index_buffer
            self._curtain_buffers.pop("coarse_index", None)  # another mesh: no coarse grid
        self._vertex_count = count
        self._curtain_format = "interleaved"
        self.set_mesh_offset(offset_m)
        self._release_vaos()

    def set_mesh_offset(self, offset_m) -> None:
        """Translate the curtain mesh (metres) in the vertex shader."""
        offset = tuple(float(v) for v in offset_m)
        if len(offset) != 3 or not all(math.isfinite(v) for v in offset):
            raise CatalogError(f"mesh offset {offset_m!r} must be three finite numbers (m)")
        self._mesh_offset = offset

    def _release_own_buffers(self) -> None:
        for buffer in getattr(self, "_own_buffers", []):
            buffer.release()
        self._own_buffers = []

    def _release_vaos(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        self._vaos.clear()

    # ------------------------------------------------------------------ derived state
    def _require_ready(self) -> None:
        if self.preset is None:
            raise CatalogError("no fabric set: call set_fabric first")
        if self.light is None:
            raise CatalogError("no light set: call set_light first")

    @property
    def viewer_inside(self) -> bool:
        return bool(self.camera.position[2] > scene_lib.WINDOW_Z)

    def shading_inputs(self):
        """The scene's :class:`catalog.optics.shading_reference.ShadingInputs` (rebuilt only on change)."""
        self._require_ready()
        key = (id(self.preset), self.light.name, id(self.light), tuple(self._key_to_light),
               self.mode, self.viewer_inside, self._is_sun)
        if key != self._inputs_key:
            self._inputs, self._decision = scene_lib.build_shading_inputs(
                self.preset, self.light.irradiance_w_m2_nm, self._key_to_light,
                is_sun=self._is_sun, fluorescence=self.mode, viewer_inside=self.viewer_inside,
                paper_beam=self.light.name.startswith("sun:"))
            self._inputs_key = key
            self._uniforms_key = None
        return self._inputs

    def _band_uniforms(self):
        inputs = self.curtain_inputs()
        key = (self._inputs_key, self.n_bands, self.room_side_active())
        if key != self._uniforms_key:
            self._uniforms = band_lib.band_uniforms(inputs, self.n_bands)
            self._uniforms_key = key
        return self._uniforms

    def variant_defines(self, gbuffer: bool = False) -> dict:
        """The switches of the curtain program this scene needs (not the specialised values)."""
        inputs = self.shading_inputs()
        defines = {"N_BANDS": self.n_bands, "NV4": band_lib.chunks(self.n_bands),
                   f"FLUORESCENCE_{inputs.fluorescence_mode.upper()}": True,
                   "SEE_THROUGH": inputs.direct > 0, "ANISOTROPIC": inputs.anisotropy != 0.0,
                   "GBUFFER": gbuffer, "SPECIALISED": self.specialise,
                   "SHARED_DIVISION": shared_division_safe(inputs.g_diff, inputs.g_spec)}
        if self.environment is not None and defines["SEE_THROUGH"]:
            defines["CURTAIN_ENVIRONMENT"] = True  # the see-through shows the image
        if self.room_lamps:
            defines["N_ROOM_LAMPS"] = len(self.room_lamps)   # the lamps light the cloth too
        if self.key_shadow and not self.curtain_open:
            defines["KEY_SHADOW"] = True   # the wall's and the folds' shadow on the cloth
        if self.sky_occlusion and not self.curtain_open:
            defines["SKY_OCCLUSION"] = True   # the folds hide part of the outside
            defines["N_OCCLUSION"] = room_light.OCCLUSION_DIRECTIONS
        if self.room_side_active():
            defines["ROOM_SIDE"] = True   # the room's own light on the cloth's room side
            if defines.get("SKY_OCCLUSION"):
                defines["OCCLUSION_MAPS"] = True   # the folds' maps (the G-buffer's view continuation)
                if self.wall_light:   # the wall and its reveals where the outside is walled
                    defines["WALL_LIGHT"] = True
                    defines["WALL_LOBE_SAMPLES"] = room_light.WALL_LOBE_SAMPLES
        if self.antialiasing == "msaa" and not gbuffer:
            defines["INTERPOLATION"] = "centroid"   # attributes from inside the triangle
        if self.patterned and not gbuffer:
            # the holes are drawn by the OIT composite: no see-through term in the shader
            defines.update({"PATTERN": True, "OIT": True, "SEE_THROUGH": False,
                            "PATTERN_LOD_BIAS": glsl_literal(self.pattern_lod_bias)})
        return defines

    def scene_values(self) -> dict:
        """The curtain shader's per-scene values (uniform name -> value), float32-exact."""
        inputs = self.shading_inputs()
        values = {
            "u_key_to_light": tuple(float(v) for v in inputs.key_to_light),
            "u_fill_to_light": tuple(float(v) for v in inputs.fill_to_light),
            "u_sun_direction": tuple(float(v) for v in inputs.key_to_light),
            "u_sun_chord2": tuple(float(v) for v in inputs.sun_chord2),
            "u_direct": float(inputs.direct), "u_a_diff": float(inputs.a_diff),
            "u_g_diff": float(inputs.g_diff), "u_a_spec": float(inputs.a_spec),
            "u_g_spec": float(inputs.g_spec), "u_anisotropy": float(inputs.anisotropy),
        }
        for name, value in self._band_uniforms().items():
            values[name] = tuple(float(v) for v in value) if isinstance(value, tuple) else value
        if not self.ambient_by_view:   # the normal view's ambient at every angle
            for name in ("u_ambient_view_outside", "u_ambient_view_room"):
                values[name] = np.ones_like(values[name])
        if not self.outside_by_view:   # the outside averaged, sky and ground alike
            values["u_ambient_tilt"] = np.zeros_like(values["u_ambient_tilt"])
        return values

    def room_lamp_values(self) -> dict:
        """ROOM_LAMPS' uniforms: each lamp's position (m) and its intensity (irradiance at 1 m,
        isotropic) times the dye, in the renderer's bands (the key light's band weights)."""
        key = (self._inputs_key, self.n_bands,
               tuple((light.name, position) for light, position in self.room_lamps))
        if getattr(self, "_lamp_values_key", None) != key:
            inputs = self.shading_inputs()
            weights, _ = band_lib.band_weights(self.n_bands, inputs.key_irradiance)
            nv4 = band_lib.chunks(self.n_bands)
            dyed = np.zeros((len(self.room_lamps), 4 * nv4), dtype="f4")
            for j, (light, _position) in enumerate(self.room_lamps):
                dyed[j, :self.n_bands] = weights @ (light.irradiance_w_m2_nm * inputs.dye_transmittance)
            self._lamp_values = {
                "u_room_lamp_position": np.asarray([p for _l, p in self.room_lamps], dtype="f4"),
                "u_room_lamp_dyed": dyed.reshape(-1, 4)}
            self._lamp_values_key = key
        return self._lamp_values

    def _curtain_program(self, gbuffer: bool, overrides: dict | None = None, folds_behind: bool = False):
        defines = self.variant_defines(gbuffer)
        if overrides:
            defines["ROOM_CAPTURE"] = True  # the room's window capture (issue 13), not the frame's
            defines.pop("ROOM_SIDE", None)  # the radiosity reflects the room's light off the cloth
            defines.pop("OCCLUSION_MAPS", None)
            defines.pop("WALL_LIGHT", None)
            defines.pop("WALL_LOBE_SAMPLES", None)
            if folds_behind and defines.get("SKY_OCCLUSION"):
                # the folds' window side where they hide the outside (curtain.frag FOLDS_BEHIND;
                # ROOM_SIDE without the room's part under ROOM_CAPTURE)
                defines.update({"ROOM_SIDE": True, "OCCLUSION_MAPS": True, "FOLDS_BEHIND": True})
        if self.specialise:
            for name, value in self._scene_values_with(overrides).items():
                defines["S_" + name[2:].upper()] = glsl_literal(value)
        return self._program("curtain.vert", "curtain.frag", defines)

    def _scene_values_with(self, overrides: dict | None) -> dict:
        values = self.scene_values()
        if overrides:
            values = {**values, **overrides}
        return values

    def _capture_overrides(self) -> dict:
        """The curtain's values for the luminaire capture: without the sun's disc seen through
        it (the key light's beam reaches the room through the shadow map instead), without the
        key light scattered by the directional lobe (the beam carries it: counted in both, the
        room was up to 1.6x too bright under a low key), and without the room's light on its
        room side (the fill light and the room's share of the ambient term, stand-ins for it,
        and the lamps): the radiosity pass reflects the room's own
        light off the closed curtain (:meth:`window_albedo_rgb`), so the capture holds only
        what comes from outside and the glow."""
        values = self.scene_values()

        def zeros(value):
            return np.zeros_like(value) if isinstance(value, np.ndarray) else tuple(0.0 for _ in value)

        out = {"u_sun_disc": zeros(values["u_sun_disc"]), "u_fill_dyed": zeros(values["u_fill_dyed"]),
               "u_ambient": values["u_ambient_outside"]}
        # the directional lobe's share of the key travels in the beam (room_shadow.frag's
        # thread part), not in the window's radiance
        out["u_a_spec"] = 0.0
        if self.room_lamps:
            dyed = self.room_lamp_values()["u_room_lamp_dyed"]
            out["u_room_lamp_dyed"] = np.zeros_like(dyed)
        return out

    def _back_capture_overrides(self) -> dict:
        """The curtain's values for the capture of its window side (issue 11): as the room
        side's (:meth:`_capture_overrides`) but with the directional lobe (its backward part is
        reflection, which the beam does not carry) and without the see-through (from outside,
        the cloth's holes show the room, which is not a source of the window wall's light)."""
        values = self.scene_values()
        out = self._capture_overrides()
        out["u_a_spec"] = values["u_a_spec"]
        out["u_direct"] = 0.0
        out.update(self._window_side_ambient())
        return out

    def _window_side_ambient(self) -> dict:
        """The ambient term of the cloth's window side seen from outside (issue 11, fourth
        round): the outside reflected by the lobes' backward factors, dye (a_diff backward(g_diff)
        + a_spec backward(g_spec)) x the outside's mean radiance, at the normal view's ratio, the
        sky and ground not split (the room eye's own terms, kept before, sent the outside's
        forward-scattered share, the light that crosses to the room, back out of the window)."""
        from dataclasses import replace  # noqa: PLC0415

        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        key = (self._inputs_key, self.n_bands, self.room_side_active())
        if getattr(self, "_window_side_key", None) != key:
            inputs = self.curtain_inputs()
            backward = (inputs.a_diff * hg_hemisphere_factors(inputs.g_diff)[1]
                        + inputs.a_spec * hg_hemisphere_factors(inputs.g_spec)[1])
            reflected = (inputs.dye_transmittance * backward
                         * 0.5 * (inputs.sky_radiance + inputs.ground_radiance))
            banded = band_lib.band_uniforms(replace(inputs, ambient_radiance=reflected,
                                                    ambient_outside_radiance=reflected,
                                                    ambient_tilt_radiance=None), self.n_bands)
            values = self.scene_values()
            self._window_side_values = {
                "u_ambient": banded["u_ambient"], "u_ambient_outside": banded["u_ambient_outside"],
                "u_ambient_occluded": banded["u_ambient_occluded"],
                "u_ambient_tilt": np.zeros_like(values["u_ambient_tilt"]),
                "u_ambient_view_outside": np.ones_like(values["u_ambient_view_outside"]),
                "u_ambient_view_room": np.ones_like(values["u_ambient_view_room"])}
            self._window_side_key = key
        return self._window_side_values

    def _program(self, vertex: str, fragment: str, defines: dict | None = None):
        key = (vertex, fragment, tuple(sorted((defines or {}).items())))
        if key not in self._programs:
            self._evict_specialised()
            self._programs[key] = create_program(self.ctx, vertex, fragment, defines)
        return self._programs[key]

    def _evict_specialised(self) -> None:
        """Keep at most MAX_SPECIALISED specialised programs (oldest released first)."""
        specialised = [k for k in self._programs if dict(k[2]).get("SPECIALISED")]
        for key in specialised[:max(0, len(specialised) - MAX_SPECIALISED + 1)]:
            program = self._programs.pop(key)
            vao = self._vaos.pop(("curtain", id(program)), None)
            if vao is not None:
                vao.release()
            program.release()

    def compiled_variants(self) -> list[dict]:
        """The switches of every curtain program compiled so far for the frame itself (for
        tests and reports; the room's window capture, ROOM_CAPTURE, is left out)."""
        return [{k: v for k, v in k2[2] if not k.startswith("S_")}
                for k2 in self._programs
                if k2[1] == "curtain.frag" and not dict(k2[2]).get("ROOM_CAPTURE")]

    def _curtain_vao(self, program):
        key = ("curtain", id(program))
        if key not in self._vaos:
            b = self._curtain_buffers
            if self._curtain_format == "interleaved":
                names = [n for n in ("in_position", "in_normal", "in_tangent") if n in program]
                layout = " ".join("3f 4x" if n in program else "16x"
                                  for n in ("in_position", "in_normal", "in_tangent"))
                content = [(b["interleaved"], layout, *names)]
            else:
                content = [(b["position"], self._curtain_format, "in_position")]
                if "in_normal" in program:
                    content.append((b["normal"], self._curtain_format, "in_normal"))
                if "in_tangent" in program:
                    content.append((b["tangent"], "3f", "in_tangent"))
            if "in_uv" in program:
                content.append((b["uv"], "2f", "in_uv"))
            self._vaos[key] = self.ctx.vertex_array(
                program, content, index_buffer=b["index"], index_element_size=4)
        return self._vaos[key]

    def _room_vao(self, program):
        key = ("room", id(program))
        if key not in self._vaos:
            self._vaos[key] = self.ctx.vertex_array(
                program, [(self._room_vbo, "3f 3f", "in_position", "in_normal")])
        return self._vaos[key]

    def _fullscreen_vao(self, program):
        key = ("fullscreen", id(program))
        if key not in self._vaos:
            self._vaos[key] = self.ctx.vertex_array(program, [])
        return self._vaos[key]

    @staticmethod
    def _set(program, name, value) -> None:
        if name not in program:
            return  # optimised away in this variant
        if isinstance(value, np.ndarray):
            program[name].write(np.ascontiguousarray(value, dtype="f4").tobytes())
        elif isinstance(value, bytes):
            program[name].write(value)
        else:
            program[name].value = value

    def current_ev100(self) -> float:
        """The EV100 the next display pass uses (fixed, or the auto exposure's)."""
        if self.ev100 is not None:
            return self.ev100
        if self.metered_ev100 is None:
            raise CatalogError("auto exposure: nothing metered yet (render a frame first)")
        return self.metered_ev100

    def exposure_scale(self) -> float:
        """Linear radiance (cd m^-2) -> scene value the tone curve takes (EV and multiplier)."""
        return self.exposure * display_lib.exposure_scale(self.current_ev100())

    def white_balance_matrix(self) -> np.ndarray:
        """Linear sRGB -> linear sRGB: CAT16 from the white of the light reaching the viewer to
        D65, with CAT16's degree of adaptation (catalog.render.adaptation), or the identity."""
        inputs = self.shading_inputs()
        key = (self._inputs_key, self.white_balance)
        if self._wb_cache is None or self._wb_cache[0] != key:
            from catalog.render import adaptation  # noqa: PLC0415

            self._wb_cache = (key, display_lib.white_balance_matrix(
                adaptation.adapting_white_xyz(inputs), self.white_balance,
                adaptation.degree_of_adaptation()))
        return self._wb_cache[1]

    def display_uniforms(self) -> dict:
        return display_lib.shader_uniforms(self.exposure_scale(), self.white_balance_matrix())

    def meter(self, vw: int, vh: int) -> float:
        """EV100 of the HDR target's (vw, vh) corner: a histogram of a mip level (at most
        METER_MAX_SIDE_PX wide), white-balanced, of display.meter_signal (largest channel)."""
        level = 0
        while max(vw, vh) >> level > METER_MAX_SIDE_PX:
            level += 1
        if level:
            self._hdr.build_mipmaps(0, level)
            self._hdr.filter = (self._moderngl.NEAREST, self._moderngl.NEAREST)
        w, h = max(1, self.size[0] >> level), max(1, self.size[1] >> level)
        data = np.frombuffer(self._hdr.read(level=level), dtype=np.float32).reshape(h, w, 4)
        cw, ch = max(1, -(-vw >> level)), max(1, -(-vh >> level))
        rgb = data[:ch, :cw, :3].astype(np.float64) @ self.white_balance_matrix().T  # as shown
        return display_lib.meter_ev100(display_lib.luminance_histogram(display_lib.meter_signal(rgb)))

    # ------------------------------------------------------------------ passes
    def _scene_uniforms(self, program, view_proj, inputs, camera_position=None) -> None:
        s = self._set
        s(program, "u_view_proj", gl_bytes(view_proj))
        eye = self.camera.position if camera_position is None else camera_position
        s(program, "u_camera_position", tuple(float(v) for v in eye))
        s(program, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_fill_to_light", tuple(float(v) for v in inputs.fill_to_light))
        s(program, "u_sun_direction", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_sun_chord2", tuple(float(v) for v in inputs.sun_chord2))

    def draw_curtain(self, view_proj, fragment: str | None = None, gbuffer: bool = False,
                     camera_position=None, overrides: dict | None = None,
                     folds_behind: bool = False) -> None:
        """The curtain pass alone into the bound framebuffer.

        ``fragment``: draw the same mesh (same vertex shader and uniforms of the mesh and
        camera) with this fragment shader file instead of the curtain's: how a benchmark
        measures the rasteriser's floor with shaders of its own (catalog/bench/shaders/).
        ``camera_position``: the eye for the view-dependent terms (default the camera's; the
        room's passes draw the curtain as seen from the key light or the room);
        ``overrides``: scene values replaced for this draw; ``folds_behind``: with ``overrides``, the room capture's variant that
        shows the folds behind through the holes (curtain.frag FOLDS_BEHIND)."""
        eye = tuple(float(v) for v in (self.camera.position if camera_position is None
                                       else camera_position))
        if fragment is not None:
            program = self._program("curtain.vert", fragment)
            self._set(program, "u_view_proj", gl_bytes(view_proj))
            self._set(program, "u_mesh_offset", self._mesh_offset)
            self._set(program, "u_camera_position", eye)
        else:
            program = self._curtain_program(gbuffer, overrides, folds_behind)
            self._set(program, "u_view_proj", gl_bytes(view_proj))
            self._set(program, "u_camera_position", eye)
            self._set(program, "u_mesh_offset", self._mesh_offset)
            if "u_pattern" in program:
                self._pattern_texture.use(location=PATTERN_UNIT)
                self._set(program, "u_pattern", PATTERN_UNIT)
                self._set(program, "u_uv_to_repeats",
                          tuple(f / r for f, r in zip(self._fabric_size_m, self._pattern_repeat_m)))
                self._set(program, "u_inv_mean_coverage", 1.0 / max(self._pattern_mean_coverage, 1e-6))
                self._set(program, "u_oit_depth_ref", self.oit_depth_reference_m())
            if not self.specialise:
                for name, value in self._scene_values_with(overrides).items():
                    self._set(program, name, value)
            if self.room_lamps:
                for name, value in self.room_lamp_values().items():
                    if overrides and name in overrides:
                        value = overrides[name]
                    self._set(program, name, value)
            if "u_environment" in program:
                self.environment[1].use(location=ENVIRONMENT_UNIT)
                self._set(program, "u_environment", ENVIRONMENT_UNIT)
                self._set(program, "u_environment_scale", self.environment_scale(self.shading_inputs()))
            if "u_key_front" in program:
                self._key_shadow_uniforms(program, self.shading_inputs())
            if "u_room_side" in program or "u_window_side_cloth" in program:   # (FOLDS_BEHIND: no room part)
                self._room_side_uniforms(program)
            if "u_capture_thread" in program:
                inputs = self.shading_inputs()
                self._set(program, "u_capture_thread", float(self._room_colours(inputs)["capture_thread"]))
            if "u_vertex_occlusion" in program:
                self._vertex_occlusion_uniforms(program)
        self.ctx.disable(self._moderngl.CULL_FACE)  # two-sided cloth
        self._curtain_vao(program).render(self._moderngl.TRIANGLES)

    def _display_colours(self, inputs) -> dict[str, tuple]:
        """Exact linear sRGB of the background and room radiances (once per scene change)."""
        if getattr(self, "_display_key", None) != self._inputs_key:
            spectra = {"u_sky_rgb": inputs.sky_radiance, "u_ground_rgb": inputs.ground_radiance,
                       "u_sun_disc_rgb": inputs.sun_disc_radiance,
                       "u_room_rgb": inputs.room_radiance,
                       "u_fill_rgb": scene_lib.ROOM_ALBEDO * inputs.fill_irradiance / math.pi,
                       "u_key_rgb": inputs.key_irradiance}
            self._display = {name: tuple(float(v) for v in band_lib.spectrum_to_display_rgb(s))
                             for name, s in spectra.items()}
            self._display_key = self._inputs_key
        return self._display

    def sky_model_for(self, inputs):
        """The clear sky behind the window (catalog/optics/sun/sky.py) with the irradiance and
        colour of the curtain's own sky term (inputs.sky_radiance), so the two agree."""
        from catalog.optics.sun.sky import sky_model  # noqa: PLC0415

        return sky_model(inputs.key_to_light, diffuse_horizontal=math.pi * inputs.sky_radiance,
                         ground_radiance=inputs.ground_radiance)

    def _sky(self, inputs):
        """The clear-sky model for a sun above the horizon (catalog/optics/sun/sky.py), else None."""
        if not (self.sky_model and self._is_sun and inputs.key_to_light[1] > 1e-3):
            return None
        key = (self._inputs_key, self.n_bands)
        if getattr(self, "_sky_key", None) != key:
            from catalog.optics.colorimetry import xyz_to_linear_srgb  # noqa: PLC0415
            from catalog.optics.sun.sky import HAZE_RAD  # noqa: PLC0415

            model = self.sky_model_for(inputs)
            self._sky_value = {
                "u_perez": np.asarray(model.perez, dtype="f4"),
                "u_zenith_xyY": tuple(float(v) for v in model.zenith),
                "u_perez_sun": tuple(float(v) for v in np.ravel(model.perez_sun)),
                "u_sky_scale": tuple(float(v) for v in model.scale_rgb),
                "u_xyz_to_rgb": gl_bytes_mat3(xyz_to_linear_srgb(np.eye(3)).T),
                "u_haze_rad": HAZE_RAD,
                "u_ground_rgb": tuple(float(v) for v in model.ground_rgb),
            }
            if self.n_bands != 3:
                self._sky_value.update(self._sky_band_values(inputs))
            self._sky_key = key
        return self._sky_value

    def spectral_sky_for(self, inputs):
        """The sky of :meth:`sky_model_for` per wavelength (catalog/optics/sun/sky.py SpectralSky)."""
        from catalog.optics.sun.sky import spectral_sky  # noqa: PLC0415

        return spectral_sky(inputs.key_to_light, math.pi * inputs.sky_radiance, inputs.ground_radiance)

    def _sky_band_values(self, inputs) -> dict:
        """SKY_BANDS' uniforms: the sky and the ground integrated over the renderer's bands (the
        key light's band weights and display matrix, as the curtain's own terms)."""
        weights, to_rgb = band_lib.band_weights(self.n_bands, inputs.key_irradiance)
        colours = self.spectral_sky_for(inputs).band_colours(weights, to_rgb)
        return {"u_sky_basis_rgb": np.asarray(colours["basis_rgb"], dtype="f4"),
                "u_sky_basis_luminance": tuple(float(v) for v in colours["basis_luminance"]),
                "u_ground_rgb": tuple(float(v) for v in colours["ground_rgb"])}

    def environment_scale(self, inputs) -> float:
        """The environment image's factor: its upper hemisphere's horizontal illuminance made
        the light's sky's, pi x Y(sky radiance) (the clear sky's diffuse illuminance for the
        sun, the lit backdrop's for a lamp)."""
        target = math.pi * float(np.dot(band_lib.spectrum_to_display_rgb(inputs.sky_radiance),
                                        (0.2126, 0.7152, 0.0722)))
        return target / self.environment[2]

    def _draw_background(self, view_proj, inputs, camera_position=None, sun_disc=True,
                         capture: bool = False) -> None:
        """The outside by direction; ``capture``: for the room's window capture (alpha 0)."""
        sky = None if self.environment is not None else self._sky(inputs)
        program = self._program("fullscreen.vert", "background.frag",
                                {"SKY_MODEL": sky is not None,
                                 "SKY_BANDS": sky is not None and self.n_bands != 3,
                                 "ENVIRONMENT": self.environment is not None,
                                 "ROOM_CAPTURE": capture})
        self._scene_uniforms(program, view_proj, inputs, camera_position)
        if self.environment is not None:
            self.environment[1].use(location=ENVIRONMENT_UNIT)
            self._set(program, "u_environment", ENVIRONMENT_UNIT)
            self._set(program, "u_environment_scale", self.environment_scale(inputs))
        self._set(program, "u_inverse_view_proj", gl_bytes(np.linalg.inv(view_proj)))
        colours = self._display_colours(inputs)
        for name in ("u_sky_rgb", "u_ground_rgb", "u_sun_disc_rgb", "u_room_rgb"):
            self._set(program, name, colours[name])
        if sky is not None:
            for name, value in sky.items():
                self._set(program, name, value)
        if not sun_disc:
            self._set(program, "u_sun_disc_rgb", (0.0, 0.0, 0.0))
        if capture:
            self._set(program, "u_capture_opening", scene_lib.WINDOW_RECT)
            self._set(program, "u_capture_wall_z", scene_lib.ROOM_BOX[2][0])
        self._fullscreen_vao(program).render(self._moderngl.TRIANGLES, vertices=3)

    def _room_order(self, to_light) -> int:
        """Reorder the room's triangles so that those facing the key light come first;
        returns their vertex count (cached per key direction)."""
        key = tuple(float(v) for v in to_light)
        if getattr(self, "_room_order_key", None) != key:
            positions, normals = scene_lib.room_props()
            facing = (normals[0::3] @ np.asarray(to_light, dtype=np.float32)) > 0.0
            order = np.concatenate([np.flatnonzero(facing), np.flatnonzero(~facing)])
            tri_p = positions.reshape(-1, 3, 3)[order].reshape(-1, 3)
            tri_n = normals.reshape(-1, 3, 3)[order].reshape(-1, 3)
            self._room_vbo.write(np.hstack([tri_p, tri_n]).astype("f4").tobytes())
            self._room_order_key = key
            self._room_facing = 3 * int(facing.sum())
        return self._room_facing

    def _draw_room(self, view_proj, inputs) -> None:
        lit = self.room_lighting
        if lit:
            facing = self._room_order(inputs.key_to_light)
            total = self._room_vbo.size // 24
            self.ctx.enable(self._moderngl.CULL_FACE)
            for beam, first, count in ((True, 0, facing), (False, facing, total - facing)):
                if count:
                    program = self._program("room.vert", "room.frag",
                                            {"ROOM_LIGHTING": True, "KEY_BEAM": beam,
                                             **self._window_light_defines(),
                                             **({"WINDOW_NEAR": True} if self.window_near() else {})})
                    self._room_lit_uniforms(program, view_proj, inputs)
                    self._room_vao(program).render(self._moderngl.TRIANGLES, vertices=count,
                                                   first=first)
            self.ctx.disable(self._moderngl.CULL_FACE)
            self._draw_rings(program)  # the last (beam-free) program
            return
        program = self._program("room.vert", "room.frag", {"ROOM_LIGHTING": False})
        self._scene_uniforms(program, view_proj, inputs)
        colours = self._display_colours(inputs)
        self._set(program, "u_room_rgb", colours["u_room_rgb"])
        self._set(program, "u_fill_rgb", colours["u_fill_rgb"])
        self.ctx.enable(self._moderngl.CULL_FACE)
        self._room_vao(program).render(self._moderngl.TRIANGLES)
        self.ctx.disable(self._moderngl.CULL_FACE)
        self._draw_rings(program)

    def _draw_rings(self, program) -> None:
        """The curtain's rings on the rod (issue 12), with the room's program (no culling)."""
        if getattr(self, "_ring_vbo", None) is None:
            return
        key = ("rings", id(program))
        if key not in self._vaos:
            self._vaos[key] = self.ctx.vertex_array(
                program, [(self._ring_vbo, "3f 3f", "in_position", "in_normal")])
        self._vaos[key].render(self._moderngl.TRIANGLES)

    def _room_lit_uniforms(self, program, view_proj, inputs) -> None:
        self._scene_uniforms(program, view_proj, inputs)
        gl = self._room_gl
        self._room_common_uniforms(program, inputs)
        self._set(program, "u_face_texels", float(room_light.FACE_TEXELS))
        gl["lightmap"].use(location=1)
        self._set(program, "u_lightmap", 1)
        gl["shadow"].use(location=2)
        self._set(program, "u_shadow", 2)
        self._set(program, "u_shadow_texel_m", room_light.shadow_texel_m(inputs.key_to_light, self.shadow_texels))
        self._set(program, "u_curtain_z", scene_lib.CURTAIN_Z)
        reveals = self._reveal_inputs(inputs)
        self._set(program, "u_reveal_sky", reveals["sky_half"])
        self._set(program, "u_reveal_ground", reveals["ground_half"])
        self._window_light_uniforms(program, inputs)   # the window side on unit 3 (the reveals)
        if self.window_near():
            gl["direct"].use(location=6)
            self._set(program, "u_lightmap_direct", 6)
            gl["window_near"].use(location=8)
            self._set(program, "u_window_near", 8)
            self._set(program, "u_near_rect", room_light.window_near_rect())
            self._set(program, "u_near_m", room_light.WINDOW_NEAR_M)
            self._set(program, "u_near_fade_m", room_light.WINDOW_NEAR_FADE_M)
        self._set(program, "u_reveal_back_level", reveals["back_level"])
        self._set(program, "u_reveal_back_size", reveals["back_size"])

    def _reveal_inputs(self, inputs) -> dict:
        """common.glsl reveal_irradiance's inputs besides the point (room.frag's reveals and
        WALL_LIGHT's): 0.5 pi x the sky's and the ground's radiance (linear sRGB), and the
        window-side capture's level of 2 x 2 patches a texel and that level's size."""
        colours = self._display_colours(inputs)
        level = room_light.BACK_LUMINAIRE_LEVEL + 1
        return {"sky_half": tuple(0.5 * math.pi * v for v in colours["u_sky_rgb"]),
                "ground_half": tuple(0.5 * math.pi * v for v in colours["u_ground_rgb"]),
                "back_level": level,
                "back_size": tuple(max(v >> level, 1) for v in
                                   room_light.luminaire_capture_size(room_light.BACK_LUMINAIRE_LEVEL))}

    def read_luminaire_back(self, level: int) -> np.ndarray:
        """The window-side capture at mip ``level``, float32 (H, W, 3), row 0 = the opening's bottom."""
        return self.read_luminaire(level, "luminaire_back")

    def read_window_near(self) -> np.ndarray:
        """room_window_near.frag's grid, float32 (N, N, 3), row 0 = its rectangle's bottom."""
        texture = self._room_resources()["window_near"]
        w, h = texture.size
        return np.frombuffer(texture.read(), dtype="f2").reshape(h, w, 4)[..., :3].astype(np.float32)

    def read_wall_captures(self) -> np.ndarray:
        """The wall eyes' captures of the box's sides at their patch level, float32 (2, 9, 3)
        (left, right; row 0 = the opening's bottom)."""
        both = self.read_luminaire(room_light.WALL_EYE_LEVEL, "luminaire_walls")
        return np.stack([both[:, 0], both[:, 1]])

    def read_side_captures(self) -> np.ndarray:
        """The side eyes' captures at their patch level, float32 (2, H, W, 3) (left, right; row
        0 = the opening's bottom), as room_lightmap.frag reads them."""
        level = room_light.SIDE_LUMINAIRE_LEVEL
        both = self.read_luminaire(level, "luminaire_sides")
        width = both.shape[1] // 2
        return np.stack([both[:, :width], both[:, width:]])

    def read_luminaire(self, level: int, name: str = "luminaire") -> np.ndarray:
        """The room-side capture (or ``name``) at mip ``level``, float32 (H, W, 3), row 0 = the
        opening's bottom."""
        texture = self._room_resources()[name]
        w, h = (max(v >> level, 1) for v in texture.size)
        data = texture.read(level=level)
        return np.frombuffer(data, dtype="f4").reshape(h, w, 4)[..., :3].copy()

    # ------------------------------------------------------------------ the room's light (issue 13)
    def _room_resources(self) -> dict:
        """The room lighting's GL objects, made on first use (docs/room.md)."""
        if self._room_gl is None:
            mgl, ctx = self._moderngl, self.ctx
            n = self.shadow_texels
            shadow = ctx.texture((n, n), 4, dtype="f2")
            shadow.filter = (mgl.LINEAR_MIPMAP_LINEAR, mgl.LINEAR)
            shadow.repeat_x = shadow.repeat_y = False
            lw, lh = room_light.luminaire_capture_size()
            luminaire = ctx.texture((lw, lh), 4, dtype="f4")
            luminaire.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            luminaire_depth = ctx.depth_renderbuffer((lw, lh))
            sw, sh = room_light.luminaire_capture_size(room_light.SIDE_LUMINAIRE_LEVEL)
            sides = ctx.texture((2 * sw, sh), 4, dtype="f4")   # the side eyes', left then right
            sides.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            sides_depth = ctx.depth_renderbuffer((2 * sw, sh))
            nt = room_light.WINDOW_NEAR_TEXELS
            # room_window_near.frag's grid, half floats: a web page filters them linearly
            # without OES_texture_float_linear (3e3 at most under the noon sun; 5e-4 relative)
            window_near = ctx.texture((nt, nt), 4, dtype="f2")
            window_near.filter = (mgl.LINEAR, mgl.LINEAR)
            window_near.repeat_x = window_near.repeat_y = False
            ww, wh = room_light.wall_eye_capture_size()
            walls = ctx.texture((2 * ww, wh), 4, dtype="f4")   # the wall eyes', left then right
            walls.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            walls_depth = ctx.depth_renderbuffer((2 * ww, wh))
            bw, bh = room_light.luminaire_capture_size(room_light.BACK_LUMINAIRE_LEVEL)
            luminaire_back = ctx.texture((bw, bh), 4, dtype="f4")
            luminaire_back.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            luminaire_back_depth = ctx.depth_renderbuffer((bw, bh))
            aw, ah = room_light.atlas_size()
            direct = ctx.texture((aw, ah), 4, dtype="f4")
            direct.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            beam = ctx.texture((aw, ah), 4, dtype="f4")
            beam.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            lightmap = ctx.texture((aw, ah), 4, dtype="f4")
            lightmap.filter = (mgl.LINEAR, mgl.LINEAR)
            lightmap.repeat_x = lightmap.repeat_y = False
            ao = ctx.texture((aw, ah), 4, data=room_light.ao_and_mask_texture().tobytes(), dtype="f4")
            ao.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            ao.build_mipmaps()
            key_front = ctx.texture((n, n), 4, dtype="f4")
            key_front.filter = (mgl.NEAREST, mgl.NEAREST)
            key_front.repeat_x = key_front.repeat_y = False
            key_front_depth = ctx.depth_renderbuffer((n, n))
            key_second = ctx.texture((n, n), 4, dtype="f4")   # the front-layer map peeled
            key_second.filter = (mgl.NEAREST, mgl.NEAREST)
            key_second.repeat_x = key_second.repeat_y = False
            key_second_depth = ctx.depth_renderbuffer((n, n))
            side = self._occlusion_grid() * room_light.OCCLUSION_TEXELS
            occlusion = ctx.texture((side, side), 4, dtype="f4")
            occlusion.filter = (mgl.NEAREST, mgl.NEAREST)
            occlusion_depth = ctx.depth_renderbuffer((side, side))
            self._room_gl = {
                "key_front": key_front, "key_front_depth": key_front_depth,
                "key_front_fbo": ctx.framebuffer([key_front], key_front_depth),
                "key_second": key_second, "key_second_depth": key_second_depth,
                "key_second_fbo": ctx.framebuffer([key_second], key_second_depth),
                "occlusion": occlusion, "occlusion_depth": occlusion_depth,
                "occlusion_fbo": ctx.framebuffer([occlusion], occlusion_depth),
                "shadow": shadow, "shadow_fbo": ctx.framebuffer([shadow]),
                "luminaire": luminaire, "luminaire_depth": luminaire_depth,
                "luminaire_fbo": ctx.framebuffer([luminaire], luminaire_depth),
                "luminaire_sides": sides, "luminaire_sides_fbo": ctx.framebuffer([sides], sides_depth),
                "luminaire_walls": walls, "luminaire_walls_fbo": ctx.framebuffer([walls], walls_depth),
                "window_near": window_near, "window_near_fbo": ctx.framebuffer([window_near]),
                "luminaire_back": luminaire_back,
                "luminaire_back_fbo": ctx.framebuffer([luminaire_back], luminaire_back_depth),
                "direct": direct, "beam": beam, "direct_fbo": ctx.framebuffer([direct, beam]),
                "lightmap": lightmap, "lightmap_fbo": ctx.framebuffer([lightmap]), "ao": ao,
            }
            rc = room_light.FACE_TEXELS >> room_light.BOUNCE_LEVEL
            patches = len(room_light.FACE_NAMES) * rc * rc
            bounces = ctx.texture((patches, patches), 3, dtype="f4")   # written by _radiosity_operator
            bounces.filter = (mgl.NEAREST, mgl.NEAREST)
            total = ctx.texture((len(room_light.FACE_NAMES) * rc, rc), 4, dtype="f4")
            total.filter = (mgl.NEAREST, mgl.NEAREST)
            tw, th = room_light.CURTAIN_SIDE_TEXELS
            side_light = ctx.texture((tw, th), 4, data=np.zeros((th, tw, 4), "f4").tobytes(), dtype="f4")
            side_light.filter = (mgl.LINEAR, mgl.LINEAR)
            side_light.repeat_x = side_light.repeat_y = False
            self._room_gl.update({"radiosity_operator": bounces, "total": total,
                                  "total_fbo": ctx.framebuffer([total]),
                                  "room_side": side_light, "room_side_fbo": ctx.framebuffer([side_light])})
            self._operator_albedo = None
        return self._room_gl

    def _dye_rgb(self, inputs, light: str) -> np.ndarray:
        """The dye per display channel (catalog.optics.dye_colour), once per scene change:
        ``"key"``, under the key, RGB(key x dye) / RGB(key), as the beam takes it; or
        ``"secondary"``, under what the key-lit cloth sends on (the key's share it passes
        and its glow), as the room's light and the folds' light between them take it."""
        from catalog.optics import dye_colour  # noqa: PLC0415

        if getattr(self, "_dye_key", None) != self._inputs_key:
            self._dyes = {"key": dye_colour.key_dye_rgb(inputs), "secondary": dye_colour.secondary_dye_rgb(inputs)}
            self._dye_key = self._inputs_key
        return self._dyes[light if self.secondary_dye else "key"]

    def _room_colours(self, inputs) -> dict:
        """Linear sRGB of the key light (irradiance) and of the beam a thread passes: the
        directional lobe's forward-scattered part, a_spec forward(g_spec), in the dye's colour
        under the key light, per unit of thread coverage (mean coverage 1 - LD)."""
        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        colours = self._display_colours(inputs)
        key = np.asarray(colours["u_key_rgb"])
        dye_rgb = self._dye_rgb(inputs, "key")
        coverage = max(1.0 - float(inputs.direct), 1e-6)
        forward = hg_hemisphere_factors(float(inputs.g_spec))[0]
        thread = np.clip(float(inputs.a_spec) * forward * dye_rgb / coverage, 0.0, 1.0)
        lobe = key * float(inputs.a_spec) * dye_rgb
        return {"u_key_rgb": tuple(float(v) for v in key), "u_mean_coverage": 1.0 - float(inputs.direct),
                "capture_thread": min(float(inputs.a_spec) * forward / coverage, 1.0),
                "u_thread_beam_rgb": tuple(float(v) for v in thread),
                "u_lobe_rgb": tuple(float(v) for v in lobe)}

    @staticmethod
    def _key_depth_per_metre(inputs) -> float:
        """The key's maps' depth (0..1) per metre along the key's travel: orthographic, window
        depth = 0.5 ndc z + 0.5 with ndc z = m[2, 2] z_view + .., so a metre is -m[2, 2] / 2."""
        return abs(float(room_light.light_view_projection(inputs.key_to_light)[2, 2])) / 2

    def _key_shadow_uniforms(self, program, inputs) -> None:
        """curtain.frag's KEY_SHADOW: the front-layer map, its frame and depth bias, the opening."""
        gl = self._room_resources()
        gl["key_front"].use(location=KEY_FRONT_UNIT)
        gl["key_second"].use(location=KEY_SECOND_UNIT)
        s = self._set
        s(program, "u_key_front", KEY_FRONT_UNIT)
        s(program, "u_key_second", KEY_SECOND_UNIT)
        matrix = room_light.light_view_projection(inputs.key_to_light)
        s(program, "u_light_view_proj", gl_bytes(matrix))
        metre = self._key_depth_per_metre(inputs)
        slope_m = KEY_SHADOW_SLOPE_TEXELS * room_light.shadow_texel_m(inputs.key_to_light, self.shadow_texels)
        s(program, "u_key_depth_bias", (KEY_SHADOW_BIAS_M * metre, slope_m * metre, KEY_SHADOW_SLOPE_CAP))
        s(program, "u_key_normal_offset", KEY_SHADOW_NORMAL_OFFSET_TEXELS
          * room_light.shadow_texel_m(inputs.key_to_light, self.shadow_texels))
        wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
        z0 = scene_lib.ROOM_BOX[2][0]
        s(program, "u_window_rect", (wx0, wx1, wy0, wy1))
        s(program, "u_wall_z", (z0, z0 - scene_lib.WALL_THICKNESS_M))
        s(program, "u_tan_sun_radius", math.tan(scene_lib.SUN_RADIUS_RAD))

    def _vertex_occlusion_uniforms(self, program) -> None:
        """curtain.vert's SKY_OCCLUSION: the per-vertex occlusion texture."""
        texture = self._room_resources().get("vertex_occlusion")
        if texture is None:   # not drawn yet (a mesh bound after the last update): none
            texture = self._vertex_target("vertex_occlusion", 1)
        texture.use(location=OCCLUSION_UNIT)
        self._set(program, "u_vertex_occlusion", OCCLUSION_UNIT)
        self._set(program, "u_vertex_occlusion_width", VERTEX_OCCLUSION_WIDTH)

    def _vertex_target(self, name: str, vertices: int):
        """A per-vertex texture ``name`` (the room's resources: "vertex_occlusion",
        "vertex_wall_light") for ``vertices`` (VERTEX_OCCLUSION_WIDTH a row), made or remade
        when the count needs more rows (its texels are written by :meth:`_draw_vertex_points`,
        which clears it first)."""
        mgl, gl = self._moderngl, self._room_resources()
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

    def _draw_vertex_points(self, name: str, defines: dict, bind) -> None:
        """occlusion_points.* with ``defines`` into the per-vertex texture ``name``, one point
        a vertex of the curtain's mesh; ``bind(program)`` sets the pass's own inputs."""
        mgl = self._moderngl
        texture = self._vertex_target(name, self._vertex_count)
        fbo = self._room_gl[name + "_fbo"]
        fbo.use()
        self.ctx.viewport = (0, 0, *texture.size)
        fbo.clear(0.0, 0.0, 0.0, 0.0)
        program = self._program("occlusion_points.vert", "occlusion_points.frag",
                                {"OCCLUSION_MAPS": True, "N_OCCLUSION": room_light.OCCLUSION_DIRECTIONS,
                                 **defines})
        self._occlusion_uniforms(program)
        bind(program)
        self._set(program, "u_mesh_offset", self._mesh_offset)
        self._set(program, "u_target_size", tuple(int(v) for v in texture.size))
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        self._curtain_vao(program).render(mgl.POINTS)

    def _draw_vertex_occlusion(self) -> None:
        """Each vertex's outside occlusion (occlusion_points.*) from the occlusion maps."""
        self._draw_vertex_points("vertex_occlusion", {}, lambda program: None)

    def _occlusion_uniforms(self, program, unit: int = OCCLUSION_UNIT) -> None:
        """common.glsl's outside_occlusion: the occlusion maps (at texture ``unit``) and each
        direction's frame."""
        gl = self._room_resources()
        gl["occlusion"].use(location=unit)
        s = self._set
        s(program, "u_occlusion_maps", unit)
        directions = room_light.occlusion_directions()
        matrices = [room_light.light_view_projection(d) for d in directions]
        s(program, "u_occlusion_view_proj", b"".join(gl_bytes(m) for m in matrices))
        s(program, "u_occlusion_depth_bias",
          tuple(OCCLUSION_BIAS_M * abs(float(m[2, 2])) / 2 for m in matrices))
        s(program, "u_occlusion_direction", np.asarray(directions, dtype="f4"))
        s(program, "u_occlusion_grid", float(self._occlusion_grid()))
        s(program, "u_occlusion_offset_m", OCCLUSION_OFFSET_M)
        wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
        z0 = scene_lib.ROOM_BOX[2][0]
        s(program, "u_occlusion_window", (wx0, wx1, wy0, wy1))
        s(program, "u_occlusion_wall_z", (z0, z0 - scene_lib.WALL_THICKNESS_M))

    @staticmethod
    def _occlusion_grid() -> int:
        return math.ceil(math.sqrt(room_light.OCCLUSION_DIRECTIONS))

    def _room_common_uniforms(self, program, inputs) -> None:
        s = self._set
        for name, value in room_light.face_uniforms().items():
            s(program, name, value)
        wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
        z0 = scene_lib.ROOM_BOX[2][0]
        s(program, "u_window_rect", (wx0, wx1, wy0, wy1))
        s(program, "u_wall_z", (z0, z0 - scene_lib.WALL_THICKNESS_M))
        s(program, "u_light_view_proj", gl_bytes(room_light.light_view_projection(inputs.key_to_light)))
        s(program, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_key_rgb", self._room_colours(inputs)["u_key_rgb"])
        s(program, "u_tan_sun_radius", math.tan(scene_lib.SUN_RADIUS_RAD))
        s(program, "u_albedo", scene_lib.ROOM_ALBEDO)

    def _shadow_vao(self, program, fine: bool = False):
        """The curtain from the key light (coarse grid; ``fine``: the drawn mesh itself, for
        the cloth's own shadow, whose depth must match the shaded surface's)."""
        key = ("shadow", id(program), fine)
        if key not in self._vaos:
            b = self._curtain_buffers
            if self._curtain_format == "interleaved":
                content = [(b["interleaved"], "3f 36x", "in_position")]
            else:
                content = [(b["position"], self._curtain_format, "in_position")]
            if "in_uv" in program and "uv" in b and self._curtain_format != "interleaved":
                content.append((b["uv"], "2f", "in_uv"))
            self._vaos[key] = self.ctx.vertex_array(
                program, content, index_buffer=b["index"] if fine else b.get("coarse_index", b["index"]),
                index_element_size=4)
        return self._vaos[key]

    def draw_room_shadow(self, inputs) -> None:
        """Pass R1: the key light's transmittance through the curtain (room_shadow.frag)."""
        mgl, gl = self._moderngl, self._room_resources()
        n = self.shadow_texels
        gl["shadow_fbo"].use()
        self.ctx.viewport = (0, 0, n, n)
        gl["shadow_fbo"].clear(1.0, 1.0, 1.0, 1.0)
        if not self.curtain_open:
            # the fabric's pattern (issue 12's texture and scale, when this renderer has them
            # and the mesh carries uvs) projects its holes; else the uniform mean coverage
            pattern = getattr(self, "_pattern_texture", None)
            patterned = (pattern is not None and getattr(self, "patterned", False)
                         and self._curtain_format != "interleaved")
            program = self._program("room_shadow.vert", "room_shadow.frag",
                                    {"HAS_UV": True, "PATTERN": patterned})
            if patterned:
                pattern.use(location=3)
                self._set(program, "u_pattern", 3)
                self._set(program, "u_uv_to_repeats", tuple(
                    f / r for f, r in zip(self._fabric_size_m, self._pattern_repeat_m)))
            colours = self._room_colours(inputs)
            self._set(program, "u_light_view_proj",
                      gl_bytes(room_light.light_view_projection(inputs.key_to_light)))
            self._set(program, "u_mesh_offset", self._mesh_offset)
            self._set(program, "u_mean_coverage", colours["u_mean_coverage"])
            self._set(program, "u_thread_beam_rgb", (0.0, 0.0, 0.0) if self.room_lobe
                      else colours["u_thread_beam_rgb"])
            self.ctx.disable(mgl.DEPTH_TEST)
            self.ctx.disable(mgl.CULL_FACE)
            self.ctx.enable(mgl.BLEND)
            self.ctx.blend_func = (mgl.ZERO, mgl.SRC_COLOR)   # dst *= this layer's transmittance
            self._shadow_vao(program).render(mgl.TRIANGLES)
            self.ctx.blend_func = mgl.DEFAULT_BLENDING
            self.ctx.disable(mgl.BLEND)
        gl["shadow"].build_mipmaps()
        self.draw_cloth_shadow_maps(inputs)

    def draw_cloth_shadow_maps(self, inputs) -> None:
        """The maps of the cloth's own shadows (issue 11): the key's front layer (KEY_SHADOW)
        and the occlusion maps (SKY_OCCLUSION), when they are on and the curtain is drawn."""
        if self.curtain_open:
            return
        pattern = getattr(self, "_pattern_texture", None)
        patterned = (pattern is not None and getattr(self, "patterned", False)
                     and self._curtain_format != "interleaved")
        if self.key_shadow:
            self._draw_key_front(inputs, patterned, self._room_colours(inputs))
        if self.sky_occlusion:
            self._draw_occlusion_maps()
            self._draw_vertex_occlusion()

    def _draw_occlusion_maps(self) -> None:
        """SKY_OCCLUSION's maps: per direction of room_light.occlusion_directions, the depth
        of the layer of cloth nearest the outside along it (one tile each)."""
        mgl, gl = self._moderngl, self._room_resources()
        n = room_light.OCCLUSION_TEXELS
        grid = self._occlusion_grid()
        gl["occlusion_fbo"].use()
        self.ctx.viewport = (0, 0, grid * n, grid * n)   # the whole atlas (use() restores the last tile's)
        gl["occlusion_fbo"].clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        program = self._program("room_shadow.vert", "room_shadow.frag",
                                {"HAS_UV": True, "PATTERN": False, "FRONT_LAYER": True,
                                 "BOTH_LAYERS": True})
        self._set(program, "u_mesh_offset", self._mesh_offset)
        self._set(program, "u_mean_coverage", 1.0)
        self._set(program, "u_thread_beam_rgb", (0.0, 0.0, 0.0))
        # the nearest layer (alpha, MIN) and the farthest (g, MAX) in one pass, no depth test
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.enable(mgl.BLEND)
        self.ctx.blend_func = (mgl.ONE, mgl.ONE)
        self.ctx.blend_equation = (mgl.MAX, mgl.MIN)
        self.ctx.disable(mgl.CULL_FACE)
        vao = self._shadow_vao(program)   # the coarse grid: the occlusion is a fold's, not a pixel's
        for j, direction in enumerate(room_light.occlusion_directions()):
            self.ctx.viewport = ((j % grid) * n, (j // grid) * n, n, n)
            self._set(program, "u_light_view_proj", gl_bytes(room_light.light_view_projection(direction)))
            vao.render(mgl.TRIANGLES)
        self.ctx.viewport = (0, 0, grid * n, grid * n)
        self.ctx.blend_equation = mgl.FUNC_ADD
        self.ctx.blend_func = mgl.DEFAULT_BLENDING
        self.ctx.disable(mgl.BLEND)

    def _draw_key_front(self, inputs, patterned: bool, colours: dict) -> None:
        """The key light's front-layer map (curtain.frag KEY_SHADOW): per texel the layer of
        cloth nearest the light, its transmittance (as the room's map, one layer) and depth."""
        mgl, gl = self._moderngl, self._room_resources()
        n = self.shadow_texels
        gl["key_front_fbo"].use()
        self.ctx.viewport = (0, 0, n, n)
        gl["key_front_fbo"].clear(1.0, 1.0, 1.0, 1.0, depth=1.0)
        program = self._program("room_shadow.vert", "room_shadow.frag",
                                {"HAS_UV": True, "PATTERN": patterned, "FRONT_LAYER": True})
        self._front_layer_uniforms(program, inputs, patterned, colours)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.depth_func = "<"
        self.ctx.disable(mgl.CULL_FACE)
        self._shadow_vao(program, fine=True).render(mgl.TRIANGLES)
        # the second layer (issue 11, seventh round): the map peeled; cleared to coverage 0
        gl["key_second_fbo"].use()
        gl["key_second_fbo"].clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        if self.key_second_layer:
            program = self._program("room_shadow.vert", "room_shadow.frag",
                                    {"HAS_UV": True, "PATTERN": patterned, "SECOND_LAYER": True,
                                     "PEEL_SPAN_TEXELS": glsl_literal(KEY_PEEL_SPAN_TEXELS)})
            self._front_layer_uniforms(program, inputs, patterned, colours)
            gl["key_front"].use(location=KEY_FRONT_UNIT)
            self._set(program, "u_first_layer", KEY_FRONT_UNIT)
            self._set(program, "u_peel_bias", KEY_SHADOW_BIAS_M * self._key_depth_per_metre(inputs))
            self._shadow_vao(program, fine=True).render(mgl.TRIANGLES)
        self.ctx.disable(mgl.DEPTH_TEST)

    def _front_layer_uniforms(self, program, inputs, patterned: bool, colours: dict) -> None:
        """room_shadow.frag's FRONT_LAYER and SECOND_LAYER inputs: the light's frame, the
        pattern's coverage."""
        if patterned:
            self._pattern_texture.use(location=3)
            self._set(program, "u_pattern", 3)
            self._set(program, "u_uv_to_repeats", tuple(
                f / r for f, r in zip(self._fabric_size_m, self._pattern_repeat_m)))
        self._set(program, "u_light_view_proj",
                  gl_bytes(room_light.light_view_projection(inputs.key_to_light)))
        self._set(program, "u_mesh_offset", self._mesh_offset)
        self._set(program, "u_mean_coverage", colours["u_mean_coverage"])
        self._set(program, "u_thread_beam_rgb", colours["u_thread_beam_rgb"])

    def draw_room_luminaire(self, inputs) -> None:
        """Pass R2: what the room sees in the window (the curtain's room-side radiance, or the
        outside where it is open), one texel per window patch, the sun's disc left out; from
        the room's middle and (side_eyes) from two eyes towards the side walls. The window
        side's capture R2b first: through the holes, the room's captures see it on the folds
        behind (curtain.frag FOLDS_BEHIND)."""
        mgl, gl = self._moderngl, self._room_resources()
        # the window side, from outside: nothing where there is no cloth (the room behind it
        # is not a source), and no see-through (it would show the outside, not the room)
        gl["luminaire_back_fbo"].use()
        self.ctx.viewport = (0, 0) + room_light.luminaire_capture_size(room_light.BACK_LUMINAIRE_LEVEL)
        gl["luminaire_back_fbo"].clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.depth_func = "<="
        if not self.curtain_open:
            self._draw_flat_curtain(room_light.back_luminaire_view_projection(),
                                    room_light.BACK_LUMINAIRE_EYE, self._back_capture_overrides())
        gl["luminaire_back"].build_mipmaps()
        # alpha: the key's irradiance on the cloth (curtain.frag ROOM_CAPTURE), 0 where none
        overrides = self._capture_overrides()
        targets = [("luminaire", room_light.LUMINAIRE_EYE, 0, room_light.LUMINAIRE_LEVEL)]
        if self.side_eyes:   # side by side, a tile a power of 2 wide at the patch level: the
            targets += [("luminaire_sides", eye, k, room_light.SIDE_LUMINAIRE_LEVEL)  # mipmaps
                        for k, eye in enumerate(room_light.CAPTURE_SIDE_EYES)]   # keep them apart
        for name, eye, tile, level in targets:
            lw, lh = room_light.luminaire_capture_size(level)
            if tile == 0:
                gl[name + "_fbo"].use()
                gl[name + "_fbo"].clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            self.ctx.viewport = (tile * lw, 0, lw, lh)
            view_proj = room_light.luminaire_view_projection(eye, self.window_front_z())
            if not self.curtain_open:
                self._draw_flat_curtain(view_proj, eye, overrides, folds_behind=self.capture_folds)
            self._draw_background(view_proj, inputs, camera_position=eye, sun_disc=False, capture=True)
        for name in {name for name, _eye, _tile, _level in targets}:
            gl[name].build_mipmaps()   # level LUMINAIRE_LEVEL: each patch's mean radiance
        if self.wall_eyes_active():   # the box's sides from the wall eyes (no outside: their ways
            gl["luminaire_walls_fbo"].use()   # through a side rise into the room)
            gl["luminaire_walls_fbo"].clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            ww, wh = room_light.wall_eye_capture_size()
            for k, eye in enumerate(room_light.WALL_EYES):
                self.ctx.viewport = (k * ww, 0, ww, wh)
                self._draw_flat_curtain(room_light.wall_eye_view_projection(k == 1, self.window_front_z()), eye,
                                        overrides, folds_behind=self.capture_folds)
            gl["luminaire_walls"].build_mipmaps()
        self.ctx.depth_func = "<"
        self.ctx.disable(mgl.DEPTH_TEST)

    def _draw_flat_curtain(self, view_proj, eye, overrides: dict, folds_behind: bool = False) -> None:
        """The room's captures draw the flat cloth (the pattern averaged, model.md section 9):
        each capture texel is a mean over a window patch anyway, and the flat variant draws in
        one pass. The whole mesh, not the coarse grid of the shadow map: under the UV lamp the
        grid's chords cut into the folds, which its front-layer map then shadowed, and the
        room's capture was 0.78x the path tracer's radiance along the same rays (0.93x with
        the mesh)."""
        patterned = getattr(self, "patterned", None)
        if patterned:
            self.patterned = False
        try:
            self.draw_curtain(view_proj, camera_position=eye, overrides=overrides,
                              folds_behind=folds_behind)
        finally:
            if patterned:
                self.patterned = patterned

    def window_albedo_rgb(self, inputs) -> tuple[float, float, float]:
        """The closed curtain's room-side reflectance under diffuse light (linear sRGB): the
        lobes scattering back, dye (a_diff backward(g_diff) + a_spec backward(g_spec)), the
        dye per channel under the key as the room's colours take it; 0 when the curtain is
        open (the window reflects nothing)."""
        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        if self.curtain_open:
            return (0.0, 0.0, 0.0)
        return self.curtain_room_reflectance_rgb(inputs)

    def curtain_forward_rgb(self, inputs) -> tuple[tuple, tuple]:
        """The cloth's transmittance of diffuse light by each lobe (linear sRGB), dye a_diff
        forward(g_diff) and dye a_spec forward(g_spec): what passes towards a viewer in the
        room of the light on the cloth's window side (curtain.frag ROOM_SIDE, the folds' light
        where they hide the outside, both lobes by the hemisphere's occlusion; and the window
        wall's, WALL_LIGHT). The dye per channel for the secondary light (:meth:`_dye_rgb`, since
        issue 11's seventh round; the key's before): the folds' light is the cloth's own, and
        the wall's reveals see the cloth's window side too. With no glow it is the key's."""
        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        dye_rgb = self._dye_rgb(inputs, "secondary")
        diffuse = float(inputs.a_diff) * hg_hemisphere_factors(float(inputs.g_diff))[0]
        directional = float(inputs.a_spec) * hg_hemisphere_factors(float(inputs.g_spec))[0]
        return tuple(tuple(float(v) for v in np.clip(dye_rgb * f, 0.0, 1.0)) for f in (diffuse, directional))

    def curtain_room_reflectance_rgb(self, inputs) -> tuple[float, float, float]:
        """The cloth's reflectance under the room's diffuse light (linear sRGB), dye (a_diff
        backward(g_diff) + a_spec backward(g_spec)), the dye per channel for the secondary
        light (:meth:`_dye_rgb`; the key's before issue 11's seventh round): what the
        radiosity's window reflects and what the curtain's room side sends back of the room's
        light (curtain.frag ROOM_SIDE)."""
        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        dye_rgb = self._dye_rgb(inputs, "secondary")
        back = (float(inputs.a_diff) * hg_hemisphere_factors(float(inputs.g_diff))[1]
                + float(inputs.a_spec) * hg_hemisphere_factors(float(inputs.g_spec))[1])
        return tuple(float(v) for v in np.clip(dye_rgb * back, 0.0, 1.0))

    def _radiosity_operator(self, window_albedo) -> None:
        """Upload room_light.radiosity_operator_rgb for this window reflectance (when it changed)."""
        key = tuple(round(v, 4) for v in window_albedo)
        if key != self._operator_albedo:
            operator = room_light.radiosity_operator_rgb(scene_lib.ROOM_ALBEDO, key)
            self._room_resources()["radiosity_operator"].write(np.ascontiguousarray(operator).tobytes())
            self._operator_albedo = key

    def _window_light_defines(self) -> dict:
        """common.glsl WINDOW_LIGHT's defines (room_lightmap.frag and the lit room.frag define
        WINDOW_LIGHT itself): the window from three eyes (SIDE_EYES), the box's sides also
        from the wall's side (WALL_EYES, with the box)."""
        return {**({"SIDE_EYES": True} if self.side_eyes else {}),
                **({"WALL_EYES": True} if self.wall_eyes_active() else {})}

    def _window_light_uniforms(self, program, inputs) -> None:
        """common.glsl WINDOW_LIGHT's inputs (the room's captures on units 3-5, the box, the
        key's lobe, the lamps), for the light map (room_lightmap.frag) and the window wall
        beside the opening per pixel (room.frag WINDOW_NEAR)."""
        gl = self._room_resources()
        gl["luminaire"].use(location=5)
        self._set(program, "u_luminaire", 5)
        if self.side_eyes:
            gl["luminaire_sides"].use(location=4)
            self._set(program, "u_luminaire_sides", 4)
            self._set(program, "u_luminaire_sides_level", room_light.SIDE_LUMINAIRE_LEVEL)
            self._set(program, "u_side_eye", np.asarray(room_light.CAPTURE_SIDE_EYES, dtype="f4"))
            self._set(program, "u_middle_eye", room_light.LUMINAIRE_EYE)
        self._set(program, "u_luminaire_size", room_light.LUMINAIRE_TEXELS)
        self._set(program, "u_luminaire_level", room_light.LUMINAIRE_LEVEL)
        gl["luminaire_back"].use(location=3)
        self._set(program, "u_luminaire_back", 3)
        self._set(program, "u_luminaire_back_level", room_light.BACK_LUMINAIRE_LEVEL)
        self._set(program, "u_back_plane_z", scene_lib.CURTAIN_Z)
        self._set(program, "u_front_z", self.window_front_z())
        if self.wall_eyes_active():   # the box's sides from the wall's side (WALL_EYES)
            gl["luminaire_walls"].use(location=7)
            self._set(program, "u_luminaire_walls", 7)
            self._set(program, "u_luminaire_walls_level", room_light.WALL_EYE_LEVEL)
            self._set(program, "u_wall_eye", np.asarray(room_light.WALL_EYES, dtype="f4"))
        colours = self._room_colours(inputs)
        self._set(program, "u_lobe_rgb", colours["u_lobe_rgb"] if self.room_lobe and not self.curtain_open
                  else (0.0, 0.0, 0.0))
        self._set(program, "u_g_spec", float(inputs.g_spec))
        lamps = self.room_lamps
        positions = np.zeros((room_light.MAX_ROOM_LAMPS, 3), dtype="f4")
        rgbs = np.zeros((room_light.MAX_ROOM_LAMPS, 3), dtype="f4")
        for k, (light, position) in enumerate(lamps):
            positions[k] = position
            rgbs[k] = band_lib.spectrum_to_display_rgb(light.irradiance_w_m2_nm)
        self._set(program, "u_lamp_count", len(lamps))
        self._set(program, "u_lamp_position", positions)
        self._set(program, "u_lamp_rgb", rgbs)

    def draw_room_lightmap(self, inputs) -> None:
        """Passes R3 and R4: the light map's direct part (area light, beam, lamps), then (R3b,
        with every bounce) the coarse patches' total irradiance, then the bounces gathered
        with ambient occlusion into the light map the room reads."""
        mgl, gl = self._moderngl, self._room_resources()
        aw, ah = room_light.atlas_size()
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        gl["direct_fbo"].use()
        self.ctx.viewport = (0, 0, aw, ah)
        program = self._program("fullscreen.vert", "room_lightmap.frag",
                                {"BEAM_SAMPLES": room_light.BEAM_SAMPLES, **self._window_light_defines()})
        self._room_common_uniforms(program, inputs)
        self._window_light_uniforms(program, inputs)
        self._set(program, "u_face_texels", float(room_light.FACE_TEXELS))
        self._set(program, "u_supersample_m", room_light.WINDOW_SUPERSAMPLE_M)
        gl["shadow"].use(location=2)
        self._set(program, "u_shadow", 2)
        (x0, x1), _, _ = scene_lib.ROOM_BOX
        spacing_m = (x1 - x0) / room_light.FACE_TEXELS / room_light.BEAM_SAMPLES   # the beam's samples'
        self._set(program, "u_beam_shadow_lod",
                  max(0.0, math.log2(spacing_m / room_light.shadow_texel_m(inputs.key_to_light, self.shadow_texels))))
        self._set(program, "u_key_on", 1.0)
        self._fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        if self.window_near():   # the window wall beside the opening, finer (room_window_near.frag)
            gl["window_near_fbo"].use()
            self.ctx.viewport = (0, 0, room_light.WINDOW_NEAR_TEXELS, room_light.WINDOW_NEAR_TEXELS)
            near = self._program("fullscreen.vert", "room_window_near.frag", self._window_light_defines())
            self._window_light_uniforms(near, inputs)
            self._set(near, "u_near_rect", room_light.window_near_rect())
            self._set(near, "u_window_rect", scene_lib.WINDOW_RECT)
            self._set(near, "u_wall_z", scene_lib.ROOM_BOX[2][0])
            self._set(near, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
            self._fullscreen_vao(near).render(mgl.TRIANGLES, vertices=3)
            gl["direct_fbo"].use()
            self.ctx.viewport = (0, 0, aw, ah)
        gl["direct"].build_mipmaps()
        gl["beam"].build_mipmaps()
        rc = room_light.FACE_TEXELS >> room_light.BOUNCE_LEVEL
        all_bounces = self.room_bounces == "all"
        window_albedo = self.window_albedo_rgb(inputs)
        if all_bounces:   # the coarse patches' total irradiance (room_radiosity.frag)
            self._radiosity_operator(window_albedo)
            gl["total_fbo"].use()
            self.ctx.viewport = (0, 0, len(room_light.FACE_NAMES) * rc, rc)
            program = self._program("fullscreen.vert", "room_radiosity.frag")
            self._bind_bounce_sources(program)
            gl["radiosity_operator"].use(location=4)
            self._set(program, "u_operator", 4)
            self._fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
            self.ctx.viewport = (0, 0, aw, ah)

        gl["lightmap_fbo"].use()
        program = self._bounce_gather_program(all_bounces, window_albedo)
        self._fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        if self.room_side_active():
            self._draw_room_side(all_bounces, window_albedo)
            if self.sky_occlusion and self.wall_light and not self.curtain_open:
                self._draw_vertex_wall_light(inputs)

    def _bounce_gather_program(self, all_bounces: bool, window_albedo, defines: dict | None = None):
        """room_bounce.frag (with ``defines``) and its inputs bound: the coarse patches' totals
        (every bounce) or their direct light, the faces, the obscurance and wall fraction, the
        albedos; for pass R4 and R4b."""
        gl = self._room_resources()
        defines = dict(defines or {})
        if all_bounces:
            defines["ALL_BOUNCES"] = True
        program = self._program("fullscreen.vert", "room_bounce.frag", defines or None)
        if all_bounces:
            gl["total"].use(location=4)
            self._set(program, "u_total", 4)
        for name, value in room_light.face_uniforms().items():
            self._set(program, name, value)
        self._bind_bounce_sources(program)
        gl["ao"].use(location=2)
        self._set(program, "u_ao_mask", 2)
        self._set(program, "u_albedo", scene_lib.ROOM_ALBEDO)
        self._set(program, "u_window_albedo", window_albedo)
        return program

    def _draw_room_side(self, all_bounces: bool, window_albedo) -> None:
        """Pass R4b (issue 11, fourth round): the room's irradiance on the curtain's room side,
        room_bounce.frag's gather at CURTAIN_SIDE_TEXELS points over the opening."""
        mgl, gl = self._moderngl, self._room_resources()
        gl["room_side_fbo"].use()
        self.ctx.viewport = (0, 0, *room_light.CURTAIN_SIDE_TEXELS)
        program = self._bounce_gather_program(all_bounces, window_albedo, {"CURTAIN_SIDE": True})
        self._set(program, "u_side_rect", room_light.curtain_side_rect())
        self._set(program, "u_side_z", scene_lib.ROOM_BOX[2][0])
        self._fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)

    def _room_side_uniforms(self, program) -> None:
        """curtain.frag's ROOM_SIDE: the room-side irradiance grid, its extent, the cloth's
        reflectance of the room's light."""
        gl = self._room_resources()
        gl["room_side"].use(location=ROOM_SIDE_UNIT)
        self._set(program, "u_room_side", ROOM_SIDE_UNIT)
        x0, y0, w, h = room_light.curtain_side_rect()
        self._set(program, "u_room_side_rect", (x0, y0, 1.0 / w, 1.0 / h))
        self._set(program, "u_room_side_reflectance", self.curtain_room_reflectance_rgb(self.shading_inputs()))
        gl["luminaire"].use(location=ROOM_SIDE_CLOTH_UNIT)
        self._set(program, "u_room_side_cloth", ROOM_SIDE_CLOTH_UNIT)
        self._set(program, "u_room_side_cloth_level", room_light.LUMINAIRE_LEVEL)
        self._set(program, "u_room_side_cloth_size", room_light.LUMINAIRE_TEXELS)
        gl["luminaire_back"].use(location=WINDOW_SIDE_CLOTH_UNIT)
        self._set(program, "u_window_side_cloth", WINDOW_SIDE_CLOTH_UNIT)
        self._set(program, "u_window_side_cloth_level", room_light.BACK_LUMINAIRE_LEVEL)
        diffuse, directional = self.curtain_forward_rgb(self.shading_inputs())
        self._set(program, "u_window_side_diffuse", diffuse)
        self._set(program, "u_window_side_directional", directional)
        if "u_occlusion_maps" in program:   # beside the per-vertex occlusion (OCCLUSION_UNIT)
            self._occlusion_uniforms(program, OCCLUSION_MAPS_UNIT)
        if "u_vertex_wall_light" in program:
            self._wall_light_uniforms(program, self.shading_inputs())
            self._set(program, "u_wall_lobe", np.asarray(
                room_light.wall_lobe_directions(float(self.shading_inputs().g_spec)), dtype="f4"))
            texture = gl.get("vertex_wall_light")
            if texture is None:   # not drawn yet (a mesh bound after the last update): none
                texture = self._vertex_target("vertex_wall_light", 1)
            texture.use(location=VERTEX_WALL_LIGHT_UNIT)
            self._set(program, "u_vertex_wall_light", VERTEX_WALL_LIGHT_UNIT)

    def _wall_light_uniforms(self, program, inputs) -> None:
        """common.glsl's WALL_LIGHT inputs: the light map (WALL_LIGHTMAP_UNIT), the room's faces
        and box, the opening and the wall's planes, the reveals' outside and the window-side
        capture (bound at WINDOW_SIDE_CLOTH_UNIT, read at the reveals' level), the key."""
        gl = self._room_resources()
        s = self._set
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
        reveals = self._reveal_inputs(inputs)
        s(program, "u_wall_sky_half", reveals["sky_half"])
        s(program, "u_wall_ground_half", reveals["ground_half"])
        gl["luminaire_back"].use(location=WINDOW_SIDE_CLOTH_UNIT)
        s(program, "u_wall_back", WINDOW_SIDE_CLOTH_UNIT)
        s(program, "u_wall_back_level", reveals["back_level"])
        s(program, "u_wall_back_size", reveals["back_size"])
        s(program, "u_wall_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_wall_key_rgb", self._room_colours(inputs)["u_key_rgb"])
        s(program, "u_wall_tan_sun", math.tan(scene_lib.SUN_RADIUS_RAD))
        s(program, "u_wall_albedo", scene_lib.ROOM_ALBEDO)

    def _draw_vertex_wall_light(self, inputs) -> None:
        """Each vertex's walled radiance (occlusion_points.* with WALL_LIGHT): what the window
        wall and its reveals show its window side, from the light map just drawn."""
        self._draw_vertex_points("vertex_wall_light", {"WALL_LIGHT": True},
                                 lambda program: self._wall_light_uniforms(program, inputs))

    def wall_light_at(self, positions, walled_share) -> np.ndarray:
        """curtain.vert WALL_LIGHT's light evaluated in numpy at world ``positions`` (P, 3) with
        the outside's walled share ``walled_share`` (P,) (the per-vertex occlusion's y), float64
        (P, 3): the diffuse lobe's forward transmittance times the walled hemisphere's radiance
        (:func:`room_light.walled_radiance`), the directional lobe's times its samples about
        the view's continuation (:func:`room_light.wall_lobe_radiance`) plus the walled share
        of the outside's mean; 0 where the room side takes the stand-ins or the outside's
        occlusion is off."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        if not self.variant_defines().get("WALL_LIGHT"):
            return np.zeros_like(p)
        sources = self.wall_light_sources()
        view = p - np.asarray(self.camera.position, dtype=np.float64)
        view /= np.linalg.norm(view, axis=-1, keepdims=True)
        inputs = self.shading_inputs()
        lobe = room_light.wall_lobe_radiance(p, view, sources, room_light.wall_lobe_directions(float(inputs.g_spec)))
        outside_mean = (np.asarray(sources.reveal_sky) + np.asarray(sources.reveal_ground)) / math.pi
        share = np.asarray(walled_share, dtype=np.float64).reshape(-1, 1)
        diffuse, directional = (np.asarray(v, dtype=np.float64) for v in self.curtain_forward_rgb(inputs))
        return diffuse * room_light.walled_radiance(p, sources) + directional * (lobe + share * outside_mean)

    def read_room_total(self) -> np.ndarray:
        """The coarse patches' last total irradiance (radiosity pass), float32 (RC, 6 RC, 3)."""
        rc = room_light.FACE_TEXELS >> room_light.BOUNCE_LEVEL
        data = self._room_resources()["total"].read()
        return np.frombuffer(data, dtype="f4").reshape(rc, len(room_light.FACE_NAMES) * rc, 4)[..., :3].copy()

    def read_room_side(self) -> np.ndarray:
        """The last room-side irradiance grid, float32 (H, W, 3), row 0 = the opening's bottom."""
        tw, th = room_light.CURTAIN_SIDE_TEXELS
        data = self._room_resources()["room_side"].read()
        return np.frombuffer(data, dtype="f4").reshape(th, tw, 4)[..., :3].copy()

    def _bind_bounce_sources(self, program) -> None:
        """The bounces' sources for room_radiosity.frag and room_bounce.frag: the direct map and
        the beam (units 1 and 3), read at the coarse level BOUNCE_LEVEL."""
        gl = self._room_resources()
        gl["direct"].use(location=1)
        self._set(program, "u_direct", 1)
        gl["beam"].use(location=3)
        self._set(program, "u_beam", 3)
        self._set(program, "u_bounce_level", room_light.BOUNCE_LEVEL)
        self._set(program, "u_coarse_texels", room_light.FACE_TEXELS >> room_light.BOUNCE_LEVEL)

    def draw_room_light(self, inputs) -> None:
        """All the room lighting's passes before the frame (R1-R4)."""
        self.draw_room_shadow(inputs)
        self.draw_room_luminaire(inputs)
        self.draw_room_lightmap(inputs)

    def read_room_shadow(self) -> np.ndarray:
        """The last transmittance shadow map, float32 (N, N, 3), row 0 = the map's bottom."""
        gl = self._room_resources()
        n = self.shadow_texels
        data = gl["shadow"].read(level=0)
        return np.frombuffer(data, dtype=np.float16).reshape(n, n, 4)[..., :3].astype(np.float32)

    def read_room_lightmap(self) -> np.ndarray:
        """The last light map (irradiance, linear sRGB), float32 (R, 6R, 3), row 0 = t = 0."""
        gl = self._room_resources()
        aw, ah = room_light.atlas_size()
        data = gl["lightmap_fbo"].read(viewport=(0, 0, aw, ah), components=4, dtype="f4")
        return np.frombuffer(data, dtype=np.float32).reshape(ah, aw, 4)[..., :3].copy()

    def _viewport_size(self, viewport) -> tuple[int, int]:
        if viewport is None:
            return self.size
        vw, vh = int(viewport[2]), int(viewport[3])
        if not (1 <= vw <= self.size[0] and 1 <= vh <= self.size[1]):
            raise CatalogError(f"viewport {tuple(viewport)} does not fit the renderer's "
                               f"{self.size[0]}x{self.size[1]} HDR target")
        return vw, vh

    def _room_light_stale(self) -> bool:
        """Whether the room's light must be redrawn this frame (see room_update_every)."""
        key = (self._inputs_key, self.curtain_open, self.key_shadow, self.sky_occlusion,
               self.room_bounces, self.room_lobe, self.room_side_active(), self.wall_light,
               self.side_eyes, self.window_box, self.wall_eyes, self.window_near_field,
               self.capture_folds, self.secondary_dye, self.key_second_layer,
               getattr(self, "patterned", None),
               getattr(self, "_pattern_key", None),
               tuple((light.name, position) for light, position in self.room_lamps))
        self._room_frames += 1
        moved = self._mesh_version != getattr(self, "_room_mesh_version", None) or (
            self._curtain_format != "3f")  # a cloth on the GPU moves unseen
        due = moved and self._room_frames >= self.room_update_every
        if key != self._room_key or due or self._room_gl is None:
            self._room_key = key
            self._room_mesh_version = self._mesh_version
            self._room_frames = 0
            return True
        return False

    def invalidate_room_light(self) -> None:
        """Redraw the room's light at the next frame (e.g. after the cloth moved on the GPU)."""
        self._room_key = None
        self._room_order_key = None  # and sort the room's triangles toward the light again

    def _timed(self, profile, name, work) -> None:
        """Run ``work()``; with a ``profile`` dict, finish the GL queue and add its wall time (s)."""
        if profile is None:
            work()
            return
        import time  # noqa: PLC0415

        self.ctx.finish()
        start = time.perf_counter()
        work()
        self.ctx.finish()
        profile[name] = profile.get(name, 0.0) + time.perf_counter() - start

    def render_hdr(self, viewport=None, profile: dict | None = None) -> tuple[int, int]:
        """Background, room and curtain into the HDR target; returns the size drawn.
        ``profile``: a dict that receives each pass's wall time (s), the GL queue finished
        around each (the benchmark's per-pass shares; slower than a frame without it)."""
        mgl = self._moderngl
        inputs = self.shading_inputs()
        vw, vh = self._viewport_size(viewport)
        view_proj = self.camera.view_projection(vw / vh)
        if (self.room_lighting or self.key_shadow or self.sky_occlusion) and self._room_light_stale():
            if self.room_lighting:   # the room's passes (the cloth's own shadow maps with them)
                self._timed(profile, "room_shadow", lambda: self.draw_room_shadow(inputs))
                self._timed(profile, "room_luminaire", lambda: self.draw_room_luminaire(inputs))
                self._timed(profile, "room_lightmap", lambda: self.draw_room_lightmap(inputs))
            else:
                self._timed(profile, "cloth_shadow", lambda: self.draw_cloth_shadow_maps(inputs))
        msaa = self._msaa_targets() if self.antialiasing == "msaa" else None
        hdr_fbo = msaa["hdr_fbo"] if msaa else self._hdr_fbo
        hdr_fbo.use()
        self.ctx.viewport = (0, 0, vw, vh)
        hdr_fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0, viewport=(0, 0, vw, vh))
        self.ctx.disable(mgl.BLEND)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.depth_func = "<="
        if not self.curtain_open and not self.patterned:
            # the opaque flat curtain first: the depth test then skips the room behind it
            self._timed(profile, "curtain", lambda: self.draw_curtain(view_proj))
        self._timed(profile, "room", lambda: self._draw_room(view_proj, inputs))
        # on the far plane: the depth test leaves only the pixels nothing covers
        self._timed(profile, "background", lambda: self._draw_background(view_proj, inputs))
        if not self.curtain_open and self.patterned:
            self._timed(profile, "curtain", lambda: self._draw_curtain_oit(view_proj, vw, vh, msaa))
        elif msaa:
            self.ctx.copy_framebuffer(self._hdr_fbo, msaa["hdr_fbo"])   # resolve
        self.ctx.depth_func = "<"
        self.ctx.disable(mgl.DEPTH_TEST)
        return vw, vh

    def _bloom_resources(self) -> dict:
        if self._bloom_gl is None:
            mgl, ctx = self._moderngl, self.ctx
            w, h = self.size
            # float32: the sun's disc (~1e9 cd m^-2) overflows half floats
            half = ctx.texture((max(1, (w + 1) // 2), max(1, (h + 1) // 2)), 4, dtype="f4")
            half.filter = (mgl.LINEAR_MIPMAP_NEAREST, mgl.LINEAR)  # whole levels: bilinear taps
            half.repeat_x = half.repeat_y = False
            glow = ctx.texture((max(1, (half.size[0] + 1) // 2), max(1, (half.size[1] + 1) // 2)),
                               4, dtype="f4")   # quarter size: the glow is wide
            glow.filter = (mgl.LINEAR, mgl.LINEAR)
            glow.repeat_x = glow.repeat_y = False
            out = ctx.texture((w, h), 4, dtype="f4")
            out.filter = (mgl.NEAREST, mgl.NEAREST)
            self._bloom_gl = {"half": half, "half_fbo": ctx.framebuffer([half]),
                              "glow": glow, "glow_fbo": ctx.framebuffer([glow]),
                              "out": out, "out_fbo": ctx.framebuffer([out])}
        return self._bloom_gl

    def oit_depth_reference_m(self) -> float:
        """The view distance (m) where the OIT depth weight is 1: just before the nearest
        the curtain can be (the camera's distance to its target less a metre)."""
        return max(0.0, self.camera.distance_m - 1.0)

    def _msaa_targets(self) -> dict:
        """The MSAA path's targets (MSAA_SAMPLES float renderbuffers: HDR, depth, the two OIT
        targets) and single-target framebuffers to resolve them from, made once."""
        if self._msaa is None:
            ctx, size, n = self.ctx, self.size, MSAA_SAMPLES
            hdr = ctx.renderbuffer(size, 4, samples=n, dtype="f4")
            depth = ctx.depth_renderbuffer(size, samples=n)
            accum = ctx.renderbuffer(size, 4, samples=n, dtype="f4")
            weight = ctx.renderbuffer(size, 1, samples=n, dtype="f4")
            oit_fbo = ctx.framebuffer([accum, weight], depth)
            oit_fbo.depth_mask = False
            self._msaa = {
                "objects": [hdr, depth, accum, weight],
                "hdr_fbo": ctx.framebuffer([hdr], depth), "oit_fbo": oit_fbo,
                "accum_src": ctx.framebuffer([accum]), "weight_src": ctx.framebuffer([weight]),
                "accum_dst": ctx.framebuffer([self._oit_accum]),
                "weight_dst": ctx.framebuffer([self._oit_weight]),
            }
        return self._msaa

    def _release_msaa(self) -> None:
        if self._msaa is not None:
            for name in ("hdr_fbo", "oit_fbo", "accum_src", "weight_src", "accum_dst", "weight_dst"):
                self._msaa[name].release()
            for obj in self._msaa["objects"]:
                obj.release()
            self._msaa = None

    def _draw_curtain_oit(self, view_proj, vw: int, vh: int, msaa: dict | None = None) -> None:
        """The curtain's layers into the OIT targets (depth-tested against the room, not
        written), then resolved over the HDR target. ``msaa``: into the multisampled targets,
        each resolved (averaged over the samples) before the composite: at an edge pixel the
        composite takes the samples' mean layer colour, revealage and background."""
        mgl = self._moderngl
        ctx = self.ctx
        (msaa["oit_fbo"] if msaa else self._oit_fbo).use()
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
                ctx.copy_framebuffer(self._hdr_fbo if dst is None else msaa[dst], msaa[src])
            ctx.enable(mgl.BLEND)
            ctx.blend_equation = mgl.FUNC_ADD
        # resolve: average colour x (1 - revealage) + behind x revealage
        self._hdr_fbo.use()
        ctx.viewport = (0, 0, vw, vh)
        ctx.disable(mgl.DEPTH_TEST)
        ctx.blend_func = (mgl.ONE, mgl.SRC_ALPHA, mgl.ZERO, mgl.ONE)
        program = self._program("fullscreen.vert", "oit_composite.frag")
        self._oit_accum.use(location=0)
        self._oit_weight.use(location=1)
        self._set(program, "u_accum", 0)
        self._set(program, "u_weight", 1)
        self._fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        ctx.disable(mgl.BLEND)
        ctx.blend_func = mgl.DEFAULT_BLENDING

    def set_antialiasing(self, mode: str) -> None:
        """``auto`` (default): :func:`choose_antialiasing` for this context (FXAA on llvmpipe);
        ``fxaa``: the post-process on the display image (shaders/fxaa.frag); ``msaa``:
        MSAA_SAMPLES samples per pixel in the HDR passes (refused where the context has
        fewer); ``off``: the tone-mapped image as it is. :attr:`antialiasing` holds the
        mode in use (never ``auto``)."""
        if mode not in ANTIALIASING_MODES:
            raise CatalogError(f"anti-aliasing {mode!r}: choose one of {', '.join(ANTIALIASING_MODES)}")
        info = dict(self.ctx.info)   # GL_RENDERER, GL_MAX_SAMPLES
        if mode == "auto":
            mode = choose_antialiasing(info)
        if mode == "msaa" and int(info.get("GL_MAX_SAMPLES", 0) or 0) < MSAA_SAMPLES:
            raise CatalogError(f"anti-aliasing msaa: this context has fewer than "
                               f"{MSAA_SAMPLES} samples (GL_MAX_SAMPLES); use fxaa")
        if mode != "msaa":
            self._release_msaa()
        self.antialiasing = mode

    def draw_bloom(self, vw: int, vh: int) -> object:
        """Glare: the HDR frame with BLOOM_STRENGTH of it spread over wide blurs
        (bloom_down.frag, then bloom.frag); returns the texture the tone map reads."""
        mgl, gl = self._moderngl, self._bloom_resources()
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        hw, hh = (vw + 1) // 2, (vh + 1) // 2
        gl["half_fbo"].use()
        self.ctx.viewport = (0, 0, hw, hh)
        program = self._program("fullscreen.vert", "bloom_down.frag")
        self._hdr.use(location=0)
        self._set(program, "u_hdr", 0)
        self._set(program, "u_hdr_size", (vw, vh))
        self._fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        gl["half"].build_mipmaps()
        full_w, full_h = gl["half"].size
        rect = (0.0, 0.0, hw / full_w, hh / full_h)
        gw, gh = gl["glow"].size
        qw, qh = (hw + 1) // 2, (hh + 1) // 2
        gl["glow_fbo"].use()
        self.ctx.viewport = (0, 0, qw, qh)
        program = self._program("fullscreen.vert", "bloom_glow.frag",
                                {"BLOOM_LEVELS": len(BLOOM_LEVEL_WEIGHTS)})
        gl["half"].use(location=1)
        self._set(program, "u_half", 1)
        self._set(program, "u_half_rect", rect)
        weights = np.asarray(BLOOM_LEVEL_WEIGHTS, dtype="f4")
        self._set(program, "u_level_weight", weights / weights.sum())
        self._fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        gl["out_fbo"].use()
        self.ctx.viewport = (0, 0, vw, vh)
        program = self._program("fullscreen.vert", "bloom.frag")
        self._hdr.use(location=0)
        self._set(program, "u_hdr", 0)
        gl["glow"].use(location=1)
        self._set(program, "u_glow", 1)
        self._set(program, "u_glow_rect", (0.0, 0.0, qw / gw, qh / gh))
        self._set(program, "u_strength", BLOOM_STRENGTH)
        self._fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        return gl["out"]

    def render(self, fbo=None, viewport=None, dt_s: float | None = None,
               profile: dict | None = None) -> None:
        """One frame: HDR passes, the glare (bloom, when on), then the display pass into
        ``fbo`` (default: our RGBA8 target) at ``viewport`` (x, y, w, h; default the whole
        renderer size).

        Auto exposure (no :meth:`set_ev`): this frame is metered (before the glare); ``dt_s``
        (the viewer's frame time) adapts the exposure toward it over
        display.ADAPTATION_TAU_S, None jumps. ``profile``: see :meth:`render_hdr` (adds
        "meter", "bloom" and "display")."""
        vw, vh = self.render_hdr(viewport, profile)
        if self.ev100 is None:
            self._timed(profile, "meter", lambda: setattr(
                self, "metered_ev100",
                display_lib.adapt_ev(self.metered_ev100, self.meter(vw, vh), dt_s)))
        source = {"texture": self._hdr}
        if self.bloom:
            self._timed(profile, "bloom", lambda: source.update(texture=self.draw_bloom(vw, vh)))
        self._timed(profile, "display",
                    lambda: self.display_pass(vw, vh, fbo, viewport, source["texture"]))

    def display_pass(self, vw: int, vh: int, fbo=None, viewport=None, hdr=None) -> None:
        """The display transform of the HDR target's (vw, vh) corner (the benchmark times it);
        ``hdr``: the texture to show (default the HDR target; the glare's output when on)."""
        target = fbo if fbo is not None else self._ldr_fbo
        target_viewport = (tuple(viewport) if (fbo is not None and viewport is not None)
                           else (0, 0, vw, vh))
        fxaa = self.antialiasing == "fxaa"
        if fxaa:   # display into our copy, FXAA from it into the target
            self._pre_fbo.use()
            self.ctx.viewport = (0, 0, vw, vh)
        else:
            target.use()
            self.ctx.viewport = target_viewport
        program = self._program("fullscreen.vert", "tonemap.frag",
                                {"DISPLAY_STAGES": self.display_stages})
        (hdr if hdr is not None else self._hdr).use(location=0)
        self._set(program, "u_hdr", 0)
        self._set(program, "u_hdr_rect", (0.0, 0.0, vw / self.size[0], vh / self.size[1]))
        for name, value in self.display_uniforms().items():
            self._set(program, name, value)
        self._fullscreen_vao(program).render(self._moderngl.TRIANGLES, vertices=3)
        if fxaa:
            target.use()
            self.ctx.viewport = target_viewport
            program = self._program("fullscreen.vert", self.fxaa_shader)
            self._pre.use(location=0)
            self._set(program, "u_ldr", 0)
            self._set(program, "u_size_px", (float(vw), float(vh)))
            self._set(program, "u_rect", (0.0, 0.0, vw / self.size[0], vh / self.size[1]))
            self._set(program, "u_texel", (1.0 / self.size[0], 1.0 / self.size[1]))
            self._fullscreen_vao(program).render(self._moderngl.TRIANGLES, vertices=3)
        self._last = (vw, vh, fbo, viewport)

    # ------------------------------------------------------------------ read back
    def read_linear(self) -> np.ndarray:
        """The last frame's HDR radiance: float32 (H, W, 3), linear sRGB, cd m^-2 scale, row 0 = top."""
        if self._last is None:
            raise CatalogError("nothing rendered yet")
        vw, vh = self._last[:2]
        data = self._hdr_fbo.read(viewport=(0, 0, vw, vh), components=4, dtype="f4")
        return np.frombuffer(data, dtype=np.float32).reshape(vh, vw, 4)[::-1, :, :3].copy()

    def display_of(self, linear) -> np.ndarray:
        """Another radiance image (H, W, 3) linear sRGB at this renderer's size shown through
        the last frame's own display step: the glare when on (bloom), its exposure and white
        balance, the tone curve and the sRGB encoding, not its anti-aliasing (a rendering
        approximation, not a display one). uint8 (H, W, 3), row 0 = top. Overwrites the
        frame's HDR target and display image: read those first. The image bench shows the
        path-traced reference through it, so that the frame's glare is not counted as error."""
        w, h = self.size
        image = np.asarray(linear, dtype=np.float32)
        if image.shape != (h, w, 3):
            size = f"{image.shape[1]}x{image.shape[0]}" if image.ndim == 3 else str(image.shape)
            raise CatalogError(f"display_of: the image is {size} px, the frame {w}x{h} (H, W, 3 needed)")
        if self._last is None:
            raise CatalogError("display_of: render a frame first (its exposure shows the image)")
        rgba = np.concatenate([image[::-1], np.ones((h, w, 1), dtype=np.float32)], axis=-1)
        self._hdr.write(np.ascontiguousarray(rgba).tobytes())
        texture = self.draw_bloom(w, h) if self.bloom else self._hdr
        mode = self.antialiasing
        self.antialiasing = "off"
        try:
            self.display_pass(w, h, hdr=texture)
        finally:
            self.antialiasing = mode
        return self.read_srgb8()

    def read_srgb8(self) -> np.ndarray:
        """The last frame tone-mapped and sRGB-encoded: uint8 (H, W, 3), row 0 = top."""
        if self._last is None:
            raise CatalogError("nothing rendered yet")
        vw, vh, fbo, viewport = self._last
        if fbo is None:
            data = self._ldr_fbo.read(viewport=(0, 0, vw, vh), components=3)
        else:
            data = fbo.read(viewport=tuple(viewport) if viewport is not None else (0, 0, vw, vh),
                            components=3)
        return np.frombuffer(data, dtype=np.uint8).reshape(vh, vw, 3)[::-1].copy()

    def room_side_irradiance_at(self, positions) -> np.ndarray:
        """(P, 3) the room-side grid's last irradiance read as curtain.frag ROOM_SIDE reads it
        at world ``positions`` (bilinear, clamped to the opening's edge), float64."""
        return room_light.sample_bilinear(self.read_room_side(), room_light.curtain_side_uv(positions))

    def room_side_light_at(self, positions, room_hidden) -> tuple[np.ndarray, np.ndarray]:
        """curtain.vert ROOM_SIDE's light evaluated in numpy at ``positions`` (P, 3) with the
        room's side hidden by ``room_hidden`` (P,): the irradiance on the room side (the grid,
        bilinear, where open; pi x the room's capture at the patch where hidden) and the
        window-side capture's radiance at the patch, float64 (P, 3) each."""
        uv = np.clip(room_light.curtain_side_uv(positions), 0.0, 0.999)
        columns = (uv[:, 0] * room_light.LUMINAIRE_TEXELS[0]).astype(int)
        rows = (uv[:, 1] * room_light.LUMINAIRE_TEXELS[1]).astype(int)
        hidden = np.asarray(room_hidden, dtype=np.float64).reshape(-1, 1)
        room = self.read_luminaire(room_light.LUMINAIRE_LEVEL)[rows, columns].astype(np.float64)
        window = self.read_luminaire_back(room_light.BACK_LUMINAIRE_LEVEL)[rows, columns].astype(np.float64)
        return (1.0 - hidden) * self.room_side_irradiance_at(positions) + hidden * math.pi * room, window

    def wall_light_sources(self) -> room_light.WallLightSources:
        """What the window wall and its reveals show the cloth's window side, from the room's
        last light (:func:`room_light.walled_radiance`'s inputs, as the GL pass binds them)."""
        inputs = self.shading_inputs()
        reveals = self._reveal_inputs(inputs)
        return room_light.WallLightSources(
            lightmap=self.read_room_lightmap(),
            back=self.read_luminaire_back(reveals["back_level"]),
            reveal_sky=np.asarray(reveals["sky_half"], dtype=np.float64),
            reveal_ground=np.asarray(reveals["ground_half"], dtype=np.float64),
            key_rgb=np.asarray(self._room_colours(inputs)["u_key_rgb"], dtype=np.float64),
            to_light=np.asarray(inputs.key_to_light, dtype=np.float64))

    def twin_spectral(self, gbuffer: dict, mask) -> np.ndarray:
        """The float64 twin's spectral radiance (P, L) at the G-buffer pixels ``mask``: eq. 8 with
        :meth:`curtain_inputs` and the pixels' shadows (without the room side's RGB term,
        :meth:`twin_room_side_rgb`)."""
        from catalog.optics import shading_reference as ref  # noqa: PLC0415

        return ref.shade_spectral(self.curtain_inputs(), gbuffer["position"][mask], gbuffer["normal"][mask],
                                  gbuffer["tangent"][mask], self.camera.position,
                                  **ref.shadow_terms(gbuffer["shadows"][mask], gbuffer["second_coverage"][mask]))

    def twin_room_side_rgb(self, gbuffer: dict, mask) -> np.ndarray:
        """The twin of ROOM_SIDE's term (P, 3) linear sRGB at the G-buffer pixels (0 when the
        room side takes the stand-ins), from the per-vertex light the G-buffer carries (its
        values against their numpy evaluation: :meth:`room_side_light_at`)."""
        from catalog.optics import shading_reference as ref  # noqa: PLC0415

        positions = gbuffer["position"][mask]
        if not self.room_side_active():
            return np.zeros((positions.shape[0], 3))
        # the per-vertex light curtain.vert read (the G-buffer's, interpolated; its values are
        # held to their numpy evaluation by tests/test_render_room.py), where the folds hide the
        # outside (the hemisphere's share, for both lobes since issue 11's sixth round) passed
        # by each lobe
        inputs, normals = self.curtain_inputs(), gbuffer["normal"][mask]
        hidden_outside = gbuffer["shadows"][mask][:, 2].astype(np.float64)[:, None]
        window_side = gbuffer["window_side_light"][mask].astype(np.float64)
        return (ref.room_side_linear_srgb(inputs, positions, normals, self.camera.position,
                                          gbuffer["room_side_light"][mask].astype(np.float64),
                                          self.curtain_room_reflectance_rgb(self.shading_inputs()))
                + sum(ref.window_side_linear_srgb(inputs, positions, normals, self.camera.position,
                                                  math.pi * share * window_side, transmittance)
                      for share, transmittance in zip((hidden_outside, hidden_outside),
                                                      self.curtain_forward_rgb(self.shading_inputs())))
                # the window wall and its reveals (WALL_LIGHT), each lobe's share already passed
                + ref.window_side_linear_srgb(inputs, positions, normals, self.camera.position,
                                              math.pi * gbuffer["wall_light"][mask].astype(np.float64),
                                              (1.0, 1.0, 1.0)))

    def twin_linear_srgb(self, gbuffer: dict, mask) -> np.ndarray:
        """The float64 twin of the curtain's linear sRGB (P, 3) at the G-buffer pixels ``mask``
        (1 nm spectral eq. 8 plus the room side's term; tests hold the shader to it)."""
        from catalog.optics import shading_reference as ref  # noqa: PLC0415

        return ref.spectral_to_linear_srgb(self.twin_spectral(gbuffer, mask)) + self.twin_room_side_rgb(gbuffer, mask)

    def render_gbuffer(self) -> dict[str, np.ndarray]:
        """The curtain alone with the G-buffer variant: radiance and the per-pixel geometry the
        shader used (world position, unit normal, weft tangent), float32 (H, W, 3) each, a
        boolean mask of curtain pixels, and ``shadows`` (H, W, 4): the key's window mask, the
        coverage of the layer in front of the key and the outside's occlusion by the cloth and
        by the window wall (issue 11; 1, 0, 0, 0 where those are off). The reference shades these positions in float64."""
        mgl = self._moderngl
        w, h = self.size
        if self.room_side_active():   # the room's light on the cloth's room side (and its maps)
            self.draw_room_light(self.shading_inputs())
        elif self.key_shadow or self.sky_occlusion:   # the cloth's shadow maps of this mesh
            self.draw_cloth_shadow_maps(self.shading_inputs())
        if self._gbuffer is None:
            textures = [self.ctx.texture((w, h), 4, dtype="f4") for _ in range(8)]
            depth = self.ctx.depth_renderbuffer((w, h))
            self._gbuffer = (textures, self.ctx.framebuffer(textures, depth))
        textures, fbo = self._gbuffer
        fbo.use()
        self.ctx.viewport = (0, 0, w, h)
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        self.draw_curtain(self.camera.view_projection(w / h), gbuffer=True)
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

    # ------------------------------------------------------------------ report
    def info(self) -> dict:
        inputs = self.shading_inputs()
        decision = self._decision
        metered = self.ev100 is not None or self.metered_ev100 is not None
        return {
            "fabric": self.preset.name,
            "light": self.light.name,
            "illuminance_lx": round(self.light.illuminance_lx, 3),
            "mode": decision.requested,
            "fluorescence_variant": inputs.fluorescence_mode,
            "fluorescence_needed": decision.needed,
            "fluorescence_delta_e": decision.delta_e,
            "bands": self.n_bands,
            "see_through": inputs.direct > 0,
            "key_to_light": [round(float(v), 6) for v in inputs.key_to_light],
            "camera": {"yaw_deg": self.camera.yaw_deg, "pitch_deg": self.camera.pitch_deg,
                       "distance_m": self.camera.distance_m},
            "exposure": self.exposure_scale() if metered else None,
            "ev100": round(self.current_ev100(), 4) if metered else None,
            "auto_exposure": self.ev100 is None,
            "white_balance": self.white_balance,
            "white_balance_adapted": not np.allclose(self.white_balance_matrix(), np.eye(3)),
            "size": list(self.size),
            "room_lighting": self.room_lighting, "key_shadow": self.key_shadow,
            "sky_occlusion": self.sky_occlusion, "ambient_by_view": self.ambient_by_view,
            "outside_by_view": self.outside_by_view,
            "room_bounces": self.room_bounces, "room_lobe": self.room_lobe,
            "room_side_solved": self.room_side_solved, "side_eyes": self.side_eyes,
            "capture_folds": self.capture_folds, "secondary_dye": self.secondary_dye,
            "key_second_layer": self.key_second_layer,
            "shadow_map_size": self.shadow_texels,
            "curtain_open": self.curtain_open,
            "sky_model": self.sky_model, "bloom": self.bloom,
            "environment": None if self.environment is None else self.environment[0],
            "room_lamps": [[light.name, list(position)] for light, position in self.room_lamps],
        }

    def release(self) -> None:
        """Free this renderer's GL objects (not the context, not buffers bound from the cloth)."""
        ours = [self._hdr_fbo, self._ldr_fbo, self._oit_fbo, self._pre_fbo] + ([self._gbuffer[1]] if self._gbuffer else [])
        if self._msaa is not None:
            ours += [self._msaa["hdr_fbo"], self._msaa["oit_fbo"]]
        ours += [obj for name, obj in list((self._room_gl or {}).items())
                 + list((self._bloom_gl or {}).items()) if name.endswith("_fbo")]
        if self.ctx.fbo in ours:  # never leave a deleted framebuffer bound
            (self.ctx.screen or self.ctx.detect_framebuffer(0)).use()
        self._release_msaa()
        self._release_vaos()
        self._release_own_buffers()
        for obj in (self._hdr_fbo, self._hdr, self._depth, self._ldr_fbo, self._ldr, self._room_vbo,
                    self._oit_fbo, self._oit_accum, self._oit_weight, self._pre_fbo, self._pre):
            obj.release()
        if self._pattern_texture is not None:
            self._pattern_texture.release()
            self._pattern_texture = None
        if self._ring_vbo is not None:
            self._ring_vbo.release()
            self._ring_vbo = None
        if self._gbuffer is not None:
            for texture in self._gbuffer[0]:
                texture.release()
            self._gbuffer[1].release()
            self._gbuffer = None
        for program in self._programs.values():
            program.release()
        self._programs.clear()
        self._release_room_resources()
        for obj in (self._bloom_gl or {}).values():
            obj.release()
        self._bloom_gl = None
        if self.environment is not None:
            self.environment[1].release()
            self.environment = None
