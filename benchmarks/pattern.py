"""Issue 12's frame cost: patterns, layers (OIT) and anti-aliasing against the frame before.

Side by side in one run, on the same context, medians of interleaved repeats (GL finished
before each clock read); issue 13's room light, sky model and glare are off on every side
(``benchmarks.room`` measures those):

- ``before``: the flat cloth (``patterned = False``: opaque, LD x background by ray
  direction), no anti-aliasing, the static sinusoidal drape: the frame as it was;
- ``patterned (static drape)``: the same mesh with the pattern texture, OIT and FXAA;
- ``patterned (settled drape)``: what ``catalog snapshot`` now draws: the pleated drape
  (96 x 56 grid), pattern, OIT, FXAA;
- ``patterned + OIT + MSAA 4x (settled drape)``: the MSAA path (HDR, depth and both OIT
  targets at 4 samples, resolved before the composite) instead of FXAA: the two
  anti-aliasing paths side by side, and ``choice``: what ``auto`` takes on this context;
- ``MSAA 4x (flat)`` against ``1x (flat)``: the HDR passes of the flat frame into a 4-sample
  float target and resolved, against one sample: what multisampling costs llvmpipe before
  any OIT target is multisampled;
- ``FXAA pass``: the post-process alone (frame with FXAA minus frame without). Issue 12's
  first FXAA shader (six bilinear reads), once timed here against today's, is in git history
  and in the recorded runs of benchmarks/bench_pattern.json.

:func:`markdown_tables` renders the JSON as the tables of docs/pattern.md and BENCHMARKS.md.
"""

from __future__ import annotations

import statistics
import time

from catalog.gl.context import own_context_unless_given

FABRIC = "lace-fwa"
LIGHT = "D65"


def _clock(ctx, draw, repeats: int) -> list[float]:
    times = []
    for _ in range(repeats):
        ctx.finish()
        start = time.perf_counter()
        draw()
        ctx.finish()
        times.append(time.perf_counter() - start)
    return times


@own_context_unless_given   # without ctx: its own, released after (the caller's current again)
def run(quick: bool = False, ctx=None, size=(1280, 720), repeats: int | None = None) -> dict:
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.gl.context import describe  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415
    from catalog.render.passes.targets import MSAA_SAMPLES, choose_antialiasing  # noqa: PLC0415
    from catalog.render.scene import draped_curtain  # noqa: PLC0415
    from catalog.render.snapshot import simulated_curtain  # noqa: PLC0415

    repeats = repeats or (3 if quick else 11)
    if quick:
        size = (320, 180)
    preset = load_preset(find_preset(FABRIC))
    static = draped_curtain()
    *settled, fabric_size = simulated_curtain(preset, 0)
    renderer = FrameRenderer(ctx, size)
    renderer.update(fabric=preset, light=LIGHT)
    # issue 13's room light, sky and glare off on both sides: issue 12's additions alone
    # (benchmarks.room measures those against the frame without them)
    renderer.update(room_lighting=False, sky_model=False, bloom=False)

    def configure(patterned, aa, mesh):
        renderer.update(patterned=patterned, antialiasing=aa)
        if mesh == "static":
            renderer.set_mesh(static.positions, static.normals, static.uvs, static.tangents,
                              static.indices)
        else:
            renderer.set_mesh(*settled, fabric_size_m=fabric_size)

    cases = {
        "before (flat, no AA, static drape)": (False, "off", "static"),
        "patterned + OIT, no AA (static drape)": (True, "off", "static"),
        "patterned + OIT + FXAA (static drape)": (True, "fxaa", "static"),
        "patterned + OIT + FXAA (settled drape)": (True, "fxaa", "settled"),
    }
    msaa_case = "patterned + OIT + MSAA 4x (settled drape)"
    if int(ctx.info.get("GL_MAX_SAMPLES", 0) or 0) >= MSAA_SAMPLES:
        cases[msaa_case] = (True, "msaa", "settled")
    samples: dict[str, list[float]] = {name: [] for name in cases}
    for name, case in cases.items():       # warm-up: compile every program once
        configure(*case)
        renderer.render()
    for _ in range(repeats):               # interleaved rounds
        for name, case in cases.items():
            configure(*case)
            samples[name] += _clock(ctx, renderer.render, 1)

    # MSAA on the flat frame's HDR passes: 4 samples into float renderbuffers + resolve
    import moderngl  # noqa: PLC0415

    w, h = renderer.size
    configure(False, "off", "static")
    msaa_colour = ctx.renderbuffer((w, h), 4, samples=4, dtype="f4")
    msaa_depth = ctx.depth_renderbuffer((w, h), samples=4)
    msaa_fbo = ctx.framebuffer([msaa_colour], msaa_depth)
    single_fbo = renderer.targets.hdr_fbo

    def hdr_single():
        renderer.targets.hdr_fbo = single_fbo
        renderer.render_hdr()

    def hdr_msaa():
        renderer.targets.hdr_fbo = msaa_fbo
        renderer.render_hdr()
        ctx.copy_framebuffer(single_fbo, msaa_fbo)   # resolve

    msaa_samples = {"1x (flat HDR passes)": [], "MSAA 4x (flat HDR passes + resolve)": []}
    hdr_single()
    hdr_msaa()
    for _ in range(repeats):
        msaa_samples["1x (flat HDR passes)"] += _clock(ctx, hdr_single, 1)
        msaa_samples["MSAA 4x (flat HDR passes + resolve)"] += _clock(ctx, hdr_msaa, 1)
    renderer.targets.hdr_fbo = single_fbo
    single_fbo.use()   # never leave a released framebuffer bound (the context is the caller's)
    for obj in (msaa_fbo, msaa_colour, msaa_depth):
        obj.release()
    renderer.release()
    del moderngl

    def row(name, times, base, base_times=None):
        median = statistics.median(times)
        out = {"case": name, "median_ms": round(1e3 * median, 2),
               "best_ms": round(1e3 * min(times), 2),
               "ratio_to_before": round(median / base, 3)}
        if base_times is not None:   # each round's own ratio (same load), their median
            out["round_ratio"] = round(statistics.median(
                t / b for t, b in zip(times, base_times)), 3)
        return out

    base = statistics.median(samples["before (flat, no AA, static drape)"])
    before_times = samples["before (flat, no AA, static drape)"]
    rows = [row(name, times, base, before_times) for name, times in samples.items()]
    by_case = {r["case"]: r for r in rows}
    fxaa_row = by_case["patterned + OIT + FXAA (settled drape)"]
    msaa_base = statistics.median(msaa_samples["1x (flat HDR passes)"])
    msaa_rows = [row(name, times, msaa_base) for name, times in msaa_samples.items()]
    fxaa_ms = (statistics.median(samples["patterned + OIT + FXAA (static drape)"])
               - statistics.median(samples["patterned + OIT, no AA (static drape)"])) * 1e3
    msaa_row = by_case.get(msaa_case)
    return {"size": list(size), "repeats": repeats, "fabric": FABRIC, "light": LIGHT,
            "gl": describe(ctx), "rows": rows, "msaa_rows": msaa_rows,
            "summary": {"frame_ratio": fxaa_row["ratio_to_before"],
                        "frame_round_ratio": fxaa_row["round_ratio"],
                        "frame_ratio_best": round(fxaa_row["best_ms"] / by_case[
                            "before (flat, no AA, static drape)"]["best_ms"], 3),
                        "msaa_frame_ratio": msaa_row["ratio_to_before"] if msaa_row else None,
                        "msaa_ratio": msaa_rows[1]["ratio_to_before"],
                        "fxaa_ms": round(fxaa_ms, 2),
                        "choice": choose_antialiasing(dict(ctx.info))}}


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/bench_pattern.json"

