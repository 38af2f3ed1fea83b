"""The web catalog against the desktop frame: site size, build time, page load time, page
frame time under SwiftShader (headless chromium, CPU WebGL2) beside the desktop frame
(EGL, Mesa llvmpipe) at the same size, and the page-vs-desktop pixel figures.

    .venv/bin/python -m benchmarks.web [--quick] [--json-out benchmarks/bench_web.json]

Prints a table and writes JSON; BENCHMARKS.md's block ``web`` is generated from that JSON
by :func:`markdown_tables`. Timings are medians (the machine is shared and noisy); the page
and the desktop frames are measured in one run, side by side.
"""

from __future__ import annotations

import argparse
import json
import platform
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from catalog.web.export import configure_desktop_frame, scene_key  # noqa: E402  (the page's modes)

#: The scene every timing uses (the page's default switches: glare on, no room lamp).
FABRIC, LIGHT, GLARE, LAMP = "fluoro-pink", "D65", "on", "none"
#: The page-vs-EGL comparisons (the browser test's scenes): fabric, light, fluorescence,
#: baked frame, camera (yaw, pitch, distance) or None, glare, room lamp.
COMPARED = (("fluoro-pink", "D65", "on", 0, None, "off", "none"),
            ("fluoro-pink", "UV-A", "off", 30, None, "off", "none"),
            ("linen-dense", "sun@8", "on", 17, None, "off", "none"),
            ("fluoro-pink", "sun@15", "on", 5, (35.0, 20.0, 1.8), "off", "none"),
            ("fluoro-pink", "D65", "on", 0, None, "on", "none"),
            ("linen-dense", "sun@18", "on", 3, None, "on", "A"))


class DesktopFrames:
    """The desktop frame (EGL) of the benchmark's scene with the page's curtain (frame 0)."""

    def __init__(self, size, animation, specialise: bool):
        import numpy as np  # noqa: PLC0415

        from catalog.gl.context import create_headless_context  # noqa: PLC0415
        from catalog.render.frame import FrameRenderer  # noqa: PLC0415
        from catalog.web import bake as bake_lib  # noqa: PLC0415

        self.ctx = create_headless_context()
        positions, normals, tangents = bake_lib.decode_frame(animation, 0)
        self.renderer = FrameRenderer(self.ctx, size, specialise=specialise)
        from catalog.web.export import GLARE as GLARE_SWITCH  # noqa: PLC0415
        from catalog.web.export import room_lamps  # noqa: PLC0415

        self.renderer.update(fabric=FABRIC)
        configure_desktop_frame(self.renderer)
        self.renderer.update(bloom=GLARE_SWITCH[GLARE], lamps=room_lamps(LAMP), light=LIGHT)
        self.renderer.set_mesh(positions, normals, animation.uv, tangents,
                               animation.indices.astype(np.int32),
                               fabric_size_m=animation.fabric_size_m)
        self.renderer.set_mesh_offset((0.0, 0.0, 0.0))
        self.renderer.set_rings(animation.rings_x_m)
        self.times(1)  # compile, and meter the exposure once
        # like the page: a fixed exposure (no per-frame read-back and histogram)
        self.renderer.update(ev=self.renderer.current_ev100())

    def times(self, frames: int) -> list[float]:
        """ms of each of ``frames`` frames (render + finish). Two of these frames run side by
        side, each on its own EGL context: this one is made current first (GL calls go to
        the current context; drawn on the other, a frame's objects crashed llvmpipe)."""
        out = []
        with self.ctx:
            for _ in range(frames):
                start = time.perf_counter()
                self.renderer.render()
                self.ctx.finish()
                out.append(1000.0 * (time.perf_counter() - start))
        return out

    def release(self) -> None:
        with self.ctx:
            self.renderer.release()
        self.ctx.release()


