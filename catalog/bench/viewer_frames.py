"""Viewer frame time and its parts (simulation, shading, UI, other) in a real window.

Runs `catalog view --frames N --stats` under a private Xvfb (Mesa llvmpipe through GLX)
for each case, takes the median of the per-frame parts after a warm-up (the first frames
pay for imports, shader compiles and the cloth's JIT), prints a table and writes JSON.

    .venv/bin/python -m catalog.bench.viewer_frames [--frames 60] [--warmup 10] [--json-out FILE]
        [--cases 1280x720:48x64,1920x1080:128x128] [--render-scale auto|S]

On a machine with a display of its own, --display :0 uses it instead of Xvfb.

``--before REV`` (e.g. the commit before issue 12): the same cases also run on that commit's
tree (``git archive`` into a temporary folder, its own ``catalog`` package, shaders and
fabrics; same Python environment), interleaved with this tree's runs (``--rounds`` of each),
so the two viewers' frame times come from one run. A GRID of ``default`` passes no
``--grid`` (each version's own default drape). :func:`markdown_tables` renders that JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from catalog.core.resources import PROJECT_ROOT as ROOT  # noqa: E402
PARTS = ("total", "simulation", "shading", "ui", "other")
DEFAULT_CASES = ("1280x720:48x64", "1920x1080:48x64", "1920x1080:128x128")


def start_xvfb() -> tuple[subprocess.Popen, str]:
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        raise SystemExit("bench_viewer: Xvfb not found (tools/setup.sh installs it)")
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen([xvfb, "-displayfd", str(write_fd), "-screen", "0", "1920x1080x24",
                             "-nolisten", "tcp"], pass_fds=(write_fd,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_fd)
    number = b""
    while not number.endswith(b"\n"):
        chunk = os.read(read_fd, 16)
        if not chunk:
            break
        number += chunk
    os.close(read_fd)
    return proc, f":{number.strip().decode()}"


def checkout(rev: str, into: Path) -> Path:
    """``rev``'s tree (git archive) extracted into ``into``; refused with one line if git fails."""
    archive = subprocess.run(["git", "archive", "--format=tar", rev], cwd=ROOT,
                             capture_output=True)
    if archive.returncode != 0:
        raise SystemExit(f"bench_viewer: --before {rev}: {archive.stderr.decode().strip()}")
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive.stdout, check=True)
    return into


def run_case(display: str, size: str, grid: str, frames: int, warmup: int, backend: str,
             fabric: str, light: str, render_scale: str, room_light: bool = True,
             tree: Path = ROOT) -> dict:
    env = dict(os.environ, DISPLAY=display)
    env.pop("WAYLAND_DISPLAY", None)
    if tree != ROOT:   # that tree's package before the editable install of this one
        env["PYTHONPATH"] = str(tree)
    grid_args = [] if grid == "default" else ["--grid", grid]
    cmd = [sys.executable, "-m", "catalog", "view", "--size", size, *grid_args,
           "--cloth-backend", backend, "--frames", str(frames + warmup), "--stats",
           "--wind", "2.0", "--fabric", fabric, "--light", light, "--render-scale", render_scale]
    if not room_light:
        cmd.append("--no-room-light")
    start = time.perf_counter()
    result = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=tree)
    wall = time.perf_counter() - start
    if result.returncode != 0:
        raise SystemExit(f"bench_viewer: {' '.join(cmd)} failed:\n{result.stderr}")
    records = [json.loads(line) for line in result.stdout.splitlines() if line.startswith("{")]
    frames_rec = [r for r in records if "frame" in r and not r.get("summary")]
    summary = next(r for r in records if r.get("summary"))
    first = frames_rec[0]
    steady = frames_rec[warmup:]
    if grid == "default":
        grid = "x".join(str(v) for v in summary.get("grid", ["default"])) + " (default)"
    row = {"size": size, "grid": grid,
           "backend": summary["cloth_backend"], "frames": len(steady),
           "render_scale": summary["render_scale"],
           "first_frame_ms": round(first["total_ms"], 1), "wall_s": round(wall, 1),
           "scipy_imported": first["heavy_modules"]["scipy"]}
    for part in PARTS:
        values = [r[f"{part}_ms"] for r in steady]
        row[f"{part}_ms"] = round(statistics.median(values), 2)
    row["fps"] = round(1e3 / row["total_ms"], 1) if row["total_ms"] > 0 else None
    return row


