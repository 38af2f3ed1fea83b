"""Cloth benchmark: this project's backends against Taichi and NVIDIA Warp, one run.

    .venv/bin/python -m benchmarks.cloth_frameworks [--quick] [--out benchmarks/bench_cloth.json]

1. The same problem everywhere (benchmarks/springs12.py): n x n explicit mass-spring
   cloth, the same 12 springs per particle (Provot's structural, shear, bend), Hooke plus
   dashpot, semi-implicit Euler, float32, one substep per step, row 0 pinned; 64x64 and
   128x128 on this 2-core CPU. Implementations:
   - ``numpy-f32``: the vectorised numpy reference in float32;
   - ``cpu``, ``cpu-2t``: the numba kernel of the cpu backend (each spring once, rows
     streamed through a 3-row force buffer), one thread and two threads (bands of rows);
   - ``gpu``: benchmarks/shaders/cloth_springs12.comp (Mesa llvmpipe here: a CPU rasteriser);
   - ``taichi``: Taichi 1.7 CPU backend (``cpu_max_num_threads=2``), one thread per
     particle gathering its 12 springs (ti.kernel over the grid);
   - ``warp``: NVIDIA Warp (warp-lang) CPU device, the same gather kernel written with
     ``@wp.kernel`` (warp.sim is gone from warp-lang 1.19).
   All must agree with the float64 numpy reference after 200 steps (max |dx| < 1e-4 m).
   Speed: steps per second, the median of interleaved repeats (the machine is shared, so
   every implementation sees the same noise); ratio to the fastest peer (Taichi, Warp).
2. Stiffness cost of the real simulation (XPBD + strain limiting + LRA, cpu backend,
   64x64, 1/30 s frames): milliseconds per frame at 1e3 and 1e6 N/m, and the ratio.
3. The GPU backend's frame on llvmpipe at 128x128, and how much of it is issue cost
   (the same frame at 4x4), for the 60 fps estimate on a real GPU (see docs/cloth.md).

Numba compiles before timing (and caches); Taichi and Warp compile in their warm-up.
"""


import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from catalog.core.constants import FRAME_DT_S  # noqa: E402
from catalog.core.resources import PROJECT_ROOT as ROOT  # noqa: E402
# numba's OpenMP threads spin while waiting by default; on a 2-core machine shared with
# other work that spinning starves the other thread (measured: 2 threads at 1/5 the speed
# of 1). Passive waiting, before numba loads OpenMP:
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from benchmarks.results import source_commit  # noqa: E402
from benchmarks.springs12 import Springs12Numba, Springs12Problem, reference_steps  # noqa: E402
from catalog.cloth.topology import GATHER_OFFSETS  # noqa: E402

RESULT_JSON = "benchmarks/bench_cloth.json"
AGREE_STEPS = 200
AGREE_TOLERANCE_M = 1e-4
#: The fair race: the peers evaluating each spring once, as ours does: a scatter with atomic
#: adds (``taichi``, ``warp``) and the springs in 12 colours without atomics (``-colours``).
PEERS = ("taichi", "warp", "taichi-colours", "warp-colours")
#: The second row: the peers' natural gather (each particle sums its 12 springs: twice the work).
GATHER_PEERS = ("taichi-gather", "warp-gather")


# ---- the docs' tables (tools/docs_figures.py) --------------------------------------------

#: The issue's goal: our cpu backend against the fastest peer (Taichi, Warp), steps per second.
GOAL_RATIO = 1.5
_COLUMNS = (("numpy-f32", "numpy f32"), ("cpu", "**cpu (numba, 1 thread)**"),
            ("cpu-2t", "cpu, 2 threads"), ("gpu", "gpu (compute, llvmpipe)"))
_PEER_LABELS = {"taichi": "Taichi", "warp": "Warp"}


def _versions(result: dict) -> dict:
    return result.get("versions") or {"taichi": "1.7.4", "warp": "1.19"}


