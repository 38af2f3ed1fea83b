"""Transmission through woven cloth: the HG phase function (eq. 6), the woven-cloth
model (eq. 7) and Cook-Torrance, the paper's baseline for the same measurements.

Everything is vectorised numpy. Results take the floating type of the inputs (float64
for Python floats and float64 arrays; float32 arrays stay float32, which is how the
GLSL port behaves, so the float32 tests here speak for the shader).

Directions and angles (model.md section 5, formats.md):

- ``travel``: the light's direction of travel (unit vector, minus the direction to
  the light);
- ``view``: the direction from the cloth to the viewer (unit vector);
- theta: the angle between them, 0 = straight through.

The robust HG form (what shaders/common.glsl ports unchanged)
--------------------------------------------------------------

Eq. 6 as printed, ``(1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^1.5)``, cancels
catastrophically as g -> 1 and theta -> 0: ``1 + g^2`` and ``2 g cos theta`` are both
near 2 and their difference near ``(1-g)^2`` (1e-6 at g = 0.999) is lost in float32
(10 % off at g = 0.999, 0 -> infinity at g = 0.9999). The same quantity written as a
sum of non-negative terms keeps full relative precision::

    one_minus_cos = 0.5 * dot(travel - view, travel - view)   # = 1 - cos theta, exact
    d     = (1 - g) * (1 - g) + 2 * g * one_minus_cos          # = 1 + g^2 - 2 g cos theta
    phase = (1 - g) * (1 + g) / (4 * pi * d * sqrt(d))         # eq. 6

For g >= 0 both terms of ``d`` are >= 0, so there is no cancellation at all. For
g < 0 the mirror case (a backward peak, theta -> pi, g -> -1) cancels the same way, and
the mirrored form keeps it exact; it is taken below ``HG_MIRROR_BELOW`` (-0.2,
catalog.core.constants: :func:`hg_denominator_robust`, which shaders/common.glsl's hg_d and
the path tracer's plugin share)::

    one_plus_cos = 0.5 * dot(travel + view, travel + view)    # = 1 + cos theta, exact
    d = (1 + g) * (1 + g) - 2 * g * one_plus_cos               # g < 0

``d * sqrt(d)`` replaces ``pow(d, 1.5)``
(one rounding instead of exp/log). ``1 - cos theta`` must come from the vectors: taking
it as ``1 - dot(travel, view)`` re-introduces the cancellation.

Cook-Torrance transmission (the baseline)
-----------------------------------------

The cloth has no refracting interface, so the transmitted lobe is the Cook-Torrance
reflection lobe mirrored through the cloth plane: with ``l`` the direction to the light
(z < 0), ``v`` the view (z > 0) and ``v' = (v_x, v_y, -v_z)`` the view mirrored to the
light's side, the half vector is ``h = normalise(l + v')`` and the cloth normal on that
side is ``n = (0, 0, -1)``; straight-through (``v = -l``) gives ``h = n``. The measured
ratio (eq. 7 with Lin = 1) is the BTDF times cos theta_i (eq. 5)::

    T_CT = direct * [straight through]
           + k_lambert * cos_i / pi
           + k_spec * D(h) * G(l, v', h) / (4 * cos_o)        # cos_i of 1/(4 cos_i cos_o) cancels
    D = exp(-tan^2 theta_h / m^2) / (pi m^2 cos^4 theta_h)    # Beckmann, roughness m
    G = min(1, 2 (n.h)(n.v') / (v'.h), 2 (n.h)(n.l) / (v'.h)) # Cook & Torrance 1982 V-groove

with Fresnel = 1 folded into ``k_spec`` (no interface to weigh). Four parameters
(direct, k_lambert, k_spec, m) against eq. 7's five.
"""

from __future__ import annotations

import math

import numpy as np

from catalog.core.constants import HG_MIRROR_BELOW

FOUR_PI = 4.0 * math.pi

#: A straight-through point: theta below this (degrees) sees the lamp through the gaps
#: (the collimated lamp's angular radius). On the OGM-3 grid only light elevation 180 with
#: camera elevation 90 qualifies; the next nearest grid points are 0.19 deg off.
STRAIGHT_THROUGH_DEG = 0.1


