"""The viewer's per-frame work without its window: the cloth step and the scene's shading.

A frame here is what `catalog view` does each frame minus the window (no panel, no copy to
the screen, no swap): the curtain's simulation step for a 1/60 s frame (the viewer's
``CurtainScene``, the chosen cloth backend) and the renderer's frame (``FrameRenderer``:
room light, shadow map, curtain, glare, display transform) at the window's size, in a
standalone EGL context. So it runs where there is no display, e.g. on a GPU server, and
it tells what a GPU does with the frame that docs/viewer.md measured in a window on
llvmpipe.

Each part ends with ``ctx.finish()`` so its wall-clock time holds the GPU's work. Medians
of ``--frames`` frames after ``--warmup`` frames (shader compiles, first uploads).

    python -m benchmarks.headless_frames [--cases 1920x1080:128x128,...]
        [--backend auto|gpu|numpy|cpu] [--frames 60] [--warmup 10] [--json-out FILE]

``auto`` is the viewer's own choice: the compute cloth on a GPU, numpy on a software
rasteriser. :func:`markdown_tables` renders the JSON (benchmarks/headless_frames_*.json).
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

from catalog.core.constants import FRAME_DT_S

#: the committed runs (on an NVIDIA H200 and on this project's 2-core llvmpipe machine)
RESULT_JSON = "benchmarks/headless_frames.json"
DEFAULT_CASES = ("1280x720:48x64", "1920x1080:48x64", "1920x1080:128x128")
PARTS = ("total", "simulation", "shading")


def parse_case(text: str) -> tuple[tuple[int, int], tuple[int, int]]:
    """``WxH:GXxGY`` -> ((w, h), (gx, gy)); SystemExit with one line when malformed."""
    try:
        size, grid = text.split(":")
        w, h = (int(v) for v in size.lower().split("x"))
        gx, gy = (int(v) for v in grid.lower().split("x"))
    except ValueError:
        raise SystemExit(f"headless_frames: --cases: {text!r} is not WxH:GXxGY "
                         "(e.g. 1920x1080:128x128)") from None
    if min(w, h, gx, gy) < 2:
        raise SystemExit(f"headless_frames: --cases: {text!r}: every size must be at least 2")
    return (w, h), (gx, gy)


def choose_backend(ctx, backend: str) -> str:
    if backend != "auto":
        return backend
    from catalog.render.passes.targets import software_rasteriser  # noqa: PLC0415

    return "numpy" if software_rasteriser(ctx.info) else "gpu"


def run_case(ctx, size: tuple[int, int], grid: tuple[int, int], backend: str, frames: int,
             warmup: int, fabric: str, light: str, wind_m_s: float,
             passes: bool = False, antialiasing: str = "auto") -> dict:
    """Median per-frame parts (ms) of one case; the renderer and the cloth are released.

    ``passes``: also the median of each render pass (FrameRenderer.render's profile: a
    ctx.finish() around each pass, so the shading total grows by those waits)."""
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415
    from catalog.viewer.scene import CurtainScene  # noqa: PLC0415

    preset = load_preset(find_preset(fabric))
    scene = CurtainScene(grid, backend=backend, wind_m_s=wind_m_s, ctx=ctx)
    renderer = FrameRenderer(ctx, size)
    renderer.update(antialiasing=antialiasing, bloom=True, room_lighting=True, sky_model=True,
                    room_update_every=1, fabric=preset, light=light)
    scene.set_fabric(preset)
    scene.set_wind(wind_m_s)
    start = time.perf_counter()
    parts: dict[str, list[float]] = {name: [] for name in PARTS}
    pass_ms: dict[str, list[float]] = {}
    try:
        for frame in range(warmup + frames):
            t0 = time.perf_counter()
            scene.step(FRAME_DT_S)
            scene.feed(renderer)
            ctx.finish()
            t1 = time.perf_counter()
            profile = {} if passes else None
            renderer.render(dt_s=FRAME_DT_S, profile=profile)
            ctx.finish()
            t2 = time.perf_counter()
            if profile and frame >= warmup:
                for name, seconds in profile.items():
                    pass_ms.setdefault(name, []).append(seconds * 1e3)
            if frame == 0:
                first_frame_s = t2 - start
            if frame >= warmup:
                parts["simulation"].append((t1 - t0) * 1e3)
                parts["shading"].append((t2 - t1) * 1e3)
                parts["total"].append((t2 - t0) * 1e3)
    finally:
        scene.forget(renderer)
        renderer.release()
    medians = {f"{name}_ms": round(statistics.median(values), 3) for name, values in parts.items()}
    return {"size": list(size), "grid": list(grid), "backend": backend,
            "antialiasing": renderer.antialiasing,
            "scene_values": "constants" if renderer.specialise else "uniforms", "frames": frames,
            "warmup": warmup, **medians,
            "fps": round(1e3 / medians["total_ms"], 1) if medians["total_ms"] > 0 else None,
            "first_frame_s": round(first_frame_s, 3),
            **({"passes_ms": {name: round(statistics.median(values), 3)
                              for name, values in pass_ms.items()}} if passes else {})}


def machine(ctx) -> dict:
    return {"renderer": ctx.info.get("GL_RENDERER", "?"),
            "gl_version": ctx.info.get("GL_VERSION", "?"),
            "cpu": platform.processor() or platform.machine(),
            "python": platform.python_version()}


def run(cases: list[str], backend: str = "auto", frames: int = 60, warmup: int = 10,
        fabric: str = "lace-fwa", light: str = "D65", wind_m_s: float = 2.0,
        passes: bool = False, antialiasing: str = "auto") -> dict:
    from catalog.gl.context import create_headless_context  # noqa: PLC0415

    parsed = [parse_case(text) for text in cases]
    ctx = create_headless_context()
    chosen = choose_backend(ctx, backend)
    rows = []
    for size, grid in parsed:
        row = run_case(ctx, size, grid, chosen, frames, warmup, fabric, light, wind_m_s, passes,
                       antialiasing)
        rows.append(row)
        print(f"{size[0]}x{size[1]} {grid[0]}x{grid[1]} {chosen}: total {row['total_ms']:.2f} ms "
              f"(simulation {row['simulation_ms']:.2f}, shading {row['shading_ms']:.2f})",
              file=sys.stderr, flush=True)
    return {"benchmark": "headless_frames", "machine": machine(ctx),
            "settings": {"fabric": fabric, "light": light, "wind_m_s": wind_m_s,
                         "frame_dt_s": FRAME_DT_S, "backend": backend, "frames": frames,
                         "warmup": warmup, "room_light": True, "bloom": True,
                         "render_scale": 1.0, "passes": passes,
                         "antialiasing": antialiasing},
            "rows": rows}


FRAME_HEADER = ("window", "cloth", "anti-aliasing", "scene values", "total ms", "fps",
                "simulation ms", "shading ms")


def _frame_cells(row: dict) -> list[str]:
    """One row's cells under FRAME_HEADER."""
    w, h = row["size"]
    gx, gy = row["grid"]
    return [f"{w}x{h}", f"{row['backend']} {gx}x{gy}", row["antialiasing"], row["scene_values"],
            f"{row['total_ms']:.1f}", f"{row['fps']:g}", f"{row['simulation_ms']:.1f}",
            f"{row['shading_ms']:.1f}"]