def run(quick: bool = False) -> dict:
    from catalog.web import bake as bake_lib  # noqa: PLC0415
    from catalog.web import browser as web_browser  # noqa: PLC0415
    from catalog.web.site import build_site, plain_data_js  # noqa: PLC0415

    reason = web_browser.missing_reason()
    if reason:
        raise SystemExit(f"bench web: {reason}")
    sizes = [(320, 240)] if quick else [(320, 240), (640, 480)]
    frames = 5
    rounds = 2 if quick else 6
    loads = 2 if quick else 3
    result: dict = {"machine": {"python": platform.python_version(), "cpu": platform.processor()
                                or platform.machine()}, "quick": quick}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "site"
        # the full default catalog (every fabric, every default light): the product's size
        start = time.perf_counter()
        report = build_site(out) if not quick else build_site(
            out, fabrics="fluoro-pink,linen-dense", lights="D65,UV-A,sun-by-hour")
        result["site"] = {
            "fabrics": len(report["fabrics"]), "lights": len(report["lights"]),
            "scenes": report["scenes"], "shader_programs": report["shader_programs"],
            "animations": len(report["animations"]),
            "total_bytes": report["total_bytes"], "first_view_bytes": report["first_view_bytes"],
            "data_js_bytes": report["bytes"]["data.js"], "app_js_bytes": report["bytes"]["app.js"],
            # data.js as plain JSON with the bytes in base64 (the form before pack_data)
            "data_js_plain_bytes": report["data_js_plain_bytes"],
            "animation_encoded_bytes": statistics.median(
                a["encoded_bytes"] for a in report["animations"].values()),
            "animation_raw_bytes": next(iter(report["animations"].values()))["raw_bytes"],
            "animation_file_bytes": statistics.median(
                v for k, v in report["bytes"].items() if k.startswith("anim/")),
            "animation_frames": next(iter(report["animations"].values()))["frames"],
            "animation_fps": next(iter(report["animations"].values()))["fps"],
            "vertices": next(iter(report["animations"].values()))["vertex_count"],
            "build_s": round(time.perf_counter() - start, 2),
            "bake_s": report["bake_s"], "record_s": report["record_s"]}
        key = web_browser.site_data(out)
        anim_key = next(f["animation"] for f in key["fabrics"] if f["name"] == FABRIC)
        animation = bake_lib.read_script(out / "anim" / f"{anim_key}.js")

        b = web_browser.Browser(1000, 900)
        try:
            # the same site with data.js as plain JSON (bytes in base64; the form before
            # site.pack_data), loaded in alternation with the packed one
            plain = Path(tmp) / "plain"
            shutil.copytree(out, plain)
            (plain / "data.js").write_text(plain_data_js(key), encoding="utf-8")
            result["site"]["data_js_plain_file_bytes"] = (plain / "data.js").stat().st_size
            samples = {form: {"first_frame_ms": [], "page_ready_ms": [], "unpack_ms": [],
                              "scripts_read_ms": []} for form in ("packed", "plain")}
            for _ in range(loads):
                for form, site in (("packed", out), ("plain", plain)):
                    b.open(site, view="viewer", fabric=FABRIC, light=LIGHT, size="320x240")
                    stats = b.driver.execute_script("return window.catalogApp.stats")
                    got = samples[form]
                    got["first_frame_ms"].append(stats["firstFrameMs"])
                    got["page_ready_ms"].append(stats["gridReadyMs"])
                    got["unpack_ms"].append(stats["unpackMs"])
                    got["scripts_read_ms"].append(b.driver.execute_script(
                        "const t = performance.getEntriesByType('navigation')[0];"
                        "return t.domContentLoadedEventEnd"))
            # ms from navigation (medians): the scripts read (data.js parsed), data.js
            # inflated and the grid built (page ready), the first curtain frame drawn
            result["load"] = {k: round(statistics.median(v), 1) for k, v in samples["packed"].items()}
            result["load"]["loads"] = loads
            result["load_plain"] = {k: round(statistics.median(v), 1)
                                    for k, v in samples["plain"].items()}
            rows = []
            for w, h in sizes:
                # side by side: rounds alternate the page and the two desktop variants, so a
                # load spike on the shared machine hits all three alike; medians of all frames
                b.open(out, view="viewer", fabric=FABRIC, light=LIGHT, size=f"{w}x{h}",
                       glare=GLARE, lamp=LAMP)
                b.benchmark(3)  # warm-up
                desktops = {"desktop": DesktopFrames((w, h), animation, True),
                            "unspecialised": DesktopFrames((w, h), animation, False)}
                samples = {"page": [], "page_cpu": [], "desktop": [], "unspecialised": []}
                try:
                    for _ in range(rounds):
                        page = b.benchmark(frames)
                        samples["page"] += page["frame_samples_ms"]
                        samples["page_cpu"] += page["cpu_samples_ms"]
                        for name, desktop in desktops.items():
                            samples[name] += desktop.times(frames)
                finally:
                    for desktop in desktops.values():
                        desktop.release()
                med = {k: statistics.median(v) for k, v in samples.items()}
                rows.append({"size": f"{w}x{h}", "page_frame_ms": round(med["page"], 2),
                             "page_cpu_ms": round(med["page_cpu"], 2),
                             "desktop_frame_ms": round(med["desktop"], 2),
                             "desktop_unspecialised_ms": round(med["unspecialised"], 2),
                             "page_over_desktop": round(med["page"] / med["desktop"], 2),
                             "page_over_unspecialised": round(med["page"] / med["unspecialised"], 2)})
            result["frames"] = rows
            result["frames_per_case"] = frames * rounds
            # the page frame against the EGL frame (the browser test's rule)
            comparisons = []
            for fabric, light, switch, frame, camera, glare, lamp in COMPARED:
                size = (160, 120)
                orbit = {} if camera is None else dict(
                    zip(("yaw_deg", "pitch_deg", "distance_m"), camera))
                b.open(out, view="viewer", fabric=fabric, light=light, fluorescence=switch,
                       frame=frame, size=f"{size[0]}x{size[1]}", glare=glare, lamp=lamp, **orbit)
                fabric_anim = next(f["animation"] for f in key["fabrics"] if f["name"] == fabric)
                scene = key["scenes"][scene_key(fabric, light, switch, glare, lamp)]
                figures = web_browser.compare_frames(
                    b.canvas(), web_browser.egl_frame(fabric, light, switch, frame, size,
                                                      bake_lib.read_script(
                                                          out / "anim" / f"{fabric_anim}.js"),
                                                      camera=camera, ev100=scene["ev100"],
                                                      glare=glare, lamp=lamp))
                view = "" if camera is None else " / camera yaw {:g} pitch {:g} d {:g} m".format(*camera)
                extra = "".join([" / glare" if glare == "on" else "",
                                 f" / lamp {lamp}" if lamp != "none" else ""])
                comparisons.append({"scene": f"{fabric} / {light} / fluorescence {switch} / "
                                             f"frame {frame}{view}{extra}", **figures,
                                    "match": web_browser.frames_match(figures)})
            result["pixels"] = comparisons
        finally:
            b.close()
    return result


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/bench_web.json"