def _check_g(g) -> None:
    g_arr = np.asarray(g)
    if not np.all(np.abs(g_arr) < 1.0):
        bad = g_arr[~(np.abs(g_arr) < 1.0)]
        raise ValueError(f"HG g must lie in (-1, 1), got {bad.ravel()[:3]}")


def one_minus_cos_between(travel: np.ndarray, view: np.ndarray) -> np.ndarray:
    """``1 - cos theta`` between unit vectors (last axis 3), as ``|a - b|^2 / 2``.

    Exact for small angles (relative precision of the inputs), where ``1 - dot(a, b)``
    would round to 0.
    """
    diff = np.asarray(travel) - np.asarray(view)
    return 0.5 * np.einsum("...i,...i->...", diff, diff)


def hg_denominator(one_minus_cos, g):
    """``1 + g^2 - 2 g cos theta`` written as ``(1 - g)^2 + 2 g (1 - cos theta)``."""
    one_minus_g = 1 - g
    return one_minus_g * one_minus_g + 2 * g * one_minus_cos


def hg_denominator_robust(one_minus_cos, one_plus_cos, g):
    """Eq. 6's ``d`` in the form that keeps its digits: the forward form above for
    ``g >= HG_MIRROR_BELOW``, the mirrored ``(1 + g)^2 - 2 g (1 + cos theta)`` below it
    (the one threshold of catalog.core.constants, which the shaders' hg_d uses too)."""
    one_plus_g = 1 + g
    return np.where(np.asarray(g) >= HG_MIRROR_BELOW, hg_denominator(one_minus_cos, g),
                    one_plus_g * one_plus_g - 2 * g * np.asarray(one_plus_cos))


def hg_phase_of_d(d, g):
    """Eq. 6 from its denominator's base ``d``: ``(1 - g)(1 + g) / (4 pi d sqrt(d))``."""
    return (1 - g) * (1 + g) / (FOUR_PI * d * np.sqrt(d))


def hg_phase_one_minus_cos(one_minus_cos, g):
    """Eq. 6 (per steradian) from ``1 - cos theta``, in the robust form above.

    ``g`` in (-1, 1) (scalar or broadcastable array); integrates to 1 over the sphere.
    """
    _check_g(g)
    # 1 - cos theta lies in [0, 2]; rounding can step just outside, and for g -> -1 at
    # theta = pi the forward form (1-g)^2 + 2g(1 - cos) cancels to a tiny negative number
    # (NaN from the square root). Below HG_MIRROR_BELOW the mirrored form (1+g)^2 - 2g(1 + cos),
    # a sum of non-negative terms, is taken (hg_denominator_robust, as hg_phase_between does).
    one_minus_cos = np.clip(np.asarray(one_minus_cos), 0.0, 2.0)  # keeps float32 as float32
    return hg_phase_of_d(hg_denominator_robust(one_minus_cos, 2.0 - one_minus_cos, g), g)


def hg_phase(cos_theta, g):
    """Eq. 6 from ``cos theta``. Prefer :func:`hg_phase_between` when vectors are at hand:
    ``1 - cos theta`` taken from a rounded ``cos theta`` has already lost its digits."""
    return hg_phase_one_minus_cos(1 - np.asarray(cos_theta), g)


def hg_phase_between(travel: np.ndarray, view: np.ndarray, g):
    """Eq. 6 for the light's direction of travel and the view direction (unit vectors,
    last axis 3): the forward robust form for g >= HG_MIRROR_BELOW, the mirrored one below."""
    _check_g(g)
    travel, view = np.asarray(travel), np.asarray(view)
    one_minus_cos = one_minus_cos_between(travel, view)
    total = travel + view
    one_plus_cos = 0.5 * np.einsum("...i,...i->...", total, total)
    return hg_phase_of_d(hg_denominator_robust(one_minus_cos, one_plus_cos, g), g)  # eq. 6


