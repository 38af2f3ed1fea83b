#!/usr/bin/env python3
"""Regenerate catalog/optics/data/reference_tables.npz from the installed colour-science and pvlib.

    .venv/bin/python tools/make_reference_tables.py [--out PATH]
"""

from __future__ import annotations

import argparse
import io
import sys

import numpy as np

from catalog.core.atomic import write_bytes_atomic
from catalog.optics.reference_tables import TABLE_PATH, build_tables


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--out", default=str(TABLE_PATH))
    args = parser.parse_args(argv)
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **build_tables())
    write_bytes_atomic(args.out, buffer.getvalue())
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
