"""HG in float32 GLSL (shaders/common.glsl) against float64 (catalog.optics.btdf), eq. 6."""

from __future__ import annotations

import math

import numpy as np
import pytest

import benchmarks  # noqa: F401  (registers benchmarks/shaders, where probe_hg.comp is)
from catalog.optics.btdf import hg_phase_one_minus_cos, hg_phase_printed
from catalog.gl.shaderlib import create_compute

pytestmark = pytest.mark.gl


def _directions(theta_rad: np.ndarray, axis_tilt: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of float32 unit vectors (travel, view) at angles theta, in a tilted plane."""
    base = np.array([math.sin(axis_tilt), 0.0, math.cos(axis_tilt)])
    ortho = np.array([math.cos(axis_tilt), 0.0, -math.sin(axis_tilt)])
    travel = np.tile(base, (theta_rad.size, 1))
    view = np.cos(theta_rad)[:, None] * base + np.sin(theta_rad)[:, None] * ortho
    return travel.astype(np.float32), view.astype(np.float32)


def _glsl_hg(ctx, travel, view, g) -> np.ndarray:
    shader = create_compute(ctx, "probe_hg.comp")
    n = travel.shape[0]
    pad = np.zeros((n, 1), np.float32)
    buffers = [ctx.buffer(np.hstack([travel, pad]).tobytes()),
               ctx.buffer(np.hstack([view, pad]).tobytes()),
               ctx.buffer(reserve=4 * n)]
    for binding, buffer in enumerate(buffers):
        buffer.bind_to_storage_buffer(binding)
    shader["u_g"].value = float(g)
    shader["u_count"].value = n
    shader.run(group_x=(n + 63) // 64)
    result = np.frombuffer(buffers[2].read(), dtype=np.float32).copy()
    for buffer in buffers:
        buffer.release()
    shader.release()
    return result


THETAS = np.concatenate([[0.0], np.geomspace(1e-6, 1e-2, 20), np.linspace(0.02, math.pi, 40)])


@pytest.mark.parametrize("g", [0.999, 0.9999, 0.97, 0.2, 0.0, -0.3, -0.999, -0.9999])
def test_glsl_hg_matches_float64_within_1e6(gl, g):
    travel, view = _directions(THETAS)
    glsl = _glsl_hg(gl, travel, view, g)
    g32 = float(np.float32(g))
    # the exact angle between the float32 vectors, in float64: 1 - cos from the chord near
    # theta = 0 and 2 - (1 + cos) from the anti-chord near theta = pi (no cancellation)
    t64 = travel / np.linalg.norm(travel.astype(np.float64), axis=1, keepdims=True)
    v64 = view / np.linalg.norm(view.astype(np.float64), axis=1, keepdims=True)
    chord2 = np.sum((v64 - t64) ** 2, axis=1)
    anti2 = np.sum((v64 + t64) ** 2, axis=1)
    one_minus_cos = np.where(chord2 < 2.0, 0.5 * chord2, 2.0 - 0.5 * anti2)
    reference = hg_phase_one_minus_cos(one_minus_cos, g32)
    assert np.all(np.isfinite(glsl))
    relative = np.abs(glsl / reference - 1.0)
    assert relative.max() < 1e-6, (g, float(relative.max()), THETAS[int(relative.argmax())])


def test_printed_form_fails_where_the_robust_one_holds():
    """The reason for the robust form: eq. 6 as printed, in float32, at g = 0.999, theta = 0."""
    g = np.float32(0.999)
    printed = hg_phase_printed(np.float32(1.0), g)
    exact = hg_phase_one_minus_cos(0.0, float(g))
    assert abs(float(printed) / exact - 1) > 0.01
    g = np.float32(0.9999)
    with np.errstate(divide="ignore"):
        assert not np.isfinite(hg_phase_printed(np.float32(1.0), g)) or \
            abs(float(hg_phase_printed(np.float32(1.0), g)) / hg_phase_one_minus_cos(0.0, float(g)) - 1) > 0.1


def test_hg_integrates_to_one_over_the_sphere(gl):
    """An invariant of eq. 6 on the GLSL values: 2 pi integral of ph sin(theta) d theta = 1."""
    theta = np.linspace(0.0, math.pi, 200001)
    travel, view = _directions(theta)
    for g in (0.0, 0.5, 0.9):
        ph = _glsl_hg(gl, travel, view, g).astype(np.float64)
        integral = np.trapezoid(2 * math.pi * ph * np.sin(theta), theta)
        assert abs(integral - 1.0) < 1e-4, (g, integral)
