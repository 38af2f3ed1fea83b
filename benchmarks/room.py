"""The room lit through the curtain (issue 13): frame time with and without, side by side.

    .venv/bin/python -m benchmarks.room [--size 1280x720] [--repeats 7] [--quick]
        [--json benchmarks/bench_room.json]

In one run, one context, one renderer (lace-fwa under sun:60, the default view), frames of
four configurations, interleaved round by round so that the shared machine's load falls on
all alike (median of the rounds):

- ``without``: the constant room (the box file under the ambient and fill stand-ins), flat sky, no bloom;
- ``room+sky, static``: room lighting (the key's maps, the room's transport) and the clear
  sky; the room's light drawn once and reused (a still cloth: the viewer's usual case);
- ``room+sky, moving, light every 4th frame``: the viewer's choice on llvmpipe for a moving
  cloth (the frame time is the mean over 4 frames, one of them a redraw);
- ``room+sky, moving``: the same, every pass every frame (a simulated cloth);
- ``room+sky+bloom, moving``: and the glare.

The goal of issue 13: ``room+sky`` at most 1.5x ``without``. Each pass's share comes from a
separate profiled frame (the GL queue finished around each pass). The GPU estimate counts
each pass's work (fragments x loop iterations) and divides by a stated nominal throughput;
it is an estimate, not a measurement (no device was lent to this run).
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path


#: Nominal GPU throughput for the estimate: shaded fragment-iterations per second (a
#: mid-range discrete GPU runs ~1e11 simple fragment operations/s; a loop iteration of the
#: light-map gather is ~10 of them).
GPU_ITERATIONS_PER_S = 1.0e10

#: moving: the room's light is redrawn every this many frames (0: never, a still cloth).
CONFIGS = (
    ("without", dict(room_lighting=False, sky_model=False, bloom=False, moving=0)),
    ("room+sky, static", dict(room_lighting=True, sky_model=True, bloom=False, moving=0)),
    ("room+sky, moving, light every 4th frame", dict(room_lighting=True, sky_model=True,
                                                      bloom=False, moving=4)),
    ("room+sky, moving", dict(room_lighting=True, sky_model=True, bloom=False, moving=1)),
    ("room+sky+bloom, moving", dict(room_lighting=True, sky_model=True, bloom=True, moving=1)),
)


def _configure(renderer, config) -> None:
    renderer.update(room_lighting=config["room_lighting"],
                    sky_model=config["sky_model"],
                    bloom=config["bloom"])


def _frame(renderer, ctx, config, index: int = 0) -> float:
    if config["moving"] and index % config["moving"] == 0:
        renderer.invalidate_room_light()
    start = time.perf_counter()
    renderer.render()
    ctx.finish()
    return time.perf_counter() - start


def work_counts(size) -> dict[str, float]:
    """Fragment-iterations per pass (the GPU estimate's numerator)."""
    from catalog.render.curtain_frames import SHADOW_TEXELS  # noqa: PLC0415
    from catalog.render.passes import room_transport_light as rtl  # noqa: PLC0415
    from catalog.render.room_operators import room_operators  # noqa: PLC0415

    w, h = size
    n = SHADOW_TEXELS
    nu, nv = room_operators("box").patches
    views = (rtl.CAPTURE_THETA * rtl.CAPTURE_PHI + rtl.WINDOW_SIDE_THETA * rtl.WINDOW_SIDE_PHI)
    texels = nu * nv * rtl.CAPTURE_TEXELS_PER_PATCH ** 2
    return {
        "room_shadow": 0.6 * n * n,
        # the room transport's parallel views of the window: the flat cloth (about 5 iterations
        # a fragment, as the curtain's) over each view's texels; its host work is not counted
        "room_transport": float(views * texels * 5),
        "room": 0.5 * w * h,
        # ROOM_SIDE: the transport's grid and the cloth's two sides per vertex
        "curtain": 0.5 * w * h * 5,
        "background": 0.2 * w * h,
        "bloom": w * h * (0.25 + 6 / 16 + 1),
        "meter": float(w * h) / 16,
        "display": float(w * h),
    }


def run(quick: bool = False, ctx=None, size=(1280, 720), repeats: int = 7) -> dict:
    from catalog.gl.context import create_headless_context  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415

    own = ctx is None
    if own:
        ctx = create_headless_context()
    if quick:
        size, repeats = (320, 180), 3
    renderer = FrameRenderer(ctx, size)
    renderer.update(fabric="lace-fwa", light="sun:60")
    samples = {name: [] for name, _ in CONFIGS}
    for name, config in CONFIGS:  # warm-up: compile every variant
        _configure(renderer, config)
        _frame(renderer, ctx, config)
        _frame(renderer, ctx, config)
    for _ in range(repeats):
        for name, config in CONFIGS:
            _configure(renderer, config)
            _frame(renderer, ctx, config)  # the switch's own first frame is not timed
            # as many frames as the update period, so that one in each is a redraw
            frames = [_frame(renderer, ctx, config, i) for i in range(max(1, config["moving"]))]
            samples[name].append(sum(frames) / len(frames))
    base = statistics.median(samples["without"])
    rows = []
    counts = work_counts(size)
    for name, config in CONFIGS:
        _configure(renderer, config)
        renderer.render()  # the switch's own redraw is not profiled
        profile: dict[str, float] = {}
        count = 4
        for i in range(count):
            if config["moving"] and i % config["moving"] == 0:
                renderer.invalidate_room_light()
            renderer.render(profile=profile)
        total = sum(profile.values())
        passes = {k: {"ms": 1000 * v / count, "share": v / total} for k, v in profile.items()}
        gpu_ms = 1000 * sum(counts[k] for k in profile) / GPU_ITERATIONS_PER_S
        median = statistics.median(samples[name])
        rows.append({"config": name, "frame_ms": 1000 * median, "ratio": median / base,
                     "best_ratio": min(samples[name]) / min(samples["without"]),
                     "passes": passes, "gpu_estimate_ms": gpu_ms})
    renderer.release()
    if own:
        ctx.release()
    by = {row["config"]: row for row in rows}
    return {"size": list(size), "repeats": repeats, "rows": rows,
            "summary": {"goal_ratio": 1.5,
                        "static_ratio": by["room+sky, static"]["ratio"],
                        "every_4th_ratio": by["room+sky, moving, light every 4th frame"]["ratio"],
                        "moving_ratio": by["room+sky, moving"]["ratio"],
                        "bloom_ratio": by["room+sky+bloom, moving"]["ratio"]}}


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/bench_room.json"

def markdown_tables(result: dict) -> dict[str, str]:
    w, h = result["size"]
    lines = [f"| configuration ({w}x{h}, llvmpipe) | frame ms (median) | x without | best-round x | GPU estimate ms |",
             "|---|---:|---:|---:|---:|"]
    for row in result["rows"]:
        lines.append(f"| {row['config']} | {row['frame_ms']:.1f} | {row['ratio']:.2f} | "
                     f"{row['best_ratio']:.2f} | {row['gpu_estimate_ms']:.2f} |")
    names = []
    for row in result["rows"]:
        for name in row["passes"]:
            if name not in names:
                names.append(name)
    passes = ["| pass | " + " | ".join(row["config"] for row in result["rows"]) + " |",
              "|---|" + "---:|" * len(result["rows"])]
    for name in names:
        cells = []
        for row in result["rows"]:
            p = row["passes"].get(name)
            cells.append(f"{p['ms']:.1f} ms ({100 * p['share']:.0f} %)" if p else "-")
        passes.append(f"| {name} | " + " | ".join(cells) + " |")
    return {"room_frame": "\n".join(lines), "room_passes": "\n".join(passes)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--json", default=None, help="write the result here")
    args = parser.parse_args(argv)
    from catalog.core.cliargs import parse_wxh  # noqa: PLC0415

    size = parse_wxh(args.size, "--size", 1, 16384)
    result = run(args.quick, size=size, repeats=args.repeats)
    for table in markdown_tables(result).values():
        print(table)
        print()
    if args.json:
        from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

        write_text_atomic(Path(args.json), json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
