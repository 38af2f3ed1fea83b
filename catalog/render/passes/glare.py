"""Pass 4 of the frame: glare before the tone map (bloom_*.frag), all at quarter size."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catalog.render.passes.gl_common import Pass, set_uniform

#: Glare: the fraction of the frame's radiance spread into the blurs, and the blurs' weights
#: (the frame's mip levels 1..6, wider blurs weighted less; normalised to sum 1).
BLOOM_STRENGTH = 0.04


BLOOM_LEVEL_WEIGHTS = (0.30, 0.24, 0.18, 0.13, 0.09, 0.06)


def quarter_level_weights() -> np.ndarray:
    """BLOOM_LEVEL_WEIGHTS on the quarter-size chain (its level k is the frame's level k + 2),
    normalised. The glow is drawn at quarter size, and there the frame's level 1 (a 2 x 2
    box) read bilinearly at a quarter-size pixel centre averages 2 x 2 of its texels: the
    frame's level 2. So level 1's weight joins level 2's and the sum is unchanged."""
    weights = np.asarray(BLOOM_LEVEL_WEIGHTS, dtype=np.float64)
    quarter = np.concatenate([[weights[0] + weights[1]], weights[2:]])
    return (quarter / quarter.sum()).astype("f4")


@dataclass(frozen=True)
class Glare:
    """What the display pass needs to add the glare: the quarter-size glow texture, the part
    of it drawn (u0, v0, du, dv) and the strength; the display pass mixes
    (1 - strength) * sharp + strength * glow per pixel (tonemap.frag's GLARE)."""
    glow: object
    rect: tuple
    strength: float


class GlarePass(Pass):
    """Glare before the tone map (bloom_down.frag, bloom_glow.frag), energy-preserving:
    BLOOM_STRENGTH of the HDR frame spread over wide blurs. Every target is quarter size;
    the full-size mix is done in the display pass (one full-size pass fewer).

    In: the HDR target. Out: a :class:`Glare` (the display pass reads it)."""

    def __init__(self, frame):
        super().__init__(frame)
        self.objects = None

    def _bloom_resources(self) -> dict:
        if self.objects is None:
            mgl, ctx = self.mgl, self.ctx
            w, h = self.frame.size
            size = (max(1, -(-w // 4)), max(1, -(-h // 4)))
            # float32: the sun's disc (~1e9 cd m^-2) overflows half floats
            quarter = ctx.texture(size, 4, dtype="f4")
            quarter.filter = (mgl.LINEAR_MIPMAP_NEAREST, mgl.LINEAR)  # whole levels: bilinear taps
            quarter.repeat_x = quarter.repeat_y = False
            glow = ctx.texture(size, 4, dtype="f4")
            glow.filter = (mgl.LINEAR, mgl.LINEAR)
            glow.repeat_x = glow.repeat_y = False
            self.objects = {"quarter": quarter, "quarter_fbo": ctx.framebuffer([quarter]),
                            "glow": glow, "glow_fbo": ctx.framebuffer([glow])}
        return self.objects

    def draw_bloom(self, vw: int, vh: int) -> Glare:
        """Glare of the HDR target's (vw, vh) corner: its 4 x 4 average (bloom_down.frag), that
        average's mip chain, their weighted sum (bloom_glow.frag); returns the :class:`Glare`
        the display pass mixes in."""
        mgl, gl = self.mgl, self._bloom_resources()
        self.ctx.disable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        qw, qh = -(-vw // 4), -(-vh // 4)
        gl["quarter_fbo"].use()
        self.ctx.viewport = (0, 0, qw, qh)
        program = self.gl.program("fullscreen.vert", "bloom_down.frag")
        self.frame.targets.hdr.use(location=0)
        set_uniform(program, "u_hdr", 0)
        set_uniform(program, "u_hdr_size", (vw, vh))
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        gl["quarter"].build_mipmaps()
        full_w, full_h = gl["quarter"].size
        rect = (0.0, 0.0, qw / full_w, qh / full_h)
        weights = quarter_level_weights()
        gl["glow_fbo"].use()
        program = self.gl.program("fullscreen.vert", "bloom_glow.frag", {"BLOOM_LEVELS": len(weights)})
        gl["quarter"].use(location=1)
        set_uniform(program, "u_quarter", 1)
        set_uniform(program, "u_quarter_rect", rect)
        set_uniform(program, "u_level_weight", weights)
        self.gl.fullscreen_vao(program).render(mgl.TRIANGLES, vertices=3)
        return Glare(gl["glow"], rect, BLOOM_STRENGTH)

    def read_glow(self, vw: int, vh: int) -> np.ndarray:
        """The last glow's drawn part: float32 (ceil(vh / 4), ceil(vw / 4), 3), row 0 = top."""
        qw, qh = -(-vw // 4), -(-vh // 4)
        data = self._bloom_resources()["glow_fbo"].read(viewport=(0, 0, qw, qh), components=4, dtype="f4")
        return np.frombuffer(data, dtype=np.float32).reshape(qh, qw, 4)[::-1, :, :3].copy()

    def framebuffers(self) -> list:
        return [obj for name, obj in (self.objects or {}).items() if name.endswith("_fbo")]

    def release(self) -> None:
        for obj in (self.objects or {}).values():
            obj.release()
        self.objects = None