def markdown_tables(result: dict) -> dict[str, str]:
    """``cloth_frameworks``: steps per second by n and implementation; the peers in two rows
    per n: the fair one (each spring once, atomic scatter, as ours) and their gather (each
    spring twice); ours' ratio to the fastest peer of each; ``cloth_stiffness``: the cost of a
    1/30 s frame at 1e3 and 1e6 N/m; ``cloth_frameworks_goal``, ``cloth_gpu_frame`` and
    ``cloth_frameworks_agreement``: the sentences docs/cloth.md's prose rests on."""
    rows = result["springs12"]
    commit = result.get("machine", {}).get("commit")
    versions = _versions(result)
    peer_heads = [f"{_PEER_LABELS[p]} {versions.get(p) or ''}".strip() for p in _PEER_LABELS]
    lines = ["| n | peers' algorithm | " + " | ".join(label for _, label in _COLUMNS) + " | "
             + " | ".join(peer_heads) + " |",
             "|---|---|" + "---|" * (len(_COLUMNS) + len(_PEER_LABELS))]

    def find(n, impl):
        return next((r for r in rows if r["n"] == n and r["impl"] == impl), None)

    for n in sorted({r["n"] for r in rows}):
        for peers, name, key in ((PEERS[:2], "each spring once, atomic scatter (fair)",
                                  "ratio_to_fastest_peer"),
                                 (PEERS[2:], "each spring once, 12 colours (fair)",
                                  "ratio_to_fastest_peer"),
                                 (GATHER_PEERS, "gather, each spring twice",
                                  "ratio_to_fastest_gather_peer")):
            cells = []
            for impl, _ in _COLUMNS:
                r = find(n, impl)
                if r is None or "steps_per_second" not in r:
                    cells.append("unavailable")
                    continue
                cell = f"{r['steps_per_second']:.0f}"
                if impl in ("cpu", "cpu-2t") and key in r:
                    cell += f" ({r[key]:.2f}x)"
                cells.append(f"**{cell}**" if impl == "cpu" else cell)
            for impl in peers:
                r = find(n, impl)
                cells.append("unavailable" if r is None or "steps_per_second" not in r
                             else f"{r['steps_per_second']:.0f} ({r[key]:.2f}x)")
            lines.append(f"| {n} | {name} | " + " | ".join(cells) + " |")
    stiff = result["stiffness_cost"]
    slines = ["| stiffness | no wind ms/frame | wind 1 m/s ms/frame | max stretch |",
              "|---|---|---|---|"]
    for k in sorted({r["stiffness_n_m"] for r in stiff["rows"]}):
        calm, windy = (next(r for r in stiff["rows"]
                            if r["stiffness_n_m"] == k and r["wind_m_s"] == w) for w in (0.0, 1.0))
        slines.append(f"| {k:.0e}".replace("e+0", "e") + f" N/m | {calm['ms_per_frame']:.1f} | "
                      f"{windy['ms_per_frame']:.1f} | {calm['max_stretch']:.3f} / "
                      f"{windy['max_stretch']:.3f} |")
    ratio = stiff["ratio_1e6_to_1e3"]
    slines.append(f"| cost(1e6) / cost(1e3) | **{ratio['0.0']:.2f}** | **{ratio['1.0']:.2f}** | |")
    ours = [r for r in rows if r["impl"] == "cpu" and "ratio_to_fastest_peer" in r]
    worst = min(r["ratio_to_fastest_peer"] for r in ours)
    goal = (f"The goal, the cpu backend at least {GOAL_RATIO:g}x the fastest peer on the fair "
            f"row (each spring once) at every size: "
            f"{'holds' if worst >= GOAL_RATIO else 'NOT met'} ("
            + ", ".join(f"{r['ratio_to_fastest_peer']:.2f}x at n = {r['n']}" for r in ours) + ").")
    if all("cpu_ratio_to_fastest_peer" in r for r in ours):
        goal += (" Per CPU second (the work, whatever share of the shared cores each got): "
                 + ", ".join(f"{r['cpu_ratio_to_fastest_peer']:.2f}x at n = {r['n']}"
                             for r in ours) + ".")
    gpu = result.get("gpu_frame_llvmpipe") or []
    gpu_text = ("A frame of the production GPU solver on llvmpipe (the compute passes on the same "
                "2 CPU cores, one run): " + ", ".join(
                    f"{r['ms_per_frame_llvmpipe']:.0f} ms at {r['n']}x{r['n']}" for r in gpu)
                + f" ({gpu[0]['substeps']} substeps)." if gpu else "The GPU frame was not measured.")
    checked = [r["max_error_m"] for r in rows if "max_error_m" in r]
    agreement = (f"Every implementation within {max(checked):.1g} m of the float64 numpy reference "
                 f"(tolerance {AGREE_TOLERANCE_M:g} m)." if checked
                 else "No implementation was checked against the reference.")
    load = result.get("machine", {}).get("load_average")
    note = ("\n\nSteps per second, medians of interleaved repeats in one run; ratios to the "
            "fastest peer of the fair rows (any of the four) or of the gather row"
            + (f"; load average {load[0]:.1f} on 2 shared cores"
                                         if load else "")
            + (f"; measured on commit {commit}" if commit else "") + ".")
    return {"cloth_frameworks": "\n".join(lines) + note, "cloth_stiffness": "\n".join(slines),
            "cloth_frameworks_goal": goal, "cloth_gpu_frame": gpu_text,
            "cloth_frameworks_agreement": agreement}


