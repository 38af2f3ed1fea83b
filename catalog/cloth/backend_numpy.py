"""The reference backend: float64 numpy over whole grids, one frame = n substeps.

One substep (the same order in every backend; Macklin et al. 2019, "Small steps in
physics simulation": many substeps, one constraint iteration each):

1. the rings slide towards their targets (kinematic, speed-limited);
2. normals from the positions (central differences);
3. predict: velocity damping, gravity, normal air drag against the gusty wind
   (semi-implicit in the normal speed, so it never overshoots), x_prev = x, x += h v;
4. XPBD distance constraints (Macklin, Mueller, Chentanez 2016), colour by colour
   (topology.SELECTORS), compliance alpha = 1/k, one Gauss-Seidel sweep; stretch and shear
   springs are also strain-limited at ``max_stretch`` (Provot 1995);
5. long-range attachments to the ring above (Kim, Chentanez, Mueller 2012): no particle
   further from its ring than its rest distance down the fabric;
6. collision with the floor (y = 0) and the window wall (z = -wall_gap);
7. v = (x - x_prev) / h, with contact damping of the tangential velocity.
"""

from __future__ import annotations

import numpy as np

from catalog.cloth.params import STRAIN_TOLERANCE, ClothParams
from catalog.cloth.state import ClothState, SolverConstants
from catalog.cloth.topology import SELECTORS
from catalog.cloth.wind import wind_velocity


