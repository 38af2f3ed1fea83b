"""The simulation state and its rest pose: rings on the rod, pleats, the fabric below.

The top row (row 0) carries the heading. Every ``ring_every`` columns (and at both
ends) a particle is held by a ring on the rod: kinematic (inverse mass 0), it slides to
its target at ``ring_speed_m_s`` and drags the fabric along. Ring j sits at
x = -width/2 + c_j dx o (o the opening: the fraction of the rest width the rings span),
on the rod (z = 0). The fabric between two rings folds into a pleat, alternately
towards the room and towards the window: in the rest pose each span is a V whose two
straight legs keep the fabric's rest length, and every column hangs straight down.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from catalog.cloth.params import ClothParams


def ring_columns(params: ClothParams) -> np.ndarray:
    """Columns of row 0 held by rings (int64, sorted): every ring_every, and the last."""
    cols = list(range(0, params.grid_w, params.ring_every))
    if cols[-1] != params.grid_w - 1:
        cols.append(params.grid_w - 1)
    return np.array(cols, dtype=np.int64)


def _max_pleat_depth(params: ClothParams) -> float:
    """A pleat's apex towards the window stays off the wall (z = -wall_gap + thickness)."""
    return params.wall_gap_m - 2.0 * params.thickness_m


def ring_positions(params: ClothParams, opening: float | None = None) -> np.ndarray:
    """(R, 3) positions of the rings on the rod for an opening (default: the params').

    On a grid so coarse that every column has a ring (ring_every = 1) there is no fabric
    between rings to fold, so the rings themselves zig-zag about the rod's line by
    1/2 sqrt(dx^2 - (o dx)^2), keeping one rest spacing between neighbours.
    """
    o = params.opening if opening is None else opening
    cols = ring_columns(params)
    dx = params.spacing_x_m
    rings = np.zeros((cols.size, 3))
    rings[:, 0] = -0.5 * params.width_m + cols * dx * o
    rings[:, 1] = params.rod_y_m
    if params.ring_every == 1:
        depth = min(0.5 * math.sqrt(max(dx * dx - (o * dx) ** 2, 0.0)), _max_pleat_depth(params))
        rings[:, 2] = np.where(cols % 2 == 0, -depth, depth)
    return rings


