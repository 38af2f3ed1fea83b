"""The benchmark problem: plain explicit mass-spring cloth, 12 springs per particle.

The same problem runs through every backend of this project and through the peers
(Taichi, NVIDIA Warp) in benchmarks/cloth_frameworks.py: an n x n grid lying flat in the
x-z plane, row 0 pinned, the rest falling and swinging under gravity; Provot's springs
as neighbour offsets (topology.GATHER_OFFSETS); each step, per particle,

    f = m g + sum_springs dir (k_e (l - l0) + k_d (dv . dir)),   dir = (x_j - x_i) / l   (Hooke + dashpot)
    v' = v + dt f / m,  x' = x + dt v'                            (semi-implicit Euler)

in float32, one substep per step, positions and velocities double-buffered (a step
reads only the old buffers, so every particle can be computed independently: the
"gather" form, each spring evaluated from both ends).

This module holds the problem, a float64 numpy reference, and the numba kernels of the
``cpu`` backend (serial and threaded), and the GLSL version on the GPU (:class:`Springs12Gpu`,
benchmarks/shaders/cloth_springs12.comp).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catalog.cloth.backend_gpu import _groups, _vec4
from catalog.cloth.params import GRAVITY_M_S2
from catalog.cloth.topology import GATHER_OFFSETS


@dataclass(frozen=True)
class Springs12Problem:
    n: int = 64
    spacing_m: float = 0.01
    mass_kg: float = 1.0e-3
    k_structural_n_m: float = 50.0
    k_shear_n_m: float = 20.0
    k_bend_n_m: float = 10.0
    k_damping_n_s_m: float = 5.0e-3
    dt_s: float = 1.0e-3  # explicit limit here: about 2 / sqrt(4 sum k / m) = 1.8 ms
    gravity_m_s2: float = GRAVITY_M_S2

    def springs(self) -> list[tuple[int, int, float, float]]:
        """(dr, dc, rest length m, stiffness N/m) of the 12 springs, GATHER_OFFSETS order."""
        out = []
        for dr, dc in GATHER_OFFSETS:
            rest = self.spacing_m * float(np.hypot(dr, dc))
            if abs(dr) + abs(dc) == 1:
                k = self.k_structural_n_m
            elif abs(dr) == 1 and abs(dc) == 1:
                k = self.k_shear_n_m
            else:
                k = self.k_bend_n_m
            out.append((dr, dc, rest, k))
        return out

    def initial_positions(self) -> np.ndarray:
        """(n, n, 3) float64: flat in the x-z plane at y = 0, row r at z = r * spacing."""
        r, c = np.meshgrid(np.arange(self.n), np.arange(self.n), indexing="ij")
        x = np.zeros((self.n, self.n, 3))
        x[..., 0] = c * self.spacing_m
        x[..., 2] = r * self.spacing_m
        return x


def reference_steps(problem: Springs12Problem, steps: int,
                    dtype: type = np.float64) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised numpy steps (the reference); returns positions and velocities (n, n, 3)."""
    x = problem.initial_positions().astype(dtype)
    v = np.zeros_like(x)
    n = problem.n
    dt = dtype(problem.dt_s)
    inv_m = dtype(1.0 / problem.mass_kg)
    kd = dtype(problem.k_damping_n_s_m)
    gravity = np.array([0.0, -problem.gravity_m_s2, 0.0], dtype=dtype)
    springs = problem.springs()
    for _ in range(steps):
        f = np.zeros_like(x)
        for dr, dc, rest, ke in springs:
            # particle (r, c) and its neighbour (r + dr, c + dc), where both exist
            rs = slice(max(0, -dr), n - max(0, dr))
            cs = slice(max(0, -dc), n - max(0, dc))
            rn = slice(max(0, dr), n + min(0, dr))
            cn = slice(max(0, dc), n + min(0, dc))
            d = x[rn, cn] - x[rs, cs]
            length = np.sqrt(np.sum(d * d, axis=-1, keepdims=True))
            dv = v[rn, cn] - v[rs, cs]
            along = np.sum(dv * d, axis=-1, keepdims=True) / length
            f[rs, cs] += d / length * (dtype(ke) * (length - dtype(rest)) + kd * along)
        v_new = v + dt * (f * inv_m + gravity)
        v_new[0] = 0.0  # row 0 pinned
        x = x + dt * v_new
        v = v_new
    return x, v


# ---- numba kernels (float32, structure of arrays) --------------------------------------
#
# Each spring is evaluated once (the 6 "forward" offsets, di >= 0) and its force added to
# both ends; rows are streamed top to bottom and a row is integrated as soon as no later
# spring can touch it (two rows later), so the forces live in a 3-row ring buffer that
# stays in L1 cache. Threads take bands of rows; the two rows above a band are evaluated
# by both bands (each keeps only the forces on its own rows), so no two threads ever
# write the same memory. The result is the gather form's, up to float32 rounding.

