"""The figures of docs/exchange.md: a lace the project draws (tools/make_lace_scan.py),
imported with ``catalog import`` and rendered by ``catalog snapshot`` in the room under
daylight and under UV; the import's JSON (with the commit it was made on) beside them.

    .venv/bin/python tools/make_exchange_figures.py [--out docs/img]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VIEWS = {"daylight": ("sun:1.5", None), "uv": ("UV-385", None), "daylight_close": ("sun:1.5", 0.6)}


def _catalog(argv: list[str]) -> dict:
    from catalog.commands.cli import main

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        status = main(argv + ["--json"])
    if status != 0:
        raise SystemExit(f"make_exchange_figures: catalog {' '.join(argv)} failed ({status})")
    return json.loads(buffer.getvalue())


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "img")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT / "tools"))
    from make_lace_scan import write_scan

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip()
    scan = args.out / "exchange_scan.png"
    write_scan(scan, size=512)
    record = {"commit": commit, "source": scan.name, "renders": {}}
    with tempfile.TemporaryDirectory() as folder:
        record["import"] = _catalog(["import", str(scan), "--name", "drawn-lace", "--out", folder])
        preset = str(Path(folder) / "drawn-lace.toml")
        for view, (light, distance) in VIEWS.items():
            out = args.out / f"exchange_{view}.png"
            extra = [] if distance is None else ["--distance", str(distance)]
            report = _catalog(["snapshot", "--fabric", preset, "--light", light, "--size",
                               "480x270", "--out", str(out), *extra])
            record["renders"][view] = {"file": out.name, "light": light, "distance_m": distance,
                                       "mean_srgb8": report["mean_srgb8"]}
    from catalog.core.atomic import write_text_atomic

    write_text_atomic(args.out / "exchange.json", json.dumps(record, indent=2) + "\n")
    print(f"wrote {scan} and {len(VIEWS)} renders under {args.out} (commit {commit})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
