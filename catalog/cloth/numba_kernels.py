"""numba kernels of the cpu backend: the same substep as backend_numpy, as loops.

Compiled on first use and cached on disk (``cache=True``), so the viewer pays the
compile once per machine, not at every start. Float64, no fastmath: the results follow
the numpy reference to rounding (the tests hold them to it).

``fp`` packs the scalar parameters (see :func:`pack_params` in backend_numba.py).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from catalog.cloth.params import STRAIN_TOLERANCE

# fp indices
DAMPING, GRAVITY, AERO, WIND_SPEED, WIND_X, WIND_Y, WIND_Z, GUST, GUST_LENGTH, GUST_PERIOD, \
    MAX_STRETCH, FLOOR, WALL, CONTACT_DAMPING, RING_SPEED, STRAIN_PASSES = range(16)
FP_SIZE = 16


@njit(cache=True, inline="always")
def _project(x, ra, ca, rb, cb, wa, wb, rest, flat, kh2, limited, max_stretch, limit_only):
    """One XPBD distance constraint resting at ``rest`` (the pose's), strain-limited at
    (1 + max_stretch) ``flat`` (the fabric's length); returns its strain beyond the limit
    before it."""
    wsum = wa + wb
    if wsum <= 0.0:
        return 0.0
    dx = x[rb, cb, 0] - x[ra, ca, 0]
    dy = x[rb, cb, 1] - x[ra, ca, 1]
    dz = x[rb, cb, 2] - x[ra, ca, 2]
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    if length <= 0.0:
        return 0.0
    limit = (1.0 + max_stretch) * flat
    if limit_only:
        shorten = max(length - limit, 0.0)
    else:
        shorten = (length - rest) * wsum * kh2 / (wsum * kh2 + 1.0)  # XPBD, lambda = 0
        if limited:
            shorten = max(shorten, length - limit)  # Provot strain limit
    scale = shorten / (wsum * length)
    sa = wa * scale
    sb = wb * scale
    x[ra, ca, 0] += sa * dx
    x[ra, ca, 1] += sa * dy
    x[ra, ca, 2] += sa * dz
    x[rb, cb, 0] -= sb * dx
    x[rb, cb, 1] -= sb * dy
    x[rb, cb, 2] -= sb * dz
    return (length - limit) / flat


@njit(cache=True)
def _selector_pass(x, w, sel, rest, flat, stiff, limited, fp, h, limit_only):
    height, width = x.shape[0], x.shape[1]
    family, di, dj, row0, row_step, col0, col_step = (sel[0], sel[1], sel[2], sel[3],
                                                      sel[4], sel[5], sel[6])
    col_low = max(0, -dj)
    if col0 < col_low:
        col0 += col_step * ((col_low - col0 + col_step - 1) // col_step)
    n_rows = (height - di - row0 + row_step - 1) // row_step
    col_stop = width - max(dj, 0)
    kh2 = stiff[family] * h * h
    max_stretch = fp[MAX_STRETCH]
    worst = -1.0
    for k in range(n_rows):
        r = row0 + k * row_step
        for c in range(col0, col_stop, col_step):
            excess = _project(x, r, c, r + di, c + dj, w[r, c], w[r + di, c + dj],
                              rest[family, r, c], flat[family], kh2,
                              limited[family], max_stretch, limit_only)
            worst = max(worst, excess)
    return worst


@njit(cache=True)
def _strain_sweep(x, w, sel, rest, flat, stiff, limited, fp, h, backward):
    """Hard strain limiting over the stretch and shear selectors; returns the worst
    excess strain met (before its correction)."""
    worst = -1.0
    count = sel.shape[0]
    for i in range(count):
        s_i = count - 1 - i if backward else i
        if limited[sel[s_i, 0]]:
            worst = max(worst, _selector_pass(x, w, sel[s_i], rest, flat, stiff, limited, fp, h,
                                                   True))
    return worst


@njit(cache=True)
def _normals(x, n):
    height, width = x.shape[0], x.shape[1]
    for r in range(height):
        r0 = max(r - 1, 0)
        r1 = min(r + 1, height - 1)
        for c in range(width):
            c0 = max(c - 1, 0)
            c1 = min(c + 1, width - 1)
            ax = x[r1, c, 0] - x[r0, c, 0]
            ay = x[r1, c, 1] - x[r0, c, 1]
            az = x[r1, c, 2] - x[r0, c, 2]
            bx = x[r, c1, 0] - x[r, c0, 0]
            by = x[r, c1, 1] - x[r, c0, 1]
            bz = x[r, c1, 2] - x[r, c0, 2]
            nx = ay * bz - az * by
            ny = az * bx - ax * bz
            nz = ax * by - ay * bx
            length = math.sqrt(nx * nx + ny * ny + nz * nz)
            if length <= 0.0:
                length = 1.0
            n[r, c, 0] = nx / length
            n[r, c, 1] = ny / length
            n[r, c, 2] = nz / length


@njit(cache=True)
def _predict(x, v, xp, n, fp, wind, h):
    height, width = x.shape[0], x.shape[1]
    keep = 1.0 / (1.0 + fp[DAMPING] * h)
    aero = fp[AERO]
    for r in range(height):
        for c in range(width):
            vx = v[r, c, 0] * keep
            vy = v[r, c, 1] * keep - h * fp[GRAVITY]
            vz = v[r, c, 2] * keep
            wx = wind[r, c, 0]
            wy = wind[r, c, 1]
            wz = wind[r, c, 2]
            nx = n[r, c, 0]
            ny = n[r, c, 1]
            nz = n[r, c, 2]
            vn = (vx - wx) * nx + (vy - wy) * ny + (vz - wz) * nz
            dvn = vn / (1.0 + aero * abs(vn) * h) - vn  # semi-implicit normal drag
            vx += dvn * nx
            vy += dvn * ny
            vz += dvn * nz
            v[r, c, 0] = vx
            v[r, c, 1] = vy
            v[r, c, 2] = vz
            for k in range(3):
                xp[r, c, k] = x[r, c, k]
            x[r, c, 0] += h * vx
            x[r, c, 1] += h * vy
            x[r, c, 2] += h * vz


@njit(cache=True)
def _wind_field(x, wind, fp, gust, t):
    """The gusty wind (wind.py) at each particle, once per frame."""
    height, width = x.shape[0], x.shape[1]
    speed = fp[WIND_SPEED]
    two_pi = 2.0 * math.pi
    for r in range(height):
        for c in range(width):
            factor = 0.0
            if speed != 0.0:
                g = 0.0
                for k in range(3):
                    phase = two_pi * ((x[r, c, 0] * gust[k, 0] + x[r, c, 1] * gust[k, 1]
                                       + x[r, c, 2] * gust[k, 2]) / fp[GUST_LENGTH]
                                      + gust[k, 3] * t / fp[GUST_PERIOD]) + gust[k, 4]
                    g += math.sin(phase)
                factor = speed * max(0.0, 1.0 + fp[GUST] * g / 3.0)
            wind[r, c, 0] = factor * fp[WIND_X]
            wind[r, c, 1] = factor * fp[WIND_Y]
            wind[r, c, 2] = factor * fp[WIND_Z]


@njit(cache=True)
def _attach(x, w, rings, lra_ring, lra_limit):
    """Long-range attachments (Kim, Chentanez, Mueller 2012) to the nearest ring."""
    height, width = x.shape[0], x.shape[1]
    for r in range(height):
        for c in range(width):
            if w[r, c] <= 0.0:
                continue
            j = lra_ring[r, c]
            limit = lra_limit[r, c]
            dx = x[r, c, 0] - rings[j, 0]
            dy = x[r, c, 1] - rings[j, 1]
            dz = x[r, c, 2] - rings[j, 2]
            dist = math.sqrt(dx * dx + dy * dy + dz * dz)
            if dist > limit:
                s = limit / dist
                x[r, c, 0] = rings[j, 0] + dx * s
                x[r, c, 1] = rings[j, 1] + dy * s
                x[r, c, 2] = rings[j, 2] + dz * s


@njit(cache=True)
def _collide(x, fp):
    height, width = x.shape[0], x.shape[1]
    for r in range(height):
        for c in range(width):
            x[r, c, 1] = max(x[r, c, 1], fp[FLOOR])
            x[r, c, 2] = max(x[r, c, 2], fp[WALL])


@njit(cache=True)
def _collide_update(x, v, xp, fp, h):
    height, width = x.shape[0], x.shape[1]
    floor = fp[FLOOR]
    wall = fp[WALL]
    keep = 1.0 / (1.0 + fp[CONTACT_DAMPING] * h)  # contact damping
    for r in range(height):
        for c in range(width):
            on_floor = False
            on_wall = False
            if x[r, c, 1] <= floor:
                x[r, c, 1] = floor
                on_floor = True
            if x[r, c, 2] <= wall:
                x[r, c, 2] = wall
                on_wall = True
            vx = (x[r, c, 0] - xp[r, c, 0]) / h
            vy = (x[r, c, 1] - xp[r, c, 1]) / h
            vz = (x[r, c, 2] - xp[r, c, 2]) / h
            if on_floor or on_wall:
                vx *= keep
            if on_floor:
                vz *= keep
            if on_wall:
                vy *= keep
            v[r, c, 0] = vx
            v[r, c, 1] = vy
            v[r, c, 2] = vz


@njit(cache=True)
def advance(x, v, xp, n, wind, w, rings, targets, ring_cols, lra_ring, lra_limit, sel, rest,
            flat, stiff, limited, gust, fp, substeps, h, t, final_passes):
    """One frame: ``substeps`` substeps of length h from time t; returns the new time.

    The last substep repeats the strain sweep (forward, backward, ...) until no spring
    exceeds the limit by more than STRAIN_TOLERANCE, at most ``final_passes`` times.
    """
    n_rings = rings.shape[0]
    ring_before = np.empty_like(rings)
    _wind_field(x, wind, fp, gust, t)
    for step in range(substeps):
        # 1. rings
        max_move = fp[RING_SPEED] * h
        for j in range(n_rings):
            dx = targets[j, 0] - rings[j, 0]
            dy = targets[j, 1] - rings[j, 1]
            dz = targets[j, 2] - rings[j, 2]
            dist = math.sqrt(dx * dx + dy * dy + dz * dz)
            s = 1.0
            if dist > max_move:
                s = max_move / dist
            for k in range(3):
                ring_before[j, k] = rings[j, k]
            rings[j, 0] += dx * s
            rings[j, 1] += dy * s
            rings[j, 2] += dz * s
        # 2. normals, 3. predict; the rings follow the rod
        _normals(x, n)
        _predict(x, v, xp, n, fp, wind, h)
        for j in range(n_rings):
            for k in range(3):
                xp[0, ring_cols[j], k] = ring_before[j, k]
                x[0, ring_cols[j], k] = rings[j, k]
        # 4. XPBD colour by colour
        for s_i in range(sel.shape[0]):
            _selector_pass(x, w, sel[s_i], rest, flat, stiff, limited, fp, h, False)
        # 5. long-range attachments, 6. collisions, 6b. strain-limit sweeps
        _attach(x, w, rings, lra_ring, lra_limit)
        _collide(x, fp)
        passes = int(fp[STRAIN_PASSES])
        if step == substeps - 1:
            passes = max(passes, final_passes)
        for k in range(passes):
            worst = _strain_sweep(x, w, sel, rest, flat, stiff, limited, fp, h, k % 2 == 1)
            if step == substeps - 1 and k + 1 >= int(fp[STRAIN_PASSES]) \
                    and worst <= STRAIN_TOLERANCE:
                break
        # clamp again, 7. velocities
        _collide_update(x, v, xp, fp, h)
        t += h
    return t
