"""Viewer frame time and its parts (simulation, shading, UI, other) in a real window.

Runs `catalog view --frames N --stats` under a private Xvfb (Mesa llvmpipe through GLX)
for each case, takes the median of the per-frame parts after a warm-up (the first frames
pay for imports, shader compiles and the cloth's JIT), prints a table and writes JSON.

    .venv/bin/python -m benchmarks.viewer_frames [--frames 60] [--warmup 10] [--json-out FILE]
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
             tree: Path = ROOT, wind_m_s: float = 2.0, paused: bool = False) -> dict:
    env = dict(os.environ, DISPLAY=display)
    env.pop("WAYLAND_DISPLAY", None)
    if tree != ROOT:   # that tree's package before the editable install of this one
        env["PYTHONPATH"] = str(tree)
    grid_args = [] if grid == "default" else ["--grid", grid]
    cmd = [sys.executable, "-m", "catalog", "view", "--size", size, *grid_args,
           "--cloth-backend", backend, "--frames", str(frames + warmup), "--stats",
           "--wind", f"{wind_m_s:g}", "--fabric", fabric, "--light", light, "--render-scale", render_scale]
    if not room_light:
        cmd.append("--no-room-light")
    if paused:
        cmd.append("--paused")
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
           "scipy_imported": first["heavy_modules"]["scipy"],
           "gl_renderer": summary.get("renderer")}
    for part in PARTS:
        values = [r[f"{part}_ms"] for r in steady]
        row[f"{part}_ms"] = round(statistics.median(values), 2)
    row["fps"] = round(1e3 / row["total_ms"], 1) if row["total_ms"] > 0 else None
    return row


def _write_report(args, fields: dict) -> None:
    """The run's JSON (the machine, then ``fields``) into ``args.json_out``, atomically."""
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    from benchmarks.results import machine_info  # noqa: PLC0415

    renderers = sorted({row["gl_renderer"] for row in fields.get("rows", []) if row.get("gl_renderer")})
    report = {"machine": {**machine_info(), "display": "Xvfb" if args.display is None
                          else args.display, "gl_renderer": ", ".join(renderers) or None},
              **fields}
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
    parser.add_argument("--at-rest", action="store_true",
                        help="each case at wind 0 (the cloth settles and sleeps) beside the "
                             "same view paused (its static frame), interleaved --rounds times")
    args = parser.parse_args(argv)
    if args.before:
        return main_before_after(args)
    if args.at_rest:
        return main_at_rest(args)

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


def main_at_rest(args) -> int:
    """Each case at wind 0 (from the settled drape the cloth sleeps within its hold time,
    docs/cloth.md "Sleep") and paused (the static frame), interleaved ``--rounds`` times;
    the rows hold the medians and at rest / static."""
    xvfb = None
    display = args.display
    if display is None:
        xvfb, display = start_xvfb()
    rows = []
    try:
        for case in args.cases.split(","):
            size, grid = case.split(":")
            runs: dict[str, list[dict]] = {"at rest": [], "static": []}
            for _ in range(args.rounds):
                for mode in runs:
                    runs[mode].append(run_case(display, size, grid, args.frames, args.warmup,
                                               args.backend, args.fabric, args.light,
                                               args.render_scale, args.room_light != "off",
                                               wind_m_s=0.0, paused=mode == "static"))
            for mode, mode_runs in runs.items():
                row = dict(mode_runs[0])
                for part in PARTS:
                    row[f"{part}_ms"] = round(statistics.median(r[f"{part}_ms"]
                                                                for r in mode_runs), 2)
                row["fps"] = round(1e3 / row["total_ms"], 1)
                row.update(mode=mode, case=case)
                rows.append(row)
            rest, static = rows[-2], rows[-1]
            rest["over_static"] = round(rest["total_ms"] / static["total_ms"], 3)
            print(f"{size} grid {grid}: at rest {rest['total_ms']:.1f} ms (simulation "
                  f"{rest['simulation_ms']:.1f}), static {static['total_ms']:.1f} ms: "
                  f"{rest['over_static']:.2f}x", flush=True)
    finally:
        if xvfb is not None:
            xvfb.terminate()
            xvfb.wait()
    _write_report(args, {"at_rest": True, "rounds": args.rounds, "frames": args.frames,
                         "warmup": args.warmup, "fabric": args.fabric, "light": args.light,
                         "rows": rows})
    print(f"wrote {args.json_out}")
    return 0


