"""Issue 12's frame cost on this machine's GL (llvmpipe in CI): the patterned frame with OIT
and FXAA against the frame before, and MSAA's cost; prints the tables, writes JSON.

    .venv/bin/python benchmarks/bench_pattern.py [--quick] [--repeats N] [--json-out F]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from catalog.benchsuite.pattern import markdown_tables, run

HERE = Path(__file__).resolve().parent


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="320x180, 3 repeats")
    parser.add_argument("--repeats", type=int, default=None)
    parser.add_argument("--json-out", type=Path, default=HERE / "bench_pattern.json")
    args = parser.parse_args(argv)
    result = run(quick=args.quick, repeats=args.repeats)
    for table in markdown_tables(result).values():
        print(table + "\n")
    args.json_out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
