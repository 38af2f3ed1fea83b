"""``catalog web``'s build: wall time, CPU time and peak memory of writing the site.

    .venv/bin/python -m benchmarks.web_build [--fabric NAME[,NAME..]] [--label TEXT]

Runs ``catalog web --json`` in a child process (``/usr/bin/time``-style: its own resource
usage and its children's, i.e. the cloth bake's process) and adds the run to the committed
JSON's ``runs`` under ``--label`` (default: the fabrics), with the commit and the machine it
ran on; earlier runs (other commits) stay, so the table shows before and after. Peak memory
is the largest resident set of the command's processes (the bake's child runs before the
frames are recorded, not beside them), and of each stage of the build
(catalog.web.site.STAGES: its VmHWM, reset at the stage's start; the bake's stage is the
parent's while its child bakes).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

RESULT_JSON = "benchmarks/bench_web_build.json"

_CHILD = """
import json, resource, sys, tempfile, time
from pathlib import Path
from catalog.web.site import build_site
fabrics = sys.argv[1] or None
with tempfile.TemporaryDirectory() as tmp:
    start = time.perf_counter()
    report = build_site(Path(tmp) / "site", fabrics=fabrics, stage_peaks=True)
    wall = time.perf_counter() - start
me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
stages = report.get("stage_peak_mb", {})  # (the stages' resets lower ru_maxrss to the last one's)
print(json.dumps({"scenes": report["scenes"], "fabrics": len(report["fabrics"]),
                  "total_bytes": report["total_bytes"], "wall_s": round(wall, 1),
                  "bake_s": report["bake_s"], "record_s": report["record_s"],
                  "cpu_s": round(me.ru_utime + me.ru_stime, 1),
                  "child_cpu_s": round(kids.ru_utime + kids.ru_stime, 1),
                  "peak_mb": max([round(me.ru_maxrss / 1024), *stages.values()]),
                  "stage_peak_mb": stages, "child_peak_mb": round(kids.ru_maxrss / 1024)}))
"""


def measure(fabrics: str | None) -> dict:
    import os  # noqa: PLC0415
    import subprocess  # noqa: PLC0415

    from benchmarks.results import machine_info  # noqa: PLC0415
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    machine = machine_info()
    done = subprocess.run([sys.executable, "-c", _CHILD, fabrics or ""], capture_output=True,
                          text=True, env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    if done.returncode != 0:
        raise CatalogError(f"catalog web failed: {done.stderr.strip().splitlines()[-1:]}")
    run = json.loads(done.stdout.strip().splitlines()[-1])
    machine["load_average_after"] = os.getloadavg()[0]
    return {**run, "machine": machine, "measured": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def _stage_cell(run: dict) -> str:
    """The run's peak resident set by stage ("bake 250, swatches 490, .. MB"), in the
    build's order; "not recorded" for a run made before the stages were measured."""
    from catalog.web.site import STAGES  # noqa: PLC0415

    peaks = run.get("stage_peak_mb") or {}
    if not peaks:
        return "not recorded"
    names = [n for n in STAGES if n in peaks] + [n for n in peaks if n not in STAGES]
    return ", ".join(f"{n} {peaks[n]}" for n in names) + " MB"


def markdown_tables(result: dict) -> dict[str, str]:
    """``web_build``: each run's scenes, wall and CPU time and peak memory, with its commit
    and the load it ran at."""
    rows = ["| run | commit | fabrics | scenes | wall | CPU (bake's child) | peak memory (bake's child) "
            "| peak memory by stage | load (1 min) |",
            "|---|---|---|---|---|---|---|---|---|"]
    for label, run in result["runs"].items():
        machine = run.get("machine", {})
        rows.append(f"| {label} | {machine.get('commit') or 'not recorded'} | {run['fabrics']} | "
                    f"{run['scenes']} | {run['wall_s']:.0f} s | {run['cpu_s']:.0f} s "
                    f"({run.get('child_cpu_s', 0):.0f} s) | {run['peak_mb']} MB "
                    f"({run.get('child_peak_mb', 0)} MB) | {_stage_cell(run)} | "
                    f"{machine.get('load_average_1min', float('nan')):.1f} |")
    return {"web_build": "\n".join(rows) + "\n\nEach run at the commit it names."}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415
    from catalog.core.resources import PROJECT_ROOT  # noqa: PLC0415

    def add_arguments(parser) -> None:
        parser.add_argument("--fabric", default=None, help="fabrics (default: every fabric)")
        parser.add_argument("--label", default=None, help="the run's name in the table")

    def make_result(args) -> dict:
        path = PROJECT_ROOT / RESULT_JSON
        result = json.loads(path.read_text()) if path.is_file() else {"runs": {}}
        run = measure(args.fabric)
        label = args.label or f"{args.fabric or 'whole catalog'}"
        result["runs"][label] = run
        result["machine"] = run["machine"]
        return result

    return study_main(sys.modules[__name__], argv, make_result=make_result,
                      add_arguments=add_arguments)


if __name__ == "__main__":
    sys.exit(main())