def at_rest_table(result: dict) -> str:
    """An ``--at-rest`` run: the windless viewer's frame beside its paused (static) frame."""
    lines = ["| window | cloth | mode | frame ms (median) | simulation | shading | UI | other "
             "| at rest / static |", "|---|---|---|---|---|---|---|---|---|"]
    for row in result["rows"]:
        ratio = f"**{row['over_static']:.2f}**" if "over_static" in row else ""
        lines.append(f"| {row['size']} x{row['render_scale']:g} | "
                     f"{BACKEND_NAMES.get(row['backend'], row['backend'])} {row['grid']} | "
                     f"{row['mode']} | {row['total_ms']:.1f} | {row['simulation_ms']:.1f} | "
                     f"{row['shading_ms']:.1f} | {row['ui_ms']:.1f} | {row['other_ms']:.1f} | "
                     f"{ratio} |")
    load = result["machine"].get("load_average_1min")
    commit = result["machine"].get("commit")
    note = f"\n\n{result['rounds']} interleaved rounds of {result['frames']} frames after " \
           f"{result['warmup']} of warm-up, medians"
    if load is not None:
        note += f"; load average {load:.1f} on the shared machine"
    if commit:
        note += f"; measured on commit {commit}"
    return "\n".join(lines) + note + "."


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


#: The committed runs the docs' generated blocks are made from (tools/docs_figures.py), in
#: table order. ``pattern``: a ``--before`` run; ``room``: a ``--room-light both`` run; every
#: other entry is a plain run whose rows go into the frame-time table, so a run on another
#: machine (a GPU with ``--display``) is one more line here.
RESULT_JSONS = {
    "defaults": "benchmarks/viewer.json",
    "scale1": "benchmarks/viewer_scale1.json",
    "numpy_cloth": "benchmarks/viewer_numpy_cloth.json",
    "gpu_cloth": "benchmarks/viewer_gpu_cloth.json",
    "pattern": "benchmarks/viewer_pattern.json",
    "room": "benchmarks/viewer_room.json",
    "rest": "benchmarks/viewer_rest.json",
}
#: Keys of RESULT_JSONS that are not plain frame-time runs.
SPECIAL_RUNS = ("pattern", "room", "rest")
BACKEND_NAMES = {"cpu": "cpu (numba)", "numpy": "numpy", "gpu": "gpu (compute)"}


def before_after_table(result: dict) -> str:
    """A ``--before`` run's JSON as a markdown table, each row's frame over its case's before."""
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
    return "\n".join(lines)


def _renderer(run: dict, row: dict) -> str:
    name = row.get("gl_renderer") or run["machine"].get("gl_renderer") or run["machine"].get("display", "?")
    return name.split(" (")[0]  # "llvmpipe (LLVM 15.0.6, 256 bits)" -> "llvmpipe"


