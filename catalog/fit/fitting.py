"""Fitting eq. 7 (and the Cook-Torrance baseline) to gonio measurements.

What the data can identify (model.md section 5): k_d, k_s, tau and rho enter eq. 7 only
as the products a_diff = rho e^-tau k_d and a_spec = rho e^-tau k_s, so the fit is over

    direct, a_diff, a_spec, g_diff, g_spec

and rho (from the weave), tau (from the dye) are supplied, k_d and k_s derived
(:func:`split_amplitudes`).

Method. The model is linear in (direct, a_diff, a_spec) for fixed g's. A scan over a
grid of (g_diff, g_spec) pairs solves the linear part exactly for each pair (variable
projection, on at most SCAN_POINTS points) and keeps the best SCAN_STARTS pairs as
starts; from each, Levenberg-Marquardt (scipy ``least_squares(method="lm")``, analytic
Jacobian) fits all five parameters, holding at zero an amplitude that would go negative
(and then the g of that lobe). The best end point wins, so no initial guess is needed.
A guess passed in is one more start: LM first moves its two g's with the amplitudes
solved by non-negative least squares at every step (robust from far away), then
polishes all five. The g's are fitted through u (g = G_MID + G_HALF tanh u keeps g in
(G_LOW, G_HIGH)), reported as g; the lobe with the larger g is called ``spec``.

Standard errors: cov = s^2 (J^T J)^-1, J the Jacobian of the weighted residuals at the
optimum in the reported parameters, s^2 = sum r^2 / (n - p) (the noise level is
estimated from the residuals).

Weighting. The gonio ratio spans four decades (a peak of tens per steradian, a skirt of
1e-4), and the two-exposure instrument's error is roughly relative, so the default
(``"relative"``) weights each point by 1 / (y + floor), floor = 2 % of the median
value. ``"none"`` is the paper's plain least squares. The reported ``rmse`` is always
the plain root-mean-square difference on the points fitted (the paper's measure).

scipy is imported inside the functions; the renderer never imports this module.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from catalog.optics.btdf import (beckmann_d, beckmann_d_droughness, ct_geometry, ct_shadowing,
                          hg_denominator, hg_phase_and_dg, hg_phase_one_minus_cos)

HG_NAMES = ("direct", "a_diff", "a_spec", "g_diff", "g_spec")
CT_NAMES = ("direct", "k_lambert", "k_spec", "roughness")
WEIGHTINGS = ("relative", "none")

#: The Cook-Torrance scan's Beckmann roughness grid.
SCAN_ROUGHNESS = np.geomspace(0.005, 2.0, 20)
#: Starts taken from the scan.
SCAN_STARTS = 3
#: The scan looks at this many points at most.
SCAN_POINTS = 1200
#: The g's are fitted as g = G_MID + G_HALF tanh(u): a transmitted lobe may lean back a
#: little (g >= -0.9; further back it only mimics a constant floor with a huge weight)
#: and be as sharp as g = 0.99999.
G_LOW, G_HIGH = -0.9, 0.99999
G_MID, G_HALF = 0.5 * (G_HIGH + G_LOW), 0.5 * (G_HIGH - G_LOW)
#: Largest |u| the optimiser may reach.
U_LIMIT = 12.0
RELATIVE_FLOOR = 0.02


#: |anisotropy| stays below this (the renderer accepts (-1, 1)).
A_LIMIT = 0.95


def anisotropy_of_w(w):
    return A_LIMIT * np.tanh(w)


def dA_dw(w):
    t = np.tanh(w)
    return A_LIMIT * (1 - t * t)


def g_of_u(u):
    return G_MID + G_HALF * np.tanh(u)


def dg_du(u):
    t = np.tanh(u)
    return G_HALF * (1 - t * t)


def u_of_g(g):
    return np.arctanh(np.clip((np.asarray(g, dtype=np.float64) - G_MID) / G_HALF,
                              -1 + 1e-12, 1 - 1e-12))


#: The scan's g grid: uniform in u from g = -0.6 to g = 0.9995.
SCAN_G = g_of_u(np.linspace(float(u_of_g(-0.6)), float(u_of_g(0.9995)), 24))


@dataclass(frozen=True)
class FitResult:
    """A fitted model: parameters with standard errors and the fit's figures."""

    model: str                      # "hg" (eq. 7) or "cook-torrance"
    params: dict[str, float]
    stderr: dict[str, float]
    rmse: float                     # plain RMS of model - data on the points fitted
    weighted_rms: float             # RMS of the weighted residuals
    points: int
    iterations: int                 # residual evaluations of the winning start (LM)
    evaluations: int                # ... summed over all starts
    starts: int
    time_s: float
    weighting: str
    predicted: np.ndarray = field(repr=False)
    covariance: np.ndarray = field(repr=False)