# ---- peers ------------------------------------------------------------------------------

def _taichi():
    import taichi as ti

    if not _taichi.initialised:
        ti.init(arch=ti.cpu, cpu_max_num_threads=2, default_fp=ti.f32, log_level=ti.WARN)
        _taichi.initialised = True
    return ti


_taichi.initialised = False
#: The 6 spring directions whose springs start at a particle (the other 6 of GATHER_OFFSETS
#: are the same springs seen from their other end): each spring once.
FORWARD_OFFSETS = tuple((dr, dc) for dr, dc in GATHER_OFFSETS if dr > 0 or (dr == 0 and dc > 0))


class TaichiScatter:
    """Each spring once in Taichi (CPU backend, 2 threads): a kernel over the particles
    evaluates the 6 springs that start there and adds the force to both ends (``+=`` on a
    field in a parallel loop is an atomic add in Taichi), then a kernel integrates and resets
    the forces to the weight: the same per-spring work as ours."""

    def __init__(self, problem: Springs12Problem):
        ti = self.ti = _taichi()
        self.problem = problem
        n = problem.n
        self.x = ti.Vector.field(3, ti.f32, shape=(n, n))
        self.v = ti.Vector.field(3, ti.f32, shape=(n, n))
        self.f = ti.Vector.field(3, ti.f32, shape=(n, n))
        springs = {(dr, dc): (r, k) for dr, dc, r, k in problem.springs()}
        offsets = list(FORWARD_OFFSETS)
        rests = [float(springs[o][0]) for o in offsets]
        kes = [float(springs[o][1]) for o in offsets]
        kd, dt = problem.k_damping_n_s_m, problem.dt_s
        inv_m, g = 1.0 / problem.mass_kg, problem.gravity_m_s2
        weight = -g / inv_m

        @ti.kernel
        def springs_kernel(sx: ti.template(), sv: ti.template(), f: ti.template()):
            for i, j in sx:
                for k in ti.static(range(6)):
                    i2 = i + offsets[k][0]
                    j2 = j + offsets[k][1]
                    if 0 <= i2 < n and 0 <= j2 < n:
                        d = sx[i2, j2] - sx[i, j]
                        length = d.norm()
                        direction = d / length
                        along = (sv[i2, j2] - sv[i, j]).dot(direction)
                        force = direction * (kes[k] * (length - rests[k]) + kd * along)
                        f[i, j] += force
                        f[i2, j2] -= force

        @ti.kernel
        def integrate(sx: ti.template(), sv: ti.template(), f: ti.template()):
            for i, j in sx:
                if i > 0:
                    vel = sv[i, j] + dt * f[i, j] * inv_m
                    sv[i, j] = vel
                    sx[i, j] = sx[i, j] + dt * vel
                f[i, j] = ti.Vector([0.0, weight, 0.0])

        self._springs, self._integrate = springs_kernel, integrate
        self.reset()

    def reset(self) -> None:
        x = self.problem.initial_positions().astype(np.float32)
        self.x.from_numpy(x)
        self.v.from_numpy(np.zeros_like(x))
        force = np.zeros_like(x)
        force[..., 1] = -self.problem.gravity_m_s2 * self.problem.mass_kg
        self.f.from_numpy(force)

    def run(self, steps: int) -> None:
        for _ in range(steps):
            self._springs(self.x, self.v, self.f)
            self._integrate(self.x, self.v, self.f)
        self.ti.sync()

    def positions(self) -> np.ndarray:
        return self.x.to_numpy().astype(np.float64)


def _colours():
    """(offset index into FORWARD_OFFSETS, axis, parity) of the 12 colours: the springs of one
    direction whose start (i, j) has (index // span) % 2 == parity along the axis they run
    (span 1 for neighbours, 2 for bend springs); no two springs of a colour share a particle,
    so a colour needs no atomics (topology.py colours the XPBD solver the same way)."""
    out = []
    for k, (dr, dc) in enumerate(FORWARD_OFFSETS):
        axis = 1 if dr == 0 else 0
        for parity in (0, 1):
            out.append((k, axis, parity))
    return tuple(out)


COLOURS = _colours()


