"""The animated curtain behind the viewer: one cloth simulation feeding the renderer(s).

CPU backends (numpy, cpu) upload positions and normals when the cloth moved; the gpu
backend's compute shader writes the vertex buffer the renderer draws (no copy).

The simulation takes the physical parameters of the fabric on the left (areal density,
stiffness from its preset's ``[cloth]`` table); in split screen the right half shows the
same drape in another fabric, so the two differ by their optics alone.
"""

from __future__ import annotations

import numpy as np

from catalog.presets import Preset

#: Rings' span when the curtain is open (fraction of the rod span they cover when closed).
OPEN_FRACTION = 0.35


class CurtainScene:
    """Steps the cloth and hands its mesh to every renderer that draws it.

    The simulation starts with the first fabric (its ``[cloth]`` table sets the physics);
    its coordinates (rod at ``rod_y_m``, curtain plane z = 0) are moved onto the renderer's
    rod as ``catalog snapshot --frame N`` does, so both show the same curtain.
    """

    def __init__(self, grid: tuple[int, int], backend: str = "cpu", wind_m_s: float = 0.0,
                 ctx=None, placement=None):
        self.grid = grid
        #: the room's rod (catalog.render.placement; None: the box's)
        self.placement = placement
        self.backend = backend
        self.ctx = ctx  # the window's context: the gpu backend computes in it
        self.wind_m_s = float(wind_m_s)
        self.opening = 1.0
        self.simulation = None
        self.preset_name: str | None = None
        self.mesh_version = 0  # bumped whenever the positions change
        self._uploaded: dict[int, int] = {}  # id(renderer) -> mesh_version it has
        self._offset = None

    # -- controls ------------------------------------------------------------------
    def set_fabric(self, preset: Preset) -> None:
        """Take the fabric's cloth parameters (a running cloth keeps its motion)."""
        from catalog.cloth.params import ClothParams  # noqa: PLC0415

        if preset.name == self.preset_name:
            return
        from catalog.cloth.drape import fullness_of  # noqa: PLC0415
        from catalog.render.placement import BOX, placed_drape_params  # noqa: PLC0415

        self.closed_opening = 1.0 / fullness_of(preset)
        fabric = placed_drape_params(preset, self.placement, grid=self.grid, wind_speed_m_s=self.wind_m_s,
                                     opening=self.closed_opening * self.opening)
        if self.simulation is None:
            from catalog.cloth.drape import settled_simulation  # noqa: PLC0415

            # the settled drape that catalog snapshot shows at frame 0
            options = {"ctx": self.ctx} if self.backend == "gpu" else {}
            self.simulation = settled_simulation(fabric, backend=self.backend, **options)
            closed = fabric.with_changes(opening=self.closed_opening)
            self._offset = (self.placement or BOX).curtain_offset(closed)
            self.mesh_version += 1
        else:
            self.simulation.set_params(areal_density_kg_m2=fabric.areal_density_kg_m2,
                                       stretch_stiffness_n_m=fabric.stretch_stiffness_n_m,
                                       bend_stiffness_n_m=fabric.bend_stiffness_n_m)
        self.preset_name = preset.name

    def set_wind(self, speed_m_s: float) -> None:
        self.wind_m_s = float(speed_m_s)
        if self.simulation is not None and speed_m_s != self.simulation.params.wind_speed_m_s:
            self.simulation.set_wind(speed_m_s)

    def set_open(self, is_open: bool) -> None:
        self.opening = OPEN_FRACTION if is_open else 1.0
        target = self.opening * getattr(self, "closed_opening", 1.0)
        if self.simulation is not None and target != self.simulation.params.opening:
            self.simulation.set_opening(target)

    # -- per frame -----------------------------------------------------------------
    def step(self, frame_dt_s: float) -> bool:
        """Advance one frame; True when the cloth moved (False while it sleeps)."""
        if self.simulation is None:
            return False
        moved = self.simulation.step(frame_dt_s)
        if moved:
            self.mesh_version += 1
        return moved

    def feed(self, renderer) -> None:
        """Give ``renderer`` the current mesh if it has not got this version yet."""
        if self.simulation is None:
            return
        have = self._uploaded.get(id(renderer))
        if have == self.mesh_version:
            return  # up to date (a sleeping cloth stays so: the frame is static)
        if have is not None and self.backend == "gpu":
            # the compute shader rewrote the buffer the renderer draws: no copy, only a note
            renderer.cloth_moved()
            self._uploaded[id(renderer)] = self.mesh_version
            return
        from catalog.cloth.mesh import CurtainMesh  # noqa: PLC0415

        mesh = CurtainMesh.from_grid(self.simulation.positions(), self.simulation.params)
        if self.backend == "gpu":
            # the mesh once (triangles, uvs), then the cloth's interleaved vertex buffer
            # drawn in place, moved onto the scene's rod in the vertex shader
            renderer.set_mesh(mesh.positions, mesh.normals, mesh.uv, mesh.tangents[:, :3],
                              mesh.indices, fabric_size_m=self._fabric_size())
            renderer.bind_cloth_vertex_buffer(self.simulation.backend.vertex_buffer,
                                              offset_m=tuple(float(v) for v in self._offset))
            self._uploaded[id(renderer)] = self.mesh_version
            return
        positions = mesh.positions + self._offset
        if have is None:
            renderer.set_mesh(positions, mesh.normals, mesh.uv, mesh.tangents[:, :3],
                              mesh.indices, fabric_size_m=self._fabric_size())
        else:
            renderer.update_positions(positions, mesh.normals)
        self._uploaded[id(renderer)] = self.mesh_version

    def _fabric_size(self) -> tuple[float, float]:
        params = self.simulation.params
        return params.width_m, params.height_m

    def forget(self, renderer) -> None:
        """``renderer`` is gone (resized, closed): the next one gets a full mesh."""
        self._uploaded.pop(id(renderer), None)
