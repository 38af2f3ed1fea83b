"""The settled drape on disk: computed once per cloth parameters, grid and solver.

Settling a curtain (catalog.cloth.drape, SETTLE_FRAMES frames of the numpy cloth) costs
seconds; every ``catalog snapshot`` process used to pay it again. The result is a pure
function of the parameters, the frame count and step, and the solver's code, so it is kept
in the user's cache folder (platformdirs' user cache dir, ``fabric-catalog/drape``) under
the SHA-256 of all of these:

- every field of :class:`~catalog.cloth.params.ClothParams` (the grid included) but the
  wind's (WIND_FIELDS: the settle hangs the cloth in still air, so a curtain at wind 0 and
  at wind 2 m/s share one settled rest: :func:`windless`), the frames and the frame step;
- the source text of the modules the numpy settle runs (a changed solver is a new key:
  old entries are never read again);
- numpy's version (its reductions may round differently).

Writes are atomic (a temporary beside the target, fsync, rename: catalog.core.atomic), so
two processes settling the same key at once both publish a whole file and a reader sees one
or the other, never a torn one. A file that cannot be read back as the key's state (torn by
a crash of the file system, edited, another key's) is ignored and written again. The cache
never fails a command: a folder that cannot be written only costs the settle next time.

``$CATALOG_CACHE_DIR`` names another folder; ``off`` (or empty) turns the cache off.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path

import numpy as np

from catalog.core.keyed_npz import UNREADABLE, read_keyed, write_keyed
from catalog.core.resources import CACHE_ENV, cache_folder  # noqa: F401 (CACHE_ENV: the tests')

#: Bumped when the file's layout changes.
FORMAT = 1
#: The modules whose code decides the settled state: the numpy backend's whole path and
#: the numba one's (drape.settled_rest settles with numba when it is installed).
SOLVER_MODULES = ("params", "state", "topology", "wind", "backend", "backend_numpy",
                  "backend_numba", "numba_kernels", "simulation", "drape")


#: The fields that shape only the wind (catalog.cloth.wind): without wind (speed 0) the air
#: is still whatever the gusts or the direction, so they change no settled drape.
WIND_FIELDS = ("wind_speed_m_s", "wind_direction", "gust_strength", "gust_length_m",
               "gust_period_s")


def windless(params):
    """``params`` in still air: the wind's fields (WIND_FIELDS) at their defaults, speed 0 (the
    parameters the settle runs with, and so the ones its key and cache hold)."""
    defaults = {f.name: f.default for f in dataclasses.fields(params) if f.name in WIND_FIELDS}
    return params.with_changes(**{**defaults, "wind_speed_m_s": 0.0})


def cache_dir() -> Path | None:
    """The drape cache folder, or None when the cache is off."""
    return cache_folder("drape")


_SOLVER_HASH: str | None = None


def solver_hash() -> str:
    """SHA-256 of the source of the modules that settle the cloth."""
    global _SOLVER_HASH
    if _SOLVER_HASH is None:
        digest = hashlib.sha256()
        here = Path(__file__).resolve().parent
        for name in SOLVER_MODULES:
            digest.update(name.encode())
            digest.update((here / f"{name}.py").read_bytes())
        _SOLVER_HASH = digest.hexdigest()
    return _SOLVER_HASH


def drape_key(params, frames: int, frame_dt_s: float) -> str:
    """The content key of a settled drape (hex SHA-256): of :func:`windless` ``params``."""
    still = windless(params)
    fields = {f.name: getattr(still, f.name) for f in dataclasses.fields(still)
              if f.compare}
    text = json.dumps({"format": FORMAT, "params": fields, "frames": int(frames),
                       "frame_dt_s": float(frame_dt_s), "solver": solver_hash(),
                       "numpy": ".".join(np.__version__.split(".")[:2])},
                      sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()


def _path(key: str) -> Path | None:
    folder = cache_dir()
    return None if folder is None else folder / f"{key}.npz"


def load(key: str, params):
    """The cached :class:`~catalog.cloth.state.ClothState` of ``key``, or None."""
    from catalog.cloth.state import ClothState  # noqa: PLC0415

    data = read_keyed(_path(key), key)
    if data is None:
        return None
    try:
        shape = (params.grid_h, params.grid_w, 3)
        positions = np.array(data["positions_m"], dtype=np.float64)
        velocities = np.array(data["velocities_m_s"], dtype=np.float64)
        if positions.shape != shape or velocities.shape != shape \
                or not np.isfinite(positions).all():
            return None
        scalars = json.loads(str(data["scalars"]))
        return ClothState(positions_m=positions, velocities_m_s=velocities,
                          ring_positions_m=np.array(data["ring_positions_m"], np.float64),
                          ring_targets_m=np.array(data["ring_targets_m"], np.float64),
                          time_s=float(scalars["time_s"]), frames=int(scalars["frames"]),
                          finite=bool(scalars["finite"]),
                          max_stretch_seen=float(scalars["max_stretch_seen"]),
                          calm_s=float(scalars["calm_s"]))
    except UNREADABLE:  # torn, edited, foreign
        return None


def store(key: str, state) -> Path | None:
    """Publish ``state`` under ``key`` atomically; None (and nothing left) when it cannot (a
    read-only or full cache folder costs the settle next time, no more)."""
    scalars = {"time_s": state.time_s, "frames": state.frames, "finite": state.finite,
               "max_stretch_seen": state.max_stretch_seen, "calm_s": state.calm_s}
    return write_keyed(_path(key), key, {
        "scalars": np.array(json.dumps(scalars)), "positions_m": state.positions_m,
        "velocities_m_s": state.velocities_m_s, "ring_positions_m": state.ring_positions_m,
        "ring_targets_m": state.ring_targets_m})