class TaichiColoured(TaichiScatter):
    """Each spring once in Taichi without atomics: the springs in 12 colours (no two sharing a
    particle), a kernel launch per colour writing both ends with plain stores."""

    def __init__(self, problem: Springs12Problem):
        super().__init__(problem)
        ti = self.ti
        n = problem.n
        springs = {(dr, dc): (r, k) for dr, dc, r, k in problem.springs()}
        kd = problem.k_damping_n_s_m
        kernels = []
        for k, axis, parity in COLOURS:
            offset = FORWARD_OFFSETS[k]
            rest, ke = (float(v) for v in springs[offset])
            kernels.append(self._colour_kernel(n, *offset, rest, ke, kd, axis, parity))
        self._colour_kernels = kernels

    def _colour_kernel(self, n, di, dj, rest, ke, kd, axis, parity):
        """One colour's kernel (its constants bound here: Taichi reads a kernel's Python
        values when it compiles, at the first call)."""
        ti = self.ti
        span = max(abs(di), abs(dj))

        @ti.kernel
        def colour(sx: ti.template(), sv: ti.template(), f: ti.template()):
            for i, j in ti.ndrange((0, n - di), (max(0, -dj), n - max(dj, 0))):
                along_index = j if ti.static(axis == 1) else i
                if (along_index // span) % 2 == parity:
                    i2 = i + di
                    j2 = j + dj
                    d = sx[i2, j2] - sx[i, j]
                    length = d.norm()
                    direction = d / length
                    along = (sv[i2, j2] - sv[i, j]).dot(direction)
                    force = direction * (ke * (length - rest) + kd * along)
                    f[i, j] = f[i, j] + force  # plain stores: the colour owns both ends
                    f[i2, j2] = f[i2, j2] - force

        return colour

    def run(self, steps: int) -> None:
        for _ in range(steps):
            for colour in self._colour_kernels:
                colour(self.x, self.v, self.f)
            self._integrate(self.x, self.v, self.f)
        self.ti.sync()


class WarpScatter:
    """Each spring once in NVIDIA Warp (CPU device): the 6 springs starting at a particle,
    ``wp.atomic_add`` / ``wp.atomic_sub`` of the force into both ends, then an integration
    kernel that resets the forces to the weight."""

    _kernels = None

    def __init__(self, problem: Springs12Problem):
        import warp as wp

        wp.config.quiet = True
        wp.init()
        self.wp = wp
        self.problem = problem
        if WarpScatter._kernels is None:
            WarpScatter._kernels = _make_warp_scatter_kernels(wp)
        n = problem.n
        springs = {(dr, dc): (r, k) for dr, dc, r, k in problem.springs()}
        self.offsets = wp.array(np.array(FORWARD_OFFSETS, dtype=np.int32), dtype=wp.vec2i,
                                device="cpu")
        self.rest = wp.array(np.array([springs[o][0] for o in FORWARD_OFFSETS],
                                      dtype=np.float32), device="cpu")
        self.ke = wp.array(np.array([springs[o][1] for o in FORWARD_OFFSETS],
                                    dtype=np.float32), device="cpu")
        self.x, self.v, self.f = (wp.zeros((n, n), dtype=wp.vec3, device="cpu")
                                  for _ in range(3))
        self.reset()

    def reset(self) -> None:
        wp, p = self.wp, self.problem
        x = p.initial_positions().astype(np.float32)
        self.x.assign(wp.array(x, dtype=wp.vec3, device="cpu"))
        self.v.zero_()
        force = np.zeros_like(x)
        force[..., 1] = -p.gravity_m_s2 * p.mass_kg
        self.f.assign(wp.array(force, dtype=wp.vec3, device="cpu"))

    def run(self, steps: int) -> None:
        wp, p = self.wp, self.problem
        springs, integrate = WarpScatter._kernels
        for _ in range(steps):
            wp.launch(springs, dim=(p.n, p.n), inputs=[self.x, self.v, self.f, self.offsets,
                                                       self.rest, self.ke, p.k_damping_n_s_m,
                                                       p.n], device="cpu")
            wp.launch(integrate, dim=(p.n, p.n), inputs=[self.x, self.v, self.f, p.dt_s,
                                                         1.0 / p.mass_kg, p.gravity_m_s2],
                      device="cpu")
        wp.synchronize()

    def positions(self) -> np.ndarray:
        return self.x.numpy().astype(np.float64)


class WarpColoured(WarpScatter):
    """Each spring once in Warp without atomics: 12 colours, a launch per colour."""

    _colour_kernel = None

    def __init__(self, problem: Springs12Problem):
        super().__init__(problem)
        if WarpColoured._colour_kernel is None:
            WarpColoured._colour_kernel = _make_warp_colour_kernel(self.wp)

    def run(self, steps: int) -> None:
        wp, p = self.wp, self.problem
        _, integrate = WarpScatter._kernels
        n = p.n
        for _ in range(steps):
            for k, axis, parity in COLOURS:
                di, dj = FORWARD_OFFSETS[k]
                wp.launch(WarpColoured._colour_kernel, dim=(n - di, n - abs(dj)),
                          inputs=[self.x, self.v, self.f, self.rest, self.ke,
                                  p.k_damping_n_s_m, k, di, dj, max(0, -dj), axis,
                                  max(abs(di), abs(dj)), parity], device="cpu")
            wp.launch(integrate, dim=(n, n), inputs=[self.x, self.v, self.f, p.dt_s,
                                                     1.0 / p.mass_kg, p.gravity_m_s2],
                      device="cpu")
        wp.synchronize()


def _make_warp_colour_kernel(wp):
    @wp.kernel
    def colour(sx: wp.array2d(dtype=wp.vec3), sv: wp.array2d(dtype=wp.vec3),
               f: wp.array2d(dtype=wp.vec3), rest: wp.array(dtype=float),
               ke: wp.array(dtype=float), kd: float, k: int, di: int, dj: int, j0: int,
               axis: int, span: int, parity: int):
        i, jj = wp.tid()
        j = jj + j0
        along_index = i
        if axis == 1:
            along_index = j
        if (along_index // span) % 2 != parity:
            return
        i2 = i + di
        j2 = j + dj
        d = sx[i2, j2] - sx[i, j]
        length = wp.length(d)
        direction = d / length
        along = wp.dot(sv[i2, j2] - sv[i, j], direction)
        force = direction * (ke[k] * (length - rest[k]) + kd * along)
        f[i, j] = f[i, j] + force  # plain stores: the colour owns both ends
        f[i2, j2] = f[i2, j2] - force

    return colour


def _make_warp_scatter_kernels(wp):
    @wp.kernel
    def springs(sx: wp.array2d(dtype=wp.vec3), sv: wp.array2d(dtype=wp.vec3),
                f: wp.array2d(dtype=wp.vec3), offsets: wp.array(dtype=wp.vec2i),
                rest: wp.array(dtype=float), ke: wp.array(dtype=float), kd: float, n: int):
        i, j = wp.tid()
        p = sx[i, j]
        vel = sv[i, j]
        for k in range(6):
            o = offsets[k]
            i2 = i + o[0]
            j2 = j + o[1]
            if i2 >= 0 and i2 < n and j2 >= 0 and j2 < n:
                d = sx[i2, j2] - p
                length = wp.length(d)
                direction = d / length
                along = wp.dot(sv[i2, j2] - vel, direction)
                force = direction * (ke[k] * (length - rest[k]) + kd * along)
                wp.atomic_add(f, i, j, force)
                wp.atomic_sub(f, i2, j2, force)

    @wp.kernel
    def integrate(sx: wp.array2d(dtype=wp.vec3), sv: wp.array2d(dtype=wp.vec3),
                  f: wp.array2d(dtype=wp.vec3), dt: float, inv_m: float, gravity: float):
        i, j = wp.tid()
        if i > 0:
            vel = sv[i, j] + dt * f[i, j] * inv_m
            sv[i, j] = vel
            sx[i, j] = sx[i, j] + dt * vel
        f[i, j] = wp.vec3(0.0, -gravity / inv_m, 0.0)

    return springs, integrate


class TaichiCloth:
    """The gather kernel in Taichi (CPU backend, 2 threads): every spring twice."""

    def __init__(self, problem: Springs12Problem):
        ti = self.ti = _taichi()
        self.problem = problem
        n = problem.n
        self.fields = [(ti.Vector.field(3, ti.f32, shape=(n, n)),
                        ti.Vector.field(3, ti.f32, shape=(n, n))) for _ in range(2)]
        springs = problem.springs()
        offsets = [(dr, dc) for dr, dc, _, _ in springs]
        rests = [float(r) for _, _, r, _ in springs]
        kes = [float(k) for _, _, _, k in springs]
        kd, dt = problem.k_damping_n_s_m, problem.dt_s
        inv_m, g = 1.0 / problem.mass_kg, problem.gravity_m_s2

        @ti.kernel
        def step(sx: ti.template(), sv: ti.template(), dx: ti.template(), dv: ti.template()):
            for i, j in sx:
                p = sx[i, j]
                vel = sv[i, j]
                if i == 0:
                    dx[i, j] = p
                    dv[i, j] = ti.Vector([0.0, 0.0, 0.0])
                else:
                    f = ti.Vector([0.0, -g / inv_m, 0.0])
                    for k in ti.static(range(12)):
                        i2 = i + offsets[k][0]
                        j2 = j + offsets[k][1]
                        if 0 <= i2 < n and 0 <= j2 < n:
                            d = sx[i2, j2] - p
                            length = d.norm()
                            direction = d / length
                            along = (sv[i2, j2] - vel).dot(direction)
                            f += direction * (kes[k] * (length - rests[k]) + kd * along)
                    vel += dt * f * inv_m
                    dv[i, j] = vel
                    dx[i, j] = p + dt * vel

        self._step = step
        self.reset()

    def reset(self) -> None:
        x = self.problem.initial_positions().astype(np.float32)
        self.fields[0][0].from_numpy(x)
        self.fields[0][1].from_numpy(np.zeros_like(x))
        self.current = 0

    def run(self, steps: int) -> None:
        for _ in range(steps):
            src, dst = self.fields[self.current], self.fields[1 - self.current]
            self._step(src[0], src[1], dst[0], dst[1])
            self.current = 1 - self.current
        self.ti.sync()

    def positions(self) -> np.ndarray:
        return self.fields[self.current][0].to_numpy().astype(np.float64)


class WarpCloth:
    """The gather kernel in NVIDIA Warp on its CPU device: every spring twice."""

    _kernel = None

    def __init__(self, problem: Springs12Problem):
        import warp as wp

        wp.config.quiet = True
        wp.init()
        self.wp = wp
        self.problem = problem
        if WarpCloth._kernel is None:
            WarpCloth._kernel = _make_warp_kernel(wp)
        n = problem.n
        springs = problem.springs()
        self.offsets = wp.array(np.array(GATHER_OFFSETS, dtype=np.int32), dtype=wp.vec2i,
                                device="cpu")
        self.rest = wp.array(np.array([s[2] for s in springs], dtype=np.float32), device="cpu")
        self.ke = wp.array(np.array([s[3] for s in springs], dtype=np.float32), device="cpu")
        self.bufs = [(wp.zeros((n, n), dtype=wp.vec3, device="cpu"),
                      wp.zeros((n, n), dtype=wp.vec3, device="cpu")) for _ in range(2)]
        self.reset()

    def reset(self) -> None:
        wp = self.wp
        x = self.problem.initial_positions().astype(np.float32)
        self.bufs[0][0].assign(wp.array(x, dtype=wp.vec3, device="cpu"))
        self.bufs[0][1].zero_()
        self.current = 0

    def run(self, steps: int) -> None:
        wp, p = self.wp, self.problem
        for _ in range(steps):
            src, dst = self.bufs[self.current], self.bufs[1 - self.current]
            wp.launch(WarpCloth._kernel, dim=(p.n, p.n),
                      inputs=[src[0], src[1], dst[0], dst[1], self.offsets, self.rest,
                              self.ke, p.k_damping_n_s_m, p.dt_s, 1.0 / p.mass_kg,
                              p.gravity_m_s2, p.n], device="cpu")
            self.current = 1 - self.current
        wp.synchronize()

    def positions(self) -> np.ndarray:
        return self.bufs[self.current][0].numpy().astype(np.float64)


def _make_warp_kernel(wp):
    @wp.kernel
    def cloth_step(sx: wp.array2d(dtype=wp.vec3), sv: wp.array2d(dtype=wp.vec3),
                   dx: wp.array2d(dtype=wp.vec3), dv: wp.array2d(dtype=wp.vec3),
                   offsets: wp.array(dtype=wp.vec2i), rest: wp.array(dtype=float),
                   ke: wp.array(dtype=float), kd: float, dt: float, inv_m: float,
                   gravity: float, n: int):
        i, j = wp.tid()
        p = sx[i, j]
        vel = sv[i, j]
        if i == 0:
            dx[i, j] = p
            dv[i, j] = wp.vec3(0.0, 0.0, 0.0)
            return
        f = wp.vec3(0.0, -gravity / inv_m, 0.0)
        for k in range(12):
            o = offsets[k]
            i2 = i + o[0]
            j2 = j + o[1]
            if i2 >= 0 and i2 < n and j2 >= 0 and j2 < n:
                d = sx[i2, j2] - p
                length = wp.length(d)
                direction = d / length
                along = wp.dot(sv[i2, j2] - vel, direction)
                f = f + direction * (ke[k] * (length - rest[k]) + kd * along)
        vel = vel + dt * f * inv_m
        dv[i, j] = vel
        dx[i, j] = p + dt * vel

    return cloth_step


# ---- ours -------------------------------------------------------------------------------

class NumpyCloth:
    def __init__(self, problem):
        self.problem = problem
        self.x = None

    def reset(self):
        self.x = None

    def run(self, steps):
        self.x, _ = reference_steps(self.problem, steps, np.float32)

    def positions(self):
        return self.x.astype(np.float64)


def make(name: str, problem: Springs12Problem, ctx=None):
    if name == "numpy-f32":
        return NumpyCloth(problem)
    if name == "cpu":
        return Springs12Numba(problem, threads=1)
    if name == "cpu-2t":
        return Springs12Numba(problem, threads=2)
    if name == "gpu":
        from benchmarks.springs12 import Springs12Gpu
        return Springs12Gpu(problem, ctx=ctx)
    if name == "taichi":
        return TaichiScatter(problem)
    if name == "warp":
        return WarpScatter(problem)
    if name == "taichi-colours":
        return TaichiColoured(problem)
    if name == "warp-colours":
        return WarpColoured(problem)
    if name == "taichi-gather":
        return TaichiCloth(problem)
    if name == "warp-gather":
        return WarpCloth(problem)
    raise ValueError(name)


def bench_springs(sizes, repeats: int, seconds_per_repeat: float, ctx) -> list[dict]:
    rows = []
    names = ["numpy-f32", "cpu", "cpu-2t", "gpu", *PEERS, *GATHER_PEERS]
    for n in sizes:
        problem = Springs12Problem(n=n)
        reference, _ = reference_steps(problem, AGREE_STEPS)
        impls, info = {}, {}
        for name in names:
            try:
                impl = make(name, problem, ctx)
                impl.run(AGREE_STEPS)  # compiles, then the agreement check
                error = float(np.abs(impl.positions() - reference).max())
                impls[name] = impl
                info[name] = {"max_error_m": error, "agrees": error < AGREE_TOLERANCE_M}
            except Exception as exc:  # noqa: BLE001 - a missing peer is reported
                info[name] = {"unavailable": f"{type(exc).__name__}: {exc}"[:200]}
        # steps per repeat so that one repeat takes about seconds_per_repeat
        steps = {}
        for name, impl in impls.items():
            trial = 2 if name == "numpy-f32" else 20
            impl.reset()
            start = time.perf_counter()
            impl.run(trial)
            rate = trial / max(time.perf_counter() - start, 1e-6)
            steps[name] = max(trial, int(rate * seconds_per_repeat))
        samples = {name: [] for name in impls}
        cpu_samples = {name: [] for name in impls}
        for _ in range(repeats):  # interleaved: every implementation sees the same noise
            for name, impl in impls.items():
                if name == "numpy-f32" and len(samples[name]) >= 2:
                    continue  # the slow reference: two samples are enough
                impl.reset()
                start, cpu_start = time.perf_counter(), time.process_time()
                impl.run(steps[name])
                samples[name].append(steps[name] / (time.perf_counter() - start))
                # CPU seconds of all the process's threads: on a machine shared by more
                # runnable threads than cores, a 2-thread peer gets twice the wall-clock share
                # of a 1-thread one; per CPU second the work itself is compared
                cpu_samples[name].append(steps[name] / max(time.process_time() - cpu_start,
                                                           1e-9))
        peer_rates = [statistics.median(samples[p]) for p in PEERS if p in samples]
        fastest_peer = max(peer_rates) if peer_rates else float("nan")
        gather_rates = [statistics.median(samples[p]) for p in GATHER_PEERS if p in samples]
        fastest_gather = max(gather_rates) if gather_rates else float("nan")
        cpu_peer = max((statistics.median(cpu_samples[p]) for p in PEERS if p in cpu_samples),
                       default=float("nan"))
        for name in names:
            row = {"n": n, "impl": name, **info[name]}
            if name in samples:
                rate = statistics.median(samples[name])
                cpu_rate = statistics.median(cpu_samples[name])
                row.update(steps_per_second=rate, samples=samples[name],
                           ratio_to_fastest_peer=rate / fastest_peer,
                           ratio_to_fastest_gather_peer=rate / fastest_gather,
                           steps_per_cpu_second=cpu_rate,
                           cpu_ratio_to_fastest_peer=cpu_rate / cpu_peer)
            rows.append(row)
    return rows


# ---- stiffness cost and the GPU frame -------------------------------------------------

def _frame_ms(sim, frames: int, dt: float, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(frames):
            sim.step(dt)
        if sim.backend_name == "gpu":
            sim.backend.ctx.finish()
        times.append((time.perf_counter() - start) / frames * 1e3)
    return statistics.median(times)


def bench_stiffness(repeats: int) -> list[dict]:
    from catalog.cloth import ClothParams, ClothSimulation

    rows = []
    for wind in (0.0, 1.0):
        for k in (1e3, 1e6):
            p = ClothParams(grid_w=64, grid_h=64, opening=0.8, stretch_stiffness_n_m=k,
                            wind_speed_m_s=wind, sleep_speed_m_s=0.0)  # never sleeps
            sim = ClothSimulation(p, "cpu")
            sim.run(15, 1 / 30)  # past the first fall
            ms = _frame_ms(sim, 15, 1 / 30, repeats)
            rows.append({"stiffness_n_m": k, "wind_m_s": wind, "ms_per_frame": ms,
                         "substeps": sim.last_substeps, "max_stretch": sim.max_stretch})
    return rows


def bench_gpu_frame(ctx, repeats: int) -> list[dict]:
    from catalog.cloth import ClothParams, ClothSimulation

    rows = []
    for n in (4, 64, 128):
        p = ClothParams(grid_w=n, grid_h=n, opening=0.8, wind_speed_m_s=1.0)
        sim = ClothSimulation(p, "gpu", ctx=ctx, monitor_every=10 ** 9)
        sim.step(FRAME_DT_S)
        ms = _frame_ms(sim, 5, FRAME_DT_S, repeats)
        rows.append({"n": n, "ms_per_frame_llvmpipe": ms, "substeps": sim.last_substeps})
    return rows


def _peer_versions() -> dict:
    from importlib import metadata  # noqa: PLC0415

    out = {}
    for peer, dist in (("taichi", "taichi"), ("warp", "warp-lang")):
        try:
            out[peer] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[peer] = None
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "bench_cloth.json"))
    args = parser.parse_args()
    repeats = 3 if args.quick else 7
    ctx = None
    try:
        from catalog.gl.context import create_headless_context
        ctx = create_headless_context()
    except Exception as exc:  # noqa: BLE001
        print(f"no GL context: {exc}", file=sys.stderr)

    started = time.time()
    springs = bench_springs((64, 128), repeats, 0.25 if args.quick else 0.5, ctx)
    print("\n12-spring explicit cloth, float32, 1 substep per step (steps/s, median of "
          f"{repeats} interleaved repeats)")
    print(f"{'n':>4} {'impl':>10} {'steps/s':>10} {'vs fastest peer':>16} {'max |dx| m':>11}")
    for row in springs:
        if "steps_per_second" in row:
            print(f"{row['n']:>4} {row['impl']:>10} {row['steps_per_second']:>10.0f} "
                  f"{row['ratio_to_fastest_peer']:>15.2f}x {row['max_error_m']:>11.1e}"
                  + ("" if row["agrees"] else "  DISAGREES"))
        else:
            print(f"{row['n']:>4} {row['impl']:>10}  unavailable: {row['unavailable']}")

    stiffness = bench_stiffness(repeats)
    print("\nStiffness cost: cpu backend, 64x64, 1/30 s frames (XPBD, strain limit, LRA)")
    for row in stiffness:
        print(f"  k = {row['stiffness_n_m']:>9.0e} N/m, wind {row['wind_m_s']} m/s: "
              f"{row['ms_per_frame']:7.2f} ms/frame, {row['substeps']} substeps, "
              f"max stretch {row['max_stretch']:.3f}")
    ratios = {}
    for wind in (0.0, 1.0):
        by_k = {r["stiffness_n_m"]: r["ms_per_frame"] for r in stiffness if r["wind_m_s"] == wind}
        ratios[str(wind)] = by_k[1e6] / by_k[1e3]
        print(f"  cost(1e6) / cost(1e3), wind {wind}: {ratios[str(wind)]:.2f}")

    gpu_frames = bench_gpu_frame(ctx, repeats) if ctx is not None else []
    if gpu_frames:
        print("\nGPU backend on llvmpipe, 1/60 s frames (10 substeps)")
        for row in gpu_frames:
            print(f"  {row['n']:>3}x{row['n']:<3} {row['ms_per_frame_llvmpipe']:8.1f} ms/frame")

    result = {
        "benchmark": "cloth",
        "machine": {"cpus": os.cpu_count(), "load_average": os.getloadavg(),
                    "omp_wait_policy": os.environ.get("OMP_WAIT_POLICY"),
                    "commit": source_commit()},
        "versions": _peer_versions(),
        "springs12": springs,
        "stiffness_cost": {"rows": stiffness, "ratio_1e6_to_1e3": ratios},
        "gpu_frame_llvmpipe": gpu_frames,
        "seconds": time.time() - started,
    }
    from catalog.core.atomic import write_text_atomic
    write_text_atomic(args.out, json.dumps(result, indent=1) + "\n")
    print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
