"""Start-up: import time, `catalog --help`, and time from the command to its first frame.

Reuses benchmarks/startup_imports.py (import and --help cases, the heavy modules a module
pulls in) and benchmarks/viewer_frames.py (a private Xvfb). Added here: the wall time of a
fresh process ``catalog snapshot ... --size 640x360`` (EGL, one frame written) and
``catalog view --frames 1`` in a 640x360 window under Xvfb (one frame shown), each from
process start to exit after the first frame, median of repeats; and which heavy modules
the viewer process had loaded at its first frame (it must not load scipy), beside the
import cost of colour-science and numba (which loads scipy itself when it is installed).
"""

from __future__ import annotations

import importlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from catalog.core.resources import PROJECT_ROOT


def load_script(name: str):
    """A benchmark module of benchmarks/ (each also runs as ``python -m``)."""
    return importlib.import_module(f"benchmarks.{name}")


def wall_seconds(cmd: list[str], repeats: int, env: dict | None = None) -> tuple[float, str]:
    """Median wall time of a fresh process; raises with its stderr if it fails."""
    samples, out = [], ""
    for _ in range(repeats):
        start = time.perf_counter()
        result = subprocess.run(cmd, capture_output=True, text=True, cwd=PROJECT_ROOT, env=env)
        samples.append(time.perf_counter() - start)
        if result.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed: {result.stderr.strip()[-400:]}")
        out = result.stdout
    return statistics.median(samples), out


def run(quick: bool = False, ctx=None, *, first_frames: bool = True, repeats=None) -> dict:
    """Import and --help times, heavy imports; with ``first_frames`` also the snapshot and
    viewer processes to their first frame."""
    startup = load_script("startup_imports")
    repeats = repeats or (3 if quick else 7)
    rows = []
    floor = None
    for name, cmd in startup.CASES.items():
        seconds = startup.time_command(cmd, repeats)
        floor = seconds if floor is None else floor
        rows.append({"case": name, "median_s": seconds, "ratio_to_python": seconds / floor})
    # colour-science: every light and CMF comes through it, and it loads scipy and matplotlib
    seconds = startup.time_command([sys.executable, "-c", "import colour"], repeats)
    rows.append({"case": "import colour (colour-science)", "median_s": seconds,
                 "ratio_to_python": seconds / floor})
    # numba: the viewer's default cloth backend; importing it loads scipy when installed
    seconds = startup.time_command([sys.executable, "-c", "import numba"], repeats)
    rows.append({"case": "import numba (cpu cloth backend)", "median_s": seconds,
                 "ratio_to_python": seconds / floor})
    imports = {name: startup.heavy_imports_of(module) for name, module in startup.IMPORT_PROBES.items()}
    for module in ("colour", "numba", "catalog.cloth.backend_numba"):
        imports[module] = startup.heavy_imports_of(module)

    frame_repeats = 1 if quick else 3
    viewer_heavy = None
    rows_note = None if first_frames else "first frames not timed (first_frames=False)"
    if first_frames:
        viewer_heavy, rows_note = first_frame_rows(rows, floor, frame_repeats)
    viewer_imports_scipy = ("scipy" in (imports.get("catalog.viewer") or [])
                            or "scipy" in (viewer_heavy or {}).get("loaded", []))
    return {"rows": rows,
            "summary": {"import_catalog_s": next(r["median_s"] for r in rows if r["case"] == "import catalog"),
                        "help_s": next(r["median_s"] for r in rows if r["case"] == "catalog --help"),
                        "viewer_imports_scipy": viewer_imports_scipy,
                        "heavy_imports": imports, "viewer_heavy_at_first_frame": viewer_heavy},
            "settings": {"repeats": repeats, "frame_repeats": frame_repeats,
                         **({"note": rows_note} if rows_note else {})}}


