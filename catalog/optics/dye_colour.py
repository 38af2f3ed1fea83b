"""The dye's colour per display channel for the light it filters (issue 11, seventh round).

The frame carries the room's light, and the light the cloth's folds send one another, in
linear sRGB, so the dye that filters that light is one number per channel: RGB(S x T) /
RGB(S) for the light's spectrum S and the dye's transmittance T (nm grid of
catalog.optics.spectra). Until the seventh round S was the key light's own spectrum. Under
the UV-A lamp the key's visible part is a faint violet leak that a yellow dye absorbs, so the
dye was 0.048 in every channel; but the light in the room and between the folds there is
mostly the cloth's own glow, which the safety-yellow dye passes at 0.11 / 0.91 / -0.11. The
spectral path tracer (catalog.pathtrace, llvm_ad_spectral) passes the glow by the dye per
wavelength: its room was 1.10-1.13x the RGB reference's, which has the frame's single dye.

Here S, the **secondary light**, is what a cloth lit by the key sends on, per unit of the
key's normal irradiance: the key's share that passes the cloth forwards, through the holes
and both lobes, K = E_key (LD + a_diff fwd(g_diff) + a_spec fwd(g_spec)), in the key's own
spectrum, plus the glow leaving one side, G = pi L_fluor (eq. 10's radiance of the effective
absorbed photons at normal incidence, or eq. 8's paper radiance). Then per channel c

    dye_c = (RGB(K T)_c + RGB(G T)_c) / (RGB(K)_c + RGB(G)_c),

exact for light of the spectrum K + G. The key's share is taken in the key's spectrum, not
dyed once already: the room's light is mostly the key through the holes, undyed, and with no
glow the dye is then the key's, as before. A channel whose light is next to nothing keeps
the key's dye.
"""

from __future__ import annotations

import math

import numpy as np

#: A channel whose secondary light is below this fraction of the largest channel's keeps the
#: key's dye (the ratio of two numbers near 0 says nothing).
NEGLIGIBLE_CHANNEL = 1e-6
#: A channel whose dyed light exceeds the undyed by more than this factor keeps the fallback:
#: a transmittance <= 1 cannot raise a light's channel that far unless the channel is a
#: near-cancellation of the colour-matching lobes (a sodium lamp's blue, -2.6e-6 of its
#: largest channel, gave sheer-teal a blue "dye" of -13,903, and rare paths through two
#: layers of cloth became huge sparkles). Saturated dyes stay well inside it (sheer-teal's
#: green under D65 is 1.42, safety-yellow's blue -0.04).
MAX_CHANNEL_RATIO = 10.0


def _rgb(spectrum: np.ndarray) -> np.ndarray:
    from catalog.optics.shading_reference import spectral_to_linear_srgb  # noqa: PLC0415

    return np.asarray(spectral_to_linear_srgb(np.asarray(spectrum, dtype=np.float64)), dtype=np.float64)


def dye_rgb_under(spectrum: np.ndarray, dye: np.ndarray, fallback) -> np.ndarray:
    """RGB(spectrum x dye) / RGB(spectrum) per linear sRGB channel, ``fallback`` (3,) where the
    spectrum's channel is negligible (NEGLIGIBLE_CHANNEL of its largest magnitude) or the ratio
    ill-conditioned (beyond MAX_CHANNEL_RATIO)."""
    light = _rgb(spectrum)
    dyed = _rgb(np.asarray(spectrum, dtype=np.float64) * np.asarray(dye, dtype=np.float64))
    usable = ((np.abs(light) > NEGLIGIBLE_CHANNEL * max(float(np.abs(light).max()), 1e-300))
              & (np.abs(dyed) <= MAX_CHANNEL_RATIO * np.abs(light)))
    return np.where(usable, dyed / np.where(usable, light, 1.0), np.asarray(fallback, dtype=np.float64))


def key_forward_share(inputs) -> float:
    """The share of the key's normal irradiance the cloth passes forwards: through the holes
    (LD) and by both lobes over the hemisphere, a_diff fwd(g_diff) + a_spec fwd(g_spec)."""
    from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

    return float(inputs.direct + inputs.a_diff * hg_hemisphere_factors(float(inputs.g_diff))[0]
                 + inputs.a_spec * hg_hemisphere_factors(float(inputs.g_spec))[0])


def glow_exitance(inputs) -> np.ndarray:
    """The glow leaving one side of a cloth lit by the key at normal incidence, pi L (W m^-2
    nm^-1 on the grid): physical mode, the effective absorbed photons (eq. 10's saturation)
    times the emission per photon; paper mode, eq. 8's radiance; 0 without fluorescence."""
    key = np.asarray(inputs.key_irradiance, dtype=np.float64)
    if inputs.fluorescence_mode == "physical" and inputs.emission_per_photon is not None:
        photons = float(inputs.absorbed_photons[0])
        effective = photons / (1.0 + photons / float(inputs.saturation_photons))
        return math.pi * effective * np.asarray(inputs.emission_per_photon, dtype=np.float64)
    if inputs.fluorescence_mode == "paper" and inputs.paper_radiance is not None:
        return math.pi * np.asarray(inputs.paper_radiance, dtype=np.float64)
    return np.zeros_like(key)


def secondary_light_spectrum(inputs) -> np.ndarray:
    """K + G of the module doc: what the key-lit cloth sends on, per unit key irradiance's
    worth (W m^-2 nm^-1 on the grid)."""
    key = np.asarray(inputs.key_irradiance, dtype=np.float64)
    return key * key_forward_share(inputs) + glow_exitance(inputs)


def key_dye_rgb(inputs) -> np.ndarray:
    """The dye per channel under the key, RGB(key x T) / RGB(key) (1 where the key's channel
    is negligible): what the beam and the light of the key's spectrum take."""
    return dye_rgb_under(inputs.key_irradiance, inputs.dye_transmittance, np.ones(3))


def secondary_dye_rgb(inputs) -> np.ndarray:
    """The dye per channel for the secondary light (module doc), the key's dye where a channel
    of that light is negligible."""
    return dye_rgb_under(secondary_light_spectrum(inputs), inputs.dye_transmittance, key_dye_rgb(inputs))
