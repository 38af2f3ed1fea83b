"""The display step and the glare against the whole static frame, per pass (llvmpipe).

A static frame (the settled drape, nothing moving: what a sleeping viewer draws) of each
SCENE at each size: the whole ``FrameRenderer.render()``, then, after it, the glare
(``GlarePass.draw_bloom``), the display pass (glare mix, tone map, FXAA) and the auto
exposure's meter, each timed alone. The machine is shared, so each is a median of
``--repeats`` of both the wall time and this process's CPU time (llvmpipe's threads
included; little of the other processes' load), and the shares are taken on CPU time:
share = (glare + display + meter) / frame, from one run. The frame's own per-pass profile
(``render(profile=...)``, wall, the GL queue finished around each pass) is kept beside it.

    PYTHONPATH=. .venv/bin/python -m benchmarks.frame_passes [--quick] [--sizes 1920x1080,...]
    (prints the table, writes benchmarks/bench_frame_passes.json)

The display pass is called the way the checkout's frame calls it (the glare as a value, or
as a texture on a tree before the glare moved into the display pass), so the same module
measures the tree before a change for the "before" row.
"""

from __future__ import annotations

import statistics

from catalog.gl.context import own_context_unless_given

#: (fabric, light, camera (yaw deg, pitch deg, distance m)): the frame check's room view under
#: the noon sun (the sun's disc and its glare), an even white under D65 and a fluorescent
#: yellow under UV-A (most cloth pixels out of gamut: the gamut compression's bisection).
SCENES = (("lace-fwa", "noon", (20.0, 15.0, 2.6)), ("voile-white", "D65", (20.0, 15.0, 2.6)),
          ("safety-yellow", "UV-A", (0.0, 0.0, 0.8)))
DEFAULT_SIZES = ((1280, 720), (1920, 1080))

#: The committed result tools/docs_figures.py makes this module's table from.
RESULT_JSON = "benchmarks/bench_frame_passes.json"


def _light_name(light: str) -> str:
    if light == "noon":
        from catalog.render.scene import sun_at_hour  # noqa: PLC0415

        return sun_at_hour(12.0).light_name
    return light


def _display_call(renderer, w, h, glare):
    if glare is None:
        return lambda: renderer.display.display_pass(w, h)
    if hasattr(glare, "glow"):   # the glare mixed in by the display pass
        return lambda: renderer.display.display_pass(w, h, glare=glare)
    return lambda: renderer.display.display_pass(w, h, hdr=glare)   # a tree before it


