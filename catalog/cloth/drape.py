"""The curtain as it hangs in the scene: fullness, pleats at rest, the settled drape.

A curtain is wider than its rod: its *fullness* f is the fabric's width over the rod's span
(1.5-2.5 for curtains; light sheers are hung fuller than heavy drapery). Closed, the rings
span the rod (the fabric's width / f), and the fabric between two rings folds into a pleat,
alternately towards the room and the window (catalog.cloth.state's rest pose). Left to hang
without wind, the pleats round off under gravity until the cloth is at rest
(:meth:`ClothSimulation.settle <catalog.cloth.simulation.ClothSimulation.settle>`: the
simulation's own integrator, relaxed by kinetic damping, at most SETTLE_FRAMES frames): that
*settled drape* is the one picture ``catalog snapshot`` shows at frame 0, and the state every
simulation (``--frame N``, the viewer) starts from, so the two agree, and a windless viewer
starts at rest and falls asleep at once.

The preset's ``[cloth]`` table may set ``fullness``; the weave's default otherwise
(:data:`FULLNESS_DEFAULTS`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from catalog.cloth.params import DEFAULT_WEAVE, ClothParams
from catalog.core.constants import FRAME_DT_S
from catalog.core.errors import InputError

#: Fabric width / rod span by weave: sheers are hung full, a heavy damask flatter.
FULLNESS_DEFAULTS = {"lace": 2.0, "voile": 2.5, "plain": 2.0, "twill": 1.8, "satin": 1.6}
FULLNESS_RANGE = (1.0, 3.0)
#: The rod span of the scene's window (m) and the fabric's length below the rings (m).
ROD_SPAN_M = 1.7
LENGTH_M = 2.2
#: Rest fabric between two rings (m): with fullness 2 a ring every 12 cm on the rod.
RING_SPACING_M = 0.24
#: The drape's grid: columns across the (full) fabric, rows down it.
GRID = (96, 56)
#: At most this many frames (FRAME_DT_S each) to settle (it stops once at rest: 4-6 s).
SETTLE_FRAMES = 900


def fullness_of(preset) -> float:
    """The preset's ``[cloth] fullness``, or its weave's default; refused outside 1-3."""
    table = preset.table("cloth") if hasattr(preset, "table") else dict(preset)
    weave = table.get("weave", DEFAULT_WEAVE)
    value = table.get("fullness", FULLNESS_DEFAULTS.get(weave, 2.0))
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or not FULLNESS_RANGE[0] <= value <= FULLNESS_RANGE[1]:
        raise InputError(f"must be a number in {FULLNESS_RANGE[0]:g}..{FULLNESS_RANGE[1]:g} "
                         f"(fabric width / rod span), found {value!r}",
                         path=getattr(preset, "path", None), field="cloth.fullness")
    return float(value)


def drape_params(preset, grid: tuple[int, int] | None = None, *, span_m: float = ROD_SPAN_M,
                 length_m: float = LENGTH_M, **overrides) -> ClothParams:
    """The cloth parameters of a preset hung on a rod, closed: the fabric ``span_m`` (the
    rod's flat span, the room's window's: catalog.render.placement) x fullness wide and
    ``length_m`` long, rings every RING_SPACING_M of fabric, spanning the rod."""
    fullness = fullness_of(preset)
    grid_w, grid_h = grid or GRID
    values = {"grid_w": grid_w, "grid_h": grid_h, "width_m": span_m * fullness,
              "height_m": length_m, "opening": 1.0 / fullness, "ring_spacing_m": RING_SPACING_M}
    values.update(overrides)
    table = preset.table("cloth") if hasattr(preset, "table") else dict(preset)
    table = {k: v for k, v in table.items() if k != "fullness"}
    return ClothParams.from_preset(table, **values)


def rod_centre_x_m(params: ClothParams) -> float:
    """x of the middle of the rings' span in the cloth's frame (the rings start at
    -width/2 and span width x opening): subtract it to centre the curtain on the window."""
    return -0.5 * params.width_m + 0.5 * params.width_m * params.opening


def settle(params: ClothParams, frames: int):
    """Hang ``params`` without wind from the rest pose until the simulation itself is at rest
    (ClothSimulation.settle, at most ``frames`` frames; numba, else the numpy cloth;
    velocities zeroed): the computation the caches keep."""
    from catalog.cloth.simulation import ClothSimulation  # noqa: PLC0415

    still = params.with_changes(wind_speed_m_s=0.0)
    # numba: float64 like the reference (the same to 1e-8 m a second), ~10x its speed;
    # the reference itself where numba is not installed
    import importlib.util  # noqa: PLC0415

    backend = "cpu" if importlib.util.find_spec("numba") is not None else "numpy"
    simulation = ClothSimulation(still, backend=backend)
    simulation.settle(max_s=frames * FRAME_DT_S)
    state = simulation.state.copy()
    state.velocities_m_s[...] = 0.0
    return state


@functools.lru_cache(maxsize=16)
def _settled(params: ClothParams, frames: int):
    from catalog.cloth import drape_cache  # noqa: PLC0415

    key = drape_cache.drape_key(params, frames, FRAME_DT_S)
    state = drape_cache.load(key, params)
    if state is None:
        state = settle(params, frames)
        drape_cache.store(key, state)
    return state


def settled_state(params: ClothParams, frames: int = SETTLE_FRAMES):
    """The cloth at rest without wind, settled from the rest pose in at most ``frames``
    frames (a copy; computed once per parameter set and solver, then read from the user's
    cache folder: catalog.cloth.drape_cache; one for every wind)."""
    from catalog.cloth import drape_cache  # noqa: PLC0415

    return _settled(drape_cache.windless(params), int(frames)).copy()


def settled_simulation(params: ClothParams, backend: str = "numpy", **options):
    """A simulation of ``params`` (wind and all) that starts from the settled drape."""
    from catalog.cloth.simulation import ClothSimulation  # noqa: PLC0415

    simulation = ClothSimulation(params, backend=backend, **options)
    state = settled_state(params)
    state.ring_targets_m = simulation.state.ring_targets_m.copy()
    simulation.state = state
    if hasattr(simulation.backend, "load"):
        simulation.backend.load(state)
    return simulation


def hem_displacement_m(positions_before: np.ndarray, positions_after: np.ndarray) -> dict:
    """How far the hem (last row) moved: mean and largest horizontal distance, and the
    largest rise (m)."""
    a = positions_before[-1]
    b = positions_after[-1]
    horizontal = np.hypot(b[:, 0] - a[:, 0], b[:, 2] - a[:, 2])
    return {"mean_m": float(horizontal.mean()), "max_m": float(horizontal.max()),
            "rise_m": float(np.max(b[:, 1] - a[:, 1]))}
