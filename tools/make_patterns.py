"""Make every catalog fabric's pattern (coverage + thread height) and its preset's [pattern].

Each fabric's structure comes from a few named parameters (PATTERNS below): a hexagonal
tulle net (cell = hole-to-hole distance), a lace motif on it, a plain or basket weave at a
thread pitch, a damask of satin floats. One free parameter per kind (the net's thread width,
the yarn width, the damask's interstice scale) is found by bisection so that the mean open
area 1 - mean(c) equals the fitted ``btdf.direct`` (LD) of the preset (model.md section 9);
the result is written as 16-bit grey PNGs under fabrics/patterns/ and the [pattern] table is
added to fabrics/<name>.toml through catalog.presets.save_preset_dict (which refuses a
pattern whose open area misses LD by more than 1 %).

    .venv/bin/python tools/make_patterns.py [NAMES..] [--out-dir fabrics] [--check]

``--check`` regenerates in memory and compares with the files on disk (exit 1 on a
difference). Deterministic: no random numbers.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))   # lace_motifs beside this file
FABRICS = ROOT / "fabrics"
SQRT3 = math.sqrt(3.0)

#: name -> the pattern's named parameters (lengths in mm). ``size`` = texture side in px.
PATTERNS: dict[str, dict] = {
    # laces (tools/lace_motifs.py): a hexagonal net ground of cell_mm holes, cord-outlined
    # cloth-stitch motifs with open fillings, at several scales on a half-drop repeat
    # (cells_u cells across, row_pairs_v pairs of hexagon rows down; even, so the filling's
    # honeycomb of twice the cell tiles too)
    # and a scalloped border along the hem (lace_motifs.scalloped_border): ``scallops`` per
    # repeat across, the cusp's rise and the ornament's band as fractions of the scallop's
    # pitch, the band's depth in rows of the repeat's pixels (a power of two: exact mips)
    "lace-fwa": {"kind": "lace", "layout": "leavers", "cell_mm": 1.0, "cells_u": 100,
                 "row_pairs_v": 86, "cord_mm": 0.8, "size": 1024,
                 "border": {"scallops": 2, "scallop_rise": 0.28, "band": 0.3, "rays": 7,
                            "picots": 14, "border_rows": 512}},
    "raschel-ivory": {"kind": "lace", "layout": "raschel", "cell_mm": 1.25, "cells_u": 96,
                      "row_pairs_v": 50, "cord_mm": 1.2, "size": 1024,
                      "border": {"scallops": 2, "scallop_rise": 0.35, "band": 0.25, "rays": 9,
                                 "picots": 12, "border_rows": 512}},
    "tulle-embroidered": {"kind": "lace", "layout": "tulle", "cell_mm": 0.8, "cells_u": 100,
                          "row_pairs_v": 56, "cord_mm": 0.6, "size": 1024,
                          "border": {"scallops": 4, "scallop_rise": 0.22, "band": 0.28,
                                     "rays": 5, "picots": 8, "border_rows": 256}},
    "net-grey": {"kind": "net", "cell_mm": 2.0, "cells_u": 8, "row_pairs_v": 5, "size": 256},
    "safety-yellow": {"kind": "net", "cell_mm": 1.5, "cells_u": 8, "row_pairs_v": 5, "size": 256},
    # woven sheers: pitch = thread spacing, the yarn width found from LD
    "voile-white": {"kind": "plain", "pitch_mm": 1.0, "size": 64},  # a coarse (etamine) voile
    "batiste-cream": {"kind": "plain", "pitch_mm": 0.3, "size": 64},
    "organza-ivory": {"kind": "plain", "pitch_mm": 0.25, "size": 64},
    "sheer-teal": {"kind": "plain", "pitch_mm": 0.5, "size": 64},
    "fluoro-pink": {"kind": "plain", "pitch_mm": 0.5, "size": 64},
    "linen-dense": {"kind": "basket", "pitch_mm": 0.6, "size": 128},
    # damask: an 8-end satin ground (long floats, few interlacings: dense) and a medallion in
    # a 3-end twill (short floats, many interlacings: lighter against the light); no holes
    "jacquard-white": {"kind": "damask", "pitch_mm": 0.4, "threads": 250, "medallion_mm": 34.0,
                       "ground_end": 8, "motif_end": 3, "size": 1024},
}

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


def _bisect(mean_of, target, low, high, iterations=60):
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

    half = _bisect(lambda h: coverage(h).mean(), 1.0 - direct, 0.0, cell / 2)
    c = coverage(half)
    height = np.clip(1.0 - (edge / max(half, 1e-9)) ** 2, 0.0, 1.0) ** 0.5 * c
    return c, height, (ru, rv), {"thread_mm": round(2 * half * 1e3, 4),
                                  "height_m": round(1.4 * half, 8)}


def _leavers(lace, ru, rv):
    """A Leavers floral all-over: per half-drop column a large six-petal flower with two
    leaves, a smaller five-petal flower on a scrolling stem, buds and scattered spots."""
    for u0, v0, flip in ((0.25 * ru, 0.25 * rv, 1.0), (0.75 * ru, 0.75 * rv, -1.0)):
        lace.flower((u0, v0), 0.021, 6, rotation=0.3 * flip)
        lace.leaf((u0 + flip * 0.026, v0 + 0.022), 0.024, 0.009, flip * 0.7)
        lace.leaf((u0 - flip * 0.020, v0 + 0.030), 0.020, 0.008, -flip * 1.1)
        small = (u0 + flip * 0.024, v0 - 0.042)
        lace.flower(small, 0.010, 5, rotation=0.5, open_petals=False)
        lace.scroll((u0 + flip * 0.012, v0 - 0.018), small, 0.006 * flip)
        lace.scroll(small, (u0 - flip * 0.018, v0 - 0.060), -0.008 * flip)
        for k, (du, dv) in enumerate(((-0.018, -0.062), (-0.030, -0.050), (0.040, -0.020))):
            lace.spot((u0 + flip * du, v0 + dv), 0.0022 if k == 0 else 0.0016)
        lace.leaf((u0 - flip * 0.032, v0 - 0.030), 0.014, 0.006, flip * 2.2)
    for k in range(9):   # point d'esprit: small spots scattered on the ground (a fixed pattern)
        lace.spot(((0.11 + 0.37 * k) % 1.0 * ru, (0.07 + 0.61 * k) % 1.0 * rv), 0.0009)


def _raschel(lace, ru, rv):
    """A Raschel lace with a heavy cord: double-ringed eight-petal flowers in a half-drop,
    linked by an ogee trail of leaves; a four-petal flower between the trails."""
    for u0, v0, flip in ((0.25 * ru, 0.25 * rv, 1.0), (0.75 * ru, 0.75 * rv, -1.0)):
        lace.flower((u0, v0), 0.028, 8, rotation=0.2)
        lace.flower((u0, v0), 0.013, 8, rotation=0.2 + math.pi / 8, open_petals=False)
        top, bottom = (u0 + flip * 0.5 * 0.5 * ru, v0 - 0.25 * rv), (u0, v0 - 0.5 * rv)
        lace.scroll((u0 + flip * 0.03, v0 - 0.02), top, 0.02 * flip)
        lace.scroll(top, bottom, 0.02 * flip)
        for t in (0.3, 0.7):
            at = (u0 + flip * 0.03 + t * (top[0] - u0 - flip * 0.03), v0 - 0.02 + t * (top[1] - v0 + 0.02))
            lace.leaf(at, 0.020, 0.008, flip * (0.9 + t))
        lace.flower((u0 + flip * 0.25 * ru, v0 + 0.02), 0.009, 4, rotation=0.78, open_petals=False)
        lace.leaf((u0 - flip * 0.034, v0 + 0.03), 0.026, 0.010, -flip * 0.5)


def _tulle(lace, ru, rv):
    """Embroidered tulle: sparse sprigs (a five-petal flower, two leaves on a short stem) on
    a fine net, in a half-drop with small scattered dots; most of the cloth is open net."""
    for u0, v0, flip in ((0.25 * ru, 0.3 * rv, 1.0), (0.75 * ru, 0.8 * rv, -1.0)):
        lace.flower((u0, v0), 0.009, 5, rotation=0.3 * flip, open_petals=False)
        end = (u0 - flip * 0.012, v0 + 0.026)
        lace.scroll((u0, v0 + 0.007), end, 0.004 * flip)
        lace.leaf((u0 - flip * 0.009, v0 + 0.016), 0.011, 0.0045, flip * 0.9)
        lace.leaf((u0 + flip * 0.002, v0 + 0.022), 0.009, 0.004, -flip * 0.6)
        lace.spot(end, 0.0018)
    for k in range(6):
        lace.spot(((0.55 + 0.41 * k) % 1.0 * ru, (0.12 + 0.29 * k) % 1.0 * rv), 0.0012)


LACE_LAYOUTS = {"leavers": _leavers, "raschel": _raschel, "tulle": _tulle}


def lace_pattern(p, direct):
    """A lace (tools/lace_motifs.py) whose net thread width is found so that the mean open
    area equals LD; the cord's relief is the height map's 1 (height_m the cord's radius).
    With a ``border``: the scalloped band along the hem as well (info's ``border``: its
    coverage and height, (rows, W), row 0 at the hem)."""
    from lace_motifs import Lace, lace_fields, scalloped_border

    cell = p["cell_mm"] * 1e-3
    ru, rv = p["cells_u"] * cell, p["row_pairs_v"] * cell * SQRT3
    n = p["size"]
    rows_v = round(n * rv / ru)

    def lace_of_rows(rows=None):
        lace = Lace(n, rows_v, ru, rv, rows=rows)
        LACE_LAYOUTS[p["layout"]](lace, ru, rv)
        return lace

    cord = p["cord_mm"] * 1e-3
    coverage, height = lace_fields(lace_of_rows(), cell, cord, 2 * cell)
    half = _bisect(lambda h: coverage(h).mean(), 1.0 - direct, 0.0, cell / 2)
    info = {"net_thread_mm": round(2 * half * 1e3, 4), "height_m": round(0.5 * cord, 8)}
    if "border" in p:
        info["border"] = scalloped_border(p["border"], lace_of_rows, half, cell, cord)
        info["border_m"] = round(p["border"]["border_rows"] * rv / rows_v, 8)
    return coverage(half), height(half), (ru, rv), info


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

    half = _bisect(lambda h: coverage(h).mean(), 1.0 - direct, 0.0, pitch / 2)
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

    scale = _bisect(lambda s: -coverage(s).mean(), -(1.0 - direct), 0.0, 10.0)
    c = coverage(scale)
    # floats: warp-faced satin ground shows vertical ridges, the twill motif horizontal ones
    ridges = (1 - in_motif) * (0.5 + 0.5 * np.cos(2 * math.pi * (x / pitch - 0.5))) \
        + in_motif * (0.5 + 0.5 * np.cos(2 * math.pi * (y / pitch - 0.5)))
    height = 0.2 + 0.7 * ridges
    return c, np.clip(height, 0, 1), (r, r), {"interstice_scale": round(scale, 6),
                                              "height_m": round(0.5 * pitch, 8)}


def make_pattern(name: str, direct: float):
    """(coverage, height, repeat (u, v) m, info) for a catalog fabric, before quantisation."""
    p = PATTERNS[name]
    kind = p["kind"]
    if kind == "lace":
        return lace_pattern(p, direct)
    if kind == "net":
        return net_pattern(p, direct)
    if kind in ("plain", "basket"):
        return weave_pattern(p, direct, basket=kind == "basket")
    if kind == "damask":
        return damask_pattern(p, direct)
    raise ValueError(f"unknown pattern kind {kind!r}")


def pattern_table(name: str, repeat) -> dict:
    return {"coverage": f"patterns/{name}.png", "height": f"patterns/{name}-height.png",
            "repeat_m": [round(repeat[0], 8), round(repeat[1], 8)],
            "kind": PATTERNS[name]["kind"]}


def regenerate(name: str, fabrics: Path = FABRICS, write: bool = True) -> dict:
    """Make one fabric's pattern; write the PNGs and the preset's [pattern] (``write``), or
    only return the quantised arrays and the table."""
    from catalog.presets.patterns import Pattern, quantise16, write_pattern_images
    from catalog.presets import load_preset, preset_to_dict, save_preset_dict

    preset_path = fabrics / f"{name}.toml"
    preset = load_preset(preset_path)
    c, h, repeat, info = make_pattern(name, preset.btdf.direct)
    c, h = quantise16(c), quantise16(h)
    table = pattern_table(name, repeat)
    border = info.pop("border", None)
    table.update(info)
    if border is not None:
        border = tuple(quantise16(b) for b in border)
        table.update({"border": f"patterns/{name}-border.png",
                      "border_height": f"patterns/{name}-border-height.png"})
    result = {"name": name, "coverage": c, "height": h, "table": table, "border": border,
              "open_area": 1.0 - float(c.mean(dtype=np.float64)), "direct": preset.btdf.direct}
    if write:
        (fabrics / "patterns").mkdir(exist_ok=True)
        pattern = Pattern(c, h, tuple(repeat), 0.0, name)
        write_pattern_images(pattern, fabrics / table["coverage"], fabrics / table["height"])
        if border is not None:
            band = Pattern(border[0], border[1], (repeat[0], table["border_m"]), 0.0, name)
            write_pattern_images(band, fabrics / table["border"], fabrics / table["border_height"])
        doc = preset_to_dict(preset)
        doc["pattern"] = table
        save_preset_dict(doc, preset_path)    # refuses when the open area misses LD by > 1 %
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="fabrics (default: every one in PATTERNS)")
    parser.add_argument("--out-dir", type=Path, default=FABRICS, help="the fabrics folder")
    parser.add_argument("--check", action="store_true",
                        help="compare with the files on disk instead of writing")
    args = parser.parse_args(argv)
    names = args.names or sorted(PATTERNS)
    status = 0
    for name in names:
        result = regenerate(name, args.out_dir, write=not args.check)
        line = (f"{name:15s} {result['table']['kind']:7s} open {result['open_area']:.5f} "
                f"LD {result['direct']:.5f}  repeat {result['table']['repeat_m']} m")
        if args.check:
            from catalog.presets.patterns import read_image

            on_disk = read_image(args.out_dir / result["table"]["coverage"])[..., 0]
            same = on_disk.shape == result["coverage"].shape and np.array_equal(
                np.round(on_disk * 65535.0), np.round(result["coverage"] * 65535.0))
            line += "  same" if same else "  DIFFERS"
            status |= 0 if same else 1
        print(line)
    return status


if __name__ == "__main__":
    sys.exit(main())
