"""The white the eye adapts to: the light that reaches the viewer, and CAT16 with its degree
of adaptation (issue 33; docs/display.md).

A person in the room adapts to the light around them, not to the key light's own white: under
a high sun a south window lets in little of the beam and much of the blue sky, so the room's
light is bluer than the sun. The room's surfaces are neutral (ROOM_ALBEDO is one number), so
the chromaticity of the room's mean irradiance is that of the light entering it:

    E_in(l) = K(l) max(0, -d_z) + (pi / 2) (L_sky(l) + L_ground(l))

- K: the key's normal irradiance, d its direction to the light (the window's plane is z =
  WINDOW_Z, the room on +z, so the beam falls on the window's outer face with cosine -d_z);
- the outside's half-space as the frame's stand-in has it: the sky's mean radiance above the
  horizon and the ground's below, each over a quarter sphere, which a vertical plane sees with
  weight pi / 2 each.

The curtain's own filtering is left out on purpose, its dye as well as its fluorescence: the
adapting white is the window's light, the same for every fabric, so that fabrics compare under
one adaptation (a pink curtain is not discounted as a pink illuminant, and the brightener's
blue-white survives: the eye adapts to the light, not to the cloth).

Adaptation is CAT16 (Li et al. 2017) with its degree of adaptation D (eq. of CIECAM02 / CAM16):
D = F (1 - (1 / 3.6) exp((-L_A - 42) / 92)), for the viewer of the display image: the sRGB
reference viewing (IEC 61966-2-1: an 80 cd m^-2 display, L_A = 80 / 5 = 16 cd m^-2, average
surround F = 1), D = 0.853. The incomplete share 1 - D keeps a strong light's colour: a
sunset stays warm. Lights far from the Planckian locus (the UV-A lamp's two violet lines) are
not adapted to at all (catalog.render.display.adapts_to), so the lamp stays violet.
"""

from __future__ import annotations

import math

import numpy as np

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
