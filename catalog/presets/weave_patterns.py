"""Woven and netted patterns from a few named parameters (model.md section 9): a hexagonal
tulle net (``cell_mm`` hole to hole), a plain or basket weave at a thread pitch, a damask of
satin and twill floats. One free parameter per kind (the net's thread width, the yarn width,
the damask's interstice scale) is found by bisection so that the mean open area 1 - mean(c)
equals the fitted ``btdf.direct`` (LD). Each returns (coverage, height, repeat (u, v) m,
info); lengths in the parameters are mm. Deterministic: no random numbers.

tools/make_patterns.py draws the catalog's patterns with these (and its laces with
tools/lace_motifs.py); ``catalog fit`` draws a fitted fabric's default pattern for its weave
(:func:`default_pattern`).
"""

from __future__ import annotations

import math

import numpy as np

SQRT3 = math.sqrt(3.0)

#: Soft edge of a thread (fraction of a pixel's width the coverage ramps over): 1 px.
EDGE_PX = 1.0


def _grid(size_u: int, size_v: int, repeat_u: float, repeat_v: float):
    """Pixel centres in metres: x along u (image columns), y along v (image rows, down)."""
    x = (np.arange(size_u) + 0.5) * (repeat_u / size_u)
    y = (np.arange(size_v) + 0.5) * (repeat_v / size_v)
    return np.meshgrid(x, y)


def _ramp(distance, half_width, px):
    """Coverage of a thread whose centre line is ``distance`` away: 1 inside half_width,
    0 outside, a linear ramp one pixel wide across the edge."""
    return np.clip(0.5 - (distance - half_width) / (EDGE_PX * px), 0.0, 1.0)


def _hex_edge_distance(x, y, cell):
    """Distance to the nearest edge of the hexagonal (Voronoi) cells around a triangular
    lattice of hole centres with spacing ``cell`` (basis (cell, 0), (cell/2, cell sqrt3/2))."""
    t = y / (cell * SQRT3 / 2)
    s = x / cell - 0.5 * t
    s0, t0 = np.floor(s), np.floor(t)
    d = []
    for ds in (-1, 0, 1, 2):
        for dt in (-1, 0, 1, 2):
            ps, pt = s0 + ds, t0 + dt
            px = (ps + 0.5 * pt) * cell
            py = pt * cell * SQRT3 / 2
            d.append((x - px) ** 2 + (y - py) ** 2)
    d = np.sort(np.stack(d), axis=0)
    return (d[1] - d[0]) / (2 * cell)  # distance to the bisector of the two nearest centres


def bisect(mean_of, target, low, high, iterations=60):
    """The parameter in [low, high] at which mean_of (increasing) equals target."""
    for _ in range(iterations):
        mid = 0.5 * (low + high)
        if mean_of(mid) < target:
            low = mid
        else:
            high = mid
    return 0.5 * (low + high)


def net_pattern(p, direct):
    cell = p["cell_mm"] * 1e-3
    ru, rv = p["cells_u"] * cell, p["row_pairs_v"] * cell * SQRT3
    n = p["size"]
    x, y = _grid(n, n, ru, rv)
    edge = _hex_edge_distance(x, y, cell)
    px = ru / n

    def coverage(half):
        return _ramp(edge, half, px)

    half = bisect(lambda h: coverage(h).mean(), 1.0 - direct, 0.0, cell / 2)
    c = coverage(half)
    height = np.clip(1.0 - (edge / max(half, 1e-9)) ** 2, 0.0, 1.0) ** 0.5 * c
    return c, height, (ru, rv), {"thread_mm": round(2 * half * 1e3, 4),
                                  "height_m": round(1.4 * half, 8)}


def weave_pattern(p, direct, basket=False):
    pitch = p["pitch_mm"] * 1e-3
    group = 2 if basket else 1
    threads = 2 * group                 # threads per repeat in each direction
    r = threads * pitch
    n = p["size"]
    x, y = _grid(n, n, r, r)
    px = r / n
    i = np.floor(x / pitch)             # warp index (vertical threads, spaced along x)
    j = np.floor(y / pitch)             # weft index
    dx = np.abs(x - (i + 0.5) * pitch)
    dy = np.abs(y - (j + 0.5) * pitch)

    def coverage(half):
        return np.maximum(_ramp(dx, half, px), _ramp(dy, half, px))

    half = bisect(lambda h: coverage(h).mean(), 1.0 - direct, 0.0, pitch / 2)
    c = coverage(half)
    # over and under: warp i is up where it crosses weft j with (i//g + j//g) even
    phase_warp = math.pi * (y / (group * pitch) - 0.5 / group) + math.pi * np.floor(i / group)
    phase_weft = math.pi * (x / (group * pitch) - 0.5 / group) + math.pi * np.floor(j / group)
    warp_centre = 0.5 + 0.3 * np.cos(phase_warp)
    weft_centre = 0.5 - 0.3 * np.cos(phase_weft)
    hw = max(half, 1e-9)
    warp_h = (warp_centre + 0.2 * np.sqrt(np.clip(1 - (dx / hw) ** 2, 0, 1))) * _ramp(dx, half, px)
    weft_h = (weft_centre + 0.2 * np.sqrt(np.clip(1 - (dy / hw) ** 2, 0, 1))) * _ramp(dy, half, px)
    height = np.maximum(warp_h, weft_h)
    return c, np.clip(height, 0, 1), (r, r), {"yarn_mm": round(2 * half * 1e3, 4),
                                              "height_m": round(half, 8)}


