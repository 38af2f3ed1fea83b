"""Eq. 7 as a Mitsuba 3 BSDF (plugin name ``woven``), written in Python on ``mi.BSDF``.

In the local shading frame (x = the weft tangent dP/du, z = the interpolated normal),
with ``wi`` towards the viewer (the previous path vertex) and ``wo`` towards the light
(the next vertex), the light travels along ``-wo`` and the angle theta of eq. 6 lies between
that direction of travel and the view ``wi`` (theta = 0: straight through, ``wo = -wi``):

    f(wi, wo) |cos wo| = dye * (a_diff ph(theta; g_diff) + a_spec ph_aniso(theta; g_spec)) |cos wo|
                                                                        (eq. 5-7, per sr)
    + LD delta(wo + wi)                      (eq. 7's LD: straight through the gaps, a null lobe)

ph is eq. 6 in the robust chord form of :mod:`catalog.optics.btdf` (``|wi + wo|^2`` = 2 (1 - cos
theta), the mirrored ``|wi - wo|^2`` for g < 0); the directional lobe's chord is weighted
(1 - anisotropy) along the weft and (1 + anisotropy) along the warp, as
:func:`catalog.optics.shading_reference.woven_chord2`. f is symmetric in (wi, wo) (reciprocal), two-sided
(|cos|, no side test) and multiplies the dye per channel (a texture: RGB in the RGB variant,
a spectrum in the spectral one).

Sampling: the gaps with probability LD / (LD + a_diff + a_spec) (null, ``wo = -wi``, weight
1 in the mean), else one HG lobe chosen in proportion to its albedo and its cos theta drawn
by HG's closed-form inverse about ``wi`` (the isotropic HG density; the anisotropic lobe's
value is divided by it, so the estimate stays unbiased and the weights stay near the
albedos). The null lobe is what Mitsuba's ``volpath`` integrator follows for shadow rays
(``eval_null_transmission``), so the sun through the gaps reaches the floor by next-event
estimation.

Pattern hook (model.md section 9): with a coverage texture c(uv) in [0, 1] the null
transmission is 1 - c and the lobes are scaled by c / mean(c), so that averaged over a
repeat the cloth is the fitted one; ``uv_scale`` maps the mesh's uv to pattern repeats.
"""

from __future__ import annotations

import math

INV_FOUR_PI = 1.0 / (4.0 * math.pi)
#: |g| below this samples the lobe uniformly (the HG inverse divides by g).
G_ISOTROPIC = 1e-3


def hg_from_chords(dr, chord2, anti2, g: float):
    """Eq. 6 from chord2 = |view - travel|^2 and anti2 = |view + travel|^2 (Dr.Jit arrays),
    the forward or the mirrored form on the threshold the shaders and the float64
    reference use (catalog.core.constants.HG_MIRROR_BELOW)."""
    from catalog.core.constants import HG_MIRROR_BELOW  # noqa: PLC0415

    if g >= HG_MIRROR_BELOW:
        d = (1.0 - g) * (1.0 - g) + g * chord2
    else:
        d = (1.0 + g) * (1.0 + g) - g * anti2
    d = dr.maximum(d, 1e-12)
    return (1.0 - g) * (1.0 + g) * INV_FOUR_PI / (d * dr.sqrt(d))


