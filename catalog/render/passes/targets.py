"""The frame's render targets and their limits: the HDR target (RGBA32F linear sRGB radiance)
and its depth, the display image (RGBA8) and its copy before FXAA, the weighted blended OIT
targets, the MSAA path's multisampled twins (made on first use), the G-buffer, and the room
light's maps (:class:`RoomTargets`: written by the shadow, window-capture and light-map
passes, read by the room and curtain passes). The frame owns them; passes draw into them."""

from __future__ import annotations

import math

import numpy as np

from catalog.core.errors import CatalogError
from catalog.render import curtain_frames


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


#: The largest image side we accept (also limited by the context's GL_MAX_TEXTURE_SIZE).
MAX_SIDE_PX = 16384


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


def occlusion_grid() -> int:
    """Tiles a side of the occlusion maps' atlas (one tile per occlusion direction)."""
    return math.ceil(math.sqrt(curtain_frames.OCCLUSION_DIRECTIONS))


class FrameTargets:
    """The frame's own targets at ``size`` (w, h): ``hdr`` / ``depth`` / ``hdr_fbo``, ``ldr`` /
    ``ldr_fbo`` (the display image), ``pre`` / ``pre_fbo`` (the display image before FXAA),
    ``oit_accum`` / ``oit_weight`` / ``oit_fbo``; :meth:`msaa_targets` and ``gbuffer`` on use."""

    def __init__(self, ctx, size: tuple[int, int]):
        import moderngl  # noqa: PLC0415

        self.ctx, self.size = ctx, size
        w, h = size
        self.hdr = ctx.texture((w, h), 4, dtype="f4")
        self.hdr.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.depth = ctx.depth_renderbuffer((w, h))
        self.hdr_fbo = ctx.framebuffer([self.hdr], self.depth)
        self.ldr = ctx.texture((w, h), 4)
        self.ldr_fbo = ctx.framebuffer([self.ldr])
        # the tone-mapped image before FXAA (fxaa.frag reads texels)
        self.pre = ctx.texture((w, h), 4)
        self.pre.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.pre.repeat_x = self.pre.repeat_y = False
        self.pre_fbo = ctx.framebuffer([self.pre])
        self.msaa = None                # the multisampled targets, made on first use
        self.gbuffer = None             # (textures, framebuffer), made on first use
        # weighted blended OIT: sum C a w | prod (1 - a), and sum a w; the scene's depth
        self.oit_accum = ctx.texture((w, h), 4, dtype="f4")
        self.oit_weight = ctx.texture((w, h), 1, dtype="f4")
        for texture in (self.oit_accum, self.oit_weight):
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.oit_fbo = ctx.framebuffer([self.oit_accum, self.oit_weight], self.depth)
        self.oit_fbo.depth_mask = False  # the layers are tested against the room, not each other

    def framebuffers(self) -> list:
        """Every framebuffer of these targets (to leave none of them bound when released)."""
        fbos = [self.hdr_fbo, self.ldr_fbo, self.oit_fbo, self.pre_fbo]
        if self.gbuffer is not None:
            fbos.append(self.gbuffer[1])
        if self.msaa is not None:
            fbos += [self.msaa["hdr_fbo"], self.msaa["oit_fbo"]]
        return fbos

    def msaa_targets(self) -> dict:
        """The MSAA path's targets (MSAA_SAMPLES float renderbuffers: HDR, depth, the two OIT
        targets) and single-target framebuffers to resolve them from, made once."""
        if self.msaa is None:
            ctx, size, n = self.ctx, self.size, MSAA_SAMPLES
            hdr = ctx.renderbuffer(size, 4, samples=n, dtype="f4")
            depth = ctx.depth_renderbuffer(size, samples=n)
            accum = ctx.renderbuffer(size, 4, samples=n, dtype="f4")
            weight = ctx.renderbuffer(size, 1, samples=n, dtype="f4")
            oit_fbo = ctx.framebuffer([accum, weight], depth)
            oit_fbo.depth_mask = False
            self.msaa = {
                "objects": [hdr, depth, accum, weight],
                "hdr_fbo": ctx.framebuffer([hdr], depth), "oit_fbo": oit_fbo,
                "accum_src": ctx.framebuffer([accum]), "weight_src": ctx.framebuffer([weight]),
                "accum_dst": ctx.framebuffer([self.oit_accum]),
                "weight_dst": ctx.framebuffer([self.oit_weight]),
            }
        return self.msaa

    def release_msaa(self) -> None:
        if self.msaa is not None:
            for name in ("hdr_fbo", "oit_fbo", "accum_src", "weight_src", "accum_dst", "weight_dst"):
                self.msaa[name].release()
            for obj in self.msaa["objects"]:
                obj.release()
            self.msaa = None

    def release(self) -> None:
        self.release_msaa()
        for obj in (self.hdr_fbo, self.hdr, self.depth, self.ldr_fbo, self.ldr,
                    self.oit_fbo, self.oit_accum, self.oit_weight, self.pre_fbo, self.pre):
            obj.release()
        if self.gbuffer is not None:
            for texture in self.gbuffer[0]:
                texture.release()
            self.gbuffer[1].release()
            self.gbuffer = None