#: the 6 forward offsets and the index of each in GATHER_OFFSETS (for rest, k)
FORWARD_SPRINGS = ((0, 1, 0), (1, 0, 2), (1, 1, 4), (1, -1, 6), (0, 2, 8), (2, 0, 10))


def _make_kernels():
    from numba import njit, prange

    @njit(inline="always", fastmath=True)
    def _spring(px, py, pz, vx, vy, vz, fa, fb, i, di, dj, rest, ke, kd):
        """Spring (i, j) -> (i + di, j + dj) for all j: +F into fa (row i), -F into fb."""
        height, width = px.shape
        i2 = i + di
        if i2 >= height:
            return
        j0 = max(0, -dj)
        j1 = min(width, width - dj)
        for j in range(j0, j1):
            dx = px[i2, j + dj] - px[i, j]
            dy = py[i2, j + dj] - py[i, j]
            dz = pz[i2, j + dj] - pz[i, j]
            d2 = dx * dx + dy * dy + dz * dz
            inv = np.float32(1.0) / np.sqrt(d2)
            length = d2 * inv
            along = ((vx[i2, j + dj] - vx[i, j]) * dx + (vy[i2, j + dj] - vy[i, j]) * dy
                     + (vz[i2, j + dj] - vz[i, j]) * dz) * inv
            s = (ke * (length - rest) + kd * along) * inv
            fa[0, j] += s * dx
            fa[1, j] += s * dy
            fa[2, j] += s * dz
            fb[0, j + dj] -= s * dx
            fb[1, j + dj] -= s * dy
            fb[2, j + dj] -= s * dz

    @njit(inline="always", fastmath=True)
    def _slot(f, row, r0, r1):
        """The ring-buffer row of grid row ``row`` for band [r0, r1); slot 3 is a sink."""
        if row < r0 or row >= r1:
            return f[3]
        return f[(row - r0) % 3]

    @njit(fastmath=True)
    def _band(src, dst, f, r0, r1, rest, ke, kd, c, dt, gdt):
        px, py, pz, vx, vy, vz = src[0], src[1], src[2], src[3], src[4], src[5]
        width = px.shape[1]
        f[:] = np.float32(0.0)
        for i in range(max(0, r0 - 2), r1):
            if i >= r0 + 1 and i + 2 < r1:
                f[(i + 2 - r0) % 3] = np.float32(0.0)
            here = _slot(f, i, r0, r1)
            _spring(px, py, pz, vx, vy, vz, here, here, i, 0, 1, rest[0], ke[0], kd)
            _spring(px, py, pz, vx, vy, vz, here, _slot(f, i + 1, r0, r1), i, 1, 0,
                    rest[2], ke[2], kd)
            _spring(px, py, pz, vx, vy, vz, here, _slot(f, i + 1, r0, r1), i, 1, 1,
                    rest[4], ke[4], kd)
            _spring(px, py, pz, vx, vy, vz, here, _slot(f, i + 1, r0, r1), i, 1, -1,
                    rest[6], ke[6], kd)
            _spring(px, py, pz, vx, vy, vz, here, here, i, 0, 2, rest[8], ke[8], kd)
            _spring(px, py, pz, vx, vy, vz, here, _slot(f, i + 2, r0, r1), i, 2, 0,
                    rest[10], ke[10], kd)
            if i < r0:
                continue
            if i == 0:  # pinned row
                for j in range(width):
                    dst[0, i, j] = px[i, j]
                    dst[1, i, j] = py[i, j]
                    dst[2, i, j] = pz[i, j]
                    dst[3, i, j] = np.float32(0.0)
                    dst[4, i, j] = np.float32(0.0)
                    dst[5, i, j] = np.float32(0.0)
                continue
            for j in range(width):  # semi-implicit Euler: v' = v + dt f/m, x' = x + dt v'
                nvx = vx[i, j] + c * here[0, j]
                nvy = vy[i, j] + c * here[1, j] - gdt
                nvz = vz[i, j] + c * here[2, j]
                dst[3, i, j] = nvx
                dst[4, i, j] = nvy
                dst[5, i, j] = nvz
                dst[0, i, j] = px[i, j] + dt * nvx
                dst[1, i, j] = py[i, j] + dt * nvy
                dst[2, i, j] = pz[i, j] + dt * nvz

    def _steps(a, b, f, steps, rest, ke, kd, c, dt, gdt):
        """``steps`` steps ping-ponging between buffer sets a and b (each (6, n, n):
        x, y, z, vx, vy, vz); f: (bands, 4, 3, n) scratch. Returns 1 if the result is in
        b, 0 if in a."""
        n = a.shape[1]
        bands = f.shape[0]
        for s in range(steps):
            src = a if s % 2 == 0 else b
            dst = b if s % 2 == 0 else a
            for k in prange(bands):
                _band(src, dst, f[k], n * k // bands, n * (k + 1) // bands, rest, ke, kd, c,
                      dt, gdt)
        return steps % 2

    serial = njit(cache=True, fastmath=True)(_steps)
    threaded = njit(cache=True, fastmath=True, parallel=True)(_renamed(_steps, "_steps_threaded"))
    return serial, threaded


