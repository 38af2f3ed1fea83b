"""The real-time frame's error against the reference (numpy; FLIP from ``flip-evaluator``).

- display: the frame's display image as it draws it (its exposure, white balance, tone
  curve, gamut step and anti-aliasing), the reference through the same display step with
  the frame's exposure and white balance (catalog.render.display), so the comparison is
  of what a viewer sees;
- FLIP (LDR-FLIP, Andersson et al. 2020, PyPI ``flip-evaluator``) of the two display
  images, mean over the image, at 67 pixels per degree (a 0.7 m, 24-inch 4K monitor);
- Delta E 2000 (catalog.optics.colorimetry) on the linear images in CIELAB, the white a perfect
  diffuser under the key light (catalog.optics.shading_reference.white_xyz), per region: curtain, floor,
  walls (:func:`catalog.pathtrace.render.region_masks`), mean and 95th percentile.
"""

from __future__ import annotations

import math

import numpy as np

from catalog.core.constants import LUMA_REC709

#: FLIP's observer: pixels per degree of visual angle (FLIP's default viewing condition).
PIXELS_PER_DEGREE = 67.0
LUMA = np.array(LUMA_REC709)


def display(linear: np.ndarray, exposure: float, white_balance=None) -> np.ndarray:
    """Linear sRGB radiance -> display sRGB in [0, 1] (float32) through the frame's own
    display step (:func:`catalog.render.display.display_transform`: exposure, white
    balance, tone curve, gamut compression, the sRGB curve)."""
    from catalog.render import display as display_lib  # noqa: PLC0415

    wb = np.eye(3) if white_balance is None else np.asarray(white_balance, dtype=np.float64)
    return np.asarray(display_lib.display_transform(linear, exposure, wb), dtype=np.float32)


def flip_map(test_display: np.ndarray, reference_display: np.ndarray) -> np.ndarray:
    """Per-pixel LDR-FLIP (H, W) in [0, 1] of two display images in [0, 1]."""
    from catalog.core.extras import require  # noqa: PLC0415

    flip_evaluator = require("flip_evaluator", "FLIP")

    error, _mean, _params = flip_evaluator.evaluate(
        np.ascontiguousarray(reference_display, dtype=np.float32),
        np.ascontiguousarray(test_display, dtype=np.float32), "LDR",
        inputsRGB=True, applyMagma=False, computeMeanError=True,
        parameters={"ppd": PIXELS_PER_DEGREE})
    return np.asarray(error, dtype=np.float32).reshape(test_display.shape[:2])


def delta_e_map(test_linear: np.ndarray, reference_linear: np.ndarray,
                white_xyz: np.ndarray) -> np.ndarray:
    """Delta E 2000 (H, W) of two linear sRGB images, CIELAB relative to ``white_xyz``."""
    from catalog.optics.colorimetry import delta_e_2000, linear_srgb_to_xyz  # noqa: PLC0415

    xyz_t = linear_srgb_to_xyz(np.asarray(test_linear, dtype=np.float64))
    xyz_r = linear_srgb_to_xyz(np.asarray(reference_linear, dtype=np.float64))
    return np.asarray(delta_e_2000(np.maximum(xyz_t, 0.0), np.maximum(xyz_r, 0.0),
                                   np.asarray(white_xyz, dtype=np.float64)))


def region_stats(values: np.ndarray, masks: dict[str, np.ndarray]) -> dict:
    out = {}
    for name, mask in masks.items():
        v = values[mask]
        out[name] = ({"mean": float(np.mean(v)), "p95": float(np.percentile(v, 95)),
                      "pixels": int(v.size)} if v.size else None)
    return out


def error_map_image(flip: np.ndarray) -> np.ndarray:
    """FLIP (H, W) -> RGB uint8 through matplotlib's magma (FLIP's own colour map)."""
    from matplotlib import colormaps  # noqa: PLC0415

    return (colormaps["magma"](np.clip(flip, 0, 1))[..., :3] * 255 + 0.5).astype(np.uint8)


def noise_between(a: np.ndarray, b: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Relative RMS noise of the mean of two independent renders of the same scene:
    sqrt(mean((a - b)^2) / 4) / mean((a + b) / 2), on luminance (the mean of two
    independent estimates has half the variance of one; (a - b)^2 estimates twice it)."""
    la, lb = np.asarray(a) @ LUMA, np.asarray(b) @ LUMA
    if mask is not None:
        la, lb = la[mask], lb[mask]
    mean = float(np.mean(0.5 * (la + lb)))
    return math.sqrt(float(np.mean((la - lb) ** 2)) / 4.0) / mean if mean > 0 else math.inf