def _write_report(args, fields: dict) -> None:
    """The run's JSON (the machine, then ``fields``) into ``args.json_out``, atomically."""
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    report = {"machine": {"cpu_count": os.cpu_count(), "platform": platform.platform(),
                          "python": platform.python_version(), "display": "Xvfb + Mesa llvmpipe"
                          if args.display is None else args.display}, **fields}
    write_text_atomic(args.json_out, json.dumps(report, indent=2) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--warmup", type=int, default=10)
    parser.add_argument("--cases", default=",".join(DEFAULT_CASES),
                        help="comma-separated SIZE:GRID, e.g. 1920x1080:128x128")
    parser.add_argument("--backend", default="auto", choices=("auto", "cpu", "numpy", "gpu"))
    parser.add_argument("--fabric", default="lace-fwa")
    parser.add_argument("--light", default="D65")
    parser.add_argument("--render-scale", default="auto",
                        help="scene resolution / window resolution, or auto (the viewer's default)")
    parser.add_argument("--display", help="use this X display instead of a private Xvfb")
    parser.add_argument("--room-light", choices=("on", "off", "both"), default="on",
                        help="the room lit through the curtain (issue 13); both: each case "
                             "without and with, side by side")
    parser.add_argument("--json-out", type=Path, default=ROOT / "benchmarks" / "viewer.json")
    parser.add_argument("--before", metavar="REV",
                        help="also run every case on this commit's tree, interleaved")
    parser.add_argument("--rounds", type=int, default=1,
                        help="with --before: runs of each version per case (medians kept)")
    args = parser.parse_args(argv)
    if args.before:
        return main_before_after(args)

    xvfb = None
    display = args.display
    if display is None:
        xvfb, display = start_xvfb()
    try:
        rows = []
        for case in args.cases.split(","):
            size, grid = case.split(":")
            settings = {"on": (True,), "off": (False,), "both": (False, True)}[args.room_light]
            for room_light in settings:
                rows.append(run_case(display, size, grid, args.frames, args.warmup, args.backend,
                                     args.fabric, args.light, args.render_scale, room_light))
                rows[-1]["room_light"] = room_light
                row = rows[-1]
                print(f"{row['size']:>10} x{row['render_scale']} grid {row['grid']:>8} room light "
                      f"{'on ' if room_light else 'off'}: "
                      f"total {row['total_ms']:7.1f} ms ({row['fps']} fps) = simulation "
                      f"{row['simulation_ms']:6.1f} + shading {row['shading_ms']:6.1f} + UI "
                      f"{row['ui_ms']:5.1f} + other {row['other_ms']:5.1f}; first frame "
                      f"{row['first_frame_ms']} ms", flush=True)
    finally:
        if xvfb is not None:
            xvfb.terminate()
            xvfb.wait()
    _write_report(args, {"frames": args.frames, "warmup": args.warmup, "fabric": args.fabric,
                         "light": args.light, "rows": rows})
    print(f"wrote {args.json_out}")
    return 0


def main_before_after(args) -> int:
    """Each case on the ``--before`` tree and on this one, interleaved, ``--rounds`` times."""
    xvfb = None
    display = args.display
    if display is None:
        xvfb, display = start_xvfb()
    rows = []
    try:
        with tempfile.TemporaryDirectory(prefix="bench-viewer-before-") as folder:
            before = checkout(args.before, Path(folder))
            for case in args.cases.split(","):
                size, grid = case.split(":")
                runs: dict[str, list[dict]] = {"before": [], "after": []}
                for _ in range(args.rounds):
                    for version, tree in (("before", before), ("after", ROOT)):
                        # the before tree may predate --no-room-light: only "after" gets it
                        room_light = version == "before" or args.room_light != "off"
                        runs[version].append(run_case(display, size, grid, args.frames,
                                                      args.warmup, args.backend, args.fabric,
                                                      args.light, args.render_scale,
                                                      room_light, tree))
                for version, version_runs in runs.items():
                    row = dict(version_runs[0])
                    for part in PARTS:
                        row[f"{part}_ms"] = round(statistics.median(
                            r[f"{part}_ms"] for r in version_runs), 2)
                    row["fps"] = round(1e3 / row["total_ms"], 1)
                    row["version"] = (f"before ({args.before})" if version == "before"
                                      else "after (this tree)")
                    row["case"] = case
                    rows.append(row)
                    print(f"{row['version']:>22} {size} grid {row['grid']}: total "
                          f"{row['total_ms']:7.1f} ms = simulation {row['simulation_ms']:6.1f}"
                          f" + shading {row['shading_ms']:6.1f} + UI {row['ui_ms']:5.1f} + "
                          f"other {row['other_ms']:5.1f}", flush=True)
    finally:
        if xvfb is not None:
            xvfb.terminate()
            xvfb.wait()
    _write_report(args, {"before": args.before, "rounds": args.rounds, "frames": args.frames,
                         "warmup": args.warmup, "fabric": args.fabric, "light": args.light,
                         "rows": rows})
    print(f"wrote {args.json_out}")
    return 0


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/viewer_pattern.json"

def markdown_tables(result: dict) -> dict[str, str]:
    """``viewer_before_after`` (a --before run's JSON): NAME -> markdown table."""
    lines = ["| viewer | window | grid | frame ms (median) | simulation | shading | UI | other "
             "| / before |", "|---|---|---|---|---|---|---|---|---|"]
    base = {}
    for row in result["rows"]:
        if row.get("version", "").startswith("before"):
            base[row["case"]] = row["total_ms"]
        ratio = row["total_ms"] / base[row["case"]] if row["case"] in base else float("nan")
        lines.append(f"| {row['version']} | {row['size']} x{row['render_scale']} | {row['grid']} "
                     f"| {row['total_ms']:.1f} | {row['simulation_ms']:.1f} | "
                     f"{row['shading_ms']:.1f} | {row['ui_ms']:.1f} | {row['other_ms']:.1f} | "
                     f"{ratio:.2f} |")
    return {"viewer_before_after": "\n".join(lines)}


if __name__ == "__main__":
    sys.exit(main())
