"""Draw a lace as a backlit scanner would see it: the project's own test and docs image.

An embroidered tulle (tools/make_patterns.py's "tulle" layout: sprigs on a hexagonal net) with
its own parameters (2 mm cells, an 80 mm repeat), seen against a white backlight: open = the
light (1), thread = what a dense yarn lets through (THREAD_TRANSMITTANCE), written as an
8-bit sRGB RGB PNG with its resolution (dpi) in the header, as a flatbed scan is.

    .venv/bin/python tools/make_lace_scan.py OUT.png [--size PX]

Deterministic: no random numbers. ``catalog import OUT.png --name N --out DIR`` reads it.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: The lace: cell, repeat and motif in mm (tools/make_patterns.py's parameters).
LACE = {"kind": "lace", "layout": "tulle", "cell_mm": 2.0, "cells_u": 40, "row_pairs_v": 23,
        "cord_mm": 1.0}
#: The geometric open area the net is drawn to (bisection on the thread width).
OPEN_AREA = 0.45
#: Backlight through a thread (a dense cotton yarn, fraction of the open light).
THREAD_TRANSMITTANCE = 0.03


def draw_scan(size: int = 512) -> tuple[np.ndarray, float, tuple[float, float]]:
    """(H, W, 3) uint8 sRGB scan, its dpi, the repeat (u, v) in metres."""
    sys.path.insert(0, str(HERE))
    from make_patterns import lace_pattern

    coverage, _height, repeat, _info = lace_pattern({**LACE, "size": size}, OPEN_AREA)
    light = (1.0 - coverage) + THREAD_TRANSMITTANCE * coverage          # linear, 0..1
    encoded = np.where(light <= 0.0031308, 12.92 * light, 1.055 * light ** (1 / 2.4) - 0.055)
    rgb = np.round(np.clip(encoded, 0, 1) * 255).astype(np.uint8)
    dpi = size / (repeat[0] / 0.0254)
    return np.repeat(rgb[..., None], 3, axis=2), dpi, repeat


def write_scan(path: Path, size: int = 512) -> float:
    """Write the scan (atomically); returns its dpi."""
    import OpenImageIO as oiio

    from catalog.core.atomic import atomic_path

    rgb, dpi, _repeat = draw_scan(size)
    spec = oiio.ImageSpec(rgb.shape[1], rgb.shape[0], 3, oiio.UINT8)  # the repeat's aspect
    spec.attribute("XResolution", float(dpi))
    spec.attribute("YResolution", float(dpi))
    spec.attribute("ResolutionUnit", "in")
    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(path))
        if out is None or not (out.open(str(tmp), spec) and out.write_image(rgb)):
            raise SystemExit(f"make_lace_scan: cannot write {path}: {oiio.geterror()}")
        out.close()
    return dpi


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--size", type=int, default=512)
    args = parser.parse_args(argv)
    dpi = write_scan(args.out, args.size)
    print(f"wrote {args.out} ({args.size} px, {dpi:.2f} dpi)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
