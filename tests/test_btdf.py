"""The HG phase function (eq. 6), eq. 7 and the Cook-Torrance baseline (catalog/optics/btdf.py).

References: the printed eq. 6 evaluated in 50-digit decimal arithmetic from the same
vectors, the closed-form HG cumulative distribution, quadrature, and the half-angle
identity for the Cook-Torrance half vector.
"""

from __future__ import annotations

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from catalog.optics import btdf

G = st.floats(min_value=-0.9999, max_value=0.9999, allow_nan=False)


def unit_vectors(draw_strategy=st.floats(-1.0, 1.0, allow_nan=False)):
    return st.tuples(draw_strategy, draw_strategy, draw_strategy).filter(
        lambda v: 1e-3 < math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2))


def _normalise(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def hg_decimal(a: np.ndarray, b: np.ndarray, g: float) -> float:
    """Eq. 6 as printed, in 50-digit decimal arithmetic, with 1 - cos theta defined from
    the given (float64, nearly unit) vectors as (|a|^2 + |b|^2)/2 - a.b = |a - b|^2 / 2."""
    getcontext().prec = 50
    da = [Decimal(float(x)) for x in a]
    db = [Decimal(float(x)) for x in b]
    dg = Decimal(float(g))
    one_minus_cos = sum((x - y) * (x - y) for x, y in zip(da, db)) / 2
    cos_theta = 1 - one_minus_cos
    denom = 1 + dg * dg - 2 * dg * cos_theta
    pi = Decimal("3.14159265358979323846264338327950288419716939937510")
    return float((1 - dg * dg) / (4 * pi * denom * denom.sqrt()))


def hg_cdf(mu0: float, g: float) -> float:
    """Closed form: the part of eq. 6 inside the cone cos theta >= mu0, 2 pi int_mu0^1.

    (1 - g^2)/(2g) (1/(1 - g) - 1/sqrt(d0)), d0 = 1 + g^2 - 2 g mu0, written without the
    cancellation at small g: (1 + g)(1 - mu0) / (sqrt(d0) (sqrt(d0) + 1 - g)).
    """
    root = math.sqrt(1 + g * g - 2 * g * mu0)
    return (1 + g) * (1 - mu0) / (root * (root + 1 - g))


def _log_panels(g: float, low: float, high: float, sign: float, nodes: int, panels: int) -> float:
    """int of ph(mu) over 1 - sign*mu = e^s, s in [low, high] (mu -> +-1 resolved)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    edges = np.linspace(low, high, panels + 1)
    total = 0.0
    for lo, hi in zip(edges[:-1], edges[1:]):
        s = 0.5 * (hi - lo) * x + 0.5 * (hi + lo)
        gap = np.exp(s)                                   # 1 - mu (sign +1) or 1 + mu (sign -1)
        one_minus_mu = gap if sign > 0 else 2.0 - gap
        f = btdf.hg_phase_one_minus_cos(one_minus_mu, g) * gap      # dmu = e^s ds
        total += 0.5 * (hi - lo) * float(np.sum(w * f))
    return total


def sphere_integral(g: float, mu0: float = -1.0, nodes: int = 24, panels: int = 120) -> float:
    """2 pi int_mu0^1 ph(mu) dmu by composite Gauss-Legendre in log(1 - mu) on [0, 1] and
    in log(1 + mu) on [-1, 0]: the peak of width (1 - |g|)^2 at mu = +-1 is resolved for
    |g| -> 1 (the pieces within e^-40 of +-1 add at most ph(+-1) e^-40, negligible)."""
    total = 0.0
    upper_start = max(mu0, 0.0)                           # [upper_start, 1]
    total += _log_panels(g, -40.0, math.log(1.0 - upper_start), +1, nodes, panels)
    if mu0 < 0:                                           # [mu0, 0]
        low = -40.0 if mu0 == -1.0 else math.log(1.0 + mu0)
        total += _log_panels(g, low, 0.0, -1, nodes, panels)
    return 2 * math.pi * total


# --- eq. 6 -------------------------------------------------------------------------------

@settings(max_examples=300, deadline=None)
@given(unit_vectors(), unit_vectors(), G)
@pytest.mark.slow
def test_hg_finite_positive_and_matches_decimal_reference(a, b, g):
    a, b = _normalise(a), _normalise(b)
    value = btdf.hg_phase_between(a, b, g)
    assert np.isfinite(value) and value > 0
    assert value == pytest.approx(hg_decimal(a, b, g), rel=1e-9)


@settings(max_examples=200, deadline=None)
@given(unit_vectors(), G, st.floats(min_value=-12, max_value=0))
@pytest.mark.slow
def test_hg_near_straight_through_matches_reference(a, g, log_angle):
    """theta -> 0: views a tiny angle away from the direction of travel."""
    a = _normalise(a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    side = _normalise(np.cross(a, helper))
    b = _normalise(a + 10.0 ** log_angle * side)
    value = btdf.hg_phase_between(a, b, g)
    assert np.isfinite(value) and value > 0
    assert value == pytest.approx(hg_decimal(a, b, g), rel=1e-9)


@pytest.mark.parametrize("g", [-0.9999, -0.99, -0.5, 0.0, 0.3, 0.9, 0.99, 0.999, 0.9999])
def test_hg_integrates_to_one_over_the_sphere(g):
    assert sphere_integral(g) == pytest.approx(1.0, abs=1e-6)


@settings(max_examples=40, deadline=None)
@given(G, st.floats(min_value=-0.999, max_value=0.999))
def test_hg_cone_integral_matches_closed_form_cdf(g, mu0):
    assert sphere_integral(g, mu0) == pytest.approx(hg_cdf(mu0, g), abs=1e-6)


def test_hg_isotropic_and_peak_values():
    cos_theta = np.linspace(-1, 1, 11)
    assert np.allclose(btdf.hg_phase(cos_theta, 0.0), 1 / (4 * math.pi), rtol=1e-15)
    for g in (0.5, 0.9999, -0.9999):
        peak = (1 + g) / (4 * math.pi * (1 - g) ** 2)             # theta = 0 closed form
        assert btdf.hg_phase(1.0, g) == pytest.approx(peak, rel=1e-13)
        back = (1 - g) / (4 * math.pi * (1 + g) ** 2)             # theta = pi
        travel, view = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
        assert btdf.hg_phase_between(travel, travel, g) == pytest.approx(peak, rel=1e-13)
        assert btdf.hg_phase_between(travel, view, g) == pytest.approx(back, rel=1e-13)


def test_hg_refuses_g_out_of_range():
    for g in (1.0, -1.0, 1.5, float("nan")):
        with pytest.raises(ValueError, match="g must lie in"):
            btdf.hg_phase(0.5, g)


def test_hg_derivative_matches_central_difference():
    omc = np.geomspace(1e-6, 2.0, 50)
    for g in (-0.6, 0.2, 0.95, 0.999):
        h = 1e-7 * (1 - abs(g))
        numeric = (btdf.hg_phase_one_minus_cos(omc, g + h)
                   - btdf.hg_phase_one_minus_cos(omc, g - h)) / (2 * h)
        assert np.allclose(btdf.hg_phase_dg(omc, g), numeric, rtol=1e-5)


# --- float32: the shader's arithmetic ------------------------------------------------------

def test_printed_form_fails_in_float32_and_robust_form_holds():
    """model.md: as printed, 10 % off at g = 0.999 and infinite at g = 0.9999 in float32."""
    one = np.float32(1.0)
    for g, bad in ((np.float32(0.999), 0.05), (np.float32(0.9999), None)):
        exact = btdf.hg_phase(1.0, float(g))                      # float64, same g
        with np.errstate(divide="ignore"):
            printed = btdf.hg_phase_printed(one, g)
        robust = btdf.hg_phase(one, g)
        assert robust.dtype == np.float32
        assert abs(robust / exact - 1) < 1e-6
        if bad is None:
            assert not np.isfinite(printed) or abs(printed / exact - 1) > 0.5
        else:
            assert abs(printed / exact - 1) > bad


@settings(max_examples=400, deadline=None)
@given(unit_vectors(), unit_vectors(), G, st.floats(min_value=-8, max_value=0),
       st.sampled_from([-1.0, 0.0, 1.0]))
@pytest.mark.slow
def test_robust_form_in_float32_within_1e6_at_all_angles(a, b, g, log_scale, near):
    """Vectors in float32 (forward, backward and random pairs) against float64 on the
    same float32 inputs."""
    a = _normalise(a)
    b = _normalise(b)
    if near:
        perp = np.cross(a, b)
        if np.linalg.norm(perp) < 0.1:
            perp = np.cross(a, np.eye(3)[int(np.argmin(np.abs(a)))])
        b = _normalise(near * a + 10.0 ** log_scale * _normalise(perp))
    a32, b32, g32 = a.astype(np.float32), b.astype(np.float32), np.float32(g)
    value = btdf.hg_phase_between(a32, b32, g32)
    assert value.dtype == np.float32
    reference = btdf.hg_phase_between(a32.astype(np.float64), b32.astype(np.float64),
                                      float(g32))
    assert np.isfinite(value) and value > 0
    assert abs(float(value) / float(reference) - 1) < 1e-6


# --- eq. 7 --------------------------------------------------------------------------------

def test_eq7_adds_direct_only_straight_through():
    omc = np.array([0.0, 1e-8, 1e-4, 0.5])
    straight = btdf.is_straight_through(omc)
    assert straight.tolist() == [True, True, False, False]
    params = dict(direct=0.3, a_diff=0.2, a_spec=0.4, g_diff=0.1, g_spec=0.9)
    total = btdf.eq7_transmittance(omc, **params)
    lobes = (0.2 * btdf.hg_phase_one_minus_cos(omc, 0.1)
             + 0.4 * btdf.hg_phase_one_minus_cos(omc, 0.9))
    assert np.allclose(total - lobes, [0.3, 0.3, 0.0, 0.0], atol=1e-12)


def test_woven_btdf_uses_the_identifiable_products():
    from catalog.presets import BTDFParams

    params = BTDFParams(direct=0.2, k_d=0.5, k_s=0.7, tau=0.3, rho=0.8, g_diff=0.2, g_spec=0.95)
    travel = np.array([[0.0, 0.0, 1.0]] * 2)
    view = np.array([[0.0, 0.0, 1.0], [math.sin(0.3), 0.0, math.cos(0.3)]])
    expected = (0.8 * math.exp(-0.3) * (0.5 * btdf.hg_phase(np.cos([0.0, 0.3]), 0.2)
                                       + 0.7 * btdf.hg_phase(np.cos([0.0, 0.3]), 0.95)))
    assert np.allclose(btdf.woven_btdf(params, travel, view), expected, rtol=1e-12)


# --- Cook-Torrance --------------------------------------------------------------------------

def test_ct_half_vector_is_the_half_angle_for_normal_light():
    """Light from straight behind, view at polar alpha: the mirrored half vector makes
    the angle alpha / 2 with the normal."""
    alpha = np.linspace(0.0, 1.5, 16)
    to_light = np.tile([0.0, 0.0, -1.0], (len(alpha), 1))
    view = np.stack([np.sin(alpha), np.zeros_like(alpha), np.cos(alpha)], axis=1)
    geometry = btdf.ct_geometry(to_light, view)
    assert np.allclose(geometry["cos_h"], np.cos(alpha / 2), atol=1e-14)
    assert np.allclose(geometry["cos_o"], np.cos(alpha), atol=1e-14)
    assert np.allclose(geometry["cos_i"], 1.0)


@pytest.mark.parametrize("roughness", [0.05, 0.2, 0.6])
def test_beckmann_projected_area_is_one(roughness):
    """int D(h) cos theta_h d omega_h = 1 over the hemisphere (quadrature in theta_h)."""
    x, w = np.polynomial.legendre.leggauss(400)
    theta = 0.25 * math.pi * (x + 1)                        # 0 .. pi/2
    cos_h = np.cos(theta)
    integrand = btdf.beckmann_d(cos_h, roughness) * cos_h * np.sin(theta) * 2 * math.pi
    assert float(np.sum(w * integrand) * 0.25 * math.pi) == pytest.approx(1.0, abs=1e-6)


def test_beckmann_derivative_matches_central_difference():
    cos_h = np.linspace(0.3, 1.0, 20)
    for m in (0.05, 0.3):
        h = 1e-7
        numeric = (btdf.beckmann_d(cos_h, m + h) - btdf.beckmann_d(cos_h, m - h)) / (2 * h)
        assert np.allclose(btdf.beckmann_d_droughness(cos_h, m), numeric, rtol=1e-5, atol=1e-9)


def test_ct_peaks_straight_through_and_is_finite_at_grazing():
    to_light = np.array([0.0, 0.0, -1.0])
    elevations = np.radians(np.linspace(0.5, 90.0, 60))
    view = np.stack([np.cos(elevations), np.zeros_like(elevations), np.sin(elevations)], axis=1)
    values = btdf.cook_torrance_transmittance(np.tile(to_light, (60, 1)), view, 0.0, 0.1,
                                              0.5, 0.2)
    assert np.all(np.isfinite(values)) and np.all(values > 0)
    assert int(np.argmax(values)) == 59                    # camera on the normal


@pytest.mark.parametrize("g", [-(1 - 1e-6), -(1 - 1e-9), -(1 - 1e-12), 1 - 1e-12])
def test_one_minus_cos_form_is_finite_at_the_extremes_of_g_and_theta(g):
    """Found by the stability sweep of `catalog bench`: g -> -1 at theta = pi used to cancel
    to a negative denominator (NaN). Closed form there: (1 - g^2) / (4 pi (1 + |g|)^3 ...)."""
    omc = np.array([0.0, 1e-12, 1.0, 2.0 - 1e-12, 2.0, 2.0 + 1e-15, -1e-17])
    values = btdf.hg_phase_one_minus_cos(omc, g)
    assert np.all(np.isfinite(values)) and np.all(values > 0)
    # exact value at theta = pi: (1 - g^2) / (4 pi (1 + g)^3) = (1 - g) / (4 pi (1 + g)^2)
    at_pi = (1 - g) / (4 * np.pi * (1 + g) ** 2)
    assert values[4] == pytest.approx(at_pi, rel=1e-9)
