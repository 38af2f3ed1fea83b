"""The display step's cost in the frame: each transform as a shader variant (ms per pass),
the auto exposure's meter, the whole frame; medians of repeats, one run side by side.

Prints a table and writes benchmarks/bench_display.json (catalog/benchsuite/display.py).

    .venv/bin/python benchmarks/bench_display.py [--quick] [--json-out FILE]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import json

from catalog.atomic import write_text_atomic
from catalog.benchsuite.display import markdown_tables, run


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--json-out", type=Path, default=Path(__file__).with_name("bench_display.json"))
    args = parser.parse_args()
    result = run(quick=args.quick)
    print("cost of each step, ms per display pass (first column: the pass with exposure and "
          "the sRGB curve only; then what each step adds)")
    print(markdown_tables(result)["display_cost"])
    write_text_atomic(args.json_out, json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
