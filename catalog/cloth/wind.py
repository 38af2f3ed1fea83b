"""Wind with gusts: a mean wind whose speed a smooth noise modulates in time and space.

    w(x, t) = U d max(0, 1 + s g(x, t)),   g = (1/3) sum_k sin(2 pi (k_k . x / L + f_k t / T) + phi_k)

U: ``wind_speed_m_s``, d: ``wind_direction``, s: ``gust_strength``, L: ``gust_length_m``,
T: ``gust_period_s``. Three travelling waves with incommensurate frequencies make a
noise that is smooth in x and t, never repeats in practice, and costs three sines, so the
numpy, numba and GLSL backends evaluate exactly the same field (shaders/cloth_step.comp
holds the same table). The wind acts on the cloth through the normal drag (state.py):
F = -1/2 rho C_d A |v_rel . n| (v_rel . n) n with v_rel = v - w.
"""

from __future__ import annotations

import math

import numpy as np

#: (wave vector k_k (per gust length), frequency f_k (per gust period), phase phi_k)
GUST_WAVES: tuple[tuple[tuple[float, float, float], float, float], ...] = (
    ((0.80, 0.30, 0.52), 1.000, 0.0),
    ((-0.35, 0.90, 0.26), 0.613, 1.7),
    ((0.50, -0.60, 0.62), 1.370, 4.1),
)


def gust_table() -> np.ndarray:
    """GUST_WAVES as a (3, 5) float array: kx, ky, kz, f, phi."""
    return np.array([[*k, f, phi] for k, f, phi in GUST_WAVES], dtype=np.float64)


def gust_noise(points_m: np.ndarray, t_s: float, length_m: float, period_s: float) -> np.ndarray:
    """g(x, t) in [-1, 1] at points (..., 3)."""
    total = np.zeros(points_m.shape[:-1])
    for k, f, phi in GUST_WAVES:
        phase = 2.0 * math.pi * ((points_m @ np.asarray(k)) / length_m + f * t_s / period_s) + phi
        total += np.sin(phase)
    return total / 3.0


def wind_velocity(points_m: np.ndarray, t_s: float, speed_m_s: float,
                  direction: tuple[float, float, float], gust_strength: float,
                  length_m: float, period_s: float) -> np.ndarray:
    """Wind velocity (m/s) at points (..., 3) and time t_s."""
    if speed_m_s == 0.0:
        return np.zeros_like(points_m)
    factor = np.maximum(0.0, 1.0 + gust_strength * gust_noise(points_m, t_s, length_m, period_s))
    return (speed_m_s * factor)[..., None] * np.asarray(direction)
