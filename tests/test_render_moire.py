"""No moire at any distance (issue 34): the pattern's mip chain is prefiltered
(catalog.presets.patterns.mip_chain: a periodic Gaussian of 0.7 of each level's texel,
resampled by Fourier cropping) instead of the hardware's 2x2 box chain.

Measure: a flat lace quad facing the camera, rendered 4x supersampled with the LOD bias
raised by log2 4 (so each 4x pixel sees the filter a 1x pixel would get) at a sweep of
distances; the share of the image's (windowed, mean-removed) spectral energy above the 1x
pixel's Nyquist frequency is what the filter leaves to alias. Bound: <= 1.5 % at every
distance (the box chain left 4.1 % at 1.1-1.6 m for lace-fwa, stripes in the net)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.presets.patterns import mip_chain
from catalog.render.frame import FrameRenderer
from catalog.render.passes.pattern import PATTERN_LOD_BIAS
from catalog.render.settings import orbit

SUPERSAMPLE = 4


def _quad_mesh():
    """A flat quad facing +z in the window (x -0.9..0.9, y -0.85..1.2 m, z -0.08), uv 0..1."""
    positions = np.array([[-0.9, 1.2, -0.08], [0.9, 1.2, -0.08], [-0.9, -0.85, -0.08],
                          [0.9, -0.85, -0.08]])
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    uvs = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    tangents = np.tile([1.0, 0.0, 0.0], (4, 1))
    return positions, normals, uvs, tangents, np.array([[0, 2, 1], [1, 2, 3]])


def energy_above_nyquist(linear_rgb: np.ndarray, supersample: int = SUPERSAMPLE) -> float:
    """Share of the luminance spectrum (middle half of the image, Hann window, mean removed)
    beyond the Nyquist frequency of pixels ``supersample`` times larger."""
    y = linear_rgb @ np.array([0.2126, 0.7152, 0.0722])
    h, w = y.shape
    y = y[h // 4:3 * h // 4, w // 4:3 * w // 4]
    y = (y - y.mean()) * np.outer(np.hanning(y.shape[0]), np.hanning(y.shape[1]))
    power = np.abs(np.fft.fft2(y)) ** 2
    fy = np.abs(np.fft.fftfreq(y.shape[0]))[:, None]
    fx = np.abs(np.fft.fftfreq(y.shape[1]))[None, :]
    high = (fx > 0.5 / supersample) | (fy > 0.5 / supersample)
    return float(power[high].sum() / max(power.sum(), 1e-30))


def test_energy_measure_sees_a_stripe_above_nyquist():
    """The measure itself: a sinusoid at 0.3 cycles/px (above 1/8) is all 'high'; at 0.05 none."""
    x = np.arange(128)[None, :] * np.ones((128, 1))
    for freq, expected in ((0.3, 1.0), (0.05, 0.0)):
        img = np.repeat((1 + np.sin(2 * math.pi * freq * x))[..., None], 3, -1)
        assert energy_above_nyquist(img) == pytest.approx(expected, abs=0.02)


def test_mip_chain_keeps_the_mean_and_removes_what_a_level_cannot_hold():
    """Closed form: a stripe of period 3 texels (above level 1's Nyquist of 4) is gone from
    level 1 (< 1 %, the 2x2 box keeps 33 %); the mean is exact; values stay in range."""
    x = np.arange(96)[None, :, None] * np.ones((64, 1, 1))
    image = 0.5 + 0.5 * np.sin(2 * math.pi * x / 3.0)
    chain = mip_chain(image)
    assert [c.shape[:2] for c in chain[:3]] == [(64, 96), (32, 48), (16, 24)]
    assert all(abs(c.mean() - image.mean()) < 1e-6 for c in chain)
    assert chain[1].std() < 0.01 * image.std()
    box = image.reshape(32, 2, 48, 2, 1).mean(axis=(1, 3))
    assert box.std() > 0.3 * image.std()
    assert all(c.min() >= 0.0 and c.max() <= 1.0 for c in chain)


def _sweep(gl, fabric: str, prefilter: bool = True, yaw_deg: float = 0.0,
           supersample: int = SUPERSAMPLE) -> list[float]:
    """The share above the 1x Nyquist at each of 8 distances, 0.3-4 m (the quad face on, or
    seen ``yaw_deg`` off its normal), measured ``supersample`` times finer."""
    renderer = FrameRenderer(gl, (96 * supersample, 64 * supersample))
    renderer.fabric_pattern.set_prefilter(prefilter)
    renderer.update(fabric=fabric, light="D65")
    renderer.set_mesh(*_quad_mesh(), fabric_size_m=(1.8, 2.05))
    renderer.update(ev=12.0)
    # filtered for the pixel the supersampled frame is measured at
    renderer.fabric_pattern.lod_bias = PATTERN_LOD_BIAS + math.log2(supersample)
    shares = []
    for distance in np.geomspace(0.3, 4.0, 8):
        renderer.update(camera=orbit(float(yaw_deg), 0.0, float(distance)))
        renderer.render()
        shares.append(energy_above_nyquist(renderer.read_linear(), supersample))
    renderer.release()
    print(fabric, "prefiltered" if prefilter else "box", f"{yaw_deg:g} deg {supersample}x",
          " ".join(f"{s:.4f}" for s in shares))
    return shares


#: The share of the image's energy the prefilter may leave above the pixel's Nyquist.
MOIRE_BOUND = 0.015


@pytest.mark.gl
@pytest.mark.slow
@pytest.mark.parametrize("fabric", ["lace-fwa", "raschel-ivory", "jacquard-white"])
def test_no_energy_above_nyquist_at_any_distance(gl, fabric):
    shares = _sweep(gl, fabric)
    assert max(shares) <= MOIRE_BOUND, shares


@pytest.mark.gl
@pytest.mark.slow
def test_the_measure_sees_the_box_chains_moire(gl):
    """The same sweep with the hardware's 2x2 box chain (the mips before): the net folds into
    stripes and the share rises over the bound (measured 4.2 % at 1.3-1.9 m; prefiltered 0.8 %)."""
    assert max(_sweep(gl, "lace-fwa", prefilter=False)) > MOIRE_BOUND


@pytest.mark.gl
@pytest.mark.slow
def test_the_measure_converges_as_the_supersampling_rises_at_60_degrees(gl):
    """Whether the 4x measure holds off the normal (issue 34): at 60 deg the lace's shares at
    4x, 8x and 16x (measured: 4x at most 0.45 percentage points under 16x, 8x within 0.05; the
    Raschel alike). It converges, so the oblique figures (lace 2.2-5.5 %, over MOIRE_BOUND) are
    the frame's; they are not all the pattern's, though: the flat cloth alone gives 1.2-2.3 %
    there and the rest is mostly the window's frame seen through the holes and the quad's
    edge inside the measured middle half (docs/pattern.md), so no oblique bound is set yet."""
    s4, s8, s16 = (np.array(_sweep(gl, "lace-fwa", yaw_deg=60.0, supersample=k)) for k in (4, 8, 16))
    assert np.abs(s8 - s16).max() <= 0.002, (s8, s16)
    assert np.abs(s4 - s16).max() <= 0.007, (s4, s16)


def _complex_reference_chain(texels: np.ndarray) -> list[np.ndarray]:
    """The chain by the first formula, in float64: the complex FFT of all channels at once,
    the kept frequencies (|ky| < lh/2, |kx| < lw/2) times the Gaussian, the real part of the
    inverse; the same clipping and mean."""
    texels = np.asarray(texels, dtype=np.float64)
    h, w = texels.shape[:2]
    low, high, mean = texels.min(axis=(0, 1)), texels.max(axis=(0, 1)), texels.mean(axis=(0, 1))
    chain, current = [texels], texels
    for level in range(1, int(math.floor(math.log2(max(h, w)))) + 1):
        ch, cw = current.shape[:2]
        lh, lw = max(1, h >> level), max(1, w >> level)
        sigma = 1.4 if level == 1 else math.sqrt(1.4 ** 2 - 0.7 ** 2)
        spectrum = np.fft.fft2(current, axes=(0, 1))
        ky = np.round(np.fft.fftfreq(ch) * ch).astype(int)
        kx = np.round(np.fft.fftfreq(cw) * cw).astype(int)
        keep_y, keep_x = np.abs(ky) < lh / 2.0, np.abs(kx) < lw / 2.0
        gain = np.exp(-2 * math.pi ** 2 * sigma ** 2 * ((kx[keep_x] / cw)[None, :, None] ** 2
                                                       + (ky[keep_y] / ch)[:, None, None] ** 2))
        small = np.zeros((lh, lw, texels.shape[2]), dtype=complex)
        small[np.ix_(ky[keep_y] % lh, kx[keep_x] % lw)] = spectrum[np.ix_(keep_y, keep_x)] * gain
        current = np.real(np.fft.ifft2(small, axes=(0, 1))) * (lh * lw) / (ch * cw)
        for _ in range(4):
            current = np.clip(current + (mean - current.mean(axis=(0, 1))), low, high)
        chain.append(current)
    return chain


@pytest.mark.parametrize("shape", [(37, 64, 4), (50, 27, 2), (64, 64, 1)])
def test_mip_chain_a_channel_at_a_time_equals_the_complex_formula(shape):
    """The chain made a channel at a time by a real FFT equals the complex FFT of all
    channels at once (odd and even sizes, a level's size rounded down): within 1e-12 of a
    value in [0, 1] (float64 rounding; the levels are float32, so at most an ulp apart)."""
    rng = np.random.default_rng(7)
    texels = rng.random(shape)
    chain, reference = mip_chain(texels), _complex_reference_chain(texels)
    assert len(chain) == len(reference)
    for level, (got, want) in enumerate(zip(chain, reference)):
        assert got.shape == want.shape and got.dtype == np.float32, level
        assert np.max(np.abs(got.astype(np.float64) - want)) <= 1e-12 + 2 ** -24, level
