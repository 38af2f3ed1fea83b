"""The curtain shader's cost per term, against the trivial shader on the same mesh (llvmpipe).

The frame's own curtain variant (the room view, the room's light on, the pattern and OIT,
the key shadow, the occlusion maps, the room-side and wall light, fluorescence) is drawn
alone (``CurtainPass.draw_curtain``: clear, depth test, one draw, finished), then the same
with one term's #define taken out (a bench-only build: the product has no setter for it),
then the trivial shader (benchmarks/shaders/trivial.frag: same vertex shader, mesh, target
and depth test). A term's cost is the full variant less the variant without it, all timed
in interleaved rounds (medians of the process's CPU time, which counts llvmpipe's threads
and little of the other processes' load; wall beside it). Ratios from one run.

    PYTHONPATH=. .venv/bin/python -m benchmarks.curtain_terms [--quick] [--sizes 1280x720,1920x1080]
    (prints the table, writes benchmarks/bench_curtain_terms.json)

The room terms (ROOM_SIDE, WALL_GRID; the window capture is another pass) are timed too,
so that their cost is known; this bench changes no shader.
"""

from __future__ import annotations

import statistics
import time

#: term label -> the defines taken out together (a term's helpers go with it)
TERMS = {
    "key shadow (KEY_SHADOW)": ("KEY_SHADOW",),
    # the wall light reads the sky occlusion's per-vertex table, so the two go out together
    "sky occlusion maps + wall light": ("SKY_OCCLUSION", "OCCLUSION_MAPS", "WALL_GRID"),
    "room side (ROOM_SIDE)": ("ROOM_SIDE",),
    "wall light (WALL_GRID)": ("WALL_GRID",),
    "pattern + OIT (PATTERN, OIT)": ("PATTERN", "OIT", "PATTERN_LOD_BIAS"),
    "fluorescence (FLUORESCENCE_PHYSICAL)": ("FLUORESCENCE_PHYSICAL",),
    "anisotropic lobes (ANISOTROPIC)": ("ANISOTROPIC",),
}
#: (fabric, light): the lace under D65 (its brightener barely excited) and the noon sun
SCENES = (("lace-fwa", "D65"), ("lace-fwa", "noon"))
DEFAULT_SIZES = ((1280, 720), (1920, 1080))
RESULT_JSON = "benchmarks/bench_curtain_terms.json"


def _light_name(light: str) -> str:
    if light == "noon":
        from catalog.render.scene import sun_at_hour  # noqa: PLC0415

        return sun_at_hour(12.0).light_name
    return light


def _drawer(renderer, drop=(), fragment=None):
    import moderngl  # noqa: PLC0415

    ctx, curtain = renderer.ctx, renderer.curtain
    view_proj = renderer.camera.view_projection(renderer.size[0] / renderer.size[1])
    own = curtain.variant_defines

    def draw():
        renderer.targets.hdr_fbo.use()
        ctx.viewport = (0, 0, *renderer.size)
        renderer.targets.hdr_fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        if drop:
            curtain.variant_defines = lambda *a, **k: {n: v for n, v in own(*a, **k).items()
                                                       if n not in drop}
        try:
            curtain.draw_curtain(view_proj, fragment=fragment)
        finally:
            curtain.variant_defines = own

    return draw