def first_frame_rows(rows: list[dict], floor: float, frame_repeats: int):
    """Append the snapshot and viewer first-frame rows; returns (the viewer's heavy modules
    at its first frame, a note when the viewer could not be timed)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "first.png"
        snapshot_cmd = [sys.executable, "-m", "catalog", "snapshot", "--fabric", "lace-fwa",
                        "--light", "D65", "--size", "640x360", "--out", str(out), "--json"]
        seconds, stdout = wall_seconds(snapshot_cmd, frame_repeats)
        report = json.loads(stdout)
        rows.append({"case": "catalog snapshot 640x360 (start to written frame)",
                     "median_s": seconds, "ratio_to_python": seconds / floor,
                     "render_s": float(report.get("render_s", 0.0))})
    viewer_heavy = None
    try:
        viewer = load_script("viewer_frames")
        xvfb, display = viewer.start_xvfb()
    except (SystemExit, OSError) as exc:
        rows_note = f"catalog view not timed: {exc}"
    else:
        rows_note = None
        try:
            env = dict(os.environ, DISPLAY=display)
            env.pop("WAYLAND_DISPLAY", None)
            view_cmd = [sys.executable, "-m", "catalog", "view", "--size", "640x360",
                        "--frames", "1", "--stats", "--fabric", "lace-fwa", "--light", "D65"]
            seconds, stdout = wall_seconds(view_cmd, frame_repeats, env)
            records = [json.loads(line) for line in stdout.splitlines() if line.startswith("{")]
            first = next((r for r in records if "heavy_modules" in r), {})
            checked = first.get("heavy_modules")
            viewer_heavy = None if checked is None else {"checked": sorted(checked),
                                                         "loaded": sorted(k for k, v in checked.items() if v)}
            rows.append({"case": "catalog view 640x360, Xvfb (start to first frame, exit)",
                         "median_s": seconds, "ratio_to_python": seconds / floor,
                         "first_frame_ms": float(first.get("total_ms", 0.0))})
        finally:
            xvfb.terminate()
            xvfb.wait()
    return viewer_heavy, rows_note


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/bench_startup.json"
#: Rows of the short table in BENCHMARKS.md.
BRIEF_CASES = ("catalog --help", "import colour (colour-science)", "import numba (cpu cloth backend)",
               "catalog snapshot 640x360 (start to written frame)",
               "catalog view 640x360, Xvfb (start to first frame, exit)")


def markdown_tables(result: dict) -> dict[str, str]:
    """``startup`` (every case and what each import loads, docs/bench.md) and
    ``startup_brief`` (BENCHMARKS.md)."""
    from benchmarks.results import fmt  # noqa: PLC0415

    s, st = result["summary"], result["settings"]

    def rows_md(rows) -> str:
        return "\n".join(["| case | median s | x `python -c pass` |", "|---|---|---|"]
                          + [f"| {r['case']} | {fmt(r['median_s'])} | {fmt(r['ratio_to_python'])} |"
                             for r in rows])

    from benchmarks.startup_imports import HEAVY  # noqa: PLC0415

    found = {k: v for k, v in s["heavy_imports"].items() if v is not None}
    light = [k for k, v in found.items() if not v]
    imports = (f"Importing {', '.join(f'`{k}`' for k in light) or 'no probed module'} loads none of "
               f"{', '.join(HEAVY)}; " if light else "")
    imports += "; ".join(f"`import {k}` loads {', '.join(v)}" for k, v in found.items() if v) + "."
    heavy = s["viewer_heavy_at_first_frame"]
    if heavy:
        viewer = (f"The viewer process at its first frame had loaded, of "
                  f"{', '.join(heavy['checked'])}: {', '.join(heavy['loaded']) or 'none'}")
        view_row = next((r for r in result["rows"] if r["case"].startswith("catalog view")), None)
        if view_row and view_row.get("first_frame_ms"):
            viewer += (f"; of its {fmt(view_row['median_s'])} s, the first frame itself took "
                       f"{fmt(view_row['first_frame_ms'] / 1e3)} s (`--stats`), the rest is imports, "
                       "the window and the GL context")
        viewer += "."
    else:
        viewer = f"The viewer was not timed ({st.get('note', 'no display')})."
    repeats = (f"Fresh processes, median of {st['repeats']} (first frames: of "
               f"{st['frame_repeats']}).")
    text = f"{imports} {viewer}"
    brief = [r for r in result["rows"] if r["case"] in BRIEF_CASES]
    return {"startup": f"{repeats}\n\n{rows_md(result['rows'])}\n\n{text}",
            "startup_brief": f"{rows_md(brief)}\n\n{repeats} {text}"}


if __name__ == "__main__":
    from benchmarks.results import section_main  # noqa: PLC0415

    raise SystemExit(section_main("startup"))
