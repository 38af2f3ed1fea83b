"""The fabric's pattern as a texture (the curtain and shadow passes sample it)."""

from __future__ import annotations

import math

import numpy as np

from catalog.render.passes.gl_common import Pass

PATTERN_ANISOTROPY = 4.0


#: The pattern's LOD bias (common.glsl thread_texel; issue 11, eighth round): the reference
#: averages a pixel's box (variance 1/12 px^2), the hardware's trilinear filter at its level
#: (texel side T about a pixel) is the mip's box and the bilinear tent, T^2/12 + T^2/6 = T^2/4:
#: three times too wide, which blurs the lace's motifs; the level with T = 1/sqrt(3) px matches
#: the box's variance. 0: the hardware's level (before).
PATTERN_LOD_BIAS = math.log2(1.0 / math.sqrt(3.0))


class PatternTexture(Pass):
    """The fabric's pattern (catalog/presets/patterns.py) as a mipmapped RGBA32F texture
    (thread normal, coverage), anisotropically filtered; one texel of coverage 1 - LD without
    a [pattern]. The curtain and shadow passes read it."""

    def __init__(self, frame):
        super().__init__(frame)
        self.texture = None
        #: the hem's band (a lace's scallops: [pattern] border), RGBA32F as the pattern,
        #: repeating across, clamped up and down; None without one
        self.border = None
        self.border_repeats = None   # the band's depth in pattern repeats along v
        self.key = None
        self._pattern = None
        self.repeat_m = None
        self.mean_coverage = None
        #: the mip levels from catalog.presets.patterns.mip_chain (True: a periodic Gaussian
        #: per level, no moire) or the hardware's 2x2 box chain (False: the web page's, which
        #: builds its levels with generateMipmap)
        self.prefilter = True
        #: the mip level's bias (log2 of the filter's texel side per pixel): PATTERN_LOD_BIAS for
        #: a frame shown at its own size; a frame rendered k times larger to be box-filtered
        #: down (a supersampled still) adds log2(k), so the pattern is filtered for the pixel
        #: it will be shown in
        self.lod_bias = PATTERN_LOD_BIAS

    def set_fabric(self, preset) -> None:
        """The preset's pattern as a mipmapped RGBA32F texture (thread normal, coverage);
        without a [pattern] a uniform coverage 1 - LD (one texel). The texels and their
        prefiltered levels come from :func:`prepared_levels` (made once for the renderers
        that load the same fabric one after another)."""
        from catalog.presets.fabric import resolve_fabric  # noqa: PLC0415

        table = preset.table("pattern")
        key = (str(preset.path), repr(sorted(table.items())), preset.btdf.direct)
        if key == self.key:
            return
        pattern = resolve_fabric(preset).pattern
        if pattern is None:
            texels = np.array([[[0.0, 0.0, 1.0, 1.0 - preset.btdf.direct]]], dtype=np.float32)
            repeat = self.frame.mesh.fabric_size_m
            levels, band, band_levels = ([] if self.prefilter else None), None, None
        else:
            texels, levels, band, band_levels = prepared_levels(pattern, self.prefilter)
            repeat = pattern.repeat_m
        self.release()
        self.texture = self._mipmapped(texels, levels, periodic_v=True)
        if band is not None:
            self.border = self._mipmapped(band, band_levels, periodic_v=False)
            self.border_repeats = pattern.border.depth_m / float(repeat[1])
        self._pattern = pattern
        self.repeat_m = tuple(float(v) for v in repeat)
        self.mean_coverage = float(np.mean(texels[..., 3], dtype=np.float64))
        self.key = key

    def _mipmapped(self, texels: np.ndarray, levels, periodic_v: bool):
        """A trilinear, anisotropic RGBA32F texture of ``texels``, repeating across and, when
        ``periodic_v``, down (else clamped: the hem's band). Its levels: ``levels`` (1..n, the
        prefiltered chain, :func:`prepared_levels`) written over the built chain, or (None)
        the hardware's box chain."""
        mgl = self.mgl
        h, w = texels.shape[:2]
        texture = self.ctx.texture((w, h), 4, np.ascontiguousarray(texels).tobytes(), dtype="f4")
        texture.repeat_x = True
        texture.repeat_y = periodic_v
        texture.filter = (mgl.LINEAR_MIPMAP_LINEAR, mgl.LINEAR)
        texture.build_mipmaps()   # allocates the levels; their texels are the prefiltered chain
        for level, image in enumerate(levels or (), start=1):
            texture.write(np.ascontiguousarray(image, dtype="f4").tobytes(), level=level)
        max_aniso = float(self.ctx.info.get("GL_MAX_TEXTURE_MAX_ANISOTROPY", 1.0) or 1.0)
        texture.anisotropy = min(PATTERN_ANISOTROPY, max_aniso)
        return texture

    def defines(self) -> dict:
        """The shaders' defines that this pattern needs beside PATTERN (HEM_BORDER)."""
        return {"HEM_BORDER": True} if self.border is not None else {}

    def bind(self, program, unit: int, fabric_size_m) -> None:
        """The pattern (and the hem's band) on texture ``unit`` (the band on BORDER_UNIT) and
        the scale from the cloth's uv (0..1 over ``fabric_size_m``) to pattern repeats."""
        from catalog.render.passes.gl_common import BORDER_UNIT, set_uniform  # noqa: PLC0415

        self.texture.use(location=unit)
        set_uniform(program, "u_pattern", unit)
        set_uniform(program, "u_uv_to_repeats",
                    tuple(f / r for f, r in zip(fabric_size_m, self.repeat_m)))
        if self.border is not None and "u_border" in program:
            self.border.use(location=BORDER_UNIT)
            set_uniform(program, "u_border", BORDER_UNIT)
            set_uniform(program, "u_border_repeats", float(self.border_repeats))

    def set_prefilter(self, on: bool) -> None:
        """The mip chain: prefiltered (True, default) or the hardware's box chain (False, what
        the web page builds). Takes effect at the next fabric load."""
        if bool(on) != self.prefilter:
            self.prefilter = bool(on)
            self.key = None

    def set_pattern_filtering(self, filtered: bool) -> None:
        """True (default): trilinear mipmapped, anisotropic; False: nearest texel, no mips
        (for measuring what the filtering buys: shimmer, the far limit)."""
        mgl = self.mgl
        texture = self.texture
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
        texture = self.texture
        w = max(1, texture.width >> level)
        h = max(1, texture.height >> level)
        data = texture.read(level=level)
        return np.frombuffer(data, dtype=np.float32).reshape(h, w, 4).copy()

    def release(self) -> None:
        for texture in (self.texture, self.border):
            if texture is not None:
                texture.release()
        self.texture = self.border = self.border_repeats = None