def markdown_tables(result: dict) -> dict[str, str]:
    """``pattern_cost`` and ``pattern_msaa``: NAME -> markdown table."""
    w, h = result["size"]
    lines = [f"| frame at {w}x{h} ({result['fabric']}, {result['light']}) | median ms | best ms "
             f"| / before (medians) | / before (median of rounds) |", "|---|---|---|---|---|"]
    lines += [f"| {r['case']} | {r['median_ms']:.1f} | {r['best_ms']:.1f} | "
              f"{r['ratio_to_before']:.2f} | {r.get('round_ratio', float('nan')):.2f} |"
              for r in result["rows"]]
    summary = result["summary"]
    lines.append("")
    lines.append(f"Whole frame / before: {summary.get('frame_round_ratio', float('nan')):.2f} "
                 f"(median of the rounds' ratios), {summary['frame_ratio']:.2f} (medians), "
                 f"{summary.get('frame_ratio_best', float('nan')):.2f} (best rounds); "
                 f"`auto` anti-aliasing takes **{summary.get('choice', 'fxaa')}** on this context.")
    msaa = ["| HDR passes of the flat frame | median ms | / 1x |", "|---|---|---|"]
    msaa += [f"| {r['case']} | {r['median_ms']:.1f} | {r['ratio_to_before']:.2f} |"
             for r in result["msaa_rows"]]
    return {"pattern_cost": "\n".join(lines), "pattern_msaa": "\n".join(msaa)}


def main(argv=None) -> int:
    """``python -m benchmarks.pattern [--quick] [--repeats N] [--json-out F]``: print the
    tables, write the JSON (default benchmarks/bench_pattern.json)."""
    import argparse  # noqa: PLC0415
    import json  # noqa: PLC0415
    from pathlib import Path  # noqa: PLC0415

    from catalog.core.resources import PROJECT_ROOT  # noqa: PLC0415

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="320x180, 3 repeats")
    parser.add_argument("--repeats", type=int, default=None)
    parser.add_argument("--json-out", type=Path,
                        default=PROJECT_ROOT / "benchmarks" / "bench_pattern.json")
    args = parser.parse_args(argv)
    result = run(quick=args.quick, repeats=args.repeats)
    for table in markdown_tables(result).values():
        print(table + "\n")
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    write_text_atomic(args.json_out, json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
