"""Pass 5 of the frame: the glare's mix, exposure, white balance, tone curve and sRGB
(tonemap.frag), then FXAA."""

from __future__ import annotations

import numpy as np

from catalog.core.errors import CatalogError
from catalog.render import adaptation as adaptation_lib, display as display_lib, display_lut
from catalog.render.passes.gl_common import Pass, set_uniform

#: Auto exposure meters a copy of the frame at most this many pixels wide (a mip level).
METER_MAX_SIDE_PX = 96


class DisplayPass(Pass):
    """The display transform (fullscreen.vert + tonemap.frag; :mod:`catalog.render.display`):
    exposure (EV100, fixed or metered from a luminance histogram of this frame), white balance
    (CAT16), the tone curve, gamut compression, the sRGB curve; then FXAA (fxaa.frag).

    In: the HDR target and the glare's glow (mixed in here, when on). Out: the caller's
    framebuffer or the frame's display image."""

    def __init__(self, frame):
        super().__init__(frame)
        self._wb_cache = None
        self._gamut_lut = None

    def gamut_boundary(self):
        """The gamut boundary's table as a float texture (display_lut.boundary_table, made
        once): linear, repeating along the hue, clamped along the lightness."""
        if self._gamut_lut is None:
            table = display_lut.boundary_table()
            self._gamut_lut = self.ctx.texture((table.shape[1], table.shape[0]), 1,
                                               table.tobytes(), dtype="f4")
            self._gamut_lut.filter = (self.mgl.LINEAR, self.mgl.LINEAR)
            self._gamut_lut.repeat_x = True
            self._gamut_lut.repeat_y = False
        return self._gamut_lut

    def release(self) -> None:
        if self._gamut_lut is not None:
            self._gamut_lut.release()
            self._gamut_lut = None

    def current_ev100(self) -> float:
        """The EV100 the next display pass uses (fixed, or the auto exposure's)."""
        if self.frame.ev100 is not None:
            return self.frame.ev100
        if self.frame.metered_ev100 is None:
            raise CatalogError("auto exposure: nothing metered yet (render a frame first)")
        return self.frame.metered_ev100

    def exposure_scale(self) -> float:
        """Linear radiance (cd m^-2) -> scene value the tone curve takes (EV and multiplier)."""
        return self.frame.exposure * display_lib.exposure_scale(self.current_ev100())

    def white_balance_matrix(self) -> np.ndarray:
        """Linear sRGB -> linear sRGB: CAT16 from the white of the light reaching the viewer to
        D65, with CAT16's degree of adaptation (catalog.render.adaptation), or the identity.
        The white is measured (a G-buffer draw) at the view of the first frame after the light,
        the fabric, the room's lamps or the size change, and kept while the camera moves (the web page replays
        camera-independent passes: catalog.web.export.check_camera_uniforms)."""
        key = self.white_key()
        if self._wb_cache is None or self._wb_cache[0] != key:
            self._wb_cache = (key, display_lib.white_balance_matrix(
                adaptation_lib.visible_white_xyz(self.frame), self.frame.white_balance,
                adaptation_lib.degree_of_adaptation()))
        return self._wb_cache[1]

    def white_key(self) -> tuple:
        """What the measured white depends on: the light and fabric (the shading inputs), the
        setting, the size, whether the room side is drawn and the room's lamps, which light
        what is seen (not the camera)."""
        self.frame.terms.shading_inputs()
        return (self.frame.terms.inputs_key, self.frame.white_balance, tuple(self.frame.size),
                self.frame.room_side_active(),
                tuple((light.name, position) for light, position in self.frame.room_lamps))

    def white_is_measured(self) -> bool:
        """Whether the next frame keeps the white it has (False: it measures a new one from
        the HDR target it draws, which a dry recording does not draw: catalog.web.export)."""
        return self._wb_cache is not None and self._wb_cache[0] == self.white_key()

    def measured_white(self) -> tuple | None:
        """(key, matrix) of the white measured last, or None: what :meth:`keep_white` takes."""
        return self._wb_cache

    def keep_white(self, measured: tuple) -> None:
        """Use a white measured before (:meth:`measured_white`) while its key holds: the web
        export keeps each scene's, whose variants come back to a light and fabric it measured."""
        self._wb_cache = measured

    def forget_white(self) -> None:
        """Measure the white again at the next frame, from its view (a still image adapts to
        its own view, as ``catalog snapshot`` does; the viewer keeps the white while orbiting)."""
        self._wb_cache = None

    def display_uniforms(self) -> dict:
        return display_lib.shader_uniforms(self.exposure_scale(), self.white_balance_matrix())

    def meter(self, vw: int, vh: int) -> float:
        """EV100 of the HDR target's (vw, vh) corner: a histogram of a mip level (at most
        METER_MAX_SIDE_PX wide), white-balanced, of display.meter_signal (largest channel)."""
        level = 0
        while max(vw, vh) >> level > METER_MAX_SIDE_PX:
            level += 1
        if level:
            self.frame.targets.hdr.build_mipmaps(0, level)
            self.frame.targets.hdr.filter = (self.mgl.NEAREST, self.mgl.NEAREST)
        w, h = max(1, self.frame.size[0] >> level), max(1, self.frame.size[1] >> level)
        data = np.frombuffer(self.frame.targets.hdr.read(level=level), dtype=np.float32).reshape(h, w, 4)
        cw, ch = max(1, -(-vw >> level)), max(1, -(-vh >> level))
        rgb = data[:ch, :cw, :3].astype(np.float64) @ self.white_balance_matrix().T  # as shown
        return display_lib.meter_ev100(display_lib.luminance_histogram(display_lib.meter_signal(rgb)))

    def display_pass(self, vw: int, vh: int, fbo=None, viewport=None, glare=None, stages: int = 3) -> None:
        """The display transform of the HDR target's (vw, vh) corner (the benchmark times it);
        ``glare``: the glare pass's :class:`~catalog.render.passes.glare.Glare` to mix in first
        (None: the HDR target as it is);
        ``stages``: tonemap.frag's DISPLAY_STAGES (3, all; fewer for the benchmark's cost per stage)."""
        self.white_balance_matrix()   # first: measuring a new white draws
        target = fbo if fbo is not None else self.frame.targets.ldr_fbo
        target_viewport = (tuple(viewport) if (fbo is not None and viewport is not None)
                           else (0, 0, vw, vh))
        fxaa = self.frame.antialiasing == "fxaa"
        if fxaa:   # display into our copy, FXAA from it into the target
            self.frame.targets.pre_fbo.use()
            self.ctx.viewport = (0, 0, vw, vh)
        else:
            target.use()
            self.ctx.viewport = target_viewport
        defines = {"DISPLAY_STAGES": int(stages), **({"GLARE": True} if glare is not None else {})}
        program = self.gl.program("fullscreen.vert", "tonemap.frag", defines)
        self.frame.targets.hdr.use(location=0)
        set_uniform(program, "u_hdr", 0)
        if glare is not None:
            glare.glow.use(location=1)
            set_uniform(program, "u_glow", 1)
            set_uniform(program, "u_glow_rect", glare.rect)
            set_uniform(program, "u_glare_strength", glare.strength)
        set_uniform(program, "u_hdr_rect", (0.0, 0.0, vw / self.frame.size[0], vh / self.frame.size[1]))
        if stages >= 3:
            self.gamut_boundary().use(location=2)
            set_uniform(program, "u_gamut_boundary", 2)
            for name, value in display_lut.shader_uniforms().items():
                set_uniform(program, name, value)
        for name, value in self.display_uniforms().items():
            set_uniform(program, name, value)
        self.gl.fullscreen_vao(program).render(self.mgl.TRIANGLES, vertices=3)
        if fxaa:
            target.use()
            self.ctx.viewport = target_viewport
            program = self.gl.program("fullscreen.vert", "fxaa.frag")
            self.frame.targets.pre.use(location=0)
            set_uniform(program, "u_ldr", 0)
            set_uniform(program, "u_size_px", (float(vw), float(vh)))
            set_uniform(program, "u_rect", (0.0, 0.0, vw / self.frame.size[0], vh / self.frame.size[1]))
            set_uniform(program, "u_texel", (1.0 / self.frame.size[0], 1.0 / self.frame.size[1]))
            self.gl.fullscreen_vao(program).render(self.mgl.TRIANGLES, vertices=3)
        self.frame._last = (vw, vh, fbo, viewport)
