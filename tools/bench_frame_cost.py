#!/usr/bin/env python3
"""Frame cost of a checkout against another, 1280x720 on this machine's GL (llvmpipe here).

    .venv/bin/python tools/bench_frame_cost.py --base OTHER_CHECKOUT [--repeats 7] [--json OUT]

For each checkout (the base and this one) a child process renders the settled drape of each
fabric under D65 with the same camera (yaw 0, pitch 0, 2.6 m: the composition both have) and,
in this checkout, the default room view; it times ``FrameRenderer.render()`` plus the read-back
(``ctx.finish()`` inside), the median of ``--repeats`` after one warm-up. Prints a table and
writes JSON naming both commits; the ratio is from this one run.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

CHILD = r'''
import json, statistics, sys, time
from pathlib import Path
from catalog.gl.context import create_headless_context
from catalog.render.frame import FrameRenderer
from catalog.render.snapshot import ring_xs_m, simulated_curtain
from catalog.presets import find_preset, load_preset
from catalog.render.settings import orbit
fabrics, repeats, views = sys.argv[1].split(","), int(sys.argv[2]), sys.argv[3].split(",")
ctx = create_headless_context()
r = FrameRenderer(ctx, (1280, 720))
out = {}
for name in fabrics:
    preset = load_preset(find_preset(name))
    r.update(fabric=preset, light="D65")
    *mesh, size = simulated_curtain(preset, 0)
    r.set_mesh(*mesh, fabric_size_m=size); r.set_rings(ring_xs_m(preset))
    for view in views:
        if view == "front":
            r.update(camera=orbit(0.0, 0.0, 2.6))
        else:
            from catalog.render.views import VIEWS
            v = VIEWS[view]
            r.update(camera=orbit(v.yaw_deg, v.pitch_deg, v.distance_m, target=v.target, fov_y_deg=v.fov_y_deg))
        r.render(); r.read_srgb8()
        times = []
        for _ in range(repeats):
            t = time.perf_counter(); r.render(); r.read_srgb8(); times.append(time.perf_counter() - t)
        out[f"{name}/{view}"] = statistics.median(times)
print(json.dumps(out))
'''


def commit_of(path: Path) -> str:
    return subprocess.run(["git", "-C", str(path), "rev-parse", "--short", "HEAD"],
                          capture_output=True, text=True).stdout.strip()


def run(checkout: Path, fabrics, repeats, views) -> dict:
    env = dict(os.environ, PYTHONPATH=str(checkout))
    done = subprocess.run([sys.executable, "-c", CHILD, ",".join(fabrics), str(repeats),
                           ",".join(views)], env=env, capture_output=True, text=True,
                          cwd=str(checkout), timeout=1800)
    if done.returncode != 0:
        raise SystemExit(f"bench_frame_cost: {checkout}: {done.stderr.strip().splitlines()[-1]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", type=Path, required=True, help="the checkout to compare with")
    parser.add_argument("--fabrics", default="lace-fwa,linen-dense,voile-white")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    fabrics = args.fabrics.split(",")
    base = run(args.base, fabrics, args.repeats, ["front"])
    ours = run(ROOT, fabrics, args.repeats, ["front", "room"])
    rows = []
    print(f"{'fabric':14s} {'base front ms':>14s} {'ours front ms':>14s} {'ratio':>6s} {'ours room ms':>13s} {'ratio':>6s}")
    for name in fabrics:
        b, f, room = base[f"{name}/front"], ours[f"{name}/front"], ours[f"{name}/room"]
        rows.append({"fabric": name, "base_front_s": b, "front_s": f, "room_s": room,
                     "front_ratio": f / b, "room_ratio": room / b})
        print(f"{name:14s} {1e3 * b:14.1f} {1e3 * f:14.1f} {f / b:6.2f} {1e3 * room:13.1f} {room / b:6.2f}")
    report = {"size": [1280, 720], "repeats": args.repeats, "base_commit": commit_of(args.base),
              "commit": commit_of(ROOT), "rows": rows}
    if args.json:
        args.json.write_text(json.dumps(report, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