def hg_phase_printed(cos_theta, g):
    """Eq. 6 exactly as printed (for comparison only: cancels as g -> 1, theta -> 0)."""
    _check_g(g)
    denom = 1 + g * g - 2 * g * np.asarray(cos_theta)
    return (1 - g * g) / (FOUR_PI * denom ** 1.5)


def hg_phase_dg(one_minus_cos, g):
    """d(eq. 6)/dg at fixed theta (for the fit's Jacobian)."""
    d = hg_denominator(one_minus_cos, g)
    dd_dg = -2 * (1 - g) + 2 * one_minus_cos
    sqrt_d = np.sqrt(d)
    return (-2 * g / (FOUR_PI * d * sqrt_d)
            - 1.5 * (1 - g) * (1 + g) * dd_dg / (FOUR_PI * d * d * sqrt_d))


def hg_phase_and_dg(one_minus_cos, g: float):
    """Eq. 6 and its derivative in g together, sharing d and sqrt(d) (the fit's inner
    loop; ``g`` a float in (-1, 1), not checked)."""
    d = hg_denominator(one_minus_cos, g)
    d_sqrt_d = d * np.sqrt(d)
    one_minus_g2 = (1 - g) * (1 + g)
    phase = one_minus_g2 / (FOUR_PI * d_sqrt_d)
    dd_dg = 2 * (one_minus_cos - (1 - g))
    return phase, phase * (-2 * g / one_minus_g2 - 1.5 * dd_dg / d)


def eq7_scattered(one_minus_cos, a_diff, a_spec, g_diff, g_spec):
    """The two HG lobes of eq. 7 with Lin = 1 (per steradian):
    ``a_diff ph(theta; g_diff) + a_spec ph(theta; g_spec)``, ``a = rho e^-tau k``."""
    return (a_diff * hg_phase_one_minus_cos(one_minus_cos, g_diff)      # eq. 7
            + a_spec * hg_phase_one_minus_cos(one_minus_cos, g_spec))


def eq7_transmittance(one_minus_cos, direct, a_diff, a_spec, g_diff, g_spec,
                      straight_through=None):
    """Eq. 7 with Lin = 1, as the gonio ratio measures it.

    ``LD`` (``direct``) is the see-through of the gaps (model.md section 5): it reaches
    the camera only in the straight-through direction, so it is added where
    ``straight_through`` (bool array) is true; by default where theta <
    :data:`STRAIGHT_THROUGH_DEG`.
    """
    one_minus_cos = np.asarray(one_minus_cos)
    if straight_through is None:
        straight_through = is_straight_through(one_minus_cos)
    return (direct * np.asarray(straight_through, dtype=one_minus_cos.dtype)
            + eq7_scattered(one_minus_cos, a_diff, a_spec, g_diff, g_spec))   # eq. 7


def is_straight_through(one_minus_cos, limit_deg: float = STRAIGHT_THROUGH_DEG):
    """True where theta < ``limit_deg``."""
    return np.asarray(one_minus_cos) < 1.0 - math.cos(math.radians(limit_deg))


def woven_one_minus_cos(travel: np.ndarray, view: np.ndarray, anisotropy: float = 0.0):
    """The directional lobe's 1 - cos theta with the warp/weft anisotropy A (our extension,
    shaders/common.glsl ``woven_chord2`` / 2): delta = view - travel in the cloth frame
    (x along the weft, y along the warp, z the normal),
    ``(dx^2 (1 - A) + dy^2 (1 + A) + dz^2) / 2``; A = 0 is eq. 6's."""
    delta = np.asarray(view) - np.asarray(travel)
    return 0.5 * (delta[..., 0] ** 2 * (1 - anisotropy) + delta[..., 1] ** 2 * (1 + anisotropy)
                  + delta[..., 2] ** 2)


def woven_btdf(params, travel: np.ndarray, view: np.ndarray, anisotropy: float = 0.0):
    """Eq. 7's scattered part (the two lobes) for a :class:`catalog.presets.BTDFParams`,
    the directional lobe with the preset's ``btdf.anisotropy`` (default 0).

    The direct see-through (``params.direct``) is a delta in the straight-through
    direction: a renderer adds it as the background seen through the gaps.
    """
    return (params.a_diff * hg_phase_one_minus_cos(one_minus_cos_between(travel, view),
                                                   params.g_diff)
            + params.a_spec * hg_phase_one_minus_cos(woven_one_minus_cos(travel, view, anisotropy),
                                                     params.g_spec))