def run_scene(ctx, size, fabric, light, repeats) -> dict:
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415
    from catalog.render.settings import orbit  # noqa: PLC0415
    from catalog.render.snapshot import ring_xs_m, simulated_curtain  # noqa: PLC0415

    preset = load_preset(find_preset(fabric))
    *mesh, fabric_size_m = simulated_curtain(preset, 0)
    renderer = FrameRenderer(ctx, size)
    try:
        renderer.update(fabric=preset, light=_light_name(light), camera=orbit(20.0, 15.0, 2.6))
        renderer.set_mesh(*mesh, fabric_size_m=fabric_size_m)
        renderer.set_rings(ring_xs_m(preset))
        renderer.render()   # the room's light, shadow and occlusion maps the terms read
        full_defines = {k: v for k, v in renderer.curtain.variant_defines().items() if v}
        drawers = {"trivial": _drawer(renderer, fragment="trivial.frag"),
                   "full": _drawer(renderer)}
        present = {label: names for label, names in TERMS.items() if names[0] in full_defines}
        for label, names in present.items():
            drawers[label] = _drawer(renderer, drop=names)
        from catalog.core.errors import EnvironmentFailure  # noqa: PLC0415

        unbuilt = {}
        for label in list(drawers):
            try:
                drawers[label]()
            except EnvironmentFailure as exc:   # a term another needs (its uniforms)
                unbuilt[label] = str(exc).rsplit(": ", 1)[-1]
                del drawers[label], present[label]
        ctx.finish()
        wall = {k: [] for k in drawers}
        cpu = {k: [] for k in drawers}
        for _ in range(repeats):
            for label, draw in drawers.items():
                ctx.finish()
                w0, c0 = time.perf_counter(), time.process_time()
                draw()
                ctx.finish()
                wall[label].append(1e3 * (time.perf_counter() - w0))
                cpu[label].append(1e3 * (time.process_time() - c0))
        med = {k: {"wall": statistics.median(wall[k]), "cpu": statistics.median(cpu[k])} for k in drawers}
        # the two alone: with the term variants between them each draw meets caches the
        # others filled (llvmpipe's shader variants, the textures), which the frame does not
        alone = {"trivial": [], "full": []}
        for _ in range(repeats):
            for label in alone:
                ctx.finish()
                c0 = time.process_time()
                drawers[label]()
                ctx.finish()
                alone[label].append(1e3 * (time.process_time() - c0))
        alone = {k: statistics.median(v) for k, v in alone.items()}
        row = {"fabric": fabric, "light": light, "size": list(size), "ms": med,
               "defines": sorted(full_defines),
               "full_over_trivial_cpu": med["full"]["cpu"] / med["trivial"]["cpu"],
               "full_over_trivial_wall": med["full"]["wall"] / med["trivial"]["wall"],
               "alone_cpu_ms": alone, "alone_full_over_trivial_cpu": alone["full"] / alone["trivial"],
               "term_cost_cpu_ms": {label: med["full"]["cpu"] - med[label]["cpu"] for label in present},
               "not_built_alone": unbuilt}
    finally:
        renderer.release()
    return row


def run(quick: bool = False, sizes=DEFAULT_SIZES) -> dict:
    import os  # noqa: PLC0415

    from benchmarks.results import machine_info  # noqa: PLC0415
    from catalog.gl.context import create_headless_context  # noqa: PLC0415

    ctx = create_headless_context()
    load_before = os.getloadavg()[0]
    try:
        rows = [run_scene(ctx, size, fabric, light, 3 if quick else 11)
                for size in sizes for fabric, light in SCENES]
        machine = machine_info(ctx)
    finally:
        ctx.release()
    machine["load_average_1min_before"] = load_before
    return {"rows": rows, "machine": machine, "goal_ratio": 3.0,
            "summary": {"full_over_trivial_cpu_max": max(r["full_over_trivial_cpu"] for r in rows),
                        "alone_full_over_trivial_cpu_max": max(r["alone_full_over_trivial_cpu"] for r in rows)}}


def markdown_tables(result: dict) -> dict[str, str]:
    rows = result["rows"]
    labels = list(TERMS)
    head = ("| scene | size | trivial ms | full ms | full / trivial | alone: trivial, full ms, ratio | "
            + " | ".join(labels) + " |\n|---|---|---:|---:|---:|---:|" + "---:|" * len(labels) + "\n")
    lines = []
    for r in rows:
        cost = r["term_cost_cpu_ms"]
        cells = " | ".join(f"{cost[k]:+.1f}" if k in cost else "-" for k in labels)
        lines.append(f"| {r['fabric']} under {r['light']} | {r['size'][0]}x{r['size'][1]} | "
                     f"{r['ms']['trivial']['cpu']:.1f} | {r['ms']['full']['cpu']:.1f} | "
                     f"{r['full_over_trivial_cpu']:.2f}x | {_alone(r)} | {cells} |")
    m = result["machine"]
    foot = (f"\n\nCPU ms of the curtain pass alone; a term's column: what taking it out saves; "
            f"alone: the full and trivial shaders timed by themselves, no term variant between them. "
            f"Goal: full / trivial <= {result['goal_ratio']:g}x. Commit {m.get('commit')}, "
            f"{m.get('gl_renderer')}, load average {m.get('load_average_1min_before', 0):.1f} before the run.")
    return {"curtain_terms": head + "\n".join(lines) + foot}


def _alone(row: dict) -> str:
    if "alone_cpu_ms" not in row:
        return "-"
    a = row["alone_cpu_ms"]
    return f"{a['trivial']:.1f}, {a['full']:.1f}, {row['alone_full_over_trivial_cpu']:.2f}x"


def main(argv: list[str] | None = None) -> int:
    import sys  # noqa: PLC0415

    from benchmarks.results import sized_study_main  # noqa: PLC0415

    return sized_study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    raise SystemExit(main())
