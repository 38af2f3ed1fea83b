"""Write the project's own default view behind the window, the procedural clear sky of
catalog/optics/sun/sky.py, as a latitude-longitude EXR (usable with ``catalog snapshot --environment``).

    .venv/bin/python tools/make_environment.py OUT.exr [--elevation DEG] [--azimuth DEG] [--height PX]

Made by this project from the Preetham et al. 1999 formulas and catalog.optics.sun.model.clear_sky: it
carries the project's licence, no third-party image.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from catalog.render import scene  # noqa: E402
from catalog.render.environment import write_sky_environment  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out")
    parser.add_argument("--elevation", type=float, default=30.0, help="sun elevation, deg")
    parser.add_argument("--azimuth", type=float, default=scene.KEY_AZIMUTH_DEG,
                        help="sun azimuth from the window normal, deg")
    parser.add_argument("--height", type=int, default=256, help="image height, px (width 2x)")
    args = parser.parse_args()
    if not 0.5 <= args.elevation <= 90.0:
        print(f"--elevation {args.elevation:g}: the sun must stand 0.5..90 deg high", file=sys.stderr)
        return 2
    if not 4 <= args.height <= 8192:
        print(f"--height {args.height}: choose 4..8192", file=sys.stderr)
        return 2
    write_sky_environment(args.out, scene.key_direction(args.elevation, args.azimuth), args.height)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
