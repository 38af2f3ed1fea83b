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
sys.path.insert(0, str(ROOT))   # the checkout's catalog package
from catalog.presets.weave_patterns import bisect, make_structure  # noqa: E402

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
    half = bisect(lambda h: coverage(h).mean(), 1.0 - direct, 0.0, cell / 2)
    info = {"net_thread_mm": round(2 * half * 1e3, 4), "height_m": round(0.5 * cord, 8)}
    if "border" in p:
        info["border"] = scalloped_border(p["border"], lace_of_rows, half, cell, cord)
        info["border_m"] = round(p["border"]["border_rows"] * rv / rows_v, 8)
    return coverage(half), height(half), (ru, rv), info


def make_pattern(name: str, direct: float):
    """(coverage, height, repeat (u, v) m, info) for a catalog fabric, before quantisation."""
    p = PATTERNS[name]
    kind = p["kind"]
    if kind == "lace":
        return lace_pattern(p, direct)
    return make_structure(p, direct)   # net, plain, basket, damask


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
