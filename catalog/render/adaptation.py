"""The white the eye adapts to: the light that reaches the viewer from the surfaces in view,
and CAT16 with its degree of adaptation (docs/display.md).

A person in the room adapts to the light around them, not to the key light's own white, and
not to the colours of the things lit: the adapting white is the mean light that reaches the
eye from the field of view with every surface in it made neutral (:func:`visible_white_xyz`),
on a grid of at most FIELD_SAMPLES_PX samples along the frame's longer side:

- the curtain: the frame's float64 twin (eq. 8, catalog.optics.shading_reference.shade_spectral)
  at the G-buffer's pixels, with the cloth's dye left out and no fluorescence
  (build_shading_inputs(neutral=True, fluorescence="off")): the light a white cloth of the
  same weave shows the viewer there, its diffuse transmission of the window's light, the sky
  seen through its open area and what its room side reflects, with the pixels' own shadows.
  So a pink curtain is not taken for a pink illuminant and the brightener's blue-white
  survives: the eye adapts to the light, not to the cloth's glow;
- the rest of the view (the room's grey surfaces, the outside through the window): the frame's
  own linear radiance there, the room's surfaces being neutral (ROOM_ALBEDO is one number).

Where nothing in view is lit (a zero mean) the light entering the room is taken
(:func:`adapting_white_xyz`):

    E_in(l) = K(l) max(0, -d_z) + (pi / 2) (L_sky(l) + L_ground(l))

- K: the key's normal irradiance, d its direction to the light (the window's plane is z =
  WINDOW_Z, the room on +z, so the beam falls on the window's outer face with cosine -d_z);
- the outside's half-space as the frame's stand-in has it: the sky's mean radiance above the
  horizon and the ground's below, each over a quarter sphere, which a vertical plane sees with
  weight pi / 2 each.

Adaptation is CAT16 (Li et al. 2017) with its degree of adaptation D (eq. of CIECAM02 / CAM16):
D = F (1 - (1 / 3.6) exp((-L_A - 42) / 92)), for the viewer of the display image: the sRGB
reference viewing (IEC 61966-2-1: an 80 cd m^-2 display, L_A = 80 / 5 = 16 cd m^-2, average
surround F = 1), D = 0.852. The incomplete share 1 - D keeps a strong light's colour. Lights far
from the Planckian locus (the UV-A lamp's two violet lines) are not adapted to at all
(catalog.render.display.adapts_to), so the lamp stays violet.
"""

from __future__ import annotations

import math

import numpy as np

#: The adapting field's grid: at most this many samples along the frame's longer side.
FIELD_SAMPLES_PX = 48
#: The display's viewing conditions that set D (IEC 61966-2-1's reference: an 80 cd m^-2
#: display white, L_A a fifth of it, average surround).
DISPLAY_WHITE_CD_M2 = 80.0
ADAPTING_LUMINANCE_CD_M2 = DISPLAY_WHITE_CD_M2 / 5.0
SURROUND_F = 1.0


def degree_of_adaptation(adapting_luminance_cd_m2: float = ADAPTING_LUMINANCE_CD_M2,
                         surround_f: float = SURROUND_F) -> float:
    """CAT16's (CIECAM02's) D = F (1 - exp((-L_A - 42) / 92) / 3.6), clipped to [0, 1]."""
    d = surround_f * (1.0 - math.exp((-adapting_luminance_cd_m2 - 42.0) / 92.0) / 3.6)
    return float(min(max(d, 0.0), 1.0))


def cat16_matrix(source_white_xyz, target_white_xyz, degree: float, cat16: np.ndarray) -> np.ndarray:
    """XYZ -> XYZ: CAT16 von Kries with degree of adaptation ``degree`` (one-step CAT16):
    the cone gains D (Y_s / Y_t) (RGB_t / RGB_s) + 1 - D; the whites on any common scale
    (each normalised to Y = 1 first). ``cat16``: the CAT16 matrix (XYZ -> sharpened RGB)."""
    m = np.asarray(cat16, dtype=np.float64)
    source = np.asarray(source_white_xyz, dtype=np.float64)
    target = np.asarray(target_white_xyz, dtype=np.float64)
    rgb_s = m @ (source / source[1])
    rgb_t = m @ (target / target[1])
    gains = degree * rgb_t / rgb_s + 1.0 - degree
    return np.linalg.inv(m) @ np.diag(gains) @ m


