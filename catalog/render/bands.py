"""Light, dye and fluorescence spectra -> N bands, once per light (or fabric) change.

Every spectral quantity of :class:`catalog.optics.shading_reference.ShadingInputs` is integrated against
band weight functions w_b(l); the shader adds the bands and converts them to display
colour with a 3 x N matrix at the end. Only the products of two spectra (light x dye) are
approximated by bands; sums (fluorescence emission, the background) are exact in any basis.

- N = 3: "RGB". The weights are the sRGB colour-matching functions,
  w = 683 M_sRGB cmf(l) dl, so a band value *is* linear sRGB (cd m^-2 scale) and the
  display matrix is the identity. Light x dye is integrated spectrally before it reaches the
  shader, so one light on one material is exact: RGB mode equals the 1 nm reference.
- N = 6, 9, 16: equal-width boxes over 360-780 nm (where the CIE 1931 functions are
  non-zero on our grid). The display colour of band b is that of the key light's own
  spectrum inside the band, so a spectrally flat cloth is exact and a dye or an emission
  that varies inside a band is not: the time-against-error study of docs/render.md.
"""

from __future__ import annotations

import math

import numpy as np

from catalog.core.errors import CatalogError
from catalog.optics.shading_reference import (LUMINOUS_EFFICACY_LM_W, PHOTON_UNIT, STEP_NM, ShadingInputs,
                                              AMBIENT_VIEW_NODES, layer_beam_transmittance,
                                              outside_occluded_radiance)
from catalog.optics.spectra import GRID_NM

#: Band counts the shaders are built for.
BAND_COUNTS = (3, 6, 9, 16)
#: The interval bands' range (nm).
BAND_RANGE_NM = (360.0, 780.0)


def check_band_count(n_bands: int) -> int:
    if n_bands not in BAND_COUNTS:
        raise CatalogError(f"--bands {n_bands!r}: choose one of {', '.join(map(str, BAND_COUNTS))}")
    return int(n_bands)


def chunks(n_bands: int) -> int:
    """NV4: the number of vec4 chunks that hold ``n_bands`` values."""
    return (n_bands + 3) // 4


