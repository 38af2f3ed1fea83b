"""The paper's Table 2 in our terms: the brightened lace backlit by the noon sun, fluorescence
off and on, mean over the curtain's pixels (docs/render.md).

    .venv/bin/python -m benchmarks.render_table2 [--size 320x180] [--json OUT.json]

For each mode (physical, paper) the frame is drawn with fluorescence off (automatic
exposure) and on at the same exposure; the JSON holds the mean 8-bit display values and the
linear change per channel. tests/test_render_table2.py holds the bounds (blue up by more
than 5 % and 5x the change of red and green); this writes the figures the docs show.
"""

from __future__ import annotations

import sys


from catalog.core.resources import FABRIC_DIR
from catalog.render.settings import SunHour

RESULT_JSON = "benchmarks/render_table2.json"
MODES = ("physical", "paper")


def _lit_cloth_mean(ctx, size, preset, mode: str, hour: float, ev):
    from catalog.render.frame import FrameRenderer

    renderer = FrameRenderer(ctx, size)
    try:
        renderer.update(ev=ev, fabric=preset, light=SunHour(hour), fluorescence=mode)
        mask = renderer.render_gbuffer()["mask"]
        renderer.render()
        linear = renderer.read_linear()[mask].mean(axis=0)
        display = renderer.read_srgb8()[mask].astype(float).mean(axis=0)
        return linear, display, renderer.info()
    finally:
        renderer.release()


def run(size=(320, 180), hour: float = 12.0) -> dict:
    from catalog.gl.context import create_headless_context, describe

    ctx = create_headless_context()
    lace = str(FABRIC_DIR / "lace-fwa.toml")
    rows = []
    for mode in MODES:
        off, off8, off_info = _lit_cloth_mean(ctx, size, lace, "off", hour, None)
        on, on8, _ = _lit_cloth_mean(ctx, size, lace, mode, hour, off_info["ev100"])
        change = (on - off) / off
        rows.append({"mode": mode, "display_off": off8.tolist(), "display_on": on8.tolist(),
                     "linear_change": change.tolist()})
    return {"fabric": "lace-fwa", "sun_hour": hour, "size": list(size), "device": describe(ctx),
            "rows": rows}


def markdown_tables(result: dict) -> dict[str, str]:
    """``render_table2``: per mode, the mean 8-bit values off -> on and the linear change."""
    lines = ["| mode | R off -> on | G off -> on | B off -> on | linear change R / G / B |",
             "|---|---|---|---|---|"]
    for r in result["rows"]:
        cells = [f"{a:.1f} -> {b:.1f}" for a, b in zip(r["display_off"], r["display_on"])]
        change = " / ".join(f"{100 * c:+.3g} %" for c in r["linear_change"])
        lines.append(f"| {r['mode']} | {' | '.join(cells)} | {change} |")
    w, h = result["size"]
    lines.append(f"\n({result['fabric']}, the sun at {result['sun_hour']:g} h, {w}x{h}, "
                 f"{result['device'].get('renderer', '?')}.)")
    return {"render_table2": "\n".join(lines)}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415

    def options(parser) -> None:
        parser.add_argument("--size", default="320x180")

    def result(args) -> dict:
        from catalog.render.snapshot import parse_size  # noqa: PLC0415

        return run(parse_size(args.size))

    return study_main(sys.modules[__name__], argv, result, options)


if __name__ == "__main__":
    sys.exit(main())