def run_scene(ctx, size, fabric, light, camera, repeats) -> dict:
    from benchmarks.timing import median_wall_and_cpu  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415
    from catalog.render.settings import orbit  # noqa: PLC0415
    from catalog.render.snapshot import ring_xs_m, simulated_curtain  # noqa: PLC0415

    preset = load_preset(find_preset(fabric))
    *mesh, fabric_size_m = simulated_curtain(preset, 0)
    renderer = FrameRenderer(ctx, size)
    try:
        renderer.update(fabric=preset,
                        light=_light_name(light),
                        antialiasing="fxaa",
                        camera=orbit(*camera))
        renderer.set_mesh(*mesh, fabric_size_m=fabric_size_m)
        renderer.set_rings(ring_xs_m(preset))
        renderer.render()
        w, h = renderer.size
        row = {"fabric": fabric, "light": light, "size": list(size)}
        wall, cpu = median_wall_and_cpu(renderer.render, repeats, finish=ctx.finish)
        row["frame_ms"] = {"wall": 1e3 * wall, "cpu": 1e3 * cpu}
        holder = {}
        wall, cpu = median_wall_and_cpu(lambda: holder.update(g=renderer.glare.draw_bloom(w, h)),
                                        repeats, finish=ctx.finish)
        row["glare_ms"] = {"wall": 1e3 * wall, "cpu": 1e3 * cpu}
        wall, cpu = median_wall_and_cpu(_display_call(renderer, w, h, holder["g"]), repeats,
                                        finish=ctx.finish)
        row["display_ms"] = {"wall": 1e3 * wall, "cpu": 1e3 * cpu}
        wall, cpu = median_wall_and_cpu(lambda: renderer.display.meter(w, h), repeats,
                                        finish=ctx.finish)
        row["meter_ms"] = {"wall": 1e3 * wall, "cpu": 1e3 * cpu}
        passes: dict[str, list[float]] = {}
        for _ in range(max(3, repeats // 2)):
            profile: dict = {}
            renderer.render(profile=profile)
            for name, seconds in profile.items():
                passes.setdefault(name, []).append(1e3 * seconds)
        row["passes_wall_ms"] = {k: statistics.median(v) for k, v in passes.items()}
        for kind in ("cpu", "wall"):
            row[f"share_{kind}"] = ((row["glare_ms"][kind] + row["display_ms"][kind]
                                     + row["meter_ms"][kind]) / row["frame_ms"][kind])
    finally:
        renderer.release()
    return row


@own_context_unless_given   # without ctx: its own, released after (the caller's current again)
def run(quick: bool = False, sizes=DEFAULT_SIZES, ctx=None) -> dict:
    import os  # noqa: PLC0415

    from benchmarks.results import machine_info  # noqa: PLC0415

    own = ctx is None
    repeats = 3 if quick else 7
    load_before = os.getloadavg()[0]
    try:
        rows = [run_scene(ctx, size, fabric, light, camera, repeats)
                for size in sizes for fabric, light, camera in SCENES]
        machine = machine_info(ctx)
    finally:
        if own:
            ctx.release()
    machine["load_average_1min_before"] = load_before
    return {"rows": rows, "repeats": repeats, "machine": machine,
            "summary": {"share_cpu_max": max(r["share_cpu"] for r in rows),
                        "share_wall_max": max(r["share_wall"] for r in rows)}}


def markdown_tables(result: dict) -> dict[str, str]:
    head = ("| scene | size | frame ms (CPU) | glare | display (mix, tone map, FXAA) | meter | "
            "share of the frame (CPU) | share (wall) |\n|---|---|---:|---:|---:|---:|---:|---:|\n")
    lines = []
    for r in result["rows"]:
        lines.append(f"| {r['fabric']} under {r['light']} | {r['size'][0]}x{r['size'][1]} | "
                     f"{r['frame_ms']['cpu']:.0f} | {r['glare_ms']['cpu']:.1f} | "
                     f"{r['display_ms']['cpu']:.1f} | {r['meter_ms']['cpu']:.1f} | "
                     f"{100 * r['share_cpu']:.0f} % | {100 * r['share_wall']:.0f} % |")
    before = result.get("before")
    if before:   # the same module on the tree before the change, for the change's figure
        for r in before["rows"]:
            lines.append(f"| *before ({before['commit']}):* {r['fabric']} under {r['light']} | "
                         f"{r['size'][0]}x{r['size'][1]} | {r['frame_ms']['cpu']:.0f} | "
                         f"{r['glare_ms']['cpu']:.1f} | {r['display_ms']['cpu']:.1f} | "
                         f"{r['meter_ms']['cpu']:.1f} | {100 * r['share_cpu']:.0f} % | "
                         f"{100 * r['share_wall']:.0f} % |")
    m = result["machine"]
    foot = (f"\n\nCommit {m.get('commit')}, {m.get('gl_renderer')}, {m.get('cpu_count')} cores, "
            f"load average {m.get('load_average_1min_before', 0):.1f} before the run; "
            f"medians of {result['repeats']}, CPU time of this process.")
    return {"frame_passes": head + "\n".join(lines) + foot}


def main(argv: list[str] | None = None) -> int:
    import sys  # noqa: PLC0415

    from benchmarks.results import sized_study_main  # noqa: PLC0415

    return sized_study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    raise SystemExit(main())
