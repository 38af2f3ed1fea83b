"""The float64 reference renderer the shaders are checked against (optics side: no GL).

A scene's light is described spectrally, once, by :class:`ShadingInputs` (on
:data:`catalog.optics.spectra.GRID_NM`, 1 nm). The renderer turns it into a few numbers per band
(:mod:`catalog.render.bands`); this module shades the same pixels from the same inputs at
every wavelength in float64 and converts to colour at the end:

    L(l) = G_key E_key(l) T(l) + G_fill E_fill(l) T(l) + L_ambient(l)          (eq. 7 lobes)
         + LD L_background(l, ray)                                            (eq. 7 LD: see-through)
         + L_fluorescence(l)                                                   (eq. 8, paper or physical)
    G    = |n . l| (a_diff ph(theta; g_diff) + a_spec ph(theta_aniso; g_spec))  (eq. 5-7)

with ph the HG phase function of :mod:`catalog.optics.btdf` (eq. 6, robust form) and theta the
angle between the light's direction of travel and the direction to the viewer. The pixels'
geometry (world position, normal, weft tangent) comes from a G-buffer pass of the same
mesh and camera read back from GL: this module shades those positions; it does not
rasterise (so the comparison is of the shading, not of the rasteriser's coverage).

Colour: ``linear_srgb = 683 * M_sRGB . sum_l cmf(l) L(l) dl`` (cd m^-2 scale for Y).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from catalog.core.constants import AMBIENT_VIEW_NODE_COUNT, LUMINOUS_EFFICACY_LM_W
from catalog.optics.btdf import hg_denominator_robust, hg_phase_of_d
from catalog.optics.spectra import GRID_NM

#: Grid step of GRID_NM (nm).
STEP_NM = 1.0
#: Photons are carried in units of 1e18 m^-2 s^-1 in the shader (float32 range and precision).
PHOTON_UNIT = 1.0e18


@dataclass(frozen=True)
class ShadingInputs:
    """Everything eq. 8 needs for one scene, spectrally (arrays on GRID_NM, float64).

    Irradiances in W m^-2 nm^-1 (on a plane normal to the beam), radiances in
    W m^-2 sr^-1 nm^-1, directions as unit 3-vectors in world space (outside = -z).
    """

    key_irradiance: np.ndarray            # the sun or lamp behind the curtain
    key_to_light: np.ndarray
    fill_irradiance: np.ndarray           # a directional light on the viewer's side
    fill_to_light: np.ndarray
    sky_radiance: np.ndarray              # outside, above the horizon
    ground_radiance: np.ndarray           # outside, below the horizon
    sun_disc_radiance: np.ndarray         # the key light's disc
    room_radiance: np.ndarray             # the room's walls
    sun_chord2: tuple[float, float]       # disc edge: |dir - sun|^2 inner, outer
    direct: float                         # LD, open-area see-through fraction
    a_diff: float
    g_diff: float
    a_spec: float
    g_spec: float
    anisotropy: float                     # warp/weft spread of the directional lobe, (-1, 1)
    dye_transmittance: np.ndarray         # T(l) multiplying both lobes (1 for an undyed cloth)
    ambient_radiance: np.ndarray          # cloth radiance towards the viewer from the diffuse surroundings
    fluorescence_mode: str                # "off" | "paper" | "physical" (after the "needed" judgement)
    paper_radiance: np.ndarray | None = None          # eq. 8: I_fluor F as a radiance
    absorbed_photons: tuple[float, float, float] = (0.0, 0.0, 0.0)  # key, fill (normal incidence), ambient; m^-2 s^-1
    absorbed_room_photons: float = 0.0   # the room's part of absorbed_photons[2] (its stand-in's), m^-2 s^-1
    saturation_photons: float = math.inf  # N_sat, m^-2 s^-1
    emission_per_photon: np.ndarray | None = None     # radiance per effective absorbed photon m^-2 s^-1, per side
    ambient_outside_radiance: np.ndarray | None = None  # the outside's share of ambient_radiance (None: 0)
    # the ambient term's dependence on the view (issue 11): ratio to the normal view's at
    # mu = |n . v| = AMBIENT_VIEW_NODES, for the outside's share and the room's (None: 1)
    ambient_view_outside: np.ndarray | None = None
    ambient_view_room: np.ndarray | None = None
    # the outside seen through the lobes by the view's elevation (issue 11): the sky's share
    # of the lobes at x = (ray_y + 1) / 2 = AMBIENT_VIEW_NODES (ray: camera to cloth, its
    # continuation behind the cloth), and the ambient's change per unit of that share away
    # from 1/2, dye (a_diff fwd + a_spec fwd) (sky - ground) (None: the outside averaged)
    outside_sky_share: np.ndarray | None = None
    ambient_tilt_radiance: np.ndarray | None = None


# --------------------------------------------------------------------------- terms

def hg_phase_chords(chord2, anti2, g):
    """Eq. 6 from the chords |view - travel|^2 and |view + travel|^2 (float64).

    1 - cos = chord2 / 2 and 1 + cos = anti2 / 2 in :func:`catalog.optics.btdf.hg_denominator_robust`,
    the same choice of form as shaders/common.glsl's hg_d (one threshold, HG_MIRROR_BELOW).
    """
    chord2 = np.asarray(chord2, dtype=np.float64)
    anti2 = np.asarray(anti2, dtype=np.float64)
    return hg_phase_of_d(hg_denominator_robust(0.5 * chord2, 0.5 * anti2, g), g)  # eq. 6


def woven_chord2(delta, t, b, n, anisotropy):
    """The anisotropic chord of the directional lobe (see shaders/common.glsl)."""
    dt = np.einsum("...i,...i->...", delta, t)
    db = np.einsum("...i,...i->...", delta, b)
    dn = np.einsum("...i,...i->...", delta, n)
    return dt * dt * (1 - anisotropy) + db * db * (1 + anisotropy) + dn * dn


def woven_transmission(to_light, to_viewer, t, b, n, inputs: ShadingInputs):
    """Eq. 5-7 without LD: radiance per unit normal irradiance of a directional light."""
    travel = -np.asarray(to_light, dtype=np.float64)
    delta = to_viewer - travel
    total = to_viewer + travel
    chord2 = np.einsum("...i,...i->...", delta, delta)
    anti2 = np.einsum("...i,...i->...", total, total)
    ph_diff = hg_phase_chords(chord2, anti2, inputs.g_diff)
    ph_spec = hg_phase_chords(woven_chord2(delta, t, b, n, inputs.anisotropy), anti2,
                              inputs.g_spec)
    cos_i = np.abs(np.einsum("...i,i->...", n, np.asarray(to_light, dtype=np.float64)))
    return cos_i * (inputs.a_diff * ph_diff + inputs.a_spec * ph_spec)  # eq. 5, 7


def _smoothstep(edge0, edge1, x):
    s = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
    return s * s * (3 - 2 * s)


def background_weights(ray, to_sun, chord2_inner, chord2_outer):
    """Weights of (sky, ground, sun disc, room) for ray directions (..., 3); outside is -z."""
    ray = np.asarray(ray, dtype=np.float64)
    d = ray - np.asarray(to_sun, dtype=np.float64)
    disc = 1.0 - _smoothstep(chord2_inner, chord2_outer, np.einsum("...i,...i->...", d, d))
    outside = ray[..., 2] < 0
    above = ray[..., 1] >= 0
    w = np.zeros(ray.shape[:-1] + (4,))
    w[..., 0] = outside & above
    w[..., 1] = outside & ~above
    w[..., 2] = np.where(outside & above, disc, 0.0)
    w[..., 3] = ~outside
    return w


def hg_hemisphere_factors(g: float) -> tuple[float, float]:
    """Cloth radiance per unit radiance of a uniform hemisphere, for a view along the normal.

    forward: the lit hemisphere behind the cloth (transmission),
    2 pi integral_0^1 ph(mu; g) mu d mu with cos(theta) = mu; backward: the hemisphere on the
    viewer's side (the thin layer scattering back), the same with cos(theta) = -mu, which by
    HG's mirror symmetry is forward(-g). In closed form (eq. 6 integrated; written without
    the cancellation of the textbook form at small g):

        forward(g) = (1 + g) / 2 - (1 - g^2) / (2 (1 + sqrt(1 + g^2)))

    forward(0) = backward(0) = 1/4; forward + backward = 1 - (1 - g^2) / (1 + sqrt(1 + g^2)),
    the integral of ph |cos| over the sphere. (A quadrature would need nodes finer than the
    peak, (1 - g)^2 / 2g in cos theta: a 20 000-node midpoint rule is 4e-4 off at g = 0.97
    and 75 % off at g = 0.999.)
    """
    if not -1.0 < g < 1.0:
        raise ValueError(f"HG g must lie in (-1, 1), got {g!r}")
    shared = (1.0 - g * g) / (2.0 * (1.0 + math.sqrt(1.0 + g * g)))
    return (1.0 + g) / 2.0 - shared, (1.0 - g) / 2.0 - shared


# --------------------------------------------------------------------------- the ambient by view (issue 11)

#: mu = |n . v| at which the ambient term's view dependence is tabulated (linear between).
AMBIENT_VIEW_NODES = np.linspace(0.0, 1.0, AMBIENT_VIEW_NODE_COUNT)


def _cos_gamma_cells(uniform: int) -> tuple[np.ndarray, np.ndarray]:
    """Midpoint-rule cells over u = cos gamma in [-1, 1] for integrals of eq. 6: ``uniform``
    uniform edges plus geometric clusters at both ends (a lobe's peak). Returns (u, du)."""
    edges = np.unique(np.concatenate([np.linspace(-1.0, 1.0, uniform),
                                      1.0 - np.geomspace(1e-7, 2.0, 4001),
                                      -1.0 + np.geomspace(1e-7, 2.0, 4001)]))
    edges = np.clip(edges, -1.0, 1.0)
    return 0.5 * (edges[1:] + edges[:-1]), np.diff(edges)


@functools.lru_cache(maxsize=64)
def hg_hemisphere_factors_by_view(g: float, nodes: tuple = tuple(AMBIENT_VIEW_NODES)) -> tuple[np.ndarray, np.ndarray]:
    """(forward, backward) at each node mu: cloth radiance per unit radiance of a uniform
    hemisphere for a view at cos = mu from the normal (model.md section 9). forward: the light
    comes from the hemisphere behind the cloth, F(mu) = integral over t.n > 0 of
    ph(t . v) (t . n) d omega; backward: from the viewer's side, the same over t.n < 0 with
    |t . n|. In coordinates about the view (t . v = cos gamma), the azimuthal integral of the
    clamped cosine max(a + b cos psi, 0), a = mu cos gamma, b = sqrt(1 - mu^2) sin gamma, is
    closed (2 (a psi0 + b sin psi0), cos psi0 = -a / b), leaving a 1-D integral over cos gamma
    (midpoint rule, nodes finer towards the peak at cos gamma = 1 for g > 0). At mu = 1 these
    are :func:`hg_hemisphere_factors` (a test checks 1e-4)."""
    u, du = _cos_gamma_cells(40001)
    sin_g = np.sqrt(np.maximum(1.0 - u * u, 0.0))
    phase = hg_phase_chords(2.0 * (1.0 - u), 2.0 * (1.0 + u), g)
    out = []
    for sign in (1.0, -1.0):
        values = []
        for mu in nodes:
            a = sign * mu * u
            b = np.abs(math.sqrt(max(1.0 - mu * mu, 0.0)) * sin_g)
            with np.errstate(divide="ignore", invalid="ignore"):
                psi0 = np.arccos(np.clip(np.where(b > 0, -a / np.where(b > 0, b, 1.0), 0.0), -1.0, 1.0))
            clamped = np.where(a >= b, 2 * math.pi * a,
                               np.where(a <= -b, 0.0, 2.0 * (a * psi0 + b * np.sin(psi0))))
            values.append(float(np.sum(phase * clamped * du)))
        out.append(np.asarray(values))
    return out[0], out[1]


def ambient_view_ratios(a_diff: float, g_diff: float, a_spec: float, g_spec: float,
                        backward: bool) -> np.ndarray:
    """The ambient term's ratio to the normal view's at AMBIENT_VIEW_NODES, for light from the
    hemisphere behind the cloth (``backward`` False) or from the viewer's side (True): the
    lobes' (a_diff F_diff(mu) + a_spec F_spec(mu)) over the same at mu = 1 in closed form."""
    k = 1 if backward else 0
    by_view = (a_diff * hg_hemisphere_factors_by_view(g_diff)[k]
               + a_spec * hg_hemisphere_factors_by_view(g_spec)[k])
    normal = (a_diff * hg_hemisphere_factors(g_diff)[k] + a_spec * hg_hemisphere_factors(g_spec)[k])
    if not normal > 0:
        return np.ones_like(AMBIENT_VIEW_NODES)
    return by_view / normal


@functools.lru_cache(maxsize=64)
def hg_sky_share(g: float, nodes: tuple = tuple(AMBIENT_VIEW_NODES)) -> np.ndarray:
    """The share of eq. 6's lobe about a direction r that lies above the horizon, at
    x = (r_y + 1) / 2 = each node (model.md section 9: the outside seen through the cloth is
    the sky above the horizon and the ground below). About r (t . r = cos gamma = u), a
    direction's height is r_y u + sqrt(1 - r_y^2) sqrt(1 - u^2) cos psi, positive on a
    fraction arccos(-a / b) / pi of the azimuths (a = r_y u, b = the sine terms; 1 or 0
    beyond |a| >= b), leaving a 1-D integral of ph(u) 2 pi over u (midpoint rule, nodes
    clustered at the peak). 1/2 at r_y = 0 by symmetry; r_y = +-1 gives 1 or 0."""
    u, du = _cos_gamma_cells(20001)
    phase = hg_phase_chords(2.0 * (1.0 - u), 2.0 * (1.0 + u), g) * 2.0 * math.pi * du
    sin_u = np.sqrt(np.maximum(1.0 - u * u, 0.0))
    out = []
    for x in nodes:
        ry = 2.0 * float(x) - 1.0
        a = ry * u
        b = math.sqrt(max(1.0 - ry * ry, 0.0)) * sin_u
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where(a >= b, 1.0, np.where(a <= -b, 0.0,
                            np.arccos(np.clip(-a / np.where(b > 0, b, 1.0), -1.0, 1.0)) / math.pi))
        out.append(float(np.sum(phase * frac) / np.sum(phase)))
    return np.asarray(out)


def outside_sky_share(a_diff: float, g_diff: float, a_spec: float, g_spec: float) -> np.ndarray:
    """The sky's share of the light the lobes bring from behind the cloth, by the view's
    elevation (AMBIENT_VIEW_NODES over x = (ray_y + 1) / 2): :func:`hg_sky_share` of each
    lobe weighted by its share of that light, a forward(g)."""
    w_diff = a_diff * hg_hemisphere_factors(g_diff)[0]
    w_spec = a_spec * hg_hemisphere_factors(g_spec)[0]
    if not w_diff + w_spec > 0:
        return np.full(AMBIENT_VIEW_NODES.size, 0.5)
    return (w_diff * hg_sky_share(g_diff) + w_spec * hg_sky_share(g_spec)) / (w_diff + w_spec)


def sky_share_at(table, ray_y) -> np.ndarray:
    """A table of :func:`outside_sky_share` at the view ray's height ray_y (linear between
    nodes; None: 1/2, the outside averaged)."""
    ray_y = np.asarray(ray_y, dtype=np.float64)
    if table is None:
        return np.full_like(ray_y, 0.5)
    x = np.clip(0.5 * (ray_y + 1.0), 0.0, 1.0)
    return np.interp(x, AMBIENT_VIEW_NODES, np.asarray(table, dtype=np.float64))


def ambient_view_ratio(table, mu) -> np.ndarray:
    """A table of :func:`ambient_view_ratios` at mu (linear between nodes; None: 1)."""
    mu = np.asarray(mu, dtype=np.float64)
    if table is None:
        return np.ones_like(mu)
    return np.interp(np.clip(mu, 0.0, 1.0), AMBIENT_VIEW_NODES, np.asarray(table, dtype=np.float64))


# --------------------------------------------------------------------------- the cloth's own shadow (issue 11)

def layer_beam_transmittance(inputs: ShadingInputs, coverage) -> np.ndarray:
    """(P, L): the key light's beam after one layer of cloth of thread coverage ``coverage``
    (P,) (model.md section 9): the holes pass it, a thread passes the directional lobe's
    forward-scattered part in the dye's colour per unit of mean coverage,
    T = (1 - c) + c a_spec forward(g_spec) dye / (1 - LD). c = 0: no layer (T = 1)."""
    c = np.asarray(coverage, dtype=np.float64).reshape(-1, 1)
    forward = hg_hemisphere_factors(inputs.g_spec)[0]
    thread = inputs.a_spec * forward * inputs.dye_transmittance / max(1.0 - inputs.direct, 1e-6)
    return (1.0 - c) + c * thread[None, :]


def outside_occluded_radiance(inputs: ShadingInputs) -> np.ndarray:
    """(L,): the ambient radiance a fully occluded outside takes away (model.md section 9):
    the outside's share of the ambient term times what a layer of cloth in the way does not
    pass of diffuse light, 1 - (LD + dye (a_diff forward(g_diff) + a_spec forward(g_spec)))."""
    if inputs.ambient_outside_radiance is None:
        return np.zeros_like(inputs.ambient_radiance)
    forward_d = hg_hemisphere_factors(inputs.g_diff)[0]
    forward_s = hg_hemisphere_factors(inputs.g_spec)[0]
    passed = inputs.direct + inputs.dye_transmittance * (inputs.a_diff * forward_d
                                                         + inputs.a_spec * forward_s)
    return (1.0 - passed) * inputs.ambient_outside_radiance


# --------------------------------------------------------------------------- shading

def shade_spectral(inputs: ShadingInputs, positions, normals, tangents,
                   camera_position, key_beam=None, front_coverage=None,
                   outside_occlusion=None, wall_occlusion=None, second_coverage=None) -> np.ndarray:
    """Spectral radiance (P, len(GRID_NM)) W m^-2 sr^-1 nm^-1 at world positions (P, 3).

    The cloth's shadows (issue 11, model.md section 9), per position (P,), default none:
    ``key_beam`` the window's mask on the key light (0..1), ``front_coverage`` the thread
    coverage of the layer of cloth between the position and the key light (0: none; the beam
    is multiplied by :func:`layer_beam_transmittance`, the excitation by 1 - c),
    ``second_coverage`` that of a second layer between them (issue 11, seventh round: the beam
    multiplied by its transmittance too, the excitation by its 1 - c),
    ``outside_occlusion`` the fraction of the outside hidden by the cloth itself (the ambient
    term loses that fraction of :func:`outside_occluded_radiance`), ``wall_occlusion`` the
    fraction hidden by the window wall (the ambient loses that fraction of the outside's
    share, ``inputs.ambient_outside_radiance``)."""
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    t = np.asarray(tangents, dtype=np.float64).reshape(-1, 3)
    t = t - np.einsum("pi,pi->p", t, n)[:, None] * n
    t = t / np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(n, t)
    ray = p - np.asarray(camera_position, dtype=np.float64)
    ray = ray / np.linalg.norm(ray, axis=1, keepdims=True)
    to_viewer = -ray

    g_key = woven_transmission(inputs.key_to_light, to_viewer, t, b, n, inputs)
    g_fill = woven_transmission(inputs.fill_to_light, to_viewer, t, b, n, inputs)
    dyed_key = inputs.key_irradiance * inputs.dye_transmittance
    dyed_fill = inputs.fill_irradiance * inputs.dye_transmittance
    count = p.shape[0]
    beam = np.ones(count) if key_beam is None else np.asarray(key_beam, dtype=np.float64).reshape(-1)
    cover = np.zeros(count) if front_coverage is None else np.asarray(front_coverage, dtype=np.float64).reshape(-1)
    cover2 = (np.zeros(count) if second_coverage is None
              else np.asarray(second_coverage, dtype=np.float64).reshape(-1))
    key_seen = (beam[:, None] * layer_beam_transmittance(inputs, cover)
                * layer_beam_transmittance(inputs, cover2) * dyed_key[None, :])
    # the ambient term by view (ratios to the normal view's): the room's share r_room, the
    # outside's r_out, the occlusions' losses with the outside's
    mu = np.abs(np.einsum("pi,pi->p", to_viewer, n))
    r_out = ambient_view_ratio(inputs.ambient_view_outside, mu)[:, None]
    r_room = ambient_view_ratio(inputs.ambient_view_room, mu)[:, None]
    outside_share = (inputs.ambient_outside_radiance if inputs.ambient_outside_radiance is not None
                     else np.zeros_like(inputs.ambient_radiance))
    radiance = (g_key[:, None] * key_seen + g_fill[:, None] * dyed_fill
                + r_room * inputs.ambient_radiance[None, :] + (r_out - r_room) * outside_share[None, :])
    if inputs.ambient_tilt_radiance is not None:   # the sky above the view's line, the ground below
        tilt = sky_share_at(inputs.outside_sky_share, ray[:, 1]) - 0.5
        if wall_occlusion is not None:   # where the wall hides the outside, neither
            tilt = tilt * (1.0 - np.asarray(wall_occlusion, dtype=np.float64).reshape(-1))
        radiance += (r_out * tilt[:, None]) * inputs.ambient_tilt_radiance[None, :]
    if outside_occlusion is not None:
        radiance -= (r_out * np.asarray(outside_occlusion, dtype=np.float64).reshape(-1, 1)
                     * outside_occluded_radiance(inputs)[None, :])
    if wall_occlusion is not None:
        radiance -= (r_out * np.asarray(wall_occlusion, dtype=np.float64).reshape(-1, 1)
                     * outside_share[None, :])
    if inputs.direct > 0:
        w = inputs.direct * background_weights(ray, inputs.key_to_light, *inputs.sun_chord2)
        radiance += (w[:, 0:1] * inputs.sky_radiance + w[:, 1:2] * inputs.ground_radiance
                     + w[:, 2:3] * inputs.sun_disc_radiance + w[:, 3:4] * inputs.room_radiance)
    if inputs.fluorescence_mode == "paper":
        radiance += inputs.paper_radiance[None, :]  # eq. 8: a constant per light
    elif inputs.fluorescence_mode == "physical":
        n_key, n_fill, n_ambient = inputs.absorbed_photons
        absorbed = (np.abs(n @ np.asarray(inputs.key_to_light)) * (beam * (1.0 - cover) * (1.0 - cover2)) * n_key
                    + np.abs(n @ np.asarray(inputs.fill_to_light)) * n_fill + n_ambient)
        effective = absorbed / (1.0 + absorbed / inputs.saturation_photons)
        radiance += effective[:, None] * inputs.emission_per_photon[None, :]
    return radiance


def _side_light_linear_srgb(table, positions, normals, camera_position, irradiance_rgb,
                            factor_rgb) -> np.ndarray:
    """(P, 3): irradiance (P, 3) over pi, times a lobe factor (3,), times the ambient's ratio by
    view ``table`` at each position's |n . v|."""
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    to_viewer = np.asarray(camera_position, dtype=np.float64) - p
    to_viewer = to_viewer / np.linalg.norm(to_viewer, axis=1, keepdims=True)
    ratio = ambient_view_ratio(table, np.abs(np.einsum("pi,pi->p", to_viewer, n)))
    return (ratio[:, None] / math.pi) * np.asarray(irradiance_rgb, dtype=np.float64).reshape(-1, 3) \
        * np.asarray(factor_rgb, dtype=np.float64)[None, :]


def room_side_linear_srgb(inputs: ShadingInputs, positions, normals, camera_position,
                          irradiance_rgb, reflectance_rgb) -> np.ndarray:
    """(P, 3) linear sRGB: the room's solved light on the curtain's room side (issue 11, fourth
    round; curtain.frag ROOM_SIDE), the twin of the term the frame adds to the shading of
    ``catalog.render.scene.with_room_solved(inputs)``: the irradiance on the room side at each
    position (P, 3; linear sRGB, x pi cd m^-2) over pi, times the cloth's reflectance of diffuse
    light from the room's side (3,), times the ambient's ratio by view for the room's hemisphere."""
    return _side_light_linear_srgb(inputs.ambient_view_room, positions, normals, camera_position,
                                   irradiance_rgb, reflectance_rgb)


def window_side_linear_srgb(inputs: ShadingInputs, positions, normals, camera_position,
                            irradiance_rgb, transmittance_rgb) -> np.ndarray:
    """(P, 3) linear sRGB: light on the curtain's window side from the folds in front of it (issue
    11, fourth round; curtain.frag ROOM_SIDE), irradiance (P, 3) over pi times a lobe's forward
    transmittance (3,) times the ambient's ratio by view for the outside's hemisphere."""
    return _side_light_linear_srgb(inputs.ambient_view_outside, positions, normals, camera_position,
                                   irradiance_rgb, transmittance_rgb)


def shadow_terms(shadows, second_coverage=None) -> dict:
    """:func:`shade_spectral`'s shadow arguments from the frame's G-buffer ``shadows`` (P, 4):
    the key's window mask, the coverage of the layer in front of the key, the outside's
    occlusion by the cloth and by the window wall; and ``second_coverage`` (P,), the G-buffer's
    second layer in front of the key (None: none)."""
    s = np.asarray(shadows, dtype=np.float64).reshape(-1, 4)
    out = {"key_beam": s[:, 0], "front_coverage": s[:, 1], "outside_occlusion": s[:, 2],
           "wall_occlusion": s[:, 3]}
    if second_coverage is not None:
        out["second_coverage"] = np.asarray(second_coverage, dtype=np.float64).reshape(-1)
    return out


def spectral_to_linear_srgb(radiance: np.ndarray) -> np.ndarray:
    """683 * M_sRGB . sum cmf L dl: linear sRGB with Y in cd m^-2 (negatives kept)."""
    from catalog.optics.colorimetry import spectrum_to_xyz, xyz_to_linear_srgb  # noqa: PLC0415

    return xyz_to_linear_srgb(LUMINOUS_EFFICACY_LM_W * spectrum_to_xyz(radiance, GRID_NM, STEP_NM))


def spectral_to_xyz(radiance: np.ndarray) -> np.ndarray:
    """683 * sum cmf L dl: XYZ with Y in cd m^-2."""
    from catalog.optics.colorimetry import spectrum_to_xyz  # noqa: PLC0415

    return LUMINOUS_EFFICACY_LM_W * spectrum_to_xyz(radiance, GRID_NM, STEP_NM)


def reference_linear_srgb(inputs: ShadingInputs, positions, normals, tangents,
                          camera_position, **shadows) -> np.ndarray:
    """The full-spectral (1 nm) float64 reference colour of the given pixels, (P, 3);
    ``shadows``: :func:`shade_spectral`'s key_beam, front_coverage, outside_occlusion."""
    return spectral_to_linear_srgb(shade_spectral(inputs, positions, normals, tangents,
                                                  camera_position, **shadows))


def white_xyz(inputs: ShadingInputs) -> np.ndarray:
    """The adapted white for Delta E: a perfect white diffuser under the key light, cd m^-2."""
    return spectral_to_xyz(inputs.key_irradiance / math.pi)