def band_weights(n_bands: int, key_irradiance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(weights (N, len(GRID_NM)) incl. dl, band_to_rgb (3, N)) for a key light."""
    from catalog.optics.colorimetry import cmfs, xyz_to_linear_srgb  # noqa: PLC0415

    check_band_count(n_bands)
    cmf = cmfs(GRID_NM)  # (L, 3)
    if n_bands == 3:
        rgb_cmf = xyz_to_linear_srgb(cmf)  # (L, 3): the sRGB matching functions
        weights = (LUMINOUS_EFFICACY_LM_W * rgb_cmf * STEP_NM).T
        return weights, np.eye(3)
    edges = np.linspace(BAND_RANGE_NM[0], BAND_RANGE_NM[1], n_bands + 1)
    index = np.searchsorted(edges, GRID_NM, side="right") - 1
    index[GRID_NM == edges[-1]] = n_bands - 1
    weights = np.zeros((n_bands, GRID_NM.size))
    to_rgb = np.zeros((3, n_bands))
    for b in range(n_bands):
        inside = index == b
        weights[b, inside] = STEP_NM
        shape = key_irradiance[inside]
        if not np.sum(shape) > 0:
            shape = np.ones(int(np.sum(inside)))  # a dark band: any shape; flat
        shape = shape / (np.sum(shape) * STEP_NM)
        xyz = LUMINOUS_EFFICACY_LM_W * (shape @ cmf[inside]) * STEP_NM
        to_rgb[:, b] = xyz_to_linear_srgb(xyz)
    return weights, to_rgb


def _pack(values: np.ndarray, n_chunks: int) -> np.ndarray:
    out = np.zeros(4 * n_chunks, dtype=np.float32)
    out[:values.size] = values
    return out


def view_segments(*tables) -> np.ndarray:
    """Ambient-by-view tables (AMBIENT_VIEW_NODES values each; None: all 1), one or two, as
    curtain.frag's view_segments: per segment i (AMBIENT_VIEW_NODES - 1 vec4s) each table's
    node i and its step to node i + 1 (float32, the step as the shader's own float32
    subtraction would round it), zeros where there is no second table: a fragment reads one
    vec4 for both tables instead of four indexed values."""
    out = np.zeros((AMBIENT_VIEW_NODES.size - 1, 4), dtype=np.float32)
    for j, table in enumerate(tables):
        values = (np.ones(AMBIENT_VIEW_NODES.size) if table is None else np.asarray(table, dtype=np.float64)).astype(np.float32)
        out[:, 2 * j] = values[:-1]
        out[:, 2 * j + 1] = values[1:] - values[:-1]
    return out.reshape(-1)


def band_uniforms(inputs: ShadingInputs, n_bands: int) -> dict[str, np.ndarray | float | tuple]:
    """The curtain shader's uniforms for ``inputs`` in ``n_bands`` bands (float32 arrays)."""
    weights, to_rgb = band_weights(n_bands, inputs.key_irradiance)
    nv4 = chunks(n_bands)

    def band(spectrum):
        return _pack(weights @ spectrum, nv4)

    zeros = np.zeros(GRID_NM.size)
    fluorescence = zeros
    if inputs.fluorescence_mode == "paper":
        fluorescence = inputs.paper_radiance
    elif inputs.fluorescence_mode == "physical":
        fluorescence = inputs.emission_per_photon * PHOTON_UNIT
    absorbed = tuple(float(v) / PHOTON_UNIT for v in inputs.absorbed_photons)
    inv_sat = 0.0 if math.isinf(inputs.saturation_photons) else PHOTON_UNIT / inputs.saturation_photons
    return {
        "u_key_dyed": band(inputs.key_irradiance * inputs.dye_transmittance),
        "u_fill_dyed": band(inputs.fill_irradiance * inputs.dye_transmittance),
        "u_ambient": band(inputs.ambient_radiance),
        # issue 11's shadows on the cloth (KEY_SHADOW, SKY_OCCLUSION in curtain.frag)
        "u_key_thread": band(inputs.key_irradiance * inputs.dye_transmittance
                             * layer_beam_transmittance(inputs, [1.0])[0]),
        # through two threads (the second layer of KEY_SHADOW's front_layers_coverage)
        "u_key_thread2": band(inputs.key_irradiance * inputs.dye_transmittance
                              * layer_beam_transmittance(inputs, [1.0])[0] ** 2),
        "u_ambient_occluded": band(outside_occluded_radiance(inputs)),
        "u_ambient_outside": band(inputs.ambient_outside_radiance
                                  if inputs.ambient_outside_radiance is not None else zeros),
        "u_ambient_view": view_segments(inputs.ambient_view_outside, inputs.ambient_view_room),
        "u_ambient_tilt": band(inputs.ambient_tilt_radiance
                               if inputs.ambient_tilt_radiance is not None else zeros),
        "u_outside_sky_share": view_segments(inputs.outside_sky_share
                                              if inputs.outside_sky_share is not None
                                              else np.full(AMBIENT_VIEW_NODES.size, 0.5)),
        "u_sky": band(inputs.sky_radiance),
        "u_ground": band(inputs.ground_radiance),
        "u_sun_disc": band(inputs.sun_disc_radiance),
        "u_room": band(inputs.room_radiance),
        "u_fluorescence": band(fluorescence),
        "u_absorbed_photons": absorbed,
        "u_inv_saturation": inv_sat,
        "u_band_to_r": _pack(to_rgb[0], nv4),
        "u_band_to_g": _pack(to_rgb[1], nv4),
        "u_band_to_b": _pack(to_rgb[2], nv4),
    }


def spectrum_to_display_rgb(spectrum: np.ndarray) -> np.ndarray:
    """Exact linear sRGB (cd m^-2 scale) of a radiance spectrum: for the background passes."""
    from catalog.optics.shading_reference import spectral_to_linear_srgb  # noqa: PLC0415

    return spectral_to_linear_srgb(spectrum)
