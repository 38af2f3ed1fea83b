"""The simulation state and its rest pose: rings on the rod, pleats, the fabric below.

The top row (row 0) is the row of rings. Ring c sits at x = -width/2 + c dx o (o the
opening: the fraction of the rest width the rings span), alternately in front of and
behind the rod's line by a pleat depth p = 1/2 sqrt(dx^2 - (o dx)^2), so neighbouring
rings stay exactly one rest spacing apart along the zig-zag, as a ring tape folds.
The rings are kinematic (inverse mass 0): they slide to new targets at
``ring_speed_m_s`` and drag the fabric along.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from catalog.cloth.params import ClothParams


def ring_positions(params: ClothParams, opening: float | None = None) -> np.ndarray:
    """(W, 3) ring positions on the rod for an opening (default: the params' opening)."""
    o = params.opening if opening is None else opening
    dx = params.spacing_x_m
    cols = np.arange(params.grid_w)
    pleat = 0.5 * math.sqrt(max(dx * dx - (o * dx) ** 2, 0.0))
    # keep the pleats clear of the window wall (the rings are not collided)
    pleat = min(pleat, 0.5 * (params.wall_gap_m - params.thickness_m))
    rings = np.empty((params.grid_w, 3))
    rings[:, 0] = -0.5 * params.width_m + cols * dx * o
    rings[:, 1] = params.rod_y_m
    rings[:, 2] = np.where(cols % 2 == 0, -pleat, pleat)
    return rings


def rest_pose(params: ClothParams, opening: float | None = None) -> np.ndarray:
    """(H, W, 3) positions: each column hangs straight down from its ring."""
    rings = ring_positions(params, opening)
    rows = np.arange(params.grid_h)
    x = np.repeat(rings[None, :, :], params.grid_h, axis=0)
    x[:, :, 1] = params.rod_y_m - rows[:, None] * params.spacing_y_m
    return x


@dataclass
class ClothState:
    """Positions and velocities (H, W, 3) float64, ring positions and targets, time."""

    positions_m: np.ndarray
    velocities_m_s: np.ndarray
    ring_positions_m: np.ndarray
    ring_targets_m: np.ndarray
    time_s: float = 0.0
    frames: int = 0
    finite: bool = True
    max_stretch_seen: float = 0.0
    quiet_frames: int = 0
    extra: dict = field(default_factory=dict)

    @classmethod
    def at_rest(cls, params: ClothParams) -> "ClothState":
        x = rest_pose(params)
        rings = x[0].copy()
        return cls(positions_m=x, velocities_m_s=np.zeros_like(x),
                   ring_positions_m=rings, ring_targets_m=rings.copy())

    def copy(self) -> "ClothState":
        return ClothState(self.positions_m.copy(), self.velocities_m_s.copy(),
                          self.ring_positions_m.copy(), self.ring_targets_m.copy(),
                          self.time_s, self.frames, self.finite, self.max_stretch_seen,
                          self.quiet_frames, dict(self.extra))


@dataclass(frozen=True)
class SolverConstants:
    """Numbers every backend needs, derived once from the parameters."""

    inv_mass_per_kg: float  # 1/m of a free particle (the rings have 0)
    rest_m: np.ndarray  # (6,) rest length per family
    stiffness_n_m: np.ndarray  # (6,) k per family; the XPBD compliance is alpha = 1/k
    strain_limited: np.ndarray  # (6,) bool
    aero_per_m: float  # 1/2 rho C_d A / m = 1/2 rho C_d / areal density, 1/m
    lra_step_m: float  # rest distance between rows (the LRA limit of row r is r * this)

    @classmethod
    def from_params(cls, params: ClothParams) -> "SolverConstants":
        from catalog.cloth.topology import FAMILIES, rest_lengths_m

        k = params.spring_stiffness_n_m()
        stiff = np.array([k[fam[3]] for fam in FAMILIES])
        return cls(
            inv_mass_per_kg=1.0 / params.particle_mass_kg,
            rest_m=rest_lengths_m(params.spacing_x_m, params.spacing_y_m),
            stiffness_n_m=stiff,
            strain_limited=np.array([fam[4] for fam in FAMILIES]),
            aero_per_m=0.5 * params.air_density_kg_m3 * params.drag_coefficient
            / params.areal_density_kg_m2,
            lra_step_m=params.spacing_y_m,
        )
