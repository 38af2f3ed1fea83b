"""The display step's cost in the frame (issue 14): each transform of tonemap.frag timed as
a shader variant, beside the auto exposure's meter and the whole frame.

Variants of the display pass (DISPLAY_STAGES): 0 exposure + sRGB curve, 1 + white balance
(a 3x3), 2 + tone curve on luminance, 3 + OKLab gamut compression (the default). The cost of
a transform is the difference of successive medians, all measured in one run side by side.
The meter (mip level, read-back, numpy histogram) and the whole frame (HDR passes + meter +
display) are timed on the same scenes. Scenes: the lace under D65 (few pixels out of gamut)
and under UV-A (the glow: most cloth pixels take the bisection), the pink under sun:500.

    .venv/bin/python -m benchmarks.display [--quick] [--json-out FILE]
    (prints the table, writes benchmarks/bench_display.json)
"""

from __future__ import annotations

from catalog.gl.context import own_context_unless_given

STAGES = ("exposure + sRGB curve", "+ white balance", "+ tone curve", "+ gamut compression")
SCENES = (("lace-fwa", "D65"), ("lace-fwa", "UV-A"), ("fluoro-pink", "sun:500"))


#: The committed result tools/docs_figures.py makes this module's tables from.
RESULT_JSON = "benchmarks/bench_display.json"


@own_context_unless_given   # without ctx: its own, released after (the caller's current again)
def run(quick: bool = False, ctx=None, size=(640, 360)) -> dict:
    from benchmarks.timing import median_seconds  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415

    own = ctx is None
    repeats = 5 if quick else 15
    renderer = FrameRenderer(ctx, size)
    rows = []
    try:
        for fabric, light in SCENES:
            renderer.update(fabric=fabric, light=light, ev=None)
            renderer.render()
            w, h = renderer.size
            row = {"fabric": fabric, "light": light, "size": list(size)}
            stage_ms = []
            for stages in range(4):
                stage_ms.append(1e3 * median_seconds(lambda: renderer.display.display_pass(w, h, stages=stages),
                                                     repeats, finish=ctx.finish))
            row["pass_ms"] = stage_ms
            row["cost_ms"] = [stage_ms[0]] + [b - a for a, b in zip(stage_ms, stage_ms[1:])]
            row["meter_ms"] = 1e3 * median_seconds(lambda: renderer.display.meter(w, h), repeats,
                                                   finish=ctx.finish)
            row["frame_ms"] = 1e3 * median_seconds(renderer.render, repeats, finish=ctx.finish)
            row["display_share"] = (stage_ms[3] + row["meter_ms"]) / row["frame_ms"]
            rows.append(row)
    finally:
        renderer.release()
        if own:
            ctx.release()
    return {"rows": rows, "stages": list(STAGES), "repeats": repeats,
            "summary": {"full_pass_ms_max": max(r["pass_ms"][3] for r in rows),
                        "gamut_ms_max": max(r["cost_ms"][3] for r in rows),
                        "display_share_max": max(r["display_share"] for r in rows)}}


def markdown_tables(result: dict) -> dict[str, str]:
    head = ("| scene | " + " | ".join(result["stages"]) + " | meter | whole frame | display share |\n"
            "|---|" + "---:|" * (len(result["stages"]) + 3) + "\n")
    lines = []
    for r in result["rows"]:
        costs = " | ".join(f"{c:+.2f}" if i else f"{c:.2f}" for i, c in enumerate(r["cost_ms"]))
        lines.append(f"| {r['fabric']} under {r['light']} ({r['size'][0]}x{r['size'][1]}) | "
                     f"{costs} | {r['meter_ms']:.2f} | {r['frame_ms']:.1f} | "
                     f"{100 * r['display_share']:.0f} % |")
    return {"display_cost": head + "\n".join(lines)}


def main() -> int:
    import argparse  # noqa: PLC0415
    import json  # noqa: PLC0415
    from pathlib import Path  # noqa: PLC0415

    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415
    from catalog.core.resources import PROJECT_ROOT  # noqa: PLC0415

    parser = argparse.ArgumentParser(description="the display step's cost in the frame")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--json-out", type=Path,
                        default=PROJECT_ROOT / "benchmarks" / "bench_display.json")
    args = parser.parse_args()
    result = run(quick=args.quick)
    print("cost of each step, ms per display pass (first column: the pass with exposure and "
          "the sRGB curve only; then what each step adds)")
    print(markdown_tables(result)["display_cost"])
    write_text_atomic(args.json_out, json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