def markdown_tables(result: dict) -> dict[str, str]:
    """Block ``web`` of BENCHMARKS.md."""
    s, load = result["site"], result["load"]
    lines = [
        f"Catalog of {s['fabrics']} fabrics x {s['lights']} lights x fluorescence on/off x glare "
        f"on/off x room lamp (none and two) ({s['scenes']} scenes, {s['shader_programs']} GLSL ES "
        f"programs, {s['animations']} baked cloth loops of the settled drape).",
        "",
        "| site | value |",
        "|---|---|",
        f"| whole site | {s['total_bytes'] / 1e6:.2f} MB |",
        f"| first view (page, data, one cloth loop) | {s['first_view_bytes'] / 1e6:.2f} MB |",
        f"| data.js (shaders, recorded frames, uniforms, swatches, pattern texels; deflated) | "
        f"{s['data_js_bytes'] / 1e3:.0f} kB |",
        f"| the same as plain JSON with base64 bytes (the form before packing) | "
        f"{s['data_js_plain_bytes'] / 1e6:.2f} MB |",
        f"| one cloth loop: {s['animation_frames']} frames at {s['animation_fps']:g} fps, "
        f"{s['vertices']} vertices | {s['animation_encoded_bytes'] / 1e3:.0f} kB encoded "
        f"(raw {s['animation_raw_bytes'] / 1e3:.0f} kB; file {s['animation_file_bytes'] / 1e3:.0f} kB in base64) |",
        f"| build (`catalog web`) | {s['build_s']:.1f} s (bake {s['bake_s']:.1f} s, record {s['record_s']:.1f} s) |",
    ]
    plain = result.get("load_plain")
    if plain:
        lines += [
            "",
            f"Loading from file:// (medians of {load['loads']} loads each, alternating), the "
            "packed data.js against the same site with data.js as plain JSON "
            f"({s['data_js_plain_file_bytes'] / 1e6:.2f} MB, the form before packing; the same "
            "page reads both):",
            "",
            "| ms from navigation | packed data.js | plain JSON data.js |",
            "|---|---|---|",
            f"| DOMContentLoaded (the scripts read and run) | {load['scripts_read_ms']:.0f} | {plain['scripts_read_ms']:.0f} |",
            f"| app.js unpacking, its own time (packed: inflate and parse the JSON; plain: decode "
            f"the base64, the JSON was parsed with the script) | {load['unpack_ms']:.0f} | "
            f"{plain['unpack_ms']:.0f} |",
            f"| page ready (grid built) | {load['page_ready_ms']:.0f} | {plain['page_ready_ms']:.0f} |",
            f"| first curtain frame (320x240) | {load['first_frame_ms']:.0f} | "
            f"{plain['first_frame_ms']:.0f} |",
        ]
    else:
        lines += [f"| load to page ready (file://) | {load['page_ready_ms']:.0f} ms |",
                  f"| load to first curtain frame (file://, 320x240) | {load['first_frame_ms']:.0f} ms |"]
    lines += [
        "",
        f"Frame times: medians of {result['frames_per_case']} frames per case, the page and the "
        "desktop variants measured in alternating rounds in one run; the page's frame ends "
        "when its pixels can be read (readPixels), the desktop's at glFinish; both at a fixed "
        "exposure (the desktop's per-frame auto-exposure metering is left out, as on the page).",
        "",
        "| size | page frame (SwiftShader) | page CPU part | desktop frame (llvmpipe) | "
        "desktop, unspecialised (the page's programs) | page / desktop | page / unspecialised |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in result["frames"]:
        lines.append(f"| {row['size']} | {row['page_frame_ms']:.1f} ms | {row['page_cpu_ms']:.1f} ms | "
                     f"{row['desktop_frame_ms']:.1f} ms | {row['desktop_unspecialised_ms']:.1f} ms | "
                     f"{row['page_over_desktop']:.2f} | {row['page_over_unspecialised']:.2f} |")
    lines += ["", "| page vs EGL frame (160x120) | mean abs /255 | max abs /255 | within 3/255 | "
              "edge pixels (one-pixel shift) | unmatched | match |", "|---|---|---|---|---|---|---|"]
    for row in result["pixels"]:
        lines.append(f"| {row['scene']} | {row['mean_abs_8bit']:.3f} | {row['max_abs_8bit']} | "
                     f"{row['within_tolerance']} of {row['pixels']} | {row['edge_shift']} | "
                     f"{row['unmatched']} | {'yes' if row['match'] else 'NO'} |")
    return {"web": "\n".join(lines)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two fabrics, one size, fewer repeats")
    parser.add_argument("--json-out", type=Path, default=None, help="write the result here")
    args = parser.parse_args(argv)
    result = run(args.quick)
    print(markdown_tables(result)["web"])
    if args.json_out:
        from catalog.core.atomic import write_text_atomic  # noqa: PLC0415
        write_text_atomic(args.json_out, json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