def _table(header: list[str] | tuple[str, ...], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(cells) + " |" for cells in rows])


def markdown_table(result: dict) -> str:
    """The rows of one run as a markdown table (ms, medians)."""
    return _table(FRAME_HEADER, [_frame_cells(row) for row in result["rows"]])


def _run_label(run: dict) -> str:
    """The machine, and for runs before issue 11's cloth shadows, that they were."""
    machine = "H200" if "NVIDIA" in run["machine"]["renderer"] else "llvmpipe (2 shared cores)"
    frame = run["settings"].get("frame", "before issue 11")
    return machine if frame.startswith("with issue 11") else f"{machine}, before issue 11"


#: the runs in the order the frame table lists them (today's GPU default first)
FRAME_RUNS = ("h200_gpu_cloth_fxaa_after11", "h200_gpu_cloth_msaa_after11", "h200_gpu_cloth_fxaa_uniforms", "h200_gpu_cloth_msaa_uniforms", "h200_gpu_cloth_fxaa",
              "h200_gpu_cloth", "h200_numba_cloth", "h200_numpy_cloth", "llvmpipe_numpy_cloth")
PASS_RUNS = ("h200_passes_fxaa_after11", "h200_passes_fxaa_uniforms", "h200_passes_fxaa", "h200_passes_msaa",
             "h200_passes_voile", "llvmpipe_numpy_cloth")