#: The last pattern's texels and levels (:func:`prepared_levels`): (weak reference to the
#: pattern, prefilter, value). One entry: the web export's swatch, meter and recording
#: renderers load each fabric in turn.
_PREPARED: list = [None]


def _prefiltered(texels: np.ndarray, periodic_v: bool) -> list[np.ndarray]:
    """Levels 1..n of ``texels``' prefiltered chain (catalog.presets.patterns.mip_chain, kept
    on disk by catalog.presets.mip_cache) as GL sizes them (w >> k by h >> k); a band (not ``periodic_v``) is mirrored about its top
    row first, what the clamped edge continues as, each level keeping its first half, and
    its chain stops where the mirrored chain runs out of rows (a band under 2^k rows)."""
    from catalog.presets.mip_cache import cached_mip_chain  # noqa: PLC0415

    h, w = texels.shape[:2]
    source = texels if periodic_v else np.concatenate([texels, texels[::-1]])
    levels = []
    # mip_chain's levels, from the disk cache when this texture was filtered before
    for level, image in enumerate(cached_mip_chain(source)[1:], start=1):
        rows = max(1, h >> level)
        image = image if periodic_v else image[:rows]
        if image.shape[:2] != (rows, max(1, w >> level)):
            break
        levels.append(image)
    return levels


def prepared_levels(pattern, prefilter: bool = True) -> tuple:
    """(texels, levels, band, band_levels) of a :class:`catalog.presets.patterns.Pattern`:
    its normal map (H, W, 4) float32, its prefiltered levels 1..n (:func:`_prefiltered`;
    None when not ``prefilter``: the hardware's box chain), the hem band's and its levels
    (None without a band). Made once for the renderers that load the same pattern object
    one after another (the last pattern is kept)."""
    import weakref  # noqa: PLC0415

    kept = _PREPARED[0]
    if kept is not None and kept[0]() is pattern and kept[1] == bool(prefilter):
        return kept[2]
    _PREPARED[0] = None   # the last pattern's arrays go before this one's are made
    texels = pattern.normal_map()
    band = pattern.border_normal_map()
    value = (texels, _prefiltered(texels, True) if prefilter else None, band,
             None if band is None or not prefilter else _prefiltered(band, False))
    _PREPARED[0] = (weakref.ref(pattern), bool(prefilter), value)
    return value


def forget_prepared() -> None:
    """Let the kept pattern's arrays go (:func:`prepared_levels`): the renderers that share
    them have loaded it (the web export's meter and recording renderer, at a fabric's first
    scene), so that they are not held beside what the recording gathers."""
    _PREPARED[0] = None
