"""The animated curtain behind the viewer: one cloth simulation feeding the renderer(s).

The simulation takes the physical parameters of the fabric on the left (areal density,
stiffness from its preset's ``[cloth]`` table); in split screen the right half shows the
same drape in another fabric, so the two differ by their optics alone.
"""

from __future__ import annotations

from catalog.presets import Preset

#: Rings' span when the curtain is open (fraction of the rest width; 1 = closed).
OPEN_FRACTION = 0.35


class CurtainScene:
    """Steps the cloth and hands its mesh to every renderer that draws it."""

    def __init__(self, grid: tuple[int, int], backend: str = "cpu", wind_m_s: float = 0.0):
        from catalog.cloth.params import ClothParams  # noqa: PLC0415
        from catalog.cloth.simulation import ClothSimulation  # noqa: PLC0415

        self._params_type = ClothParams
        self.grid = grid
        params = ClothParams(grid_w=grid[0], grid_h=grid[1], wind_speed_m_s=wind_m_s)
        self.simulation = ClothSimulation(params, backend=backend)
        self.preset_name: str | None = None
        self.mesh_version = 0  # bumped whenever the positions change
        self._uploaded: dict[int, int] = {}  # id(renderer) -> mesh_version it has

    # -- controls ------------------------------------------------------------------
    def set_fabric(self, preset: Preset) -> None:
        """Take the fabric's cloth parameters (keeps the motion: same grid, same state)."""
        if preset.name == self.preset_name:
            return
        fabric = self._params_type.from_preset(preset)
        self.simulation.set_params(areal_density_kg_m2=fabric.areal_density_kg_m2,
                                   stretch_stiffness_n_m=fabric.stretch_stiffness_n_m,
                                   bend_stiffness_n_m=fabric.bend_stiffness_n_m)
        self.preset_name = preset.name

    def set_wind(self, speed_m_s: float) -> None:
        if speed_m_s != self.simulation.params.wind_speed_m_s:
            self.simulation.set_wind(speed_m_s)

    def set_open(self, is_open: bool) -> None:
        fraction = OPEN_FRACTION if is_open else 1.0
        if fraction != self.simulation.params.opening:
            self.simulation.set_opening(fraction)

    # -- per frame -----------------------------------------------------------------
    def step(self, frame_dt_s: float) -> bool:
        """Advance one frame; True when the cloth moved (False while it sleeps)."""
        moved = self.simulation.step(frame_dt_s)
        if moved:
            self.mesh_version += 1
        return moved

    def feed(self, renderer) -> None:
        """Give ``renderer`` the current mesh if it has not got this version yet."""
        have = self._uploaded.get(id(renderer))
        if have == self.mesh_version:
            return
        mesh = self.simulation.mesh()
        if have is None:
            renderer.set_mesh(mesh.positions, mesh.normals, mesh.uv, mesh.tangents,
                              mesh.indices)
        else:
            renderer.update_positions(mesh.positions, mesh.normals)
        self._uploaded[id(renderer)] = self.mesh_version

    def forget(self, renderer) -> None:
        """``renderer`` is gone (resized, closed): the next one gets a full mesh."""
        self._uploaded.pop(id(renderer), None)
