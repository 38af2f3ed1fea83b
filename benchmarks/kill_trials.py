"""Kill trials: SIGTERM and SIGINT at random moments to the commands that write, each run
over a folder that already holds that command's good outputs, every outcome classified.

    python -m benchmarks.kill_trials [--trials 200] [--seed 37] [--budget-s 1500]
                                        [--json benchmarks/kill_trials.json]

Per command, one full run first makes the good outputs (the "base") and measures the run
time T; each trial copies the base into a fresh folder, starts the command over it (with
arguments that make it write new content: another light, a frame more), waits a uniform
random time in [0.05 s, 1.1 T] and sends the signal (to the process group, as a terminal's
Ctrl-C or a supervisor does). Outcomes counted:

- ``lost``: an output of the base is missing afterwards;
- ``torn``: an output is neither the base's bytes nor a whole new file (images read back
  with their size, TOML and JSON parsed, the web site's manifest complete);
- ``litter``: a temporary file or staging folder of the output layer is left;
- ``hang``: the process had not exited 5 s after the signal (then killed);
- ``slow``: it exited, but more than 1 s after the signal (the promise);
- ``crash``: an exit status other than 0 (finished first), 130 or 143, a negative one (a
  segfault), or a traceback on stderr.

The run stops when the trials are done or the time budget is spent (the JSON says how many
ran). Commands run as subprocesses of this checkout (PYTHONPATH).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

from catalog.core.resources import FABRIC_DIR, PROJECT_ROOT

#: The committed results the docs' generated block is made from (tools/docs_figures.py):
#: every command, and a later run of one command after a fix (``--commands fit``).
RESULT_JSONS = {"all commands, on the final code (200 trials)": "benchmarks/kill_trials.json",
                "fit, after them": "benchmarks/kill_trials_fit.json",
                "all commands, after them": "benchmarks/kill_trials_after.json"}
HANG_S = 5.0
PROMISE_S = 1.0
GONIO = FABRIC_DIR / "measurements" / "voile-white" / "gonio.csv"
OUTCOMES = ("clean", "lost", "torn", "litter", "hang", "slow", "crash")


@dataclass(frozen=True)
class Command:
    name: str
    base: tuple[str, ...]    # makes the good outputs in {dir}
    trial: tuple[str, ...]   # the killed run over them (writes new content)
    outputs: tuple[str, ...]  # files (relative to {dir}) that must stay whole


def commands() -> list[Command]:
    snap = ("snapshot", "--fabric", "voile-white", "--size", "96x72", "--out", "{dir}/s.png")
    sheet = ("sheet", "--fabric", "voile-white,net-grey", "--size", "48x36", "--out",
             "{dir}/sheet")
    fit = ("fit", "--gonio", str(GONIO), "--name", "p", "--out", "{dir}/p.toml", "--plot",
           "{dir}/p.png")
    ref = ("reference", "--fabric", "voile-white", "--size", "48x36", "--out", "{dir}/r.exr")
    web = ("web", "--fabric", "voile-white", "--out", "{dir}/site")
    batch = ("render-catalog", "--fabric", "voile-white", "--lights", "D65", "--size", "48x36",
             "--out", "{dir}/cat")
    return [
        Command("snapshot", snap + ("--light", "D65"), snap + ("--light", "A"), ("s.png",)),
        Command("sheet", sheet + ("--lights", "D65"), sheet + ("--lights", "A,FL2"),
                ("sheet/grid.png",)),
        Command("fit", fit, fit + ("--tau", "0.3"), ("p.toml", "p.png")),
        Command("reference", ref + ("--spp", "4"), ref + ("--spp", "48", "--seed", "7"),
                ("r.exr",)),
        Command("web", web + ("--lights", "D65"), web + ("--lights", "A"), ("site/index.html",)),
        Command("render-catalog", batch + ("--frames", "0:2"), batch + ("--frames", "0:6"),
                ("cat/manifest.json",)),
    ]


def _argv(args: tuple[str, ...], folder: Path) -> list[str]:
    return [a.replace("{dir}", str(folder)) for a in args]


def _run(args: list[str], **kw) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(PROJECT_ROOT))
    return subprocess.Popen([sys.executable, "-m", "catalog", *args], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, **kw)


def _whole(path: Path) -> bool:
    """A file that is complete as its kind: an image read back, TOML or JSON parsed."""
    try:
        suffix = path.suffix.lower()
        if suffix in (".png", ".exr"):
            import OpenImageIO as oiio  # noqa: PLC0415

            buf = oiio.ImageBuf(str(path))
            pixels = buf.get_pixels(oiio.FLOAT)
            return pixels is not None and pixels.size > 0 and not buf.has_error
        if suffix == ".toml":
            tomllib.loads(path.read_text(encoding="utf-8"))
            return True
        if suffix == ".json":
            json.loads(path.read_text(encoding="utf-8"))
            return True
        return path.stat().st_size > 0
    except Exception:  # noqa: BLE001 - anything unreadable is torn
        return False


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}


def _site_whole(site: Path) -> bool:
    try:
        manifest = json.loads((site / "catalog-web-site.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return all((site / name).is_file() for name in manifest.get("files", []))


def classify(command: Command, folder: Path, base: dict[str, bytes], status: int | None,
             latency_s: float, stderr: str) -> str:
    from catalog.core.atomic import STAGE_MARKER, TEMP_MARK  # noqa: PLC0415

    if status is None:
        return "hang"
    if status not in (0, 130, 143) or "Traceback" in stderr:
        return "crash"
    now = _snapshot(folder)
    if any(name not in now for name in base):
        return "lost"
    for name, data in now.items():
        path = folder / name
        if TEMP_MARK in name or STAGE_MARKER in name:
            return "litter"
        if base.get(name) != data and path.suffix.lower() in (".png", ".exr", ".toml", ".json") \
                and not _whole(path):
            return "torn"
    if (folder / "site").exists() and not _site_whole(folder / "site"):
        return "torn"
    if latency_s > PROMISE_S:
        return "slow"
    return "clean"


def run_trials(trials: int, seed: int, budget_s: float, only: list[str] | None = None) -> dict:
    rng = random.Random(seed)
    commit = _commit()  # the code measured: the checkout as it is when the run starts
    chosen = [c for c in commands() if only is None or c.name in only]
    work = Path(tempfile.mkdtemp(prefix="kill-trials-"))
    started = time.monotonic()
    results: dict[str, dict] = {}
    bases: dict[str, tuple[Path, dict, float]] = {}
    try:
        for command in chosen:
            folder = work / f"base-{command.name}"
            folder.mkdir()
            t0 = time.monotonic()
            proc = _run(_argv(command.base, folder))
            _, err = proc.communicate(timeout=900)
            if proc.returncode != 0:
                raise SystemExit(f"kill_trials: {command.name}: the base run failed: {err[-400:]}")
            # the full trial run's time: where the kills are spread
            probe = work / f"probe-{command.name}"
            shutil.copytree(folder, probe, symlinks=True)
            t0 = time.monotonic()
            proc = _run(_argv(command.trial, probe))
            proc.communicate(timeout=900)
            run_s = time.monotonic() - t0
            shutil.rmtree(probe)
            bases[command.name] = (folder, _snapshot(folder), run_s)
            results[command.name] = {"run_s": round(run_s, 2), "trials": 0,
                                     **dict.fromkeys(OUTCOMES, 0), "latency_s": []}
        failures = []
        for index in range(trials):
            if time.monotonic() - started > budget_s:
                break
            command = chosen[index % len(chosen)]
            base_folder, base, run_s = bases[command.name]
            folder = work / f"trial-{index}"
            shutil.copytree(base_folder, folder, symlinks=True)
            signum = rng.choice((signal.SIGTERM, signal.SIGINT))
            delay = rng.uniform(0.05, 1.1 * run_s)
            proc = _run(_argv(command.trial, folder))
            time.sleep(delay)
            sent = time.monotonic()
            with_signal = proc.poll() is None
            if with_signal:
                os.killpg(proc.pid, signum)
            try:
                _, err = proc.communicate(timeout=HANG_S)
                status, latency = proc.returncode, time.monotonic() - sent
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                _, err = proc.communicate()
                status, latency = None, HANG_S
            if not with_signal:
                latency = 0.0
            outcome = classify(command, folder, base, status, latency, err or "")
            row = results[command.name]
            row["trials"] += 1
            row[outcome] += 1
            if with_signal and status is not None:
                row["latency_s"].append(round(latency, 3))
            if outcome != "clean":
                failures.append({"command": command.name, "signal": int(signum),
                                 "delay_s": round(delay, 3), "outcome": outcome,
                                 "status": status, "stderr": (err or "")[-300:]})
            shutil.rmtree(folder, ignore_errors=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    for row in results.values():
        lat = sorted(row.pop("latency_s"))
        row["signalled"] = len(lat)
        row["latency_median_s"] = lat[len(lat) // 2] if lat else None
        row["latency_max_s"] = lat[-1] if lat else None
    total = {k: sum(r[k] for r in results.values()) for k in ("trials", *OUTCOMES)}
    return {"commands": results, "total": total, "trials_asked": trials, "seed": seed,
            "wall_s": round(time.monotonic() - started, 1), "failures": failures,
            "commit": commit, "machine": _machine()}


def _commit() -> str | None:
    try:
        return subprocess.run(["git", "-C", str(PROJECT_ROOT), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, timeout=10).stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        return None


def _machine() -> dict:
    from benchmarks.results import machine_info  # noqa: PLC0415

    return machine_info()


def markdown_tables(results: dict) -> dict[str, str]:
    """One table per run (``results``: label -> result), in the order of RESULT_JSONS."""
    return {"kill_trials": "\n\n".join(f"**{label}**\n\n" + _table(result)
                                         for label, result in results.items())}


def _table(result: dict) -> str:
    head = ("| command | trials | " + " | ".join(OUTCOMES) + " | exit after signal, median / max s |\n"
            "|---|---|" + "---|" * len(OUTCOMES) + "---|")
    lines = [head]
    for name, row in [*result["commands"].items(), ("all", None)]:
        counts = row if row is not None else result["total"]
        label = "**all**" if row is None else name
        latency = "" if row is None else f"{row['latency_median_s']} / {row['latency_max_s']}"
        lines.append(f"| {label} | {counts['trials']} | "
                     + " | ".join(str(counts[k]) for k in OUTCOMES) + f" | {latency} |")
    lines.append("")
    lines.append(f"{result['total']['trials']} of {result['trials_asked']} trials asked ran "
                 f"(seed {result['seed']}, {result['wall_s']:.0f} s, commit {result['commit']}, "
                 f"load average {result['machine'].get('load_average_1min') or 0:.1f} on "
                 f"{result['machine'].get('cpu_count')} cores at the end).")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int, default=200)
    parser.add_argument("--seed", type=int, default=37)
    parser.add_argument("--budget-s", type=float, default=1500.0,
                        help="stop starting trials after this many seconds")
    parser.add_argument("--commands", default=None, help="comma-separated subset")
    parser.add_argument("--json", type=Path, default=PROJECT_ROOT / "benchmarks" / "kill_trials.json")
    args = parser.parse_args(argv)
    only = args.commands.split(",") if args.commands else None
    result = run_trials(args.trials, args.seed, args.budget_s, only)
    print(_table(result))
    for failure in result["failures"]:
        print(f"  {failure['command']}: signal {failure['signal']} at {failure['delay_s']} s "
              f"-> {failure['outcome']} (status {failure['status']})")
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    write_text_atomic(args.json, json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
