"""The room light by the precomputed transport against the box's special-case light, on the
path tracer (the accuracy bench's scenes, neutral display and FLIP: benchmarks/accuracy.py),
and what a room update and a static frame cost (llvmpipe, 1280x720).

``python -m benchmarks.room_light accuracy --scenes N --seed S --rooms box,living --size 160x90 --spp 128``
``python -m benchmarks.room_light cost``
Each writes benchmarks/bench_room_light_{accuracy,cost}.json (with the commit measured).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def git_commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              cwd=HERE, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def frame_linear(ctx, desc, preset, light, room: str | None, repeats: int = 3) -> tuple[np.ndarray, float]:
    """The frame's linear radiance as benchmarks.image.frame_images draws it, in ``room``
    (None: the box's special-case light), and its median render time (s)."""
    from benchmarks.image import frame_images  # noqa: PLC0415

    frame = frame_images(ctx, desc, preset, light, 3, "physical", repeats=repeats, room=room)
    return frame["linear"], frame["seconds"]


def cached_reference(acc, scene, size, spp, own, cache_dir):
    """benchmarks.accuracy.reference_halves, kept in ``cache_dir`` (None: not kept) by scene,
    room, size and spp (a rerun of the frame's side reuses the references)."""
    if cache_dir is None:
        return acc.reference_halves(scene, size, spp, own)
    import hashlib  # noqa: PLC0415

    key = hashlib.sha256(json.dumps([scene["label"], scene["room"], list(size), spp]).encode()).hexdigest()[:16]
    path = Path(cache_dir) / f"reference-{key}.npz"
    if path.exists():
        with np.load(path) as data:
            return {"a": data["a"], "b": data["b"], "seconds": float(data["seconds"]),
                    "masks": {k[5:]: data[k] for k in data.files if k.startswith("mask_")}}
    halves = acc.reference_halves(scene, size, spp, own)
    Path(cache_dir).mkdir(parents=True, exist_ok=True)
    np.savez(path, a=halves["a"], b=halves["b"], seconds=halves["seconds"],
             **{f"mask_{k}": v for k, v in halves["masks"].items()})
    return halves


def accuracy(scenes: int, seed: int, rooms: list[str], size, spp: int, cache_dir=None,
             only: list[int] | None = None, variants: dict | None = None) -> dict:
    from benchmarks import accuracy as acc  # noqa: PLC0415
    from catalog.gl.context import create_headless_context  # noqa: PLC0415
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.pathtrace import metrics  # noqa: PLC0415
    from catalog.pathtrace.render import reference_settings  # noqa: PLC0415
    from catalog.pathtrace.scene import describe_scene  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415

    ctx = create_headless_context()
    own: dict = {}
    rows = []
    for room in rooms:
        for number, scene in enumerate(acc.draw_scenes(scenes, seed, room)):
            if only is not None and number not in only:
                continue
            preset = load_preset(find_preset(scene["fabric"]))
            light = get_light(scene["light"])
            cam = scene["camera"]
            desc = describe_scene(reference_settings(preset, light, yaw_deg=cam["yaw_deg"],
                                                     pitch_deg=cam["pitch_deg"],
                                                     distance_m=cam["distance_m"], room=room),
                                  size=tuple(size))
            scene["_desc"] = desc
            halves = cached_reference(acc, scene, size, spp, own, cache_dir)
            scene.pop("_desc")
            reference = 0.5 * (halves["a"] + halves["b"])
            scale = acc.exposure_from_reference(reference)
            shown_reference = acc.neutral_display(reference, scale)
            noise = float(metrics.flip_map(acc.neutral_display(halves["a"], scale),
                                           acc.neutral_display(halves["b"], scale)).mean())
            row = {k: v for k, v in scene.items() if not k.startswith("_")}
            row.update({"size": list(size), "spp": spp, "reference_flip_noise": noise,
                        "reference_s": float(halves["seconds"])})
            masks = halves["masks"]
            lights = {"transport": room} if room != "box" else {"special_case": None, "transport": room}
            if variants:
                lights = {name: value for name, value in variants.items()
                          if room == "box" or value is not None}
            for name, frame_room in lights.items():
                linear, wall = frame_linear(ctx, desc, preset, light, frame_room)
                flip = metrics.flip_map(acc.neutral_display(linear, scale), shown_reference)
                row[name] = {"mean_flip": float(flip.mean()), "frame_ms": 1e3 * wall,
                             "regions": acc.region_flip(flip, masks)}
            rows.append(row)
            print(room, row["label"], {k: round(row[k]["mean_flip"], 4) for k in lights},
                  "noise", round(noise, 4), flush=True)
    summary = {}
    for room in rooms:
        sel = [r for r in rows if r["room"] == room]
        names = [k for k in sel[0] if isinstance(sel[0][k], dict) and "mean_flip" in sel[0][k]] if sel else []
        summary[room] = {name: {"median_mean_flip": float(np.median([r[name]["mean_flip"] for r in sel])),
                                "mean_mean_flip": float(np.mean([r[name]["mean_flip"] for r in sel])),
                                "max_mean_flip": float(np.max([r[name]["mean_flip"] for r in sel]))}
                         for name in names}
    return {"commit": git_commit(), "settings": {"scenes": scenes, "seed": seed, "size": list(size),
                                                 "spp": spp, "display": "benchmarks.accuracy neutral"},
            "rows": rows, "summary": summary}


def cost(size=(1280, 720), repeats: int = 7) -> dict:
    """Wall and process CPU time (ms, medians) of a room update (the curtain moved: every room
    pass and the frame) and of a static frame (nothing stale), with no room light (the
    constant room), the special-case light and the transport's in box and living. The
    configurations are measured in turns, one frame each per round, so that a shared
    machine's load falls on all alike; CPU time counts this process's threads (llvmpipe's
    included) and little of other processes', its ratios the steadier."""
    from catalog.gl.context import create_headless_context, describe  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415
    from catalog.render.settings import orbit  # noqa: PLC0415

    ctx = create_headless_context()
    configs = (("none", None, False), ("special_case", None, True),
               ("transport_box", "box", True), ("transport_living", "living", True))
    renderers, setup = {}, {}
    for name, room, lit in configs:
        renderer = FrameRenderer(ctx, size)
        renderer.update(fabric="lace-fwa", light="D65", room_lighting=lit)
        if room is not None:
            start = time.perf_counter()
            renderer.update(room=room)
            setup[name] = time.perf_counter() - start
        renderer.update(camera=orbit(20.0, -5.0, 2.8, inside=True))
        renderer.render()
        renderers[name] = renderer
    samples = {name: {"static": [], "update": [], "static_cpu": [], "update_cpu": []} for name in renderers}

    def timed(work):
        ctx.finish()
        wall, cpu = time.perf_counter(), time.process_time()
        work()
        ctx.finish()
        return time.perf_counter() - wall, time.process_time() - cpu

    def update(renderer):
        renderer.invalidate_room_light()
        renderer.render()

    try:
        for _ in range(repeats):
            for name, renderer in renderers.items():
                wall, cpu = timed(renderer.render)
                samples[name]["static"].append(wall)
                samples[name]["static_cpu"].append(cpu)
                wall, cpu = timed(lambda r=renderer: update(r))
                samples[name]["update"].append(wall)
                samples[name]["update_cpu"].append(cpu)
        out = {}
        for name, renderer in renderers.items():
            profile: dict = {}
            renderer.invalidate_room_light()
            renderer.render(profile=profile)
            med = {k: 1e3 * float(np.median(v)) for k, v in samples[name].items()}
            out[name] = {"static_frame_ms": med["static"], "static_frame_cpu_ms": med["static_cpu"],
                         "room_update_frame_ms": med["update"], "room_update_frame_cpu_ms": med["update_cpu"],
                         "profile_ms": {k: round(1e3 * v, 2) for k, v in profile.items()}}
            if name in setup:
                out[name]["set_room_s"] = setup[name]
            print(name, out[name], flush=True)
    finally:
        for renderer in renderers.values():
            renderer.release()
    base = out["none"]
    for name in out:
        out[name]["static_vs_no_room_light"] = out[name]["static_frame_ms"] / base["static_frame_ms"]
        out[name]["static_cpu_vs_no_room_light"] = out[name]["static_frame_cpu_ms"] / base["static_frame_cpu_ms"]
    return {"commit": git_commit(), "size": list(size), "repeats": repeats, "gl": describe(ctx),
            "results": out,
            "note": ("a room update redraws every room pass and the frame (invalidate_room_light); "
                     "static: nothing stale. Configurations in turns, medians; wall and process CPU "
                     "time on a shared llvmpipe machine (2 cores).")}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.room_light")
    parser.add_argument("what", choices=("accuracy", "cost"))
    parser.add_argument("--scenes", type=int, default=6)
    parser.add_argument("--seed", type=int, default=33033)
    parser.add_argument("--rooms", default="box,living")
    parser.add_argument("--size", default="160x90")
    parser.add_argument("--spp", type=int, default=128)
    parser.add_argument("--out", default=None)
    parser.add_argument("--reference-cache", default=None, help="a folder keeping the references")
    parser.add_argument("--only", default=None, help="scene numbers to measure, e.g. 3,4")
    args = parser.parse_args(argv)
    if args.what == "accuracy":
        w, h = (int(v) for v in args.size.split("x"))
        only = None if args.only is None else [int(v) for v in args.only.split(",")]
        result = accuracy(args.scenes, args.seed, args.rooms.split(","), (w, h), args.spp,
                          args.reference_cache, only)
    else:
        result = cost()
    path = Path(args.out or HERE / f"bench_room_light_{args.what}.json")
    path.write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    print(json.dumps(result.get("summary", result.get("results")), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