#: The key's front-layer maps' side at most (texels; curtain.frag KEY_SHADOW through
#: key_visibility.frag). Finer, the strip along a fold's terminator (its flat triangles just
#: behind their own layer, seen from the key) sharpens into one wedge per triangle row.
KEY_FRONT_TEXELS = 256


class RoomTargets:
    """The curtain's maps the room's light draws (docs/room-light.md), made on first use by
    :meth:`get` as a dict of name -> GL object: the key light's transmittance map ``shadow``
    (``shadow_texels`` a side) and the cloth's front-layer maps ``key_front`` / ``key_second``
    (``key_texels`` a side), the occlusion maps, the cloth's room-side grid ``room_side``
    (written by the room's transport); the per-vertex textures are added by the shadow pass."""

    def __init__(self, ctx, shadow_texels: int):
        import moderngl  # noqa: PLC0415

        self.ctx, self.mgl = ctx, moderngl
        self.shadow_texels = int(shadow_texels)
        self.objects: dict | None = None
        #: what the maps hold: map group -> the key of its last real drawing (the shadow pass
        #: keeps a group whose inputs did not change); emptied with the maps
        self.drawn: dict = {}

    def get(self) -> dict:
        """The maps, made on first use."""
        if self.objects is None:
            mgl, ctx = self.mgl, self.ctx
            n = self.shadow_texels
            shadow = ctx.texture((n, n), 4, dtype="f2")
            shadow.filter = (mgl.LINEAR_MIPMAP_LINEAR, mgl.LINEAR)
            shadow.repeat_x = shadow.repeat_y = False
            n = self.key_texels
            key_front = ctx.texture((n, n), 4, dtype="f4")
            key_front.filter = (mgl.NEAREST, mgl.NEAREST)
            key_front.repeat_x = key_front.repeat_y = False
            key_front_depth = ctx.depth_renderbuffer((n, n))
            key_second = ctx.texture((n, n), 4, dtype="f4")   # the front-layer map peeled
            key_second.filter = (mgl.NEAREST, mgl.NEAREST)
            key_second.repeat_x = key_second.repeat_y = False
            key_second_depth = ctx.depth_renderbuffer((n, n))
            side = occlusion_grid() * curtain_frames.OCCLUSION_TEXELS
            occlusion = ctx.texture((side, side), 4, dtype="f4")
            occlusion.filter = (mgl.NEAREST, mgl.NEAREST)
            occlusion_depth = ctx.depth_renderbuffer((side, side))
            tw, th = curtain_frames.CURTAIN_SIDE_TEXELS
            side_light = ctx.texture((tw, th), 4, data=np.zeros((th, tw, 4), "f4").tobytes(), dtype="f4")
            side_light.filter = (mgl.LINEAR, mgl.LINEAR)
            side_light.repeat_x = side_light.repeat_y = False
            self.objects = {
                "key_front": key_front, "key_front_depth": key_front_depth,
                "key_front_fbo": ctx.framebuffer([key_front], key_front_depth),
                "key_second": key_second, "key_second_depth": key_second_depth,
                "key_second_fbo": ctx.framebuffer([key_second], key_second_depth),
                "occlusion": occlusion, "occlusion_depth": occlusion_depth,
                "occlusion_fbo": ctx.framebuffer([occlusion], occlusion_depth),
                "shadow": shadow, "shadow_fbo": ctx.framebuffer([shadow]),
                "room_side": side_light,
            }
        return self.objects

    @property
    def key_texels(self) -> int:
        """The key's front-layer maps' side: the shadow map's, at most KEY_FRONT_TEXELS."""
        return min(self.shadow_texels, KEY_FRONT_TEXELS)

    def framebuffers(self) -> list:
        return [obj for name, obj in (self.objects or {}).items() if name.endswith("_fbo")]

    def release(self) -> None:
        """Free the maps (made again on next use, e.g. at another shadow map size)."""
        if self.objects is None:
            return
        if self.ctx.fbo in self.framebuffers():
            (self.ctx.screen or self.ctx.detect_framebuffer(0)).use()
        for obj in self.objects.values():
            obj.release()
        self.objects = None
        self.drawn = {}