def noise_scale(values: np.ndarray, weighting: str = "relative") -> np.ndarray:
    """Per-point scale s_i of the residuals (residual / s_i is minimised)."""
    values = np.asarray(values, dtype=np.float64)
    if weighting == "none":
        return np.ones_like(values)
    if weighting != "relative":
        raise ValueError(f"weighting must be one of {WEIGHTINGS}, got {weighting!r}")
    floor = RELATIVE_FLOOR * float(np.median(values))
    if not floor > 0:
        floor = RELATIVE_FLOOR * float(np.mean(values))
    if not floor > 0:
        raise ValueError("all values are zero: nothing to fit")
    return values + floor


def _gram(columns: np.ndarray) -> np.ndarray:
    """A^T A of a tall (n, p) matrix. einsum's own loop, not BLAS: on a busy machine the
    threaded BLAS spends ~10x longer waking threads than computing these small products."""
    return np.einsum("ki,kj->ij", columns, columns)


def _project(columns: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """A^T y for a tall (n, p) matrix (einsum, as :func:`_gram`)."""
    return np.einsum("ki,k->i", columns, vector)


def _combine(columns: np.ndarray, coefficients: np.ndarray) -> np.ndarray:
    """A x for a tall (n, p) matrix (einsum, as :func:`_gram`)."""
    return np.einsum("ki,i->k", columns, coefficients)


def _covariance(jac: np.ndarray, residual: np.ndarray) -> np.ndarray:
    n, p = jac.shape
    dof = max(n - p, 1)
    s2 = float(np.einsum("k,k->", residual, residual)) / dof
    jtj = _gram(jac)
    try:
        return s2 * np.linalg.inv(jtj)
    except np.linalg.LinAlgError:
        return s2 * np.linalg.pinv(jtj)


def _stderr(cov: np.ndarray) -> np.ndarray:
    diag = np.diag(cov)
    return np.sqrt(np.where(diag >= 0, diag, np.nan))


# --- eq. 7 ----------------------------------------------------------------------------

class _HGProblem:
    """Weighted eq. 7 residuals over (direct, a_diff, a_spec, u_diff, u_spec[, w]).

    With ``spread`` (per point, ``(delta_y^2 - delta_x^2) / 2`` of delta = view - travel
    in the cloth frame, x along the weft, y along the warp) the directional lobe takes
    the renderer's anisotropic chord (shaders/common.glsl ``woven_chord2``):
    1 - cos theta becomes ``one_minus_cos + A spread``, A = A_LIMIT tanh(w), the sixth
    parameter.
    """

    def __init__(self, one_minus_cos, straight, values, scale, spread=None):
        self.omc = np.asarray(one_minus_cos, dtype=np.float64)
        self.straight = np.asarray(straight, dtype=np.float64)
        self.values = np.asarray(values, dtype=np.float64)
        self.inv_scale = 1.0 / np.asarray(scale, dtype=np.float64)
        self.target = self.values * self.inv_scale
        self.spread = None if spread is None else np.asarray(spread, dtype=np.float64)
        self.size = 5 if spread is None else 6
        self.evaluations = 0
        self._lobes: dict[tuple[float, float], tuple[np.ndarray, ...]] = {}

    def lobe(self, u: float, w: float | None = None):
        """(phase, d phase / du, d phase / dw) of one HG lobe at g(u) (and anisotropy
        A(w) when w is given), cached: LM asks for the residual and the Jacobian at the
        same point."""
        u = min(max(float(u), -U_LIMIT), U_LIMIT)
        key = (u, math.nan if w is None else float(w))
        cached = self._lobes.get(key)
        if cached is None:
            g = float(g_of_u(u))
            if w is None:
                phase, dphase_dg = hg_phase_and_dg(self.omc, g)
                dphase_dw = None
            else:
                omc = self.omc + float(anisotropy_of_w(w)) * self.spread
                phase, dphase_dg = hg_phase_and_dg(omc, g)
                # d ph / d(1 - cos) = -3 g ph / d (eq. 6)
                dphase_dw = (-3.0 * g * phase / hg_denominator(omc, g)
                             * self.spread * float(dA_dw(w)))
            cached = (phase, dphase_dg * float(dg_du(u)), dphase_dw)
            if len(self._lobes) > 8:
                self._lobes.clear()
            self._lobes[key] = cached
        return cached

    def _spec(self, p):
        return self.lobe(p[4], p[5] if self.size == 6 else None)

    def model(self, p):
        return (p[0] * self.straight + p[1] * self.lobe(p[3])[0]
                + p[2] * self._spec(p)[0])                                          # eq. 7

    def residual(self, p):
        self.evaluations += 1
        return self.model(p) * self.inv_scale - self.target

    def jacobian(self, p):
        (ph_d, dph_d, _), (ph_s, dph_s, dph_w) = self.lobe(p[3]), self._spec(p)
        cols = np.empty((len(self.omc), self.size))
        cols[:, 0] = self.straight
        cols[:, 1] = ph_d
        cols[:, 2] = ph_s
        cols[:, 3] = p[1] * dph_d
        cols[:, 4] = p[2] * dph_s
        if self.size == 6:
            cols[:, 5] = p[2] * dph_w
        return cols * self.inv_scale[:, None]

    def basis(self, g_d, g_s, anisotropy: float = 0.0):
        """Weighted columns of the linear part for fixed shapes: (n, 3)."""
        omc_s = self.omc if not anisotropy else self.omc + anisotropy * self.spread
        return np.stack([self.straight, hg_phase_one_minus_cos(self.omc, g_d),
                         hg_phase_one_minus_cos(omc_s, g_s)], axis=1) * self.inv_scale[:, None]

    def projected(self, u):
        """Amplitudes solved exactly (non-negative least squares) for g(u):
        (amplitudes, weighted residual)."""
        self.evaluations += 1
        u = np.clip(u, -U_LIMIT, U_LIMIT)
        basis = self.basis(g_of_u(u[0]), g_of_u(u[1]))
        amps = _nnls_small(_gram(basis), _project(basis, self.target))
        return amps, _combine(basis, amps) - self.target


def _nnls_small(gram: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Non-negative least squares for a few unknowns from the normal equations: the best
    of the unconstrained solutions on every subset of free variables that is feasible."""
    p = len(rhs)
    best, best_value = np.zeros(p), 0.0          # objective relative to y.y: -2 a.b + a.G.a
    ridge = 1e-12 * np.trace(gram)
    for mask in range(1, 1 << p):
        free = [i for i in range(p) if mask >> i & 1]
        sub = gram[np.ix_(free, free)] + ridge * np.eye(len(free))
        try:
            a_free = np.linalg.solve(sub, rhs[free])
        except np.linalg.LinAlgError:
            continue
        if np.any(a_free < 0):
            continue
        value = -float(a_free @ rhs[free])        # at a stationary point a.G.a = a.b
        if value < best_value:
            best_value = value
            best = np.zeros(p)
            best[free] = a_free
    return best


def _scan_hg(problem: _HGProblem, count: int) -> list[np.ndarray]:
    """Best (direct, a_d, a_s, u_d, u_s) starts over the SCAN_G pair grid (g_d < g_s),
    on at most SCAN_POINTS points (every k-th, and all straight-through ones): the starts
    only need to be near the optimum."""
    step = max(1, len(problem.omc) // SCAN_POINTS)
    keep = (np.arange(len(problem.omc)) % step == 0) | (problem.straight > 0)
    phases = hg_phase_one_minus_cos(problem.omc[keep][None, :], SCAN_G[:, None])
    columns = (np.vstack([problem.straight[keep][None, :], phases])
               * problem.inv_scale[keep][None, :])
    target = problem.target[keep]
    gram = np.einsum("ik,jk->ij", columns, columns)
    rhs = np.einsum("ik,k->i", columns, target)
    i, j = np.triu_indices(len(SCAN_G), k=1)
    idx = np.stack([np.zeros_like(i), i + 1, j + 1], axis=1)          # (pairs, 3)
    a = gram[idx[:, :, None], idx[:, None, :]]
    b = rhs[idx]
    a = a + 1e-12 * np.trace(a, axis1=1, axis2=2)[:, None, None] * np.eye(3)
    amps = np.linalg.solve(a, b[..., None])[..., 0]
    sse = float(np.einsum("k,k->", target, target)) - np.einsum("pi,pi->p", amps, b)
    physical = np.all(amps >= 0, axis=1)
    order = np.lexsort((sse, ~physical))                               # physical first
    starts = []
    for k in order[:count]:
        starts.append(np.array([*amps[k], u_of_g(SCAN_G[i[k]]), u_of_g(SCAN_G[j[k]])]))
    return starts


def _lm(fun, x0, jac="2-point"):
    from scipy.optimize import least_squares

    return least_squares(fun, x0, jac=jac, method="lm", xtol=1e-12, ftol=1e-12, gtol=1e-12,
                         max_nfev=1000)


def _run_hg_start(problem: _HGProblem, start: np.ndarray,
                  project_first: bool) -> tuple[np.ndarray, int]:
    """One start: (for a guess from outside) LM on the g's with the amplitudes projected
    out, then LM on all the parameters, holding at zero any amplitude that would go
    negative (and the shape of a lobe with no weight, which has none to fit)."""
    before = problem.evaluations
    x = np.array(start, dtype=np.float64)
    if project_first:
        u_fit = np.clip(_lm(lambda u: problem.projected(u)[1], x[3:5]).x, -U_LIMIT, U_LIMIT)
        x[:5] = np.concatenate([problem.projected(u_fit)[0], u_fit])
    free = np.ones(problem.size, dtype=bool)
    for _ in range(4):
        free[:3] &= x[:3] > 0
        free[3] &= bool(free[1])
        free[4:] &= bool(free[2])
        x[:3][~free[:3]] = 0.0
        fixed = x.copy()

        def residual(q, fixed=fixed, free=free.copy()):
            full = fixed.copy()
            full[free] = q
            return problem.residual(full)

        def jacobian(q, fixed=fixed, free=free.copy()):
            full = fixed.copy()
            full[free] = q
            return problem.jacobian(full)[:, free]

        x = fixed.copy()
        x[free] = _lm(residual, fixed[free], jac=jacobian).x
        if np.all(x[:3] >= 0):
            break
    x[:3] = np.maximum(x[:3], 0.0)
    return x, problem.evaluations - before


def _hg_start_from_guess(guess, size: int = 5) -> np.ndarray:
    anisotropy = 0.0
    if isinstance(guess, dict):
        anisotropy = float(guess.get("anisotropy", 0.0))
        guess = [guess[name] for name in HG_NAMES]
    guess = np.asarray(guess, dtype=np.float64)
    if guess.shape != (5,):
        raise ValueError(f"an eq. 7 start needs {HG_NAMES}, got {guess!r}")
    start = np.concatenate([guess[:3], u_of_g(guess[3:])])
    if size == 6:
        start = np.append(start, np.arctanh(np.clip(anisotropy / A_LIMIT, -0.999, 0.999)))
    return start


def fit_hg(one_minus_cos, straight, values, *, weighting: str = "relative", starts=(),
           scan: bool = True, spread=None, on_start=None) -> FitResult:
    """Fit eq. 7 (direct, a_diff, a_spec, g_diff, g_spec) to ``values``.

    ``one_minus_cos``: 1 - cos theta per point; ``straight``: where the direct
    see-through reaches the camera; ``starts``: extra initial guesses (dicts keyed by
    HG_NAMES or 5-sequences); ``scan=False`` uses only those; ``spread``: also fit the
    directional lobe's warp/weft ``anisotropy`` (see :class:`_HGProblem`); ``on_start()``:
    called as each start is done (the progress). ``time_s`` of the result excludes
    importing scipy.
    """
    import scipy.optimize  # noqa: F401  (lazily, and outside the timing)

    t0 = time.perf_counter()
    values = np.asarray(values, dtype=np.float64)
    problem = _HGProblem(one_minus_cos, straight, values, noise_scale(values, weighting),
                         spread)
    start_list = [(_hg_start_from_guess(s, problem.size), True) for s in starts]
    if scan:
        start_list += [(np.append(s, [0.0] * (problem.size - 5)), False)
                       for s in _scan_hg(problem, SCAN_STARTS)]
    if not start_list:
        raise ValueError("no start: pass starts or scan=True")
    best, best_key, best_evals = None, None, 0
    for start, project_first in start_list:
        x, evals = _run_hg_start(problem, start, project_first)
        if x[3] > x[4]:
            # the sharper lobe is called 'spec'; with anisotropy (which belongs to that
            # lobe) the swapped point is polished again
            x = _ordered_lobes(x)
            if problem.size == 6:
                x[5] = 0.0
                x, more = _run_hg_start(problem, x, False)
                evals += more
        cost = float(np.sum(problem.residual(x) ** 2))
        key = (not (x[1] >= 0 and x[2] >= 0), cost)
        if best is None or key < best_key:
            best, best_key, best_evals = x, key, evals
        if on_start is not None:
            on_start()
    residual = problem.residual(best)
    # Jacobian in the reported parameters: d/dg = d/du / (dg/du), d/dA = d/dw / (dA/dw)
    jac = problem.jacobian(best)
    jac[:, 3:5] /= dg_du(best[3:5])[None, :]
    names = list(HG_NAMES)
    values_out = [*best[:3], *g_of_u(best[3:5])]
    if problem.size == 6:
        jac[:, 5] /= float(dA_dw(best[5]))
        names.append("anisotropy")
        values_out.append(anisotropy_of_w(best[5]))
    cov = _covariance(jac, residual)
    params = dict(zip(names, [float(v) for v in values_out]))
    predicted = problem.model(best)
    return FitResult(model="hg", params=params,
                     stderr=dict(zip(names, map(float, _stderr(cov)))),
                     rmse=float(np.sqrt(np.mean((predicted - values) ** 2))),
                     weighted_rms=float(np.sqrt(np.mean(residual ** 2))),
                     points=len(values), iterations=best_evals,
                     evaluations=problem.evaluations, starts=len(start_list),
                     time_s=time.perf_counter() - t0, weighting=weighting,
                     predicted=predicted, covariance=cov)


def _ordered_lobes(x: np.ndarray) -> np.ndarray:
    """Name the sharper lobe 'spec' (g_spec >= g_diff): the two lobes are interchangeable."""
    x = np.array(x, dtype=np.float64)
    x[3:5] = np.clip(x[3:5], -U_LIMIT, U_LIMIT)
    if x[3] > x[4]:
        x[[1, 2, 3, 4]] = x[[2, 1, 4, 3]]
    return x


def fit_channels(one_minus_cos, straight, channel_values, g_diff: float, g_spec: float, *,
                 direct: float | None = None, spread=None, anisotropy: float = 0.0,
                 weighting: str = "relative") -> list[dict[str, dict[str, float]]]:
    """Per-channel (direct, a_diff, a_spec) with the shape (g's, anisotropy) of the grey fit.

    ``direct`` given: the see-through of the gaps is colourless, so every channel keeps
    that value (its standard error reported as 0) and only a_diff, a_spec are fitted.
    Linear least squares per channel; returns, per channel,
    ``{"params": .., "stderr": .., "rmse": ..}``.
    """
    out = []
    channel_values = np.asarray(channel_values, dtype=np.float64)
    for c in range(channel_values.shape[1]):
        values = channel_values[:, c]
        problem = _HGProblem(one_minus_cos, straight, values, noise_scale(values, weighting),
                             spread)
        full_basis = problem.basis(g_diff, g_spec, anisotropy)
        basis, target = full_basis, problem.target
        if direct is not None:
            target = target - direct * basis[:, 0]
            basis = basis[:, 1:]
        amps = _nnls_small(_gram(basis), _project(basis, target))
        residual = _combine(basis, amps) - target
        errors = _stderr(_covariance(basis, residual))
        if direct is not None:
            amps, errors = np.concatenate([[direct], amps]), np.concatenate([[0.0], errors])
        predicted = _combine(full_basis, amps) / problem.inv_scale
        out.append({"params": dict(zip(HG_NAMES[:3], map(float, amps))),
                    "stderr": dict(zip(HG_NAMES[:3], map(float, errors))),
                    "rmse": float(np.sqrt(np.mean((predicted - values) ** 2)))})
    return out


def split_amplitudes(a_diff: float, a_spec: float, rho: float, tau: float) -> tuple[float, float]:
    """k_d, k_s from the identifiable products (a = rho e^-tau k, eq. 7)."""
    if not (0 < rho <= 1):
        raise ValueError(f"rho must lie in (0, 1], got {rho}")
    scale = rho * math.exp(-tau)
    return a_diff / scale, a_spec / scale


# --- Cook-Torrance ----------------------------------------------------------------------

class _CTProblem:
    """Weighted Cook-Torrance residuals over (direct, k_lambert, k_spec, log m)."""

    def __init__(self, to_light, view, straight, values, scale):
        self.geometry = ct_geometry(to_light, view)
        self.shadow = ct_shadowing(self.geometry)
        self.lambert = self.geometry["cos_i"] / math.pi
        self.spec_factor = self.shadow / (4 * self.geometry["cos_o"])
        self.straight = np.asarray(straight, dtype=np.float64)
        self.values = np.asarray(values, dtype=np.float64)
        self.inv_scale = 1.0 / np.asarray(scale, dtype=np.float64)
        self.target = self.values * self.inv_scale
        self.evaluations = 0
        self._spec: dict[float, tuple[np.ndarray, np.ndarray]] = {}

    def spec(self, log_m: float):
        """(D G / (4 cos_o), its derivative in log m) at roughness e^log_m, cached:
        LM asks for the residual and the Jacobian at the same point."""
        log_m = float(log_m)
        cached = self._spec.get(log_m)
        if cached is None:
            m = math.exp(log_m)
            cos_h = self.geometry["cos_h"]
            spec = beckmann_d(cos_h, m) * self.spec_factor
            dspec = beckmann_d_droughness(cos_h, m) * self.spec_factor * m
            if len(self._spec) > 8:
                self._spec.clear()
            cached = self._spec[log_m] = (spec, dspec)
        return cached

    def model(self, p):
        direct, k_l, k_s, log_m = p
        return direct * self.straight + k_l * self.lambert + k_s * self.spec(log_m)[0]

    def residual(self, p):
        self.evaluations += 1
        return self.model(p) * self.inv_scale - self.target

    def jacobian(self, p):
        direct, k_l, k_s, log_m = p
        spec, dspec = self.spec(log_m)
        cols = np.empty((len(self.values), 4))
        cols[:, 0] = self.straight
        cols[:, 1] = self.lambert
        cols[:, 2] = spec
        cols[:, 3] = k_s * dspec
        return cols * self.inv_scale[:, None]


def fit_cook_torrance(to_light, view, straight, values, *,
                      weighting: str = "relative", on_start=None) -> FitResult:
    """Fit the Cook-Torrance baseline (btdf module docstring) to the same data;
    ``on_start()``: called as each start is done."""
    import scipy.optimize  # noqa: F401  (lazily, and outside the timing)

    t0 = time.perf_counter()
    values = np.asarray(values, dtype=np.float64)
    problem = _CTProblem(to_light, view, straight, values, noise_scale(values, weighting))
    scans = []
    target2 = float(np.einsum("k,k->", problem.target, problem.target))
    for m in SCAN_ROUGHNESS:                  # the linear part solved exactly for each m
        spec = beckmann_d(problem.geometry["cos_h"], m) * problem.spec_factor
        basis = np.stack([problem.straight, problem.lambert, spec], axis=1) \
            * problem.inv_scale[:, None]
        gram, rhs = _gram(basis), _project(basis, problem.target)
        amps = np.linalg.solve(gram + 1e-12 * np.trace(gram) * np.eye(3), rhs)
        scans.append((target2 - float(amps @ rhs), np.array([*amps, math.log(m)])))
    scans.sort(key=lambda item: item[0])
    best, best_cost, best_evals = None, math.inf, 0
    for _, start in scans[:SCAN_STARTS]:
        before = problem.evaluations
        x = _lm(problem.residual, start, jac=problem.jacobian).x
        cost = float(np.sum(problem.residual(x) ** 2))
        if cost < best_cost:
            best, best_cost, best_evals = x, cost, problem.evaluations - before
        if on_start is not None:
            on_start()
    residual = problem.residual(best)
    m = math.exp(best[3])
    jac = problem.jacobian(best)
    jac[:, 3] /= m                       # d/dm = d/dlog m / m
    cov = _covariance(jac, residual)
    predicted = problem.model(best)
    params = dict(zip(CT_NAMES, [float(best[0]), float(best[1]), float(best[2]), m]))
    return FitResult(model="cook-torrance", params=params,
                     stderr=dict(zip(CT_NAMES, map(float, _stderr(cov)))),
                     rmse=float(np.sqrt(np.mean((predicted - values) ** 2))),
                     weighted_rms=float(np.sqrt(np.mean(residual ** 2))),
                     points=len(values), iterations=best_evals,
                     evaluations=problem.evaluations, starts=min(SCAN_STARTS, len(scans)),
                     time_s=time.perf_counter() - t0, weighting=weighting,
                     predicted=predicted, covariance=cov)


# --- on GonioData -----------------------------------------------------------------------

def anisotropy_identifiable(data) -> bool:
    """Whether a gonio set constrains the warp/weft anisotropy: it needs views whose offset
    from the light's travel has both an x (weft) and a y (warp) part. The paper's 79
    points lie in one plane and do not; the OGM-3 grid does."""
    delta = data.view - data.travel
    return bool(np.any(np.abs(delta[:, 0]) > 0.05) and np.any(np.abs(delta[:, 1]) > 0.05))


def fit_gonio_hg(data, values=None, *, anisotropy="auto", **kwargs) -> FitResult:
    """:func:`fit_hg` on a :class:`catalog.fit.gonio.GonioData` (its grey column by default).

    ``anisotropy``: True fits the directional lobe's warp/weft anisotropy (our extension
    of eq. 7, the renderer's ``btdf.anisotropy``), False does not, "auto" fits it when
    :func:`anisotropy_identifiable`.
    """
    if anisotropy == "auto":
        anisotropy = anisotropy_identifiable(data)
    return fit_hg(data.one_minus_cos, data.straight_through,
                  data.transmittance if values is None else values,
                  spread=data.anisotropy_spread if anisotropy else None, **kwargs)


def fit_gonio_ct(data, values=None, **kwargs) -> FitResult:
    return fit_cook_torrance(data.to_light, data.view, data.straight_through,
                             data.transmittance if values is None else values, **kwargs)


__all__ = ["FitResult", "HG_NAMES", "CT_NAMES", "fit_hg", "fit_cook_torrance",
           "fit_channels", "fit_gonio_hg", "fit_gonio_ct", "split_amplitudes",
           "anisotropy_identifiable",
           "noise_scale"]
