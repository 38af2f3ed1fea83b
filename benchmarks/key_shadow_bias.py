"""The key light's shadow on the cloth (curtain.frag KEY_SHADOW): which depth bias (issue 11).

A fragment is in a fold's shadow when it lies more than a bias behind the cloth layer nearest
the key light (the front-layer map). Too small a bias and a layer shades itself on its
flanks; too large and a fold lying close behind another escapes its shadow (the trough lines
of the close-ups). Candidates: constant biases, slope-scaled ones (a base plus a number of
map texels times the tangent of the angle between the cloth's normal and the key, capped),
and normal-offset lookups (the map read at a point moved towards the light along the
cloth's normal by a number of texels times the sine of that angle).

Chosen on data disjoint from the image section's scenes: the test drape
(:func:`catalog.render.scene.draped_curtain`, 60 x 40, not the simulated drapes of the
reference scenes) under keys that cross its folds and are not the scenes' lights, against
float64 ray casts in numpy (:mod:`catalog.render.raycast`): a pixel is truly behind a fold
when a ray towards the light meets the mesh farther than TRUTH_MIN_M; pixels within 1.5 map
texels of a shadow's edge are left out (the map is read at its nearest texels). The score is
the share of the remaining pixels where the G-buffer's "behind" (front coverage > 0.5) agrees.
"""

from __future__ import annotations

import numpy as np
from catalog.render.settings import orbit
from catalog.gl.context import own_context_unless_given

#: (base bias m, slope texels, tangent cap, normal offset texels); the first is the frame's
#: earlier constant 2 cm.
CANDIDATES = ((0.02, 0.0, 0.0, 0.0), (0.008, 0.0, 0.0, 0.0), (0.004, 0.0, 0.0, 0.0),
              (0.004, 1.5, 4.0, 0.0), (0.004, 1.0, 2.0, 0.0), (0.004, 1.0, 4.0, 0.0),
              (0.002, 1.0, 4.0, 0.0), (0.006, 0.5, 4.0, 0.0), (0.004, 1.5, 1.5, 0.0),
              (0.004, 1.0, 1.0, 0.0), (0.003, 1.5, 2.0, 0.0),
              # normal-offset lookups (the last number: texels x sin(normal, key))
              (0.004, 0.0, 0.0, 1.0), (0.004, 0.0, 0.0, 1.5), (0.002, 0.0, 0.0, 1.5),
              (0.004, 0.5, 2.0, 1.0), (0.004, 1.5, 4.0, 1.0))
#: The test drapes (draped_curtain's folds and depth): the default, and deeper, narrower folds
#: like the simulated drapes' (their flanks lie close behind one another).
DRAPES = ((5.5, 0.07), (8.0, 0.12))
#: Keys (elevation deg, azimuth deg) across the folds; none is a scene of the image section.
KEYS = ((20.0, 60.0), (15.0, -45.0), (30.0, 70.0))
#: Farther than this along the ray, a mesh hit is another layer (not the pixel's own).
TRUTH_MIN_M = 0.003
RESULT_JSON = "benchmarks/key_shadow_bias.json"


def shadow_truth(points: np.ndarray, to_light: np.ndarray, mesh) -> tuple[np.ndarray, np.ndarray]:
    """(behind, clear) per point: a ray towards the light meets the mesh farther than
    TRUTH_MIN_M; and the same answer for the ray moved 1.5 map texels either side (away from
    a shadow's edge)."""
    from catalog.render import curtain_frames  # noqa: PLC0415
    from catalog.render.raycast import first_hit, mesh_triangles  # noqa: PLC0415

    triangles = mesh_triangles(mesh)
    start = points + 1e-4 * to_light
    distance = first_hit(start, to_light, triangles)
    behind = np.isfinite(distance) & (distance > TRUTH_MIN_M)
    texel = curtain_frames.shadow_texel_m(to_light)
    side = np.cross(to_light, [0.0, 1.0, 0.0])
    side /= np.linalg.norm(side)
    clear = np.ones_like(behind)
    for offset in (-1.5 * texel, 1.5 * texel):
        moved = first_hit(start + offset * side, to_light, triangles)
        clear &= (np.isfinite(moved) & (moved > TRUTH_MIN_M)) == behind
    return behind, clear


