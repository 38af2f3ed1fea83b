"""Two flat layers of cloth, path-traced: how well the frame passes the key light through a
nearer layer (issue 11).

Behind a fold nearer the key light, the frame lights the cloth with the key dimmed by that
layer (curtain.frag KEY_SHADOW): the holes pass it, a thread passes the directional lobe's
forward-scattered part as if it went on along the key (the collimated model,
``shading_reference.layer_beam_transmittance``). This study puts a seen layer B (LD 0: no
see-through) 10 cm behind a large layer A (towards the key), a directional key at
``theta`` from the normal behind them and a camera at ``phi`` in front, and path-traces B's
radiance (Mitsuba, volpath, the woven plugin; the layers' light between them included),
against:

- M1, the frame's model: B's eq. 7 for the key x ((1 - c) + c thread), c = 1 - LD,
  thread = a_spec forward(g_spec) / c;
- M2, the thread's light spread over the hemisphere behind B instead: (1 - c) x B's eq. 7
  + c thread x (a_diff F(mu; g_diff) + a_spec F(mu; g_spec)) / pi (the ambient by view's
  factors), the bound on the other side.

Without A, B's path-traced radiance is its eq. 7 (a column: the set-up's check).
"""

from __future__ import annotations

import math

import numpy as np

RESULT_JSON = "benchmarks/two_layers.json"
#: (key angle from the normal, view angle from the normal), degrees.
ANGLES = tuple((t, p) for t in (20, 40, 60) for p in (0, 30, 60))
GAP_M = 0.1
SPP = 4096


def _woven(btdf, direct: float) -> dict:
    return {"type": "woven", "direct": float(direct), "a_diff": btdf.a_diff, "g_diff": btdf.g_diff,
            "a_spec": btdf.a_spec, "g_spec": btdf.g_spec, "anisotropy": 0.0}


def _scene(mi, btdf, to_light, camera, with_front: bool):
    t = mi.ScalarTransform4f
    scene = {"type": "scene", "integrator": {"type": "volpath", "max_depth": 12},
             "sensor": {"type": "perspective", "fov": 2.0,
                        "to_world": t().look_at(origin=camera, target=[0, 0, 0], up=[0, 1, 0]),
                        "film": {"type": "hdrfilm", "width": 16, "height": 16, "pixel_format": "rgb",
                                 "rfilter": {"type": "box"}}},
             "seen": {"type": "rectangle", "to_world": t().scale([0.5, 0.5, 1]), "bsdf": _woven(btdf, 0.0)},
             "key": {"type": "directional", "direction": [-v for v in to_light],
                     "irradiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}}
    if with_front:
        scene["front"] = {"type": "rectangle", "to_world": t().translate([0, 0, -GAP_M]).scale([3, 3, 1]),
                          "bsdf": _woven(btdf, btdf.direct)}
    return mi.load_dict(scene)


def _eq7(mi, btdf, to_light, view) -> float:
    import drjit as dr  # noqa: PLC0415

    bsdf = mi.load_dict(_woven(btdf, 0.0))
    si = dr.zeros(mi.SurfaceInteraction3f)
    si.wi = mi.Vector3f(*[float(x) for x in view])
    si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))
    value = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(*[float(x) for x in to_light]))
    return float(np.asarray(value)[0].ravel()[0])


def run(fabric: str = "voile-white", spp: int = SPP) -> dict:
    from benchmarks.results import machine_info  # noqa: PLC0415
    from catalog.optics.shading_reference import (AMBIENT_VIEW_NODES, hg_hemisphere_factors,  # noqa: PLC0415
                                                  hg_hemisphere_factors_by_view)
    from catalog.pathtrace.backend import load_mitsuba  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415

    mi = load_mitsuba()
    btdf = load_preset(find_preset(fabric)).btdf
    coverage = 1.0 - btdf.direct
    thread = btdf.a_spec * hg_hemisphere_factors(btdf.g_spec)[0] / coverage
    rows = []
    for theta, phi in ANGLES:
        th, ph = math.radians(theta), math.radians(phi)
        to_light = [math.sin(th), 0.0, -math.cos(th)]
        view = np.array([math.sin(ph), 0.0, math.cos(ph)])
        camera = [float(5 * v) for v in view]
        traced = {}
        for front in (True, False):
            image = mi.render(_scene(mi, btdf, to_light, camera, front), spp=spp)
            traced[front] = float(np.asarray(image)[..., 0].mean())
        eq7 = _eq7(mi, btdf, to_light, view)

        def spread(g):
            return float(np.interp(abs(view[2]), AMBIENT_VIEW_NODES, hg_hemisphere_factors_by_view(g)[0]))

        diffuse = (btdf.a_diff * spread(btdf.g_diff) + btdf.a_spec * spread(btdf.g_spec)) / math.pi
        m1 = ((1.0 - coverage) + coverage * thread) * eq7
        m2 = (1.0 - coverage) * eq7 + coverage * thread * diffuse
        rows.append({"key_deg": theta, "view_deg": phi, "alone_traced": traced[False], "alone_eq7": eq7,
                     "behind_traced": traced[True], "m1_collimated": m1, "m2_spread": m2,
                     "m1_ratio": m1 / traced[True], "m2_ratio": m2 / traced[True]})
    log_m1 = [abs(math.log(r["m1_ratio"])) for r in rows]
    log_m2 = [abs(math.log(r["m2_ratio"])) for r in rows]
    return {"machine": machine_info(), "fabric": fabric, "spp": spp, "gap_m": GAP_M, "rows": rows,
            "summary": {"m1_ratio_range": [min(r["m1_ratio"] for r in rows), max(r["m1_ratio"] for r in rows)],
                        "m2_ratio_range": [min(r["m2_ratio"] for r in rows), max(r["m2_ratio"] for r in rows)],
                        "m1_mean_abs_log": float(np.mean(log_m1)), "m2_mean_abs_log": float(np.mean(log_m2))}}


def markdown_tables(result: dict) -> dict[str, str]:
    """``two-layers``: per angle pair, B alone (traced, eq. 7) and behind A (traced, M1, M2)."""
    lines = ["| key (deg) | view (deg) | B alone, traced | B alone, eq. 7 | behind A, traced "
             "| M1 collimated (x traced) | M2 spread (x traced) |", "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['key_deg']} | {r['view_deg']} | {r['alone_traced']:.4f} | {r['alone_eq7']:.4f} | "
                     f"{r['behind_traced']:.4f} | {r['m1_collimated']:.4f} ({r['m1_ratio']:.2f}x) | "
                     f"{r['m2_spread']:.4f} ({r['m2_ratio']:.2f}x) |")
    s = result["summary"]
    lines.append("")
    lines.append(f"{result['fabric']}, {result['spp']} spp, the layers {100 * result['gap_m']:g} cm apart. "
                 f"M1 (the frame's) is {s['m1_ratio_range'][0]:.2f}-{s['m1_ratio_range'][1]:.2f}x the traced "
                 f"radiance, M2 {s['m2_ratio_range'][0]:.2f}-{s['m2_ratio_range'][1]:.2f}x; mean |log ratio| "
                 f"{s['m1_mean_abs_log']:.2f} against {s['m2_mean_abs_log']:.2f}.")
    return {"two-layers": "\n".join(lines)}


def main(argv=None) -> int:
    import sys  # noqa: PLC0415

    from benchmarks.results import study_main  # noqa: PLC0415

    return study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    raise SystemExit(main())