SUMMARY_RUNS = ("h200_gpu_cloth_fxaa_after11", "h200_gpu_cloth_msaa_after11", "h200_gpu_cloth_fxaa_uniforms", "h200_gpu_cloth_msaa_uniforms",
                "h200_gpu_cloth_fxaa", "h200_numba_cloth", "llvmpipe_numpy_cloth")


def _findings(runs: dict) -> str:
    """The figures docs/gpu.md's "What the figures say" rests on, from the same runs."""
    def row(key: str, size, grid) -> dict:
        return next(r for r in runs[key]["rows"] if r["size"] == list(size) and r["grid"] == list(grid))
    hd, big = (1920, 1080), (128, 128)
    gpu_sim = [r["simulation_ms"] for k, run in runs.items() if k.startswith("h200_")
               for r in run["rows"] if r["backend"] == "gpu"]
    grids = sorted({tuple(r["grid"]) for k, run in runs.items() if k.startswith("h200_gpu")
                    for r in run["rows"]}, key=lambda g: g[0] * g[1])
    numba = [row("h200_numba_cloth", hd, g)["simulation_ms"] for g in ((48, 64), big)]
    numpy_ = [row("h200_numpy_cloth", hd, g)["simulation_ms"] for g in ((48, 64), big)]
    constants = row("h200_gpu_cloth_fxaa", hd, big)["total_ms"]
    uniforms = row("h200_gpu_cloth_fxaa_uniforms", hd, big)["total_ms"]
    msaa = row("h200_gpu_cloth_msaa_uniforms", hd, big)["total_ms"]
    today = row("h200_gpu_cloth_fxaa_after11", hd, big)["total_ms"]
    today_msaa = row("h200_gpu_cloth_msaa_after11", hd, big)["total_ms"]
    shadow = [row(k, hd, big)["passes_ms"]["room_shadow"]
              for k in ("h200_passes_fxaa_uniforms", "h200_passes_fxaa_after11")]
    fxaa_passes = row("h200_passes_fxaa", hd, big)["passes_ms"]
    msaa_passes = row("h200_passes_msaa", hd, big)["passes_ms"]
    display = [r["passes_ms"]["display"] for k, run in runs.items() if k.startswith("h200_passes")
               for r in run["rows"] if r["size"] == list(hd) and "passes_ms" in r]
    llvmpipe = row("llvmpipe_numpy_cloth", hd, big)["total_ms"]
    budget = 1000.0 / 60.0
    lines = ["| figure (H200 unless named; medians of the runs above) | value |", "|---|---|",
             f"| compute cloth, 10 substeps, grids {grids[0][0]}x{grids[0][1]} to "
             f"{grids[-1][0]}x{grids[-1][1]} | {min(gpu_sim):.1f}-{max(gpu_sim):.1f} ms |",
             f"| numba cloth (16 cores), 48x64 / 128x128 | {numba[0]:.0f} / {numba[1]:.0f} ms |",
             f"| numpy cloth, 48x64 / 128x128 | {numpy_[0]:.0f} / {numpy_[1]:.0f} ms |",
             f"| frame, 1920x1080, 128x128, FXAA: scene values as constants -> uniforms | "
             f"{constants:.1f} -> {uniforms:.1f} ms |",
             f"| the same frame with MSAA 4x (uniforms) | {msaa:.1f} ms |",
             f"| with issue 11's cloth shadows, outside occlusion and ambient by view: FXAA / "
             f"MSAA (uniforms) | {today:.1f} / {today_msaa:.1f} ms |",
             f"| shadow pass (room, and since issue 11 the cloth's maps), FXAA: before -> with "
             f"issue 11 | {shadow[0]:.1f} -> {shadow[1]:.1f} ms |",
             f"| left of the {budget:.1f} ms budget for the panel and the swap (today's frame, "
             f"uniforms, FXAA) | {budget - today:.1f} ms |",
             f"| curtain pass of the passes' sum, 1920x1080, constants: FXAA / MSAA | "
             f"{fxaa_passes['curtain']:.1f} of {sum(fxaa_passes.values()):.1f} / "
             f"{msaa_passes['curtain']:.1f} of {sum(msaa_passes.values()):.1f} ms |",
             f"| display pass at 1920x1080 | {min(display):.1f}-{max(display):.1f} ms |",
             f"| llvmpipe (2 shared cores), 1920x1080, 128x128 (numpy cloth); x the H200's FXAA + "
             f"uniforms frame | {llvmpipe:.0f} ms; {llvmpipe / uniforms:.0f}x |"]
    return "\n".join(lines)


