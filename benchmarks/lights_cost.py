"""Cost of a light: a fresh process that imports colour-science alone vs one that loads a
light by name, and the in-process cost of computing (uncached) and fetching (cached) one.

Prints a table and writes JSON. Process figures are medians of --repeats fresh processes
(the machine is shared and noisy); in-process figures are medians of --repeats calls.

    .venv/bin/python -m benchmarks.lights_cost [--repeats 5] [--json-out FILE]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

RESULT_JSON = "benchmarks/bench_lights.json"


def markdown_tables(result: dict) -> dict[str, str]:
    """``lights_cost``: every case of one committed run (medians), seconds for whole
    processes, milliseconds or microseconds in process."""
    lines = [f"| case | kind | median (of {result['repeats']} processes, or of at least 20 calls) |",
             "|---|---|---|"]
    for r in result["rows"]:
        value = r["seconds"]
        shown = (f"{value:.2f} s" if value >= 0.1 else f"{value * 1e3:.1f} ms" if value >= 1e-3
                 else f"{value * 1e6:.3g} us")
        lines.append(f"| {r['case']} | {r['kind']} | {shown} |")
    return {"lights_cost": "\n".join(lines)}


PROCESS_CASES = {
    "python -c pass (floor)": "pass",
    "import colour (the bound for a CIE light)": "import colour",
    "get_light('D65')": "from catalog.optics.lights import get_light; get_light('D65')",
    "get_light('FL2')": "from catalog.optics.lights import get_light; get_light('FL2')",
    "get_light('UV-A')": "from catalog.optics.lights import get_light; get_light('UV-A')",
    "get_light('sun:22') (+ pvlib, pandas)": "from catalog.optics.lights import get_light; "
                                             "get_light('sun:22')",
    "get_light('sun@2026-06-21T12:00,34.7,135.5')":
        "from catalog.optics.lights import get_light; get_light('sun@2026-06-21T12:00,34.7,135.5')",
}


def time_process(code: str, repeats: int) -> float:
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


#: Measured inside a fresh process after ``import colour``: what a light adds to colour's
#: own import (the shared machine's noise between processes is larger than this).
INCREMENT_CASES = {
    "get_light('D65') after import colour": "get_light('D65')",
    "get_light('FL2') after import colour": "get_light('FL2')",
    "light_names() after import colour": "light_names()",
}


def time_increment(statement: str, repeats: int) -> float:
    code = ("import time, colour\n"
            "from catalog.optics.lights import get_light, light_names\n"
            "t = time.perf_counter()\n"
            f"{statement}\n"
            "print(time.perf_counter() - t)")
    samples = []
    for _ in range(repeats):
        out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                             text=True).stdout
        samples.append(float(out.strip()))
    return statistics.median(samples)


def time_call(fn, repeats: int) -> float:
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--json-out", default="benchmarks/bench_lights.json")
    args = parser.parse_args(argv)

    rows = []
    for label, code in PROCESS_CASES.items():
        rows.append({"case": label, "kind": "fresh process", "seconds": time_process(code, args.repeats)})

    for label, statement in INCREMENT_CASES.items():
        rows.append({"case": label, "kind": "increment",
                     "seconds": time_increment(statement, args.repeats)})

    from catalog.optics.lights import _base_light, get_light  # noqa: PLC0415
    from catalog.optics.sun.model import clear_sky  # noqa: PLC0415

    get_light("D65")
    get_light("sun:22")  # imports done

    def uncached(name):
        return lambda: _base_light.__wrapped__(name)

    in_process = {
        "D65 computed (uncached)": uncached("D65"),
        "LED-warm computed (uncached)": uncached("LED-warm"),
        "sun:300 computed (uncached)": uncached("sun:300"),
        "sun-clear:300 computed (uncached)": uncached("sun-clear:300"),
        "clear_sky(60 deg), delta-Eddington": lambda: clear_sky(60.0),
        "get_light('D65') cached": lambda: get_light("D65"),
    }
    for label, fn in in_process.items():
        rows.append({"case": label, "kind": "in process",
                     "seconds": time_call(fn, max(args.repeats, 20))})

    width = max(len(r["case"]) for r in rows)
    print(f"{'case':<{width}}  {'kind':<13}  median")
    for r in rows:
        value = r["seconds"]
        shown = f"{value:.3f} s" if value >= 0.01 else f"{value * 1e6:.1f} us"
        print(f"{r['case']:<{width}}  {r['kind']:<13}  {shown}")
    out = Path(args.json_out)
    out.parent.mkdir(parents=True, exist_ok=True)
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    write_text_atomic(out, json.dumps({"repeats": args.repeats, "rows": rows}, indent=1) + "\n")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
