"""The fast CPU backend: backend_numpy's algorithm as numba loops (numba_kernels.py).

Each frame is one call into compiled code that runs every substep; inside, each colour
of springs is a parallel loop over rows (no two springs of a colour share a particle,
so the threads never write the same particle).
"""

from __future__ import annotations

import numpy as np

from catalog.cloth.params import ClothParams
from catalog.cloth.state import ClothState, SolverConstants
from catalog.cloth.topology import selector_table
from catalog.cloth.wind import gust_table


def pack_params(params: ClothParams, constants: SolverConstants) -> np.ndarray:
    """The scalar parameters in the order of numba_kernels' fp indices."""
    from catalog.cloth import numba_kernels as k

    fp = np.zeros(k.FP_SIZE)
    fp[k.DAMPING] = params.damping_per_s
    fp[k.GRAVITY] = params.gravity_m_s2
    fp[k.AERO] = constants.aero_per_m
    fp[k.WIND_SPEED] = params.wind_speed_m_s
    fp[k.WIND_X:k.WIND_Z + 1] = params.wind_direction
    fp[k.GUST] = params.gust_strength
    fp[k.GUST_LENGTH] = params.gust_length_m
    fp[k.GUST_PERIOD] = params.gust_period_s
    fp[k.MAX_STRETCH] = params.max_stretch
    fp[k.FLOOR] = params.thickness_m
    fp[k.WALL] = -params.wall_gap_m + params.thickness_m
    fp[k.CONTACT_DAMPING] = params.contact_damping_per_s
    fp[k.RING_SPEED] = params.ring_speed_m_s
    fp[k.STRAIN_PASSES] = params.strain_passes
    return fp


class NumbaBackend:
    name = "cpu"

    def __init__(self, params: ClothParams):
        from catalog.cloth import numba_kernels

        self._kernels = numba_kernels
        self._selectors = selector_table()
        self._gust = gust_table()
        self._scratch: dict[str, np.ndarray] = {}
        self.set_params(params)

    def set_params(self, params: ClothParams) -> None:
        self.params = params
        self.constants = SolverConstants.from_params(params)
        self._fp = pack_params(params, self.constants)
        self._rest = np.ascontiguousarray(self.constants.spring_rest_m, dtype=np.float64)
        self._flat = np.ascontiguousarray(self.constants.rest_m, dtype=np.float64)
        self._stiff = np.ascontiguousarray(self.constants.stiffness_n_m, dtype=np.float64)
        self._limited = np.ascontiguousarray(self.constants.strain_limited, dtype=np.bool_)
        self._inv_mass = np.ascontiguousarray(self.constants.inv_mass_per_kg, dtype=np.float64)
        self._ring_cols = np.ascontiguousarray(self.constants.ring_cols, dtype=np.int64)
        self._lra_ring = np.ascontiguousarray(self.constants.lra_ring, dtype=np.int64)
        self._lra_limit = np.ascontiguousarray(self.constants.lra_limit_m, dtype=np.float64)

    def _work(self, name: str, like: np.ndarray) -> np.ndarray:
        buf = self._scratch.get(name)
        if buf is None or buf.shape != like.shape:
            buf = self._scratch[name] = np.empty_like(like)
        return buf

    def advance(self, state: ClothState, substeps: int, h: float) -> None:
        x, v = state.positions_m, state.velocities_m_s
        state.ring_positions_m = np.ascontiguousarray(state.ring_positions_m, dtype=np.float64)
        state.ring_targets_m = np.ascontiguousarray(state.ring_targets_m, dtype=np.float64)
        state.time_s = self._kernels.advance(
            x, v, self._work("x_prev", x), self._work("normals", x), self._work("wind", x),
            self._inv_mass, state.ring_positions_m, state.ring_targets_m, self._ring_cols,
            self._lra_ring, self._lra_limit, self._selectors, self._rest, self._flat,
            self._stiff,
            self._limited, self._gust, self._fp, int(substeps), float(h),
            float(state.time_s), int(self.params.final_strain_passes))

    def sync(self, state: ClothState) -> None:
        """Nothing to do: the state's arrays are the working arrays."""

