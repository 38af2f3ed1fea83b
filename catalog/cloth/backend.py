"""What :class:`catalog.cloth.simulation.ClothSimulation` asks of a backend.

Three backends implement it: ``numpy`` (:mod:`.backend_numpy`, the float64 reference),
``cpu`` (:mod:`.backend_numba`) and ``gpu`` (:mod:`.backend_gpu`, GLSL compute). The state
(:class:`~catalog.cloth.state.ClothState`) belongs to the simulation; a backend advances it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from catalog.cloth.params import ClothParams
    from catalog.cloth.state import ClothState


@runtime_checkable
class ClothBackend(Protocol):
    """Every backend: a name of ``simulation.BACKENDS`` and three calls."""

    name: str

    def set_params(self, params: ClothParams) -> None:
        """Take new parameters that keep the grid (wind, stiffness, opening, ...)."""

    def advance(self, state: ClothState, substeps: int, h: float) -> None:
        """One frame of ``substeps`` steps of ``h`` seconds; the state may stay on a device."""

    def sync(self, state: ClothState) -> None:
        """Bring the state's arrays up to date (a download for a device backend)."""


@runtime_checkable
class DeviceBackend(ClothBackend, Protocol):
    """A backend that keeps the state on a device (the GPU): loaded once, ring targets
    uploaded on change, and a vertex buffer the renderer can draw without a copy."""

    def load(self, state: ClothState) -> None:
        """Upload the whole state (at start)."""

    def set_ring_targets(self, targets: np.ndarray) -> None:
        """Upload new ring targets (the curtain opens or closes)."""

    def bind_to_vertex_array(self, program, position: str = "in_position",
                             normal: str = "in_normal", tangent: str = "in_tangent",
                             uv: str = "in_uv"):
        """A vertex array of ``program`` that reads the device's vertex buffer."""