def _renamed(func, name: str):
    """A copy of ``func`` under another name: numba caches by name, and the serial and
    the threaded builds of the same source must not share a cache entry."""
    import types

    copy = types.FunctionType(func.__code__.replace(co_name=name, co_qualname=name),
                              func.__globals__, name, func.__defaults__, func.__closure__)
    copy.__qualname__ = name
    return copy


_KERNELS = None


def numba_kernels():
    """(serial, threaded) compiled step loops; built (or loaded from cache) on first use."""
    global _KERNELS
    if _KERNELS is None:
        _KERNELS = _make_kernels()
    return _KERNELS


class Springs12Numba:
    """The benchmark problem on the cpu backend: float32 SoA, gather kernel, numba."""

    def __init__(self, problem: Springs12Problem, threads: int = 1):
        self.problem = problem
        self.threads = max(1, int(threads))
        springs = problem.springs()
        self.rest = np.array([s[2] for s in springs], dtype=np.float32)
        self.ke = np.array([s[3] for s in springs], dtype=np.float32)
        self.reset()

    def reset(self) -> None:
        n = self.problem.n
        self.a = np.zeros((6, n, n), dtype=np.float32)
        self.b = np.zeros_like(self.a)
        self.scratch = np.zeros((self.threads, 4, 3, n), dtype=np.float32)
        x = self.problem.initial_positions()
        self.a[0], self.a[1], self.a[2] = x[..., 0], x[..., 1], x[..., 2]
        self.current = 0

    def run(self, steps: int) -> None:
        serial, threaded = numba_kernels()
        p = self.problem
        src, dst = (self.a, self.b) if self.current == 0 else (self.b, self.a)
        if self.threads == 1:
            # one band: in place. Row i is integrated right after its own (forward) springs,
            # and no later row's springs read it, so the old row is dead by then: one set of
            # arrays streamed through the cache instead of two
            dst = src
        kernel = threaded if self.threads > 1 else serial
        which = kernel(src, dst, self.scratch, steps, self.rest, self.ke, np.float32(p.k_damping_n_s_m),
                       np.float32(p.dt_s / p.mass_kg), np.float32(p.dt_s),
                       np.float32(p.gravity_m_s2 * p.dt_s))
        if which == 1 and dst is not src:
            self.current = 1 - self.current

    def positions(self) -> np.ndarray:
        buf = self.a if self.current == 0 else self.b
        return np.stack([buf[0], buf[1], buf[2]], axis=-1).astype(np.float64)


class Springs12Gpu:
    """The benchmark problem in benchmarks/shaders/cloth_springs12.comp (a compute shader)."""

    def __init__(self, problem, ctx=None):
        from catalog.gl.shaderlib import create_compute

        if ctx is None:
            from catalog.gl.context import create_headless_context
            ctx = create_headless_context()
        self.ctx = ctx
        self.problem = problem
        self.program = create_compute(ctx, "cloth_springs12.comp")
        springs = problem.springs()
        prog = self.program
        prog["u_n"].value = problem.n
        prog["u_offset"].write(np.array(GATHER_OFFSETS, dtype=np.int32).tobytes())
        prog["u_rest"].write(np.array([s[2] for s in springs], dtype=np.float32).tobytes())
        prog["u_ke"].write(np.array([s[3] for s in springs], dtype=np.float32).tobytes())
        prog["u_kd"].value = problem.k_damping_n_s_m
        prog["u_dt"].value = problem.dt_s
        prog["u_inv_mass"].value = 1.0 / problem.mass_kg
        prog["u_gravity"].value = problem.gravity_m_s2
        n = problem.n * problem.n
        self.bufs = [[ctx.buffer(reserve=n * 16), ctx.buffer(reserve=n * 16)] for _ in range(2)]
        self.reset()

    def reset(self) -> None:
        x = _vec4(self.problem.initial_positions())
        self.bufs[0][0].write(x.tobytes())
        self.bufs[0][1].write(np.zeros_like(x).tobytes())
        self.current = 0

    def run(self, steps: int) -> None:
        groups = _groups(self.problem.n ** 2)
        for _ in range(steps):
            src, dst = self.bufs[self.current], self.bufs[1 - self.current]
            src[0].bind_to_storage_buffer(0)
            src[1].bind_to_storage_buffer(1)
            dst[0].bind_to_storage_buffer(2)
            dst[1].bind_to_storage_buffer(3)
            self.program.run(groups)
            self.ctx.memory_barrier()
            self.current = 1 - self.current

    def positions(self) -> np.ndarray:
        """(n, n, 3) float64 (waits for the GPU)."""
        data = np.frombuffer(self.bufs[self.current][0].read(), dtype=np.float32)
        n = self.problem.n
        return data.reshape(n, n, 4)[..., :3].astype(np.float64)