def frame_table(runs: dict[str, dict]) -> str:
    """The plain runs' rows: the frame's parts in ms, the machine's load while it ran."""
    lines = ["| GL | window | scene scale | cloth | load | total | fps | simulation | shading | UI "
             "| other | first frame |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for run in runs.values():
        load = run["machine"].get("load_average_1min")
        for row in run["rows"]:
            lines.append(
                f"| {_renderer(run, row)} | {row['size']} | {row['render_scale']:g} | "
                f"{BACKEND_NAMES.get(row['backend'], row['backend'])} {row['grid']} | "
                f"{'-' if load is None else f'{load:.1f}'} | {row['total_ms']:.0f} | {row['fps']} | "
                f"{row['simulation_ms']:.0f} | {row['shading_ms']:.0f} | {row['ui_ms']:.0f} | "
                f"{row['other_ms']:.0f} | {row['first_frame_ms'] / 1e3:.1f} s |")
    return "\n".join(lines)


def _row(run: dict, size: str, grid: str) -> dict | None:
    return next((r for r in run["rows"] if r["size"] == size and r["grid"] == grid), None)


def findings(runs: dict[str, dict]) -> str:
    """The comparisons docs/viewer.md's prose rests on, from the same runs."""
    out = []
    default, numpy_run = runs.get("defaults"), runs.get("numpy_cloth")
    if default and numpy_run:
        for size, grid in (("1280x720", "48x64"), ("1920x1080", "128x128")):
            a, b = _row(default, size, grid), _row(numpy_run, size, grid)
            if a and b and a["backend"] != b["backend"]:
                out.append(f"At {size} with a {grid} cloth the default {BACKEND_NAMES.get(a['backend'], a['backend'])} "
                           f"cloth costs {a['simulation_ms']:.0f} ms a frame against numpy's "
                           f"{b['simulation_ms']:.0f} ms ({b['simulation_ms'] / a['simulation_ms']:.1f}x), "
                           f"its first frame {a['first_frame_ms'] / 1e3:.1f} s against "
                           f"{b['first_frame_ms'] / 1e3:.1f} s.")
    scale1 = runs.get("scale1")
    if default and scale1:
        a, b = _row(default, "1920x1080", "48x64"), _row(scale1, "1920x1080", "48x64")
        if a and b and a["render_scale"] != b["render_scale"]:
            out.append(f"Rendering the scene at scale {a['render_scale']:g} instead of "
                       f"{b['render_scale']:g} (1920x1080) cuts shading from {b['shading_ms']:.0f} "
                       f"to {a['shading_ms']:.0f} ms ({b['shading_ms'] / a['shading_ms']:.1f}x; the "
                       f"pixels: {(b['render_scale'] / a['render_scale']) ** 2:.0f}x).")
    gpu = runs.get("gpu_cloth")
    if default and gpu:
        a, b = _row(default, "1920x1080", "128x128"), _row(gpu, "1920x1080", "128x128")
        if a and b and a["backend"] != b["backend"]:
            out.append(f"The compute-shader cloth at 128x128 on {_renderer(gpu, b)}: "
                       f"{b['simulation_ms']:.0f} ms a frame against {a['simulation_ms']:.0f} ms "
                       f"for the {BACKEND_NAMES.get(a['backend'], a['backend'])} cloth.")
    return " ".join(out)


def room_light_table(result: dict) -> str:
    """A ``--room-light both`` run: each case without and with the room lit through the curtain."""
    lines = ["| window | cloth | room light | frame ms (median) | simulation | shading | UI | other "
             "| with / without |", "|---|---|---|---|---|---|---|---|---|"]
    without = {}
    for row in result["rows"]:
        key = (row["size"], row["grid"])
        if not row.get("room_light"):
            without[key] = row["total_ms"]
        ratio = f"{row['total_ms'] / without[key]:.2f}" if row.get("room_light") and key in without else ""
        lines.append(f"| {row['size']} x{row['render_scale']:g} | {BACKEND_NAMES.get(row['backend'], row['backend'])} "
                     f"{row['grid']} | {'on' if row.get('room_light') else 'off'} | "
                     f"{row['total_ms']:.1f} | {row['simulation_ms']:.1f} | {row['shading_ms']:.1f} "
                     f"| {row['ui_ms']:.1f} | {row['other_ms']:.1f} | {ratio} |")
    load = result["machine"].get("load_average_1min")
    return "\n".join(lines) + ("" if load is None else f"\n\nLoad average while it ran: {load:.1f}.")


def markdown_tables(results: dict[str, dict]) -> dict[str, str]:
    """``viewer_before_after`` (the ``pattern`` run), ``viewer_room_light`` (the ``room`` run),
    ``viewer_at_rest`` (the ``rest`` run: ``--at-rest``),
    ``viewer_frames`` and ``viewer_findings`` (every other run, docs/viewer.md) and
    ``viewer_brief`` (the default run, BENCHMARKS.md)."""
    runs = {k: v for k, v in results.items() if k not in SPECIAL_RUNS}
    return {"viewer_before_after": before_after_table(results["pattern"]),
            "viewer_room_light": room_light_table(results["room"]),
            "viewer_at_rest": at_rest_table(results["rest"]),
            "viewer_frames": frame_table(runs), "viewer_findings": findings(runs),
            "viewer_brief": frame_table({"defaults": results["defaults"]})}


if __name__ == "__main__":
    sys.exit(main())
