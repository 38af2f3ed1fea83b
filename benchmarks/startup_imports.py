"""Start-up cost: package import time, `catalog --help`, and what a command imports.

Prints a table and writes JSON (default benchmarks/bench_startup_imports.json; the docs'
start-up tables come from benchmarks/startup.py, which reuses these cases). Each figure is the median of --repeats fresh processes
(the machine is shared and noisy; medians, not means).

    .venv/bin/python -m benchmarks.startup_imports [--repeats 7] [--json-out FILE]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

HEAVY = ("numpy", "scipy", "colour", "matplotlib", "moderngl", "OpenImageIO", "numba",
         "trimesh", "pvlib", "glfw", "imgui_bundle")

CASES = {
    "python -c pass (floor)": [sys.executable, "-c", "pass"],
    "import catalog": [sys.executable, "-c", "import catalog"],
    "import catalog.commands.cli + build parser": [sys.executable, "-c",
                                          "from catalog.commands.cli import build_parser; build_parser()"],
    "catalog --help": [sys.executable, "-m", "catalog", "--help"],
}

IMPORT_PROBES = {
    # what a module pulls in when imported: the viewer must not pull in scipy
    "catalog.commands.cli": "catalog.commands.cli",
    "catalog.render": "catalog.render",
    "catalog.viewer": "catalog.viewer",
    "catalog.optics.lights": "catalog.optics.lights",
    "catalog.optics.fluorescence": "catalog.optics.fluorescence",
}


def time_command(cmd: list[str], repeats: int) -> float:
    """Median wall time of ``repeats`` fresh processes, after one untimed run (so that the
    first case, the floor, does not pay alone for a cold file cache)."""
    subprocess.run(cmd, check=True, capture_output=True)
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def heavy_imports_of(module: str) -> list[str] | None:
    code = (f"import sys, json, importlib\n"
            f"try:\n    importlib.import_module({module!r})\n"
            f"except ModuleNotFoundError:\n    print('null'); raise SystemExit\n"
            f"print(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r}))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout
    return json.loads(out) if out.strip() else None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--quick", action="store_true", help="3 repeats")
    from catalog.core.resources import PROJECT_ROOT  # noqa: PLC0415

    parser.add_argument("--json-out", type=Path,
                        default=PROJECT_ROOT / "benchmarks" / "bench_startup_imports.json")
    args = parser.parse_args(argv)
    repeats = 3 if args.quick else args.repeats

    rows = []
    floor = None
    for name, cmd in CASES.items():
        seconds = time_command(cmd, repeats)
        floor = seconds if floor is None else floor
        rows.append({"case": name, "median_s": seconds, "ratio_to_python": seconds / floor})
    print(f"{'case':40s} {'median ms':>10s} {'x python':>9s}")
    for row in rows:
        print(f"{row['case']:40s} {row['median_s'] * 1e3:10.1f} {row['ratio_to_python']:9.2f}")
    imports = {name: heavy_imports_of(mod) for name, mod in IMPORT_PROBES.items()}
    print("\nheavy modules imported by importing:")
    for name, heavy in imports.items():
        print(f"  {name:24s} {'(absent)' if heavy is None else ', '.join(heavy) or 'none'}")
    from benchmarks.results import machine_info  # noqa: PLC0415
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    result = {"benchmark": "startup", "repeats": repeats, "rows": rows, "imports": imports,
              "machine": machine_info()}
    args.json_out.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.json_out, json.dumps(result, indent=2) + "\n")
    print(f"wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