def entering_irradiance(inputs) -> np.ndarray:
    """E_in(l) (module docstring), W m^-2 nm^-1 on the window's plane, into the room."""
    key = np.asarray(inputs.key_irradiance, dtype=np.float64)
    to_light = np.asarray(inputs.key_to_light, dtype=np.float64)
    beam = key * max(0.0, -float(to_light[2]) / float(np.linalg.norm(to_light)))
    outside = 0.5 * math.pi * (np.asarray(inputs.sky_radiance) + np.asarray(inputs.ground_radiance))
    return beam + outside


def adapting_white_xyz(inputs) -> np.ndarray:
    """XYZ (a white diffuser's radiance, cd m^-2) under the light entering the room; falls
    back to the key's own white where none is defined."""
    from catalog.optics.shading_reference import spectral_to_xyz, white_xyz  # noqa: PLC0415

    xyz = spectral_to_xyz(entering_irradiance(inputs) / math.pi)
    if not (np.all(np.isfinite(xyz)) and xyz[1] > 0):
        return white_xyz(inputs)
    return np.asarray(xyz, dtype=np.float64)


def neutral_curtain_inputs(frame):
    """The frame's curtain inputs (SceneTerms.curtain_inputs) for a white cloth of the same
    weave: the dye left out, no fluorescence."""
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    light = frame.light
    inputs, _ = scene_lib.build_shading_inputs(
        frame.preset, light.irradiance_w_m2_nm, frame._key_to_light, is_sun=frame._is_sun,
        fluorescence="off", viewer_inside=frame.viewer_inside, neutral=True,
        paper_beam=light.sun is not None and light.sun.model == "paper")
    return scene_lib.with_room_solved(inputs) if frame.room_side_active() else inputs


def field_samples(shape, samples_px: int = FIELD_SAMPLES_PX) -> tuple[slice, slice]:
    """The adapting field's grid on an (H, W) image: every s-th pixel from s // 2, s the
    smallest stride giving at most ``samples_px`` along the longer side."""
    stride = max(1, -(-max(shape[:2]) // int(samples_px)))
    return slice(stride // 2, None, stride), slice(stride // 2, None, stride)


def visible_white_xyz(frame) -> np.ndarray:
    """XYZ (cd m^-2) of the mean light reaching the viewer from the surfaces in view, each made
    neutral (module docstring), from the frame's HDR target as last drawn and its G-buffer (drawn
    here with the room's light and shadow maps of that frame; the bound framebuffer and viewport
    are restored)."""
    from catalog.optics import shading_reference as ref  # noqa: PLC0415
    from catalog.optics.colorimetry import linear_srgb_to_xyz  # noqa: PLC0415

    ctx = frame.ctx
    bound, viewport = ctx.fbo, ctx.viewport
    try:
        gbuffer = frame.curtain.render_gbuffer(refresh_light=False)   # the maps as this frame drew them
        w, h = frame.size
        data = frame.targets.hdr_fbo.read(viewport=(0, 0, w, h), components=4, dtype="f4")
    finally:
        bound.use()
        ctx.viewport = viewport
    rows, columns = field_samples((h, w))
    linear = np.frombuffer(data, dtype=np.float32).reshape(h, w, 4)[::-1, :, :3][rows, columns]
    field = {name: value[rows, columns] for name, value in gbuffer.items()}
    mask = field["mask"]
    xyz = linear_srgb_to_xyz(linear.reshape(-1, 3).astype(np.float64))
    if mask.any():
        neutral = ref.spectral_to_xyz(ref.shade_spectral(
            neutral_curtain_inputs(frame), field["position"][mask], field["normal"][mask],
            field["tangent"][mask], frame.camera.position,
            **ref.shadow_terms(field["shadows"][mask], field["second_coverage"][mask])))
        neutral = neutral + linear_srgb_to_xyz(frame.twin.twin_room_side_rgb(field, mask))
        xyz[mask.reshape(-1)] = neutral
    white = xyz.mean(axis=0)
    if not (np.all(np.isfinite(white)) and white[1] > 0):
        return adapting_white_xyz(frame.terms.shading_inputs())
    return white