def grid_differences(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(down, across): central differences of an (H, W, 3) grid along its rows and columns,
    one-sided at the edges (the tangents the normals and the weft tangents are made from)."""
    down = np.empty_like(x)
    across = np.empty_like(x)
    down[1:-1] = x[2:] - x[:-2]
    down[0] = x[1] - x[0]
    down[-1] = x[-1] - x[-2]
    across[:, 1:-1] = x[:, 2:] - x[:, :-2]
    across[:, 0] = x[:, 1] - x[:, 0]
    across[:, -1] = x[:, -1] - x[:, -2]
    return down, across


def grid_normals(x: np.ndarray) -> np.ndarray:
    """Unit normals (H, W, 3) by central differences (one-sided at the edges).

    n = (x[r+1] - x[r-1]) x (x[c+1] - x[c-1]), normalised: +z for the flat rest pose
    (rows run down, columns along +x).
    """
    down, across = grid_differences(x)
    n = np.cross(down, across)
    length = np.sqrt(np.sum(n * n, axis=-1, keepdims=True))
    return n / np.where(length > 0.0, length, 1.0)


def move_rings(rings: np.ndarray, targets: np.ndarray, max_move_m: float) -> np.ndarray:
    """Rings after one substep: towards the targets, at most max_move_m each."""
    step = targets - rings
    dist = np.sqrt(np.sum(step * step, axis=-1, keepdims=True))
    scale = np.where(dist > max_move_m, max_move_m / np.where(dist > 0, dist, 1.0), 1.0)
    return rings + step * scale


class NumpyBackend:
    """Vectorised reference. Works on the state's arrays in place."""

    name = "numpy"

    def __init__(self, params: ClothParams):
        self.set_params(params)

    def set_params(self, params: ClothParams) -> None:
        """Recompute the constants (cheap: the grid stays)."""
        self.params = params
        self.constants = SolverConstants.from_params(params)
        w, h = params.grid_w, params.grid_h
        self._inv_mass = self.constants.inv_mass_per_kg
        self._free = (self._inv_mass > 0.0)[..., None]
        self._ring_cols = self.constants.ring_cols
        self._slices = [sel.slices(w, h) for sel in SELECTORS]
        self._lra_limit = self.constants.lra_limit_m[..., None]

    def advance(self, state: ClothState, substeps: int, h: float) -> None:
        """One frame. The wind field is taken once per frame, at its start."""
        p = self.params
        wind = wind_velocity(state.positions_m, state.time_s, p.wind_speed_m_s,
                             p.wind_direction, p.gust_strength, p.gust_length_m,
                             p.gust_period_s)
        for step in range(substeps):
            self._substep(state, h, wind, last=step == substeps - 1)

    def sync(self, state: ClothState) -> None:
        """Nothing to do: the state's arrays are the working arrays."""

    def _substep(self, state: ClothState, h: float, wind: np.ndarray, last: bool) -> None:
        p, c = self.params, self.constants
        x, v = state.positions_m, state.velocities_m_s
        ring_cols = self._ring_cols
        # 1. rings
        rings_before = state.ring_positions_m
        rings = move_rings(rings_before, state.ring_targets_m, p.ring_speed_m_s * h)
        state.ring_positions_m = rings
        # 2. normals at the start of the substep
        n = grid_normals(x)
        # 3. predict (the rings are overwritten below: they only follow the rod)
        v *= 1.0 / (1.0 + p.damping_per_s * h)
        v[..., 1] -= h * p.gravity_m_s2
        vn = np.sum((v - wind) * n, axis=-1, keepdims=True)
        # dv_n/dt = -c |v_n| v_n, taken semi-implicitly: v_n' = v_n / (1 + c |v_n| h)
        v += n * (vn / (1.0 + c.aero_per_m * np.abs(vn) * h) - vn)
        x_prev = x.copy()
        x_prev[0, ring_cols] = rings_before
        x += h * v
        x[0, ring_cols] = rings
        # 4. XPBD, colour by colour
        for sel, (sa, sb) in zip(SELECTORS, self._slices):
            self._project(x, sa, sb, sel.family, h)
        # 5. long-range attachments
        d = x - rings[c.lra_ring]
        dist = np.sqrt(np.sum(d * d, axis=-1, keepdims=True))
        over = (dist > self._lra_limit) & self._free
        x[...] = np.where(over, rings[c.lra_ring] + d * (self._lra_limit
                                                        / np.where(over, dist, 1.0)), x)
        # 6. collisions (the rings are on the rod, above the floor, in front of the wall)
        floor = p.thickness_m
        wall = -p.wall_gap_m + p.thickness_m
        np.maximum(x[..., 1], floor, out=x[..., 1])
        np.maximum(x[..., 2], wall, out=x[..., 2])
        # 6b. strain limiting sweeps (Provot): stretch and shear springs beyond the limit,
        # hard, alternately forward and backward; the frame's last substep repeats them
        # until no spring is more than STRAIN_TOLERANCE over (at most final_strain_passes)
        passes = max(p.strain_passes, p.final_strain_passes) if last else p.strain_passes
        for k in range(passes):
            worst = self._strain_sweep(x, h, backward=k % 2 == 1)
            if last and k + 1 >= p.strain_passes and worst <= STRAIN_TOLERANCE:
                break
        # the sweeps may have nudged a particle into a plane: clamp again
        np.maximum(x[..., 1], floor, out=x[..., 1])
        np.maximum(x[..., 2], wall, out=x[..., 2])
        # 7. velocities, contact damping (tangential)
        v[...] = (x - x_prev) / h
        keep = 1.0 / (1.0 + p.contact_damping_per_s * h)
        on_floor = x[..., 1] <= floor
        on_wall = x[..., 2] <= wall
        v[..., 0] *= np.where(on_floor | on_wall, keep, 1.0)
        v[..., 2] *= np.where(on_floor, keep, 1.0)
        v[..., 1] *= np.where(on_wall, keep, 1.0)
        state.time_s += h

    def _strain_sweep(self, x: np.ndarray, h: float, backward: bool) -> float:
        worst = -1.0
        order = list(zip(SELECTORS, self._slices))
        for sel, (sa, sb) in (reversed(order) if backward else order):
            if self.constants.strain_limited[sel.family]:
                worst = max(worst, self._project(x, sa, sb, sel.family, h, limit_only=True))
        return worst

    def _project(self, x: np.ndarray, sa, sb, family: int, h: float,
                 limit_only: bool = False) -> float:
        """One selector's XPBD constraints; returns the worst strain beyond the limit
        (before correction) among springs with a movable end."""
        c = self.constants
        a = x[sa]
        b = x[sb]
        wa = self._inv_mass[sa][..., None]
        wb = self._inv_mass[sb][..., None]
        wsum = wa + wb
        d = b - a
        length = np.sqrt(np.sum(d * d, axis=-1, keepdims=True))
        # the elastic rest: the spring's length in the pleated pose; the strain limit: the
        # fabric's own length between the two particles (flat), never stretched beyond it
        rest = c.spring_rest_m[family][sa][..., None]
        flat = c.rest_m[family]
        kh2 = c.stiffness_n_m[family] * h * h
        # XPBD with lambda = 0 (one iteration): dlambda = -C / (wa + wb + alpha/h^2);
        # written with k h^2 = h^2/alpha so that k = 0 gives no pull and k -> inf a hard one
        limit = (1.0 + self.params.max_stretch) * flat
        if limit_only:  # only pull back what is beyond the strain limit
            shorten = np.maximum(length - limit, 0.0)
        else:
            shorten = (length - rest) * wsum * kh2 / (wsum * kh2 + 1.0)
            if c.strain_limited[family]:  # Provot: never longer than (1 + max_stretch) rest
                shorten = np.maximum(shorten, length - limit)
        safe = (wsum > 0.0) & (length > 0.0)
        scale = np.where(safe, shorten / np.where(safe, wsum * length, 1.0), 0.0)
        x[sa] = a + (wa * scale) * d
        x[sb] = b - (wb * scale) * d
        excess = np.where(safe, (length - limit) / flat, -1.0)
        return float(excess.max()) if excess.size else -1.0