def register(mi) -> None:
    """Define the plugin class for the current variant and register it as ``woven``."""
    import drjit as dr  # noqa: PLC0415

    class WovenBSDF(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.direct = float(props.get("direct", 0.0))
            self.a_diff = float(props.get("a_diff", 0.0))
            self.g_diff = float(props.get("g_diff", 0.0))
            self.a_spec = float(props.get("a_spec", 0.0))
            self.g_spec = float(props.get("g_spec", 0.0))
            self.anisotropy = float(props.get("anisotropy", 0.0))
            for name in ("g_diff", "g_spec", "anisotropy"):
                if not -1.0 < getattr(self, name) < 1.0:
                    raise ValueError(f"woven: {name} must lie in (-1, 1)")
            if min(self.direct, self.a_diff, self.a_spec) < 0:
                raise ValueError("woven: direct, a_diff and a_spec must be >= 0")
            # the dye: three factors in the RGB variant (unbounded: a relative T / T_mean, as
            # the 3-band frame multiplies it), a spectrum texture in the spectral variant
            self.dye = props.get_texture("dye", 1.0) if "dye" in props else None
            self.dye_rgb = None
            if "dye_r" in props:
                self.dye_rgb = [float(props.get(f"dye_{c}", 1.0)) for c in "rgb"]
            self.coverage = (props.get_texture("coverage", 1.0)
                             if "coverage" in props else None)
            self.coverage_mean = float(props.get("coverage_mean", 1.0 - self.direct))
            self.uv_scale = (float(props.get("uv_scale_u", 1.0)), float(props.get("uv_scale_v", 1.0)))
            lobes = (mi.BSDFFlags.GlossyTransmission | mi.BSDFFlags.GlossyReflection
                     | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide)
            null = mi.BSDFFlags.Null | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
            self.m_components = [lobes, null]
            self.m_flags = lobes | null

        # -------------------------------------------------------------- pieces
        def _weights(self, si, active):
            """(null transmission, lobe scale) at si: LD and 1, or 1 - c and c / mean(c)."""
            if self.coverage is None:
                return mi.Float(self.direct), mi.Float(1.0)
            si2 = mi.SurfaceInteraction3f(si)
            si2.uv = mi.Point2f(si.uv.x * self.uv_scale[0], si.uv.y * self.uv_scale[1])
            c = dr.clip(self.coverage.eval_1(si2, active), 0.0, 1.0)
            return 1.0 - c, c / max(self.coverage_mean, 1e-6)

        def _dye(self, si, active):
            if self.dye_rgb is not None and not mi.is_spectral:
                return mi.Spectrum(*self.dye_rgb)
            if self.dye is None:
                return mi.Spectrum(1.0)
            return self.dye.eval(si, active)

        def _lobes(self, wi, wo):
            """a_diff ph_diff + a_spec ph_aniso (per sr), symmetric in wi, wo."""
            delta = wi + wo          # view - travel
            total = wi - wo          # view + travel
            chord2 = dr.squared_norm(delta)
            anti2 = dr.squared_norm(total)
            a = self.anisotropy
            chord_aniso = (delta.x * delta.x * (1.0 - a) + delta.y * delta.y * (1.0 + a)
                           + delta.z * delta.z)
            value = mi.Float(0.0)
            if self.a_diff > 0:
                value += self.a_diff * hg_from_chords(dr, chord2, anti2, self.g_diff)
            if self.a_spec > 0:
                value += self.a_spec * hg_from_chords(dr, chord_aniso, anti2, self.g_spec)
            return value

        def _lobe_pdf(self, wi, wo):
            """The isotropic mixture density the lobes are sampled from (per sr)."""
            total = self.a_diff + self.a_spec
            if total <= 0:
                return mi.Float(0.0)
            chord2 = dr.squared_norm(wi + wo)
            anti2 = dr.squared_norm(wi - wo)
            pdf = mi.Float(0.0)
            if self.a_diff > 0:
                pdf += (self.a_diff / total) * hg_from_chords(dr, chord2, anti2, self.g_diff)
            if self.a_spec > 0:
                pdf += (self.a_spec / total) * hg_from_chords(dr, chord2, anti2, self.g_spec)
            return pdf

        def _p_null(self, null_t, scale):
            lobes = scale * (self.a_diff + self.a_spec)
            return dr.select(null_t + lobes > 0, null_t / (null_t + lobes), 0.0)

        def _lobes_enabled(self, ctx):
            return (ctx.is_enabled(mi.BSDFFlags.GlossyTransmission, 0)
                    or ctx.is_enabled(mi.BSDFFlags.GlossyReflection, 0))

        # -------------------------------------------------------------- interface
        def sample(self, ctx, si, sample1, sample2, active=True):
            null_t, scale = self._weights(si, active)
            use_null = ctx.is_enabled(mi.BSDFFlags.Null, 1)
            use_lobes = self._lobes_enabled(ctx) and (self.a_diff + self.a_spec) > 0
            p_null = self._p_null(null_t, scale) if (use_null and use_lobes) else (
                mi.Float(1.0) if use_null else mi.Float(0.0))
            pick_null = sample1 < p_null
            s_lobe = dr.select(pick_null, 0.0, (sample1 - p_null) / dr.maximum(1.0 - p_null, 1e-12))

            # one HG lobe, in proportion to its albedo; cos theta by the closed-form inverse
            total = max(self.a_diff + self.a_spec, 1e-30)
            pick_diff = s_lobe < self.a_diff / total
            g = dr.select(pick_diff, self.g_diff, self.g_spec)
            xi = sample2.x
            sq = (1.0 - g * g) / (1.0 + g - 2.0 * g * xi)
            cos_hg = dr.select(dr.abs(g) < G_ISOTROPIC, 1.0 - 2.0 * xi,
                               (1.0 + g * g - sq * sq) / (2.0 * g))
            cos_hg = dr.clip(cos_hg, -1.0, 1.0)
            sin_hg = dr.safe_sqrt(1.0 - cos_hg * cos_hg)
            phi = 2.0 * math.pi * sample2.y
            travel = mi.Frame3f(si.wi).to_world(
                mi.Vector3f(sin_hg * dr.cos(phi), sin_hg * dr.sin(phi), cos_hg))
            wo = dr.select(pick_null, -si.wi, -travel)

            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = wo
            bs.eta = 1.0
            lobe_pdf = self._lobe_pdf(si.wi, wo) * (1.0 - p_null)
            bs.pdf = dr.select(pick_null, p_null, lobe_pdf)
            transmits = mi.Frame3f.cos_theta(si.wi) * mi.Frame3f.cos_theta(wo) < 0
            bs.sampled_type = dr.select(
                pick_null, mi.UInt32(int(mi.BSDFFlags.Null)),
                dr.select(transmits, mi.UInt32(int(mi.BSDFFlags.GlossyTransmission)),
                          mi.UInt32(int(mi.BSDFFlags.GlossyReflection))))
            bs.sampled_component = dr.select(pick_null, mi.UInt32(1), mi.UInt32(0))
            dye = self._dye(si, active)
            lobe_value = dye * (scale * self._lobes(si.wi, wo) * dr.abs(mi.Frame3f.cos_theta(wo)))
            weight = dr.select(pick_null, mi.Spectrum(null_t / dr.maximum(p_null, 1e-12)),
                               lobe_value / dr.maximum(lobe_pdf, 1e-30))
            ok = active & (bs.pdf > 0)
            return bs, dr.select(ok, weight, 0.0)

        def eval(self, ctx, si, wo, active=True):
            if not self._lobes_enabled(ctx):
                return mi.Spectrum(0.0)
            _, scale = self._weights(si, active)
            value = scale * self._lobes(si.wi, wo) * dr.abs(mi.Frame3f.cos_theta(wo))
            return dr.select(active, self._dye(si, active) * value, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            if not self._lobes_enabled(ctx):
                return mi.Float(0.0)
            null_t, scale = self._weights(si, active)
            p_null = self._p_null(null_t, scale) if ctx.is_enabled(mi.BSDFFlags.Null, 1) else 0.0
            return dr.select(active, self._lobe_pdf(si.wi, wo) * (1.0 - p_null), 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def eval_null_transmission(self, si, active=True):
            null_t, _ = self._weights(si, active)
            return dr.select(active, mi.Spectrum(null_t), 0.0)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return (f"WovenBSDF[direct={self.direct}, a_diff={self.a_diff}, g_diff={self.g_diff}, "
                    f"a_spec={self.a_spec}, g_spec={self.g_spec}, anisotropy={self.anisotropy}]")

    mi.register_bsdf("woven", lambda props: WovenBSDF(props))