def _folds_in_span(k: int, dx: float, span: float, max_depth: float) -> tuple[int, float]:
    """(n, depth): the fewest V folds the ``k`` rest spacings between two rings make so
    that each fold's apex stays within ``max_depth`` while its legs keep their rest length
    (k dx / 2n each). A single V deeper than the wall allows would squeeze the heading
    (legs shorter than the fabric), and the squeezed fabric spreads below it: the hem
    flared wider than the rod. More, shallower folds hold the same fabric at rest length.
    """
    for n in range(1, max(1, k // 2) + 1):
        if k % n:
            continue
        half_leg, half_span = 0.5 * k * dx / n, 0.5 * span / n
        depth = math.sqrt(max(half_leg ** 2 - half_span ** 2, 0.0))
        if depth <= max_depth:
            return n, depth
    return n, min(depth, max_depth)


def top_row(params: ClothParams, opening: float | None = None) -> np.ndarray:
    """(W, 3) heading: rings on the rod, V-shaped pleats of rest length between them
    (split into several folds where one would reach the wall, :func:`_folds_in_span`)."""
    o = params.opening if opening is None else opening
    dx = params.spacing_x_m
    cols = ring_columns(params)
    rings = ring_positions(params, o)
    row = np.zeros((params.grid_w, 3))
    row[:, 1] = params.rod_y_m
    row[cols] = rings
    max_depth = _max_pleat_depth(params)
    for j in range(cols.size - 1):
        c0, c1 = int(cols[j]), int(cols[j + 1])
        k = c1 - c0
        if k == 1:
            continue
        span = rings[j + 1, 0] - rings[j, 0]
        folds, depth = _folds_in_span(k, dx, span, max_depth)
        sign = 1.0 if j % 2 == 0 else -1.0
        for c in range(c0, c1 + 1):
            s = (c - c0) / k  # 0..1 along the span
            f = min(int(s * folds), folds - 1)   # which fold, and where along it
            t = s * folds - f
            row[c, 0] = rings[j, 0] + s * span
            row[c, 2] = sign * (-1.0) ** f * depth * (1.0 - abs(2.0 * t - 1.0))
    return row


def rest_pose(params: ClothParams, opening: float | None = None) -> np.ndarray:
    """(H, W, 3) positions: every column hangs straight down from the heading."""
    row = top_row(params, opening)
    rows = np.arange(params.grid_h)
    x = np.repeat(row[None, :, :], params.grid_h, axis=0)
    x[:, :, 1] = params.rod_y_m - rows[:, None] * params.spacing_y_m
    return x


def spring_rest_lengths_m(params: ClothParams) -> np.ndarray:
    """(6, H, W) the rest length of each spring, by family (topology.FAMILIES) and first
    particle (r, c): its length in the rest pose, the pleated heading hanging straight down
    (where a family has no spring from (r, c), its flat rest length).

    Springs resting flat pushed every pleat open where the pose's chord is shorter than the
    flat length: the bend springs across each fold (2 dx flat), the stretch and shear
    springs across an apex that falls between two columns. Below the rings nothing held the
    pleats in, so they opened towards the hem and the hem flared wider than the heading (the
    voile's hem 2.04 m under a 1.70 m heading). Resting at the pleated shape, the fabric
    keeps its folds as a heading tape and pressing set them: the rest pose is free of
    stress but for gravity, and the pleats hang down to the hem."""
    from catalog.cloth.topology import FAMILIES, rest_lengths_m  # noqa: PLC0415

    x = rest_pose(params)
    h, w = params.grid_h, params.grid_w
    flat = rest_lengths_m(params.spacing_x_m, params.spacing_y_m)
    rest = np.empty((len(FAMILIES), h, w))
    for family, (_, di, dj, _, _) in enumerate(FAMILIES):
        rest[family] = flat[family]
        c0, c1 = max(0, -dj), w - max(dj, 0)
        a = x[0:h - di, c0:c1]
        b = x[di:h, c0 + dj:c1 + dj]
        rest[family, 0:h - di, c0:c1] = np.linalg.norm(b - a, axis=-1)
    return rest


def inverse_mass(params: ClothParams) -> np.ndarray:
    """(H, W) 1/m per particle (1/kg); 0 for the particles held by rings."""
    w = np.full((params.grid_h, params.grid_w), 1.0 / params.particle_mass_kg)
    w[0, ring_columns(params)] = 0.0
    return w


def attachments(params: ClothParams) -> tuple[np.ndarray, np.ndarray]:
    """Long-range attachments (Kim, Chentanez, Mueller 2012): for each particle the
    index (into the rings) of its nearest ring in the rest fabric, and its rest distance
    from it (m), which its distance from that ring may never exceed. (H, W) each."""
    cols = ring_columns(params)
    c = np.arange(params.grid_w)
    nearest = np.argmin(np.abs(c[:, None] - cols[None, :]), axis=1)
    dc = (c - cols[nearest]) * params.spacing_x_m
    dr = np.arange(params.grid_h) * params.spacing_y_m
    limit = np.sqrt(dr[:, None] ** 2 + dc[None, :] ** 2)
    ring_index = np.broadcast_to(nearest[None, :], limit.shape).copy()
    return ring_index, limit


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
    calm_s: float = -1.0  # simulated seconds calm (below the sleep thresholds); -1: not calm
    extra: dict = field(default_factory=dict)

    @classmethod
    def at_rest(cls, params: ClothParams) -> "ClothState":
        x = rest_pose(params)
        rings = ring_positions(params)
        return cls(positions_m=x, velocities_m_s=np.zeros_like(x),
                   ring_positions_m=rings, ring_targets_m=rings.copy())

    def copy(self) -> "ClothState":
        return ClothState(self.positions_m.copy(), self.velocities_m_s.copy(),
                          self.ring_positions_m.copy(), self.ring_targets_m.copy(),
                          self.time_s, self.frames, self.finite, self.max_stretch_seen,
                          self.calm_s, dict(self.extra))


@dataclass(frozen=True)
class SolverConstants:
    """Numbers and tables every backend needs, derived once from the parameters."""

    inv_mass_per_kg: np.ndarray  # (H, W) 1/m; 0 where a ring holds the particle
    ring_cols: np.ndarray  # (R,) columns of row 0 held by rings
    rest_m: np.ndarray  # (6,) rest length per family
    spring_rest_m: np.ndarray  # (6, H, W) rest length per family and first particle (the pose's)
    stiffness_n_m: np.ndarray  # (6,) k per family; the XPBD compliance is alpha = 1/k
    strain_limited: np.ndarray  # (6,) bool
    aero_per_m: float  # 1/2 rho C_d A / m = 1/2 rho C_d / areal density, 1/m
    lra_ring: np.ndarray  # (H, W) index of the attached ring
    lra_limit_m: np.ndarray  # (H, W) rest distance from it

    @classmethod
    def from_params(cls, params: ClothParams) -> "SolverConstants":
        from catalog.cloth.topology import FAMILIES, rest_lengths_m

        k = params.spring_stiffness_n_m()
        lra_ring, lra_limit = attachments(params)
        return cls(
            inv_mass_per_kg=inverse_mass(params),
            ring_cols=ring_columns(params),
            rest_m=rest_lengths_m(params.spacing_x_m, params.spacing_y_m),
            spring_rest_m=spring_rest_lengths_m(params),
            stiffness_n_m=np.array([k[fam[3]] for fam in FAMILIES]),
            strain_limited=np.array([fam[4] for fam in FAMILIES]),
            aero_per_m=0.5 * params.air_density_kg_m3 * params.drag_coefficient
            / params.areal_density_kg_m2,
            lra_ring=lra_ring,
            lra_limit_m=lra_limit,
        )