def damask_pattern(p, direct):
    pitch = p["pitch_mm"] * 1e-3
    r = p["threads"] * pitch
    n = p["size"]
    x, y = _grid(n, n, r, r)
    px = r / n
    radius = p["medallion_mm"] * 1e-3
    motif = np.full(x.shape, np.inf)
    for cx in (0.0, r / 2, r):
        for cy in (0.0, r / 2, r):
            if (cx == r / 2) != (cy == r / 2):
                continue
            dx, dy = x - cx, y - cy
            rr = np.hypot(dx, dy)
            theta = np.arctan2(dy, dx)
            shape = radius * (0.6 + 0.4 * np.cos(4 * theta)) * (1.0 - 0.25 * np.cos(8 * theta))
            motif = np.minimum(motif, rr - shape)
    in_motif = _ramp(motif, 0.0, px)                  # 1 in the medallion (weft-faced twill)
    i = np.floor(x / pitch)
    j = np.floor(y / pitch)
    # interlacing points: satin (ground) where (2 i - j) mod end == 0 (a sateen step of 2),
    # twill (motif) where (i + j) mod end == 0; an interstice opens where threads interlace
    ground_points = np.mod(2 * i - j, p["ground_end"]) == 0
    motif_points = np.mod(i + j, p["motif_end"]) == 0
    # an interstice opens where threads interlace: the open area of a region is in proportion
    # to its interlacings per crossing (1 / end), spread over the crossings' corners so that
    # the threads show at the thread scale
    lx = (x / pitch) - i - 0.5
    ly = (y / pitch) - j - 0.5
    corner = np.exp(-((np.abs(lx) - 0.5) ** 2 + (np.abs(ly) - 0.5) ** 2) / (2 * 0.25 ** 2))
    points = (1 - in_motif) * ground_points + in_motif * motif_points
    density = (1 - in_motif) / p["ground_end"] + in_motif / p["motif_end"]
    interstice = density * (0.6 + 0.4 * corner) * (0.7 + 0.3 * points)

    def coverage(scale):
        return 1.0 - np.clip(scale * interstice, 0.0, 0.9)

    scale = bisect(lambda s: -coverage(s).mean(), -(1.0 - direct), 0.0, 10.0)
    c = coverage(scale)
    # floats: warp-faced satin ground shows vertical ridges, the twill motif horizontal ones
    ridges = (1 - in_motif) * (0.5 + 0.5 * np.cos(2 * math.pi * (x / pitch - 0.5))) \
        + in_motif * (0.5 + 0.5 * np.cos(2 * math.pi * (y / pitch - 0.5)))
    height = 0.2 + 0.7 * ridges
    return c, np.clip(height, 0, 1), (r, r), {"interstice_scale": round(scale, 6),
                                              "height_m": round(0.5 * pitch, 8)}


#: A fitted fabric's default structure for its weave (``catalog fit`` without ``--pattern``):
#: a tulle net for a lace (a lace's motifs are a design, not a weave), plain weaves at a
#: sheer's and a cloth's thread pitch, satin and twill as a damask whose ground and motif
#: share one weave.
WEAVE_DEFAULTS: dict[str, dict] = {
    "lace": {"kind": "net", "cell_mm": 1.0, "cells_u": 8, "row_pairs_v": 5, "size": 256},
    "voile": {"kind": "plain", "pitch_mm": 0.5, "size": 64},
    "plain": {"kind": "plain", "pitch_mm": 0.4, "size": 64},
    "twill": {"kind": "damask", "pitch_mm": 0.4, "threads": 24, "medallion_mm": 0.0,
              "ground_end": 3, "motif_end": 3, "size": 192},
    "satin": {"kind": "damask", "pitch_mm": 0.4, "threads": 32, "medallion_mm": 0.0,
              "ground_end": 8, "motif_end": 8, "size": 256},
}


def make_structure(p: dict, direct: float):
    """The pattern of a parameter set ``p`` (its ``kind``: net, plain, basket, damask) whose
    open area is ``direct``."""
    kind = p["kind"]
    if kind == "net":
        return net_pattern(p, direct)
    if kind in ("plain", "basket"):
        return weave_pattern(p, direct, basket=kind == "basket")
    if kind == "damask":
        return damask_pattern(p, direct)
    raise ValueError(f"unknown pattern kind {kind!r}")


def default_pattern(weave: str, direct: float):
    """(coverage, height, repeat (u, v) m, [pattern] table entries) of ``weave``'s default
    structure at open area ``direct``."""
    p = WEAVE_DEFAULTS[weave]
    coverage, height, repeat, info = make_structure(p, direct)
    return coverage, height, repeat, {"kind": p["kind"], **info}