# --- Cook-Torrance (the paper's baseline) -----------------------------------------------

def mirror_view(view: np.ndarray) -> np.ndarray:
    """The view direction mirrored through the cloth plane (z -> -z)."""
    mirrored = np.array(view, dtype=np.float64, copy=True)
    mirrored[..., 2] = -mirrored[..., 2]
    return mirrored


def ct_geometry(to_light: np.ndarray, view: np.ndarray) -> dict[str, np.ndarray]:
    """Cosines Cook-Torrance needs, on the light's side (normal (0, 0, -1)).

    Returns cos_i, cos_o, cos_h (n.h) and vh (v'.h).
    """
    to_light = np.asarray(to_light, dtype=np.float64)
    mirrored = mirror_view(view)
    half = to_light + mirrored            # both have z < 0, so half != 0
    half /= np.linalg.norm(half, axis=-1, keepdims=True)
    return {"cos_i": -to_light[..., 2], "cos_o": -mirrored[..., 2], "cos_h": -half[..., 2],
            "vh": np.einsum("...i,...i->...", mirrored, half)}


def beckmann_d(cos_h, roughness):
    """Beckmann microfacet distribution (Cook & Torrance 1982), per steradian."""
    cos2 = cos_h * cos_h
    tan2 = (1 - cos2) / cos2
    m2 = roughness * roughness
    return np.exp(-tan2 / m2) / (math.pi * m2 * cos2 * cos2)


def beckmann_d_droughness(cos_h, roughness):
    """dD/dm of :func:`beckmann_d`."""
    cos2 = cos_h * cos_h
    tan2 = (1 - cos2) / cos2
    return beckmann_d(cos_h, roughness) * (2 * tan2 / roughness ** 3 - 2 / roughness)


def ct_shadowing(geometry: dict[str, np.ndarray]):
    """Cook-Torrance V-groove masking/shadowing G."""
    g = geometry
    vh = np.maximum(g["vh"], 1e-12)       # v'.h > 0 for both directions on one side
    return np.minimum(1.0, np.minimum(2 * g["cos_h"] * g["cos_o"] / vh,
                                      2 * g["cos_h"] * g["cos_i"] / vh))


def ct_lobes(geometry: dict[str, np.ndarray], roughness) -> tuple[np.ndarray, np.ndarray]:
    """Per-unit-weight Cook-Torrance terms: (Lambert cos_i/pi, spec D G / (4 cos_o))."""
    lambert = geometry["cos_i"] / math.pi
    spec = (beckmann_d(geometry["cos_h"], roughness) * ct_shadowing(geometry)
            / (4 * geometry["cos_o"]))
    return lambert, spec


def cook_torrance_transmittance(to_light: np.ndarray, view: np.ndarray, direct, k_lambert,
                                k_spec, roughness, straight_through=None):
    """The baseline's prediction of the gonio ratio (see the module docstring)."""
    geometry = ct_geometry(to_light, view)
    if straight_through is None:
        straight_through = is_straight_through(
            one_minus_cos_between(-np.asarray(to_light, dtype=np.float64), view))
    lambert, spec = ct_lobes(geometry, roughness)
    return (direct * np.asarray(straight_through, dtype=np.float64)
            + k_lambert * lambert + k_spec * spec)


__all__ = ["STRAIGHT_THROUGH_DEG", "one_minus_cos_between", "hg_denominator",
           "hg_denominator_robust", "hg_phase_of_d",
           "hg_phase", "hg_phase_between", "hg_phase_one_minus_cos", "hg_phase_printed",
           "hg_phase_dg", "hg_phase_and_dg", "eq7_scattered", "eq7_transmittance", "is_straight_through",
           "woven_btdf", "woven_one_minus_cos", "cook_torrance_transmittance", "ct_geometry", "ct_lobes",
           "beckmann_d", "beckmann_d_droughness", "ct_shadowing", "mirror_view"]
