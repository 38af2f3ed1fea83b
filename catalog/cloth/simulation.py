"""ClothSimulation: the one object the viewer, the CLI and the tests drive.

    sim = ClothSimulation(ClothParams(grid_w=64, grid_h=96), backend="cpu")
    sim.set_wind(2.0)            # m/s from the window; wakes the simulation
    sim.step(1 / 60)             # one frame (substeps inside); False if it slept
    mesh = sim.mesh()            # positions, normals, uv, tangents, triangle indices

Backends: ``numpy`` (reference, float64), ``cpu`` (numba, float64, same algorithm),
``gpu`` (GLSL compute through moderngl, float32; keeps the state on the GPU and writes
the renderer's vertex buffer directly, see docs/cloth.md).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from catalog.cloth.backend import ClothBackend, DeviceBackend
from catalog.cloth.params import ClothParams
from catalog.cloth.state import ClothState, inverse_mass, ring_positions
from catalog.cloth.topology import FAMILIES, rest_lengths_m
from catalog.core.constants import FRAME_DT_S
from catalog.core.errors import CatalogError, InputError

BACKENDS = ("numpy", "cpu", "gpu")


def make_backend(name: str, params: ClothParams, **options: Any) -> ClothBackend:
    """The backend object for a name of BACKENDS (the protocol of :mod:`.backend`)."""
    if name == "numpy":
        from catalog.cloth.backend_numpy import NumpyBackend
        return NumpyBackend(params)
    if name == "cpu":
        from catalog.cloth.backend_numba import NumbaBackend
        return NumbaBackend(params)
    if name == "gpu":
        from catalog.cloth.backend_gpu import GpuBackend
        return GpuBackend(params, **options)
    raise InputError(f"unknown backend {name!r}; choose one of {', '.join(BACKENDS)}",
                     field="backend")


def max_spring_strain(positions_m: np.ndarray, params: ClothParams) -> float:
    """Largest (length - rest) / rest over all springs of all families (float64)."""
    x = np.asarray(positions_m, dtype=np.float64)
    rest = rest_lengths_m(params.spacing_x_m, params.spacing_y_m)
    free = inverse_mass(params) > 0.0
    worst = -math.inf
    h, w = params.grid_h, params.grid_w
    for family, (_, di, dj, _, _) in enumerate(FAMILIES):
        c0 = max(0, -dj)
        a = x[0:h - di, c0:w - max(dj, 0)]
        b = x[di:h, c0 + dj:w - max(dj, 0) + dj]
        if a.size == 0:
            continue
        length = np.sqrt(np.sum((b - a) ** 2, axis=-1))
        strain = (length - rest[family]) / rest[family]
        # a spring between two rings: the rod sets it, not the solver
        movable = free[0:h - di, c0:w - max(dj, 0)] | free[di:h, c0 + dj:w - max(dj, 0) + dj]
        strain = strain[movable]
        if strain.size:
            worst = max(worst, float(np.max(strain)))
    return worst


def kinetic_energy_j(velocities_m_s: np.ndarray, params: ClothParams) -> float:
    """1/2 m sum |v|^2 over the free particles (the rings are driven, not counted)."""
    v = np.asarray(velocities_m_s, dtype=np.float64)[inverse_mass(params) > 0.0]
    return 0.5 * params.particle_mass_kg * float(np.sum(v * v))


def calm_spell_s(calm_s: float, peak_speed_m_s: float, rms_speed_m_s: float, still: bool,
                 elapsed_s: float, params: ClothParams) -> float:
    """The sleep test with hysteresis: how long the cloth has been calm (simulated s; -1:
    not calm) after a check ``elapsed_s`` after the last one.

    A calm spell starts when the largest particle speed is under ``sleep_speed_m_s`` and the
    RMS speed (the kinetic energy's, 1/2 M v_rms^2) under ``sleep_rms_speed_m_s``; it lasts
    while neither exceeds ``wake_factor`` times its threshold and the cloth is ``still``
    (no wind, rings arrived). Asleep once it has lasted ``sleep_hold_s``."""
    p = params
    calm = peak_speed_m_s < p.sleep_speed_m_s and rms_speed_m_s < p.sleep_rms_speed_m_s
    loud = peak_speed_m_s > p.wake_factor * p.sleep_speed_m_s \
        or rms_speed_m_s > p.wake_factor * p.sleep_rms_speed_m_s
    if not still or loud or (calm_s < 0.0 and not calm):
        return -1.0
    if calm_s < 0.0:
        return 0.0  # a calm spell starts now
    return calm_s + elapsed_s


class ClothSimulation:
    """A curtain on a rod: parameters, state, a backend, sleep and monitoring."""

    def __init__(self, params: ClothParams, backend: str = "numpy",
                 monitor_every: int | None = None, **backend_options: Any):
        if not isinstance(params, ClothParams):
            raise TypeError("params must be a ClothParams")
        self.params = params
        self.state = ClothState.at_rest(params)
        self.backend_name = backend
        self.backend = make_backend(backend, params, **backend_options)
        if isinstance(self.backend, DeviceBackend):
            self.backend.load(self.state)
        # checks (finite, stretch, energy, sleep) need the state on the CPU: every frame
        # for the CPU backends, every few frames for the GPU one (a small download)
        self.monitor_every = monitor_every or (30 if backend == "gpu" else 1)
        self.sleeping = False
        self.last_substeps = 0
        self.kinetic_energy = 0.0
        self.peak_speed_m_s = 0.0  # largest particle speed at the last check
        self.rms_speed_m_s = 0.0  # RMS speed of the free particles at the last check
        self._unchecked_s = 0.0  # simulated time since the last check
        self.max_stretch = max_spring_strain(self.state.positions_m, params)

    # ---- controls ----------------------------------------------------------------
    def wake(self) -> None:
        self.sleeping = False
        self.state.calm_s = -1.0

    def set_wind(self, speed_m_s: float, direction: tuple[float, float, float] | None = None,
                 gust_strength: float | None = None) -> None:
        changes: dict[str, Any] = {"wind_speed_m_s": speed_m_s}
        if direction is not None:
            changes["wind_direction"] = direction
        if gust_strength is not None:
            changes["gust_strength"] = gust_strength
        self.set_params(**changes)

    def set_opening(self, fraction: float) -> None:
        """Slide the rings so they span ``fraction`` of the rest width (1 = closed)."""
        self.set_params(opening=fraction)

    def set_params(self, **changes: Any) -> None:
        """Change parameters that keep the grid (wind, stiffness, opening, ...); wakes."""
        new = self.params.with_changes(**changes)
        if (new.grid_w, new.grid_h) != (self.params.grid_w, self.params.grid_h):
            raise CatalogError("the grid size cannot change on a running simulation")
        self.params = new
        self.backend.set_params(new)
        self.state.ring_targets_m = ring_positions(new)
        if isinstance(self.backend, DeviceBackend):
            self.backend.set_ring_targets(self.state.ring_targets_m)
        self.wake()

    # ---- stepping ----------------------------------------------------------------
    def step(self, frame_dt_s: float) -> bool:
        """Advance one frame. Returns False (and does nothing) while asleep."""
        if self.sleeping:
            return False
        n = self.params.substeps_for(frame_dt_s)
        h = frame_dt_s / n
        self.backend.advance(self.state, n, h)
        self.last_substeps = n
        self.state.frames += 1
        self._unchecked_s += frame_dt_s
        if self.state.frames % self.monitor_every == 0:
            self._monitor()
        return True

    def settle(self, max_s: float = 15.0, frame_dt_s: float = FRAME_DT_S,
               tolerance: float = 0.5) -> float:
        """Relax to the rest shape of the current parameters by kinetic damping (dynamic
        relaxation, Cundall 1976) and fall asleep; returns the simulated seconds it took.

        Frames run as usual (the same substeps, damping and constraints as every later
        frame, so the result is a rest state of this simulation, not of another solver);
        whenever the kinetic energy falls from one frame to the next, a swing has passed the
        bottom of its potential and every velocity is zeroed: its energy is taken out at
        once, where the light physical damping (0.5 /s) would let the curtain ring for tens
        of seconds. It stops when, after a frame, the largest and the RMS particle speeds are
        both under ``tolerance`` times the sleep thresholds (a frame from zero velocity
        reaches speed = residual force / mass x frame time, so this bounds the residual) for
        ``sleep_hold_s`` (so that slow swings, whose speed grows slowly, show), or after
        ``max_s``. Needs no wind (there is no rest in a gust)."""
        if self.params.wind_speed_m_s != 0.0:
            raise CatalogError("settle: the wind blows; a curtain settles only without wind")
        p = self.params
        elapsed = calm_s = 0.0
        energy_before = 0.0
        monitor_every, self.monitor_every = self.monitor_every, 1 << 62  # speeds only, below
        try:
            while elapsed < max_s:
                self.sleeping = False
                self.step(frame_dt_s)
                elapsed += frame_dt_s
                if not self._measure_motion():
                    break
                if self.peak_speed_m_s < tolerance * p.sleep_speed_m_s \
                        and self.rms_speed_m_s < tolerance * p.sleep_rms_speed_m_s:
                    calm_s += frame_dt_s
                    if calm_s >= p.sleep_hold_s:
                        break
                else:
                    calm_s = 0.0
                if self.kinetic_energy < energy_before:
                    self._zero_velocities()
                    energy_before = 0.0
                else:
                    energy_before = self.kinetic_energy
        finally:
            self.monitor_every = monitor_every
        self._unchecked_s = 0.0
        self._monitor()  # the strain and the finite check of the result
        self._zero_velocities()
        self.sleeping = self.state.finite
        self.state.calm_s = 0.0
        return elapsed

    def _measure_motion(self) -> bool:
        """Kinetic energy, largest and RMS speed of the free particles (a download on the
        GPU); False (and the state marked not finite) if a value is not finite."""
        self.backend.sync(self.state)
        x, v = self.state.positions_m, self.state.velocities_m_s
        if not (np.isfinite(x).all() and np.isfinite(v).all()):
            self.state.finite = False
            self.max_stretch = self.kinetic_energy = math.inf
            return False
        p = self.params
        speed2 = np.sum(v * v, axis=-1)[inverse_mass(p) > 0.0]
        self.kinetic_energy = 0.5 * p.particle_mass_kg * float(np.sum(speed2))
        self.peak_speed_m_s = float(np.sqrt(np.max(speed2))) if speed2.size else 0.0
        self.rms_speed_m_s = float(np.sqrt(np.mean(speed2))) if speed2.size else 0.0
        return True

    def _zero_velocities(self) -> None:
        self.backend.sync(self.state)
        self.state.velocities_m_s[...] = 0.0
        self.kinetic_energy = self.peak_speed_m_s = self.rms_speed_m_s = 0.0
        if isinstance(self.backend, DeviceBackend):
            self.backend.load(self.state)

    def run(self, frames: int, frame_dt_s: float) -> int:
        """Step ``frames`` frames; returns how many were actually simulated (not asleep)."""
        return sum(1 for _ in range(frames) if self.step(frame_dt_s))

    def _monitor(self) -> None:
        self.backend.sync(self.state)
        x, v = self.state.positions_m, self.state.velocities_m_s
        finite = bool(np.isfinite(x).all() and np.isfinite(v).all())
        self.state.finite = self.state.finite and finite
        if not finite:
            self.max_stretch = math.inf
            self.kinetic_energy = math.inf
            return
        self.max_stretch = max_spring_strain(x, self.params)
        self.state.max_stretch_seen = max(self.state.max_stretch_seen, self.max_stretch)
        p = self.params
        self._measure_motion()
        elapsed, self._unchecked_s = self._unchecked_s, 0.0
        # the GPU keeps the rings in float32: "arrived" within a micrometre
        rings_done = np.allclose(self.state.ring_positions_m, self.state.ring_targets_m,
                                 rtol=0.0, atol=1e-6)
        still = p.wind_speed_m_s == 0.0 and rings_done
        self.state.calm_s = calm_spell_s(self.state.calm_s, self.peak_speed_m_s,
                                         self.rms_speed_m_s, still, elapsed, p)
        if self.state.calm_s >= p.sleep_hold_s:
            self.sleeping = True

    # ---- reading -----------------------------------------------------------------
    def positions(self) -> np.ndarray:
        """(H, W, 3) float64 positions (downloads from the GPU backend)."""
        self.backend.sync(self.state)
        return self.state.positions_m

    def velocities(self) -> np.ndarray:
        self.backend.sync(self.state)
        return self.state.velocities_m_s

    @property
    def finite(self) -> bool:
        return self.state.finite

    def mesh(self):
        """The current curtain as a CurtainMesh (positions, normals, uv, tangents, indices)."""
        from catalog.cloth.mesh import CurtainMesh
        return CurtainMesh.from_grid(self.positions(), self.params)


def warm_up_numba() -> float:
    """Compile (first run on a machine) or load from numba's cache (later runs) the cpu
    backend's kernels, on a 4x4 curtain; returns the seconds it took. A viewer can call this
    in a background thread at start so the first frame does not wait for it."""
    import time

    start = time.perf_counter()
    ClothSimulation(ClothParams(grid_w=4, grid_h=4, wind_speed_m_s=1.0), "cpu").step(FRAME_DT_S)
    return time.perf_counter() - start
