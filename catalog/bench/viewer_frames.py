"""Viewer frame time and its parts (simulation, shading, UI, other) in a real window.

Runs `catalog view --frames N --stats` under a private Xvfb (Mesa llvmpipe through GLX)
for each case, takes the median of the per-frame parts after a warm-up (the first frames
pay for imports, shader compiles and the cloth's JIT), prints a table and writes JSON.

    .venv/bin/python -m catalog.bench.viewer_frames [--frames 60] [--warmup 10] [--json-out FILE]
        [--cases 1280x720:48x64,1920x1080:128x128] [--render-scale auto|S]

On a machine with a display of its own, --display :0 uses it instead of Xvfb.
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


def run_case(display: str, size: str, grid: str, frames: int, warmup: int, backend: str,
             fabric: str, light: str, render_scale: str, room_light: bool = True) -> dict:
    env = dict(os.environ, DISPLAY=display)
    env.pop("WAYLAND_DISPLAY", None)
    cmd = [sys.executable, "-m", "catalog", "view", "--size", size, "--grid", grid,
           "--cloth-backend", backend, "--frames", str(frames + warmup), "--stats",
           "--wind", "2.0", "--fabric", fabric, "--light", light, "--render-scale", render_scale]
    if not room_light:
        cmd.append("--no-room-light")
    start = time.perf_counter()
    result = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT)
    wall = time.perf_counter() - start
    if result.returncode != 0:
        raise SystemExit(f"bench_viewer: {' '.join(cmd)} failed:\n{result.stderr}")
    records = [json.loads(line) for line in result.stdout.splitlines() if line.startswith("{")]
    frames_rec = [r for r in records if "frame" in r and not r.get("summary")]
    summary = next(r for r in records if r.get("summary"))
    first = frames_rec[0]
    steady = frames_rec[warmup:]
    row = {"size": size, "grid": grid, "backend": summary["cloth_backend"], "frames": len(steady),
           "render_scale": summary["render_scale"],
           "first_frame_ms": round(first["total_ms"], 1), "wall_s": round(wall, 1),
           "scipy_imported": first["heavy_modules"]["scipy"]}
    for part in PARTS:
        values = [r[f"{part}_ms"] for r in steady]
        row[f"{part}_ms"] = round(statistics.median(values), 2)
    row["fps"] = round(1e3 / row["total_ms"], 1) if row["total_ms"] > 0 else None
    return row


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
    args = parser.parse_args(argv)

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
    report = {"machine": {"cpu_count": os.cpu_count(), "platform": platform.platform(),
                          "python": platform.python_version(), "display": "Xvfb + Mesa llvmpipe"
                          if args.display is None else args.display},
              "frames": args.frames, "warmup": args.warmup, "fabric": args.fabric,
              "light": args.light, "rows": rows}
    args.json_out.parent.mkdir(parents=True, exist_ok=True)
    args.json_out.write_text(json.dumps(report, indent=2) + "\n")
    print(f"wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