@own_context_unless_given   # without ctx: its own, released after (the caller's current again)
def run(ctx=None, size=(96, 72), fabric: str = "voile-white") -> dict:
    from benchmarks.results import machine_info  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render import frame as frame_lib  # noqa: PLC0415
    from catalog.render.passes import shadow as shadow_lib  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    preset = load_preset(find_preset(fabric))
    meshes = [scene_lib.draped_curtain(columns=60, rows=40, folds=f, depth_m=d) for f, d in DRAPES]
    saved = (shadow_lib.KEY_SHADOW_BIAS_M, shadow_lib.KEY_SHADOW_SLOPE_TEXELS, shadow_lib.KEY_SHADOW_SLOPE_CAP,
             shadow_lib.KEY_SHADOW_NORMAL_OFFSET_TEXELS)
    truth: dict = {}
    rows = []
    try:
        for candidate in CANDIDATES:
            (shadow_lib.KEY_SHADOW_BIAS_M, shadow_lib.KEY_SHADOW_SLOPE_TEXELS,
             shadow_lib.KEY_SHADOW_SLOPE_CAP, shadow_lib.KEY_SHADOW_NORMAL_OFFSET_TEXELS) = candidate
            scores, shaded = [], []
            for (elevation, azimuth), (m, mesh) in [(k, d) for d in enumerate(meshes) for k in KEYS]:
                renderer = frame_lib.FrameRenderer(ctx, size)
                try:
                    renderer.update(fabric=preset,
                                    light="D65",
                                    fluorescence="off",
                                    camera=orbit(0.0, 0.0, 1.6))
                    renderer.set_mesh(mesh.positions, mesh.normals, mesh.uvs, mesh.tangents, mesh.indices)
                    renderer.update(key_direction_deg=(elevation, azimuth))
                    g = renderer.render_gbuffer()
                    to_light = np.asarray(renderer.shading_inputs().key_to_light, dtype=np.float64)
                finally:
                    renderer.release()
                mask = g["mask"]
                if (m, elevation, azimuth) not in truth:
                    truth[(m, elevation, azimuth)] = shadow_truth(
                        g["position"][mask].astype(np.float64), to_light, mesh)
                behind, clear = truth[(m, elevation, azimuth)]
                seen = g["shadows"][mask][:, 1] > 0.5
                scores.append(float((seen[clear] == behind[clear]).mean()))
                shaded.append(float(behind[clear].mean()))
            rows.append({"bias_m": candidate[0], "slope_texels": candidate[1], "tangent_cap": candidate[2],
                         "normal_offset_texels": candidate[3],
                         "agreement": scores, "mean_agreement": float(np.mean(scores)),
                         "truly_shaded_share": shaded})
    finally:
        (shadow_lib.KEY_SHADOW_BIAS_M, shadow_lib.KEY_SHADOW_SLOPE_TEXELS,
         shadow_lib.KEY_SHADOW_SLOPE_CAP, shadow_lib.KEY_SHADOW_NORMAL_OFFSET_TEXELS) = saved
    best = max(rows, key=lambda r: r["mean_agreement"])   # the first of equals: CANDIDATES' order
    return {"machine": machine_info(), "fabric": fabric, "keys": [list(k) for k in KEYS],
            "drapes": [{"folds": f, "depth_m": d} for f, d in DRAPES],
            "truth_min_m": TRUTH_MIN_M, "rows": rows,
            "best": {k: best[k] for k in ("bias_m", "slope_texels", "tangent_cap",
                                          "normal_offset_texels", "mean_agreement")},
            "frame_uses": dict(zip(("bias_m", "slope_texels", "tangent_cap", "normal_offset_texels"), saved))}


def markdown_tables(result: dict) -> dict[str, str]:
    """``key-shadow-bias``: the candidates' agreement with the ray casts."""
    keys = ", ".join(f"{e:g} deg high, {a:g} deg aside" for e, a in result["keys"])
    drapes = " and ".join(f"{d['folds']:g} folds {100 * d['depth_m']:g} cm deep"
                          for d in result.get("drapes", [{"folds": 5.5, "depth_m": 0.07}]))
    lines = ["| base bias (mm) | slope (texels x tan) | tan cap | normal offset (texels x sin) "
             "| agreement per drape and key | mean |",
             "|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {1e3 * r['bias_m']:g} | {r['slope_texels']:g} | {r['tangent_cap']:g} | "
                     f"{r.get('normal_offset_texels', 0.0):g} | "
                     + " / ".join(f"{100 * a:.2f} %" for a in r["agreement"])
                     + f" | {100 * r['mean_agreement']:.2f} % |")
    used = result["frame_uses"]
    shaded = result["rows"][0]["truly_shaded_share"]
    lines.append("")
    lines.append(f"Drapes: {drapes}; keys: {keys}; the share of pixels truly behind a fold: "
                 + " / ".join(f"{100 * s:.1f} %" for s in shaded)
                 + f". The frame uses {1e3 * used['bias_m']:g} mm + {used['slope_texels']:g} texels x tan "
                 f"(cap {used['tangent_cap']:g}), the lookup offset "
                 f"{used.get('normal_offset_texels', 0.0):g} texels x sin.")
    return {"key-shadow-bias": "\n".join(lines)}


def main(argv=None) -> int:
    import sys  # noqa: PLC0415

    from benchmarks.results import study_main  # noqa: PLC0415

    return study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    raise SystemExit(main())
