"""What alpha-to-coverage would do to the curtain's layers (issue 12's MSAA path keeps the
coverage in the OIT's alpha instead): one and two full-screen white layers of coverage c over
black, drawn into a 4-sample target with GL_SAMPLE_ALPHA_TO_COVERAGE and the depth test,
resolved; the open fraction (1 - mean white) against the exact 1 - c and (1 - c)^2.

    .venv/bin/python -m benchmarks.alpha_to_coverage [--json-out FILE]

On llvmpipe the mask is a fixed function of alpha (quarters, no dither) and two layers cover
the same samples: the open fraction behind two layers equals one layer's.
"""

from __future__ import annotations

import numpy as np

from catalog.gl.context import own_context_unless_given

GL_SAMPLE_ALPHA_TO_COVERAGE = 0x809E
COVERAGES = (0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9)
SIZE_PX = 32
SAMPLES = 4


@own_context_unless_given   # without ctx: its own, released after (the caller's current again)
def run(ctx=None) -> dict:
    import moderngl  # noqa: PLC0415

    from catalog.gl.context import describe  # noqa: PLC0415
    from catalog.gl.shaderlib import create_program  # noqa: PLC0415

    size = (SIZE_PX, SIZE_PX)
    colour = ctx.renderbuffer(size, 4, samples=SAMPLES, dtype="f4")
    depth = ctx.depth_renderbuffer(size, samples=SAMPLES)
    fbo = ctx.framebuffer([colour], depth)
    resolved = ctx.texture(size, 4, dtype="f4")
    resolved_fbo = ctx.framebuffer([resolved])
    program = create_program(ctx, "a2c_layer.vert", "a2c_layer.frag")
    vao = ctx.vertex_array(program, [])
    rows = []
    try:
        for c in COVERAGES:
            open_fraction = []
            for layers in (1, 2):
                fbo.use()
                ctx.viewport = (0, 0, *size)
                fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
                ctx.enable(moderngl.DEPTH_TEST)
                ctx.enable_direct(GL_SAMPLE_ALPHA_TO_COVERAGE)
                program["u_coverage"].value = c
                for z in (0.0, 0.5)[:layers]:
                    program["u_depth"].value = z
                    vao.render(moderngl.TRIANGLES, vertices=3)
                ctx.disable_direct(GL_SAMPLE_ALPHA_TO_COVERAGE)
                ctx.disable(moderngl.DEPTH_TEST)
                ctx.copy_framebuffer(resolved_fbo, fbo)
                image = np.frombuffer(resolved.read(), np.float32).reshape(SIZE_PX, SIZE_PX, 4)
                open_fraction.append(float(1.0 - image[..., 0].mean()))
            rows.append({"coverage": c, "open_one": round(open_fraction[0], 4),
                         "exact_one": round(1.0 - c, 4), "open_two": round(open_fraction[1], 4),
                         "exact_two": round((1.0 - c) ** 2, 4)})
    finally:
        (ctx.screen or ctx.detect_framebuffer(0)).use()   # none of ours left bound
        for obj in (vao, program, fbo, colour, depth, resolved_fbo, resolved):
            obj.release()
    worst_one = max(abs(r["open_one"] - r["exact_one"]) for r in rows)
    worst_two = max(abs(r["open_two"] - r["exact_two"]) for r in rows)
    return {"gl": describe(ctx), "samples": SAMPLES, "rows": rows,
            "summary": {"worst_one_layer": round(worst_one, 4),
                        "worst_two_layers": round(worst_two, 4)}}


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/bench_a2c.json"

def markdown_tables(result: dict) -> dict[str, str]:
    """``a2c_layers``: NAME -> markdown table."""
    lines = [f"| coverage c | open, 1 layer | exact 1 - c | open, 2 layers | exact (1 - c)^2 |",
             "|---|---|---|---|---|"]
    lines += [f"| {r['coverage']:.2f} | {r['open_one']:.3f} | {r['exact_one']:.3f} | "
              f"{r['open_two']:.3f} | {r['exact_two']:.3f} |" for r in result["rows"]]
    return {"a2c_layers": "\n".join(lines)}


def main(argv=None) -> int:
    import sys  # noqa: PLC0415

    from benchmarks.results import study_main  # noqa: PLC0415

    return study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    raise SystemExit(main())
