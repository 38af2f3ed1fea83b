"""The GPU backend: the substep of backend_numpy as GLSL compute passes (moderngl).

The state stays on the GPU in std430 buffers (positions as vec4); each frame ends with a
pass that writes positions, normals and tangents straight into :attr:`vertex_buffer`, the
buffer the renderer draws (no copy through the CPU). :meth:`bind_to_vertex_array` makes
the renderer's vertex array from it. Reading the state back (:meth:`sync`) is only for
checks and exports.

Float32 throughout, so it follows the float64 reference to about 1e-4 m after a second
(tests/test_cloth_gpu.py). The last substep's strain sweeps run a fixed number of times
(``gpu_final_passes``) instead of the CPU backends' adaptive count, as a convergence
test would need a read-back.

Shaders: shaders/cloth_step.comp (one program per pass, by #define).
"""

from __future__ import annotations

import numpy as np

from catalog.cloth.params import ClothParams
from catalog.cloth.state import ClothState, SolverConstants
from catalog.cloth.topology import SELECTORS
from catalog.cloth.wind import gust_table

LOCAL_SIZE = 64
PASSES = ("WIND", "NORMALS", "PREDICT", "RINGS", "SPRINGS", "ATTACH", "UPDATE", "VERTICES")
#: Strain sweeps in a frame's last substep on the GPU (fixed: no read-back to test).
GPU_FINAL_PASSES = 4


