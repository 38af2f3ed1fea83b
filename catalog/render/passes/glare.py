"""Pass 4 of the frame: glare before the tone map (bloom_*.frag)."""

from __future__ import annotations

import numpy as np

from catalog.render.passes.gl_common import Pass, set_uniform

#: Glare (bloom.frag): the fraction of the frame's radiance spread into the blurs, and the
#: blurs' weights (mip levels 1..6, wider blurs weighted less; normalised to sum 1).
BLOOM_STRENGTH = 0.04


BLOOM_LEVEL_WEIGHTS = (0.30, 0.24, 0.18, 0.13, 0.09, 0.06)


class GlarePass(Pass):
    """Glare before the tone map (bloom_down.frag, bloom_glow.frag, bloom.frag),
    energy-preserving: BLOOM_STRENGTH of the HDR frame spread over wide blurs.

    In: the HDR target. Out: its own full-size texture (the display pass reads it)."""

    def __init__(self, frame):
        super().__init__(frame)
        self.objects = None

    def _bloom_resources(self) -> dict:
        if self.objects is None:
            mgl, ctx = self.mgl, self.ctx
            w, h = self.frame.size
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
            self.objects = {"half": half, "half_fbo": ctx.framebuffer([half]),
                              "glow": glow, "glow_fbo": ctx.framebuffer([glow]),
                              "out": out, "out_fbo": ctx.framebuffer([out])}
        return self.objects

    def draw_bloom(self, vw: int, vh: int) -> object:
        """Glare: the HDR frame with BLOOM_STRENGTH of it spread over wide blurs
        (bloom_down.frag, then bloom.frag); returns the texture the tone map reads."""
        mgl, gl = self.mgl, self._bloom_resources()
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        hw, hh = (vw + 1) // 2, (vh + 1) // 2
        gl["half_fbo"].use()
        self.ctx.viewport = (0, 0, hw, hh)
        program = self.gl.program("fullscreen.vert", "bloom_down.frag")
        self.frame.targets.hdr.use(location=0)
        set_uniform(program, "u_hdr", 0)
        set_uniform(program, "u_hdr_size", (vw, vh))
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        gl["half"].build_mipmaps()
        full_w, full_h = gl["half"].size
        rect = (0.0, 0.0, hw / full_w, hh / full_h)
        gw, gh = gl["glow"].size
        qw, qh = (hw + 1) // 2, (hh + 1) // 2
        gl["glow_fbo"].use()
        self.ctx.viewport = (0, 0, qw, qh)
        program = self.gl.program("fullscreen.vert", "bloom_glow.frag",
                                {"BLOOM_LEVELS": len(BLOOM_LEVEL_WEIGHTS)})
        gl["half"].use(location=1)
        set_uniform(program, "u_half", 1)
        set_uniform(program, "u_half_rect", rect)
        weights = np.asarray(BLOOM_LEVEL_WEIGHTS, dtype="f4")
        set_uniform(program, "u_level_weight", weights / weights.sum())
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        gl["out_fbo"].use()
        self.ctx.viewport = (0, 0, vw, vh)
        program = self.gl.program("fullscreen.vert", "bloom.frag")
        self.frame.targets.hdr.use(location=0)
        set_uniform(program, "u_hdr", 0)
        gl["glow"].use(location=1)
        set_uniform(program, "u_glow", 1)
        set_uniform(program, "u_glow_rect", (0.0, 0.0, qw / gw, qh / gh))
        set_uniform(program, "u_strength", BLOOM_STRENGTH)
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        return gl["out"]

    def framebuffers(self) -> list:
        return [obj for name, obj in (self.objects or {}).items() if name.endswith("_fbo")]

    def release(self) -> None:
        for obj in (self.objects or {}).values():
            obj.release()
        self.objects = None
