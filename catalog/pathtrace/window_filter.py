"""The outside's own spectrum in a spectral variant: a filter across the window (issue 11,
eighth round; BSDF plugin name ``window_filter``).

Mitsuba's environment map carries an RGB per texel and, in a spectral variant, upsamples it
to a smooth spectrum after clamping it into the sRGB gamut. A UV lamp's outside (the backdrop
it lights, sky and ground) is its faint violet leak: out of gamut (green -0.92 of red), so
the spectral reference had to take an in-gamut colour of the same luminance for it
(scene.in_gamut_same_luminance), a far paler violet than the light. Seen through a mesh's
holes that is a different colour from the lamp's: the frame's, whose linear sRGB keeps the
negative green, was bluer on every fold (the safety-yellow room under the lamp, +0.7 in blue
in the troughs).

Where the outside's radiance is the key light's spectrum S times a scalar per direction (sky
and ground lit by the key, no sky image: ``outside_carries_key_spectrum``) and the camera is
in the room (``sheet_applies``), the reference
now renders it exactly: the environment map holds the scalar (the texel's luminance, as
grey), which Mitsuba emits as luminance times its D65 (normalised to luminance 1), and a
null-scattering sheet across the window's outer plane passes light by

    T(lambda) = S(lambda) / (Y(S) D65(lambda))

so that what enters the room is luminance x S / Y(S): the outside's own spectrum at its own
luminance. The key, a directional light, crosses the same sheet, so its spectrum is given as
its luminance times D65 and leaves the sheet as the key's. Light leaving the room through
the window is lost either way. T exceeds 1 where S is concentrated (a weight, not a
reflectance: the sheet stands for the change of spectrum, not a physical filter).
"""

from __future__ import annotations

import numpy as np

from catalog.core.constants import LUMA_REC709
from catalog.pathtrace.tabulated import TabulatedSpectrum

#: The sheet's shape id (render.region_masks counts it as the outside).
SHEET_ID = "window_filter"
#: How far (m) the sheet lies outside the wall's outer plane, and how far beyond the window
#: opening it reaches (only rays through the opening can meet it).
SHEET_OFFSET_M = 0.01
SHEET_MARGIN_M = 0.5


def register(mi) -> None:
    """Define the BSDF class for the current variant and register it as ``window_filter``."""
    import drjit as dr  # noqa: PLC0415

    class WindowFilter(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.values = None
            null = mi.BSDFFlags.Null | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
            self.m_components = [null]
            self.m_flags = null

        def set_transmission(self, wavelengths_nm, values) -> None:
            """T on the evenly spaced ``wavelengths_nm`` (0 outside them)."""
            self.values = TabulatedSpectrum(mi, wavelengths_nm, values)

        def _transmission(self, si, active):
            if self.values is None:
                return mi.Spectrum(1.0)
            return self.values.at(mi, si.wavelengths, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = -si.wi
            bs.pdf = mi.Float(1.0)
            bs.eta = mi.Float(1.0)
            bs.sampled_type = mi.UInt32(int(mi.BSDFFlags.Null))
            bs.sampled_component = mi.UInt32(0)
            use = active & ctx.is_enabled(mi.BSDFFlags.Null, 0)
            return bs, dr.select(use, self._transmission(si, use), 0.0)

        def eval(self, ctx, si, wo, active=True):
            return mi.Spectrum(0.0)

        def pdf(self, ctx, si, wo, active=True):
            return mi.Float(0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return mi.Spectrum(0.0), mi.Float(0.0)

        def eval_null_transmission(self, si, active=True):
            return dr.select(active, self._transmission(si, active), 0.0)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return "WindowFilter[]"

    mi.register_bsdf("window_filter", lambda props: WindowFilter(props))


def outside_carries_key_spectrum(desc) -> bool:
    """Whether the outside's radiance is the key's spectrum times a scalar: no sky image, and
    the sky's and the ground's RGB both parallel to the key's (a lamp's backdrop; the sun's
    sky is tinted, and daylight lies in the gamut anyway)."""
    if desc.sky is not None:
        return False
    key = np.asarray(desc.key_rgb, dtype=np.float64)
    if not np.linalg.norm(key) > 0:
        return False
    for rgb in (desc.sky_rgb, desc.ground_rgb):
        rgb = np.asarray(rgb, dtype=np.float64)
        if np.linalg.norm(rgb) == 0:
            continue
        if abs(rgb @ key) / (np.linalg.norm(rgb) * np.linalg.norm(key)) < 1.0 - 1e-6:
            return False
    return True


def sheet_applies(desc) -> bool:
    """Whether the reference takes the sheet: the outside carries the key's spectrum and the
    camera is in the room. From outside, the camera would look into the room through the
    sheet, and the room's light would reach it filtered; there the in-gamut stand-in stays."""
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    inside = float(np.asarray(desc.camera_position, dtype=np.float64)[2]) > scene_lib.WINDOW_Z
    return inside and outside_carries_key_spectrum(desc)


def mitsuba_d65(mi, wavelengths_nm: np.ndarray) -> np.ndarray:
    """Mitsuba's D65 (luminance 1 on its film) at ``wavelengths_nm``: what an environment
    texel of grey 1 emits in a spectral variant."""
    import drjit as dr  # noqa: PLC0415

    si = dr.zeros(mi.SurfaceInteraction3f)
    w = mi.Float(np.asarray(wavelengths_nm, dtype=np.float32))
    si.wavelengths = mi.Spectrum(w, w, w, w)
    return np.asarray(mi.load_dict({"type": "d65"}).eval(si)[0], dtype=np.float64)


def transmission(key_values: np.ndarray, key_luminance: float, d65: np.ndarray) -> np.ndarray:
    """T(lambda) = S / (Y(S) D65) of the module doc: ``key_values`` S, ``key_luminance`` its
    film luminance Y(S), ``d65`` Mitsuba's D65 on the same wavelengths (mitsuba_d65)."""
    d65 = np.asarray(d65, dtype=np.float64)
    if not key_luminance > 0:
        return np.zeros_like(d65)
    return np.asarray(key_values, dtype=np.float64) / (key_luminance * np.maximum(d65, 1e-12))


def grey_environment(env_rgb: np.ndarray) -> np.ndarray:
    """The environment map as grey texels of each texel's luminance (linear sRGB weights;
    the out-of-gamut colour's luminance is its CIE Y, positive)."""
    luminance = np.clip(np.asarray(env_rgb, dtype=np.float64) @ np.array(LUMA_REC709), 0.0, None)
    return np.repeat(luminance[..., None], 3, axis=-1).astype(np.float32)


def sheet_geometry() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(positions (4, 3), faces (2, 3), normals (4, 3)) of the sheet: a rectangle beyond the
    window wall's outer plane covering the opening with SHEET_MARGIN_M to spare."""
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    x0, x1, y0, y1 = scene_lib.WINDOW_RECT
    z = scene_lib.WINDOW_Z - scene_lib.WALL_THICKNESS_M - SHEET_OFFSET_M
    m = SHEET_MARGIN_M
    positions = np.array([[x0 - m, y0 - m, z], [x1 + m, y0 - m, z],
                          [x1 + m, y1 + m, z], [x0 - m, y1 + m, z]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    normals = np.repeat(np.array([[0.0, 0.0, 1.0]]), 4, axis=0)
    return positions, faces, normals
