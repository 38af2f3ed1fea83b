"""The fluorescence shells' radiance as a Mitsuba texture (plugin name ``patterned_glow``).

The glow is the per-vertex emission of :func:`catalog.pathtrace.scene.fluorescence_per_vertex`
(a mesh attribute, interpolated over each triangle) times, when the fabric has a pattern,
c(uv) / mean(c): the threads glow, the holes do not, and the repeat's average is the
unpatterned glow, as the real-time frame draws it (curtain.frag: the threads' radiance times
1 / mean(c), alpha c).

Why a texture of its own, not Mitsuba's ``mesh_attribute``: an area emitter whose radiance is
spatially varying is sampled for next-event estimation by the texture's ``sample_position``
in uv, mapped onto the shape by ``eval_parameterization``. The built-in attribute texture
does not provide that mapping on a mesh, and next-event estimation saw a much fainter glow
than a ray that hits the shell (issue 11: the room lit by the shells alone, with the
``direct`` integrator, was 10x darker from emitter samples than from BSDF samples). Here
uv is sampled uniformly (pdf 1 per unit uv area; Mitsuba divides by the Jacobian of the
mesh's uv map), and the shells carry the curtain's uv, a one-to-one map of [0, 1]^2, so
every point of the shell can be drawn. tests/test_pathtrace.py checks that the two
estimators agree.
"""

from __future__ import annotations

import numpy as np

from catalog.pathtrace.tabulated import TabulatedSpectrum

#: The mesh attribute holding the per-vertex emission (linear sRGB radiance per side).
ATTRIBUTE = "vertex_fluorescence"


def register(mi) -> None:
    """Define the texture class for the current variant and register it as ``patterned_glow``."""
    import drjit as dr  # noqa: PLC0415

    class PatternedGlow(mi.Texture):
        def __init__(self, props):
            mi.Texture.__init__(self, props)
            self.coverage = (props.get_texture("coverage", 1.0)
                             if "coverage" in props else None)
            self.inv_mean = 1.0 / max(float(props.get("coverage_mean", 1.0)), 1e-6)
            self.uv_scale = (float(props.get("uv_scale_u", 1.0)), float(props.get("uv_scale_v", 1.0)))
            self.mean_radiance = float(props.get("mean_radiance", 1.0))
            self.max_radiance = float(props.get("max_radiance", 1.0))
            self.mesh = None
            self.spectrum = None   # spectral variants: set_spectrum

        def set_spectrum(self, wavelengths_nm, values, luminance) -> None:
            """Spectral variants: the glow's spectral shape (``values`` on the evenly spaced
            ``wavelengths_nm``) whose sRGB luminance, as Mitsuba's film converts it, is
            ``luminance``. A point then emits the shape times its RGB attribute's luminance
            over ``luminance``: every vertex's RGB is the same colour scaled (the effective
            photons, module doc), so the spectrum the film sees converts back to it."""
            self.spectrum = TabulatedSpectrum(mi, wavelengths_nm, values)
            self.inv_luminance = 1.0 / max(float(luminance), 1e-30)

        def attach(self, mesh) -> None:
            """The shell whose ATTRIBUTE this texture reads (set once the mesh exists)."""
            self.mesh = mesh

        def _value(self, si, active):
            value = self.mesh.eval_attribute_3(ATTRIBUTE, si, active)
            if self.coverage is not None:
                si2 = mi.SurfaceInteraction3f(si)
                si2.uv = mi.Point2f(si.uv.x * self.uv_scale[0], si.uv.y * self.uv_scale[1])
                c = dr.clip(self.coverage.eval_1(si2, active), 0.0, 1.0)
                value = value * (c * self.inv_mean)
            return value

        def eval(self, si, active=True):
            if self.spectrum is None:
                return dr.select(active, mi.Spectrum(self._value(si, active)), 0.0)
            rgb = self._value(si, active)
            scale = (0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z) * self.inv_luminance
            return dr.select(active, self.spectrum.at(mi, si.wavelengths, active) * scale, 0.0)

        def eval_3(self, si, active=True):
            return dr.select(active, mi.Color3f(self._value(si, active)), 0.0)

        def sample_position(self, sample, active=True):
            return mi.Point2f(sample), mi.Float(1.0)   # uniform in uv: pdf 1

        def pdf_position(self, p, active=True):
            return mi.Float(1.0)

        def is_spatially_varying(self):
            return True

        def mean(self):
            return self.mean_radiance

        def max(self):
            return self.max_radiance

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return f"PatternedGlow[pattern={self.coverage is not None}]"

    mi.register_texture("patterned_glow", lambda props: PatternedGlow(props))