def markdown_tables(result: dict) -> dict[str, str]:
    """RESULT_JSON's runs as docs/gpu.md's tables: frames per machine, cloth backend,
    anti-aliasing and scene values (constants or uniforms); the render passes; a summary at
    1920x1080 with the 128x128 cloth; the curtain's accuracy against the float64 reference."""
    frames = _table(("machine", *FRAME_HEADER),
                    [[_run_label(result["runs"][key]), *_frame_cells(row)]
                     for key in FRAME_RUNS for row in result["runs"][key]["rows"]])
    rows = []
    for key in PASS_RUNS:
        run = result["runs"][key]
        rows += [(_run_label(run), run["settings"]["fabric"], r) for r in run["rows"] if "passes_ms" in r]
    names = list(rows[0][2]["passes_ms"]) if rows else []
    passes = ["| machine | fabric | window | cloth | anti-aliasing | scene values | "
              + " | ".join(names) + " |", "|---|---|---|---|---|---|" + "---|" * len(names)]
    for label, fabric, row in rows:
        w, h = row["size"]
        gx, gy = row["grid"]
        passes.append(f"| {label} | {fabric} | {w}x{h} | {gx}x{gy} | {row['antialiasing']} | "
                      f"{row['scene_values']} | "
                      + " | ".join(f"{row['passes_ms'].get(n, 0.0):.2f}" for n in names) + " |")
    summary = ["| machine | 1920x1080, 128x128 cloth | frame ms (fps) | cloth step ms | shading ms |",
               "|---|---|---|---|---|"]
    for key in SUMMARY_RUNS:
        run = result["runs"][key]
        for row in run["rows"]:
            if row["size"] == [1920, 1080] and row["grid"] == [128, 128]:
                summary.append(f"| {_run_label(run)} | {row['backend']} cloth, {row['antialiasing']}, "
                               f"scene values as {row['scene_values']} | {row['total_ms']:.1f} "
                               f"({row['fps']:g}) | {row['simulation_ms']:.1f} | {row['shading_ms']:.1f} |")
    accuracy = ["| light, fluorescence | H200, constants: max | median | H200, uniforms: max | "
                "median | llvmpipe, constants: max | median |", "|---|---|---|---|---|---|---|"]
    for case, gpu in result["accuracy_h200"].items():
        uniform = result["accuracy_h200_uniforms"][case]
        cpu = result["accuracy_llvmpipe"][case]
        accuracy.append(f"| {case} | {gpu['max']:.2e} | {gpu['median']:.2e} | {uniform['max']:.2e} | "
                        f"{uniform['median']:.2e} | {cpu['max']:.2e} | {cpu['median']:.2e} |")
    return {"viewer-headless-frames": frames,
            "viewer-gpu-findings": _findings(result["runs"]),
            "gpu-frame-summary": "\n".join(summary),
            "viewer-headless-passes": "\n".join(passes),
            "viewer-gpu-accuracy": "\n".join(accuracy)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.headless_frames",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", default=",".join(DEFAULT_CASES),
                        help="WxH:GXxGY,... window size and cloth grid per case")
    parser.add_argument("--backend", default="auto", choices=("auto", "gpu", "numpy", "cpu"))
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--warmup", type=int, default=10)
    parser.add_argument("--fabric", default="lace-fwa")
    parser.add_argument("--light", default="D65")
    parser.add_argument("--antialiasing", default="auto", choices=("auto", "fxaa", "msaa", "off"))
    parser.add_argument("--passes", action="store_true",
                        help="also time each render pass (adds a GL finish around each)")
    parser.add_argument("--json-out", type=Path, default=None,
                        help="write the JSON here (default: print it only)")
    args = parser.parse_args(argv)
    if args.frames < 1 or args.warmup < 0:
        parser.error("--frames must be at least 1 and --warmup at least 0")
    result = run([c for c in args.cases.split(",") if c], backend=args.backend,
                 frames=args.frames, warmup=args.warmup, fabric=args.fabric, light=args.light,
                 passes=args.passes, antialiasing=args.antialiasing)
    print(markdown_table(result))
    text = json.dumps(result, indent=1)
    if args.json_out is not None:
        from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

        write_text_atomic(args.json_out, text + "\n")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