def _groups(count: int) -> int:
    return max(1, (count + LOCAL_SIZE - 1) // LOCAL_SIZE)


def _vec4(array: np.ndarray) -> np.ndarray:
    """(..., 3) -> (N, 4) float32 with w = 0."""
    flat = np.asarray(array, dtype=np.float64).reshape(-1, 3)
    out = np.zeros((flat.shape[0], 4), dtype=np.float32)
    out[:, :3] = flat
    return out


class GpuBackend:
    name = "gpu"

    def __init__(self, params: ClothParams, ctx=None):
        from catalog.gl.shaderlib import create_compute

        if ctx is None:
            from catalog.gl.context import create_headless_context
            ctx = create_headless_context()
        self.ctx = ctx
        self.programs = {name: create_compute(ctx, "cloth_step.comp", {f"PASS_{name}": True})
                         for name in PASSES}
        w, h = params.grid_w, params.grid_h
        self.count = w * h
        n = self.count
        self.buffers = {name: ctx.buffer(reserve=n * 16)
                        for name in ("x", "v", "x_prev", "normal", "wind")}
        self.vertex_buffer = ctx.buffer(reserve=n * 48)
        self.static_buffer = None
        self.index_buffer = None
        self._members: dict = {}
        self._stale = False
        self.set_params(params)

    # ---- set-up ------------------------------------------------------------------
    def set_params(self, params: ClothParams) -> None:
        self.params = params
        c = self.constants = SolverConstants.from_params(params)
        particle = np.zeros((self.count, 4), dtype=np.float32)
        particle[:, 0] = c.inv_mass_per_kg.ravel()
        particle[:, 1] = c.lra_limit_m.ravel()
        particle[:, 2] = c.lra_ring.ravel()
        for name in ("_static", "_ring_cols", "_selector_buffer", "_spring_rest"):  # a change of parameters
            old = getattr(self, name, None)
            if old is not None:
                old.release()
        self._static = self.ctx.buffer(particle.tobytes())
        self._spring_rest = self.ctx.buffer(np.ascontiguousarray(c.spring_rest_m, dtype=np.float32).tobytes())
        self._ring_cols = self.ctx.buffer(c.ring_cols.astype(np.int32).tobytes())
        self.ring_count = int(c.ring_cols.size)
        if not hasattr(self, "_rings"):
            self._rings = self.ctx.buffer(reserve=self.ring_count * 16)
            self._targets = self.ctx.buffer(reserve=self.ring_count * 16)
        self._set_uniforms()

    def _uniform(self, program: str, name: str, value) -> None:
        key = (program, name)
        member = self._members.get(key, False)
        if member is False:  # the compiler drops uniforms a pass does not use
            prog = self.programs[program]
            member = self._members[key] = prog[name] if name in prog else None
        if member is not None:
            member.value = value

    def _set_uniforms(self) -> None:
        p, c = self.params, self.constants
        for name in PASSES:
            self._uniform(name, "u_grid", (p.grid_w, p.grid_h))
        gust = gust_table()
        self._uniform("WIND", "u_wind_speed", p.wind_speed_m_s)
        self._uniform("WIND", "u_wind_dir", tuple(p.wind_direction))
        self._uniform("WIND", "u_gust", p.gust_strength)
        self._uniform("WIND", "u_gust_length", p.gust_length_m)
        self._uniform("WIND", "u_gust_period", p.gust_period_s)
        prog = self.programs["WIND"]
        if "u_gust_k" in prog:
            prog["u_gust_k"].write(np.ascontiguousarray(gust[:, :4], dtype=np.float32).tobytes())
            prog["u_gust_phase"].write(np.ascontiguousarray(gust[:, 4], dtype=np.float32)
                                       .tobytes())
        self._uniform("PREDICT", "u_damping", p.damping_per_s)
        self._uniform("PREDICT", "u_gravity", p.gravity_m_s2)
        self._uniform("PREDICT", "u_aero", c.aero_per_m)
        self._uniform("RINGS", "u_ring_count", self.ring_count)
        self._uniform("RINGS", "u_ring_speed", p.ring_speed_m_s)
        for name in ("ATTACH", "UPDATE"):
            self._uniform(name, "u_floor", p.thickness_m)
            self._uniform(name, "u_wall", -p.wall_gap_m + p.thickness_m)
        self._uniform("UPDATE", "u_contact_damping", p.contact_damping_per_s)
        w, h = p.grid_w, p.grid_h
        table = np.zeros(len(SELECTORS), dtype=[("offset_first", "i4", 4),
                                                ("step_count", "i4", 4),
                                                ("rest_k_limit", "f4", 4),
                                                ("family", "i4", 4)])
        self._selectors = []  # (index, selector, groups x, groups y)
        for index, sel in enumerate(SELECTORS):
            rows, cols = sel.ranges(w, h)
            rest = float(c.rest_m[sel.family])
            table[index] = ((sel.di, sel.dj, rows.start, cols.start),
                            (rows.step, cols.step, len(rows), len(cols)),
                            (rest, float(c.stiffness_n_m[sel.family]),
                             (1.0 + p.max_stretch) * rest, float(c.strain_limited[sel.family])),
                            (sel.family, 0, 0, 0))
            if len(rows) and len(cols):
                self._selectors.append((index, sel, _groups(len(cols)), len(rows)))
        self._selector_buffer = self.ctx.buffer(table.tobytes())

    def load(self, state: ClothState) -> None:
        """Upload a state (positions, velocities, rings)."""
        self.buffers["x"].write(_vec4(state.positions_m).tobytes())
        self.buffers["x_prev"].write(_vec4(state.positions_m).tobytes())
        self.buffers["v"].write(_vec4(state.velocities_m_s).tobytes())
        self._rings.write(_vec4(state.ring_positions_m).tobytes())
        self.set_ring_targets(state.ring_targets_m)
        self._time = float(state.time_s)
        self._write_vertices()
        self._stale = False

    def set_ring_targets(self, targets: np.ndarray) -> None:
        self._targets.write(_vec4(targets).tobytes())

    def _bind(self) -> None:
        b = self.buffers
        b["x"].bind_to_storage_buffer(0)
        b["v"].bind_to_storage_buffer(1)
        b["x_prev"].bind_to_storage_buffer(2)
        b["normal"].bind_to_storage_buffer(3)
        b["wind"].bind_to_storage_buffer(4)
        self._static.bind_to_storage_buffer(5)
        self._spring_rest.bind_to_storage_buffer(11)
        self._rings.bind_to_storage_buffer(6)
        self._targets.bind_to_storage_buffer(7)
        self._ring_cols.bind_to_storage_buffer(8)
        self.vertex_buffer.bind_to_storage_buffer(9)
        self._selector_buffer.bind_to_storage_buffer(10)

    def _run(self, name: str, groups_x: int, groups_y: int = 1) -> None:
        self.programs[name].run(groups_x, groups_y)
        self.ctx.memory_barrier()

    # ---- stepping ----------------------------------------------------------------
    def advance(self, state: ClothState, substeps: int, h: float) -> None:
        p = self.params
        self._bind()
        groups = _groups(self.count)
        self._uniform("WIND", "u_time", self._time)
        self._run("WIND", groups)
        for name in ("PREDICT", "RINGS", "SPRINGS", "UPDATE"):
            self._uniform(name, "u_h", h)
        for step in range(substeps):
            self._run("NORMALS", groups)
            self._run("PREDICT", groups)
            self._run("RINGS", _groups(self.ring_count))
            self._uniform("SPRINGS", "u_limit_only", False)
            for index, sel, gx, gy in self._selectors:
                self._uniform("SPRINGS", "u_selector", index)
                self._run("SPRINGS", gx, gy)
            self._run("ATTACH", groups)
            passes = p.strain_passes
            if step == substeps - 1:
                passes = max(passes, min(p.final_strain_passes, GPU_FINAL_PASSES))
            self._uniform("SPRINGS", "u_limit_only", True)
            for k in range(passes):
                order = self._selectors[::-1] if k % 2 == 1 else self._selectors
                for index, sel, gx, gy in order:
                    if self.constants.strain_limited[sel.family]:
                        self._uniform("SPRINGS", "u_selector", index)
                        self._run("SPRINGS", gx, gy)
            self._run("UPDATE", groups)
            self._time += h
        self._run("VERTICES", groups)
        state.time_s = self._time
        self._stale = True

    def _write_vertices(self) -> None:
        self._bind()
        self._run("VERTICES", _groups(self.count))

    # ---- reading -----------------------------------------------------------------
    def sync(self, state: ClothState) -> None:
        """Download positions, velocities and rings into ``state`` (checks, exports)."""
        if not self._stale:
            return
        shape = state.positions_m.shape
        read = lambda buf, n: np.frombuffer(buf.read(), dtype=np.float32).reshape(n, 4)[:, :3]
        state.positions_m = read(self.buffers["x"], self.count).astype(np.float64).reshape(shape)
        state.velocities_m_s = read(self.buffers["v"], self.count).astype(np.float64) \
            .reshape(shape)
        state.ring_positions_m = read(self._rings, self.ring_count).astype(np.float64)
        self._stale = False

    def vertex_data(self) -> np.ndarray:
        """(N, 12) float32: the vertex buffer as the renderer sees it (for tests)."""
        return np.frombuffer(self.vertex_buffer.read(), dtype=np.float32).reshape(-1, 12)

    # ---- drawing -----------------------------------------------------------------
    def bind_to_vertex_array(self, program, position: str = "in_position",
                             normal: str = "in_normal", tangent: str = "in_tangent",
                             uv: str = "in_uv"):
        """A moderngl VertexArray drawing this curtain with ``program``.

        Dynamic buffer (written by the simulation): vec4 position, vec4 normal, vec4
        tangent per vertex; static buffer: vec2 uv, vec2 uv_m; indices: two triangles per
        cell. Attributes the program does not use are skipped.
        """
        from catalog.cloth.mesh import CurtainMesh
        from catalog.cloth.state import rest_pose

        if self.static_buffer is None:
            mesh = CurtainMesh.from_grid(rest_pose(self.params), self.params)
            self.static_buffer = self.ctx.buffer(mesh.static_data().tobytes())
            self.index_buffer = self.ctx.buffer(mesh.indices.tobytes())
        names = [(position, "4f"), (normal, "4f"), (tangent, "4f")]
        fmt, attrs = [], []
        for name, f in names:
            if name and name in program:
                fmt.append(f)
                attrs.append(name)
            else:
                fmt.append("16x")
        content = [(self.vertex_buffer, " ".join(fmt), *attrs)]
        if uv and uv in program:
            content.append((self.static_buffer, "2f 8x", uv))
        return self.ctx.vertex_array(program, content, self.index_buffer,
                                     index_element_size=4)

