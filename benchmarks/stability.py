"""Numerical stability: every model's parameters swept to their edges.

Each probe returns the number of values it checked, the worst relative error against its
float64 reference (or closed form) and the number of non-finite values found; the bar is
zero non-finite values anywhere.

- ``hg_glsl``: eq. 6 in float32 GLSL (benchmarks/shaders/probe_hg.comp, the shader's own function)
  against float64 (catalog.optics.btdf) for g from -0.99999 to 0.99999 and theta from 0 (exactly)
  to pi;
- ``hg_float64``: eq. 6 in float64 at |g| up to 1 - 1e-15 and theta from 0 to pi, in the
  1 - cos form and the vector form: finite, and the sphere integral of ph still 1 where
  the quadrature resolves the lobe;
- ``render_irradiance``: the renderer's float32 frame against the float64 spectral
  reference with the light scaled over 12 orders of magnitude (1e-6 .. 1e6 x its level,
  so brightener saturation is reached), in RGB (exact for one light on one material, so
  any difference is float32), with tau at 0 and 20 (e^-tau down to 2e-9) and the HG g's
  at +-0.999; ``render_band_scaling``: a 16-band frame scales with the light;
- ``fluorescence``: physical-mode emission over irradiance 1e-6 .. 1e6 x D65 against the
  closed form phi N / (1 + N / N_sat), and photons emitted <= absorbed;
- ``cloth``: stretch stiffness 10 .. 1e7 N/m, bend 0 .. 100 N/m, frame dt 1/1000 .. 1/10 s
  and wind 0 .. 30 m/s on the ``cpu`` backend (``numpy`` where numba cannot run); "relative error" is the largest spring
  strain over the strain limit's (max_stretch) allowance.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from catalog.core.constants import FRAME_DT_S
from catalog.gl.context import own_context_unless_given

G_EDGES = (-0.99999, -0.9999, -0.999, -0.9, -0.3, 0.0, 0.3, 0.9, 0.999, 0.9999, 0.99999)
THETAS = np.concatenate([[0.0], np.geomspace(1e-7, 1e-2, 24), np.linspace(0.02, math.pi, 60)])
SCALES = tuple(10.0 ** k for k in range(-6, 7, 2))  # 12 orders of magnitude
QUICK_SCALES = (1e-6, 1.0, 1e6)
#: Rec. 709 / sRGB luminance of linear RGB.
LUMINANCE_WEIGHTS = np.array([0.2126, 0.7152, 0.0722])


def _probe(name: str, checked: int, worst: float, non_finite: int, **extra) -> dict:
    return {"probe": name, "checked": int(checked), "worst_rel_error": float(worst),
            "non_finite": int(non_finite), **extra}


def hg_glsl(ctx) -> list[dict]:
    """The shader's HG (float32) against float64, via the renderer's probe shader."""
    from catalog.optics.btdf import hg_phase_one_minus_cos  # noqa: PLC0415
    from catalog.gl.shaderlib import create_compute  # noqa: PLC0415

    tilt = 0.3
    base = np.array([math.sin(tilt), 0.0, math.cos(tilt)])
    ortho = np.array([math.cos(tilt), 0.0, -math.sin(tilt)])
    travel = np.tile(base, (THETAS.size, 1)).astype(np.float32)
    view = (np.cos(THETAS)[:, None] * base + np.sin(THETAS)[:, None] * ortho).astype(np.float32)
    t64 = travel / np.linalg.norm(travel.astype(np.float64), axis=1, keepdims=True)
    v64 = view / np.linalg.norm(view.astype(np.float64), axis=1, keepdims=True)
    chord2 = np.sum((v64 - t64) ** 2, axis=1)
    anti2 = np.sum((v64 + t64) ** 2, axis=1)
    one_minus_cos = np.where(chord2 < 2.0, 0.5 * chord2, 2.0 - 0.5 * anti2)
    shader = create_compute(ctx, "probe_hg.comp")
    n = THETAS.size
    pad = np.zeros((n, 1), np.float32)
    buffers = [ctx.buffer(np.hstack([travel, pad]).tobytes()),
               ctx.buffer(np.hstack([view, pad]).tobytes()), ctx.buffer(reserve=4 * n)]
    for binding, buffer in enumerate(buffers):
        buffer.bind_to_storage_buffer(binding)
    rows = []
    try:
        for g in G_EDGES:
            shader["u_g"].value = float(g)
            shader["u_count"].value = n
            shader.run(group_x=(n + 63) // 64)
            glsl = np.frombuffer(buffers[2].read(), dtype=np.float32).astype(np.float64)
            reference = hg_phase_one_minus_cos(one_minus_cos, float(np.float32(g)))
            bad = ~np.isfinite(glsl)
            rel = np.abs(glsl - reference) / np.abs(reference)
            rows.append(_probe("hg_glsl", n, float(np.max(np.where(bad, 0.0, rel))),
                               int(np.sum(bad)), parameter=f"g={g}"))
    finally:
        for buffer in buffers:
            buffer.release()
        shader.release()
    return rows


def hg_float64() -> list[dict]:
    """Float64 eq. 6 at the very edges of g, in both of catalog.optics.btdf's forms: from 1 - cos
    theta (the fit's) and from the two direction vectors (the reference renderer's, which
    takes 1 + cos theta from |a + b|^2 / 2 for g < 0). Finite everywhere, and the sphere
    integral of ph still 1 where the quadrature resolves the lobe."""
    from catalog.optics.btdf import hg_phase_between, hg_phase_one_minus_cos  # noqa: PLC0415

    rows = []
    # dense at both ends: the forward lobe lives near 1 - cos = 0, the backward one near 2
    near = np.geomspace(1e-16, 1.0, 2000)
    omc = np.unique(np.concatenate([[0.0], near, 2.0 - near, [2.0]]))
    theta = np.arccos(np.clip(1.0 - omc, -1.0, 1.0))
    theta[-1] = math.pi
    travel = np.tile([0.0, 0.0, 1.0], (omc.size, 1))
    view = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=1)
    for g in (-(1 - 1e-15), -(1 - 1e-12), -(1 - 1e-9), -0.99999, 0.99999, 1 - 1e-9,
              1 - 1e-12, 1 - 1e-15):
        for form in ("1 - cos", "vectors"):
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                ph = (hg_phase_one_minus_cos(omc, g) if form == "1 - cos"
                      else hg_phase_between(travel, view, g))
            bad = ~np.isfinite(ph)
            # sphere integral 2 pi int ph d(1 - cos): the trapezoid on the log grids resolves
            # the lobe for |g| <= 0.99999 (its width ~ 1 - |g| >> the grid's 1e-16 start;
            # 2 - near rounds to a spacing of 2e-16 there, fine for widths of 1e-5)
            integral = 2 * math.pi * float(np.trapezoid(np.where(bad, 0.0, ph), omc))
            rel = abs(integral - 1.0) if abs(g) <= 0.99999 else 0.0
            rows.append(_probe("hg_float64", omc.size, rel, int(np.sum(bad)),
                               parameter=f"g={g!r}, {form} form", integral=integral))
    return rows


def fluorescence_sweep(scales) -> list[dict]:
    """Physical-mode emission against the closed form, over the irradiance range."""
    from catalog.optics.fluorescence import (absorbed_photon_irradiance, emitted_exitance_w_m2_nm,  # noqa: PLC0415
                                      photon_energy_j)
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render.scene import fluorescent_material  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    material = fluorescent_material(load_preset(find_preset("lace-fwa")))
    d65 = get_light("D65").irradiance_w_m2_nm
    rows = []
    worst, bad, violations = 0.0, 0, 0
    for scale in np.geomspace(1e-6, 1e6, 25) if len(scales) > 3 else scales:
        light = d65 * scale
        absorbed = absorbed_photon_irradiance(material, light)
        exitance = emitted_exitance_w_m2_nm(material, light)
        bad += int(np.sum(~np.isfinite(exitance))) + int(not math.isfinite(absorbed))
        emitted_photons = float(np.sum(exitance / photon_energy_j(GRID_NM)))  # dl = 1 nm
        expected = material.quantum_yield * absorbed / (1 + absorbed / material.saturation_photon_irradiance)
        worst = max(worst, abs(emitted_photons - expected) / expected)
        violations += int(emitted_photons > absorbed * (1 + 1e-12))
    rows.append(_probe("fluorescence", 25 if len(scales) > 3 else len(scales), worst, bad,
                       parameter="irradiance 1e-6..1e6 x D65", photons_created=violations))
    return rows


def render_sweep(ctx, scales, quick: bool) -> list[dict]:
    """Float32 frames against the float64 reference over 12 decades of light and edge
    values of tau and g."""
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415

    base = load_preset(find_preset("lace-fwa"))
    variants = [("lace-fwa", base)]
    variants.append(("tau=20", replace(base, btdf=replace(base.btdf, tau=20.0))))
    variants.append(("tau=0, g=+-0.999", replace(base, btdf=replace(base.btdf, tau=0.0,
                                                                    g_diff=-0.999, g_spec=0.999))))
    renderer = FrameRenderer(ctx, (48, 27) if quick else (96, 54))
    rows = []
    try:
        for label, preset in variants:
            renderer.update(fabric=preset)
            for light_name in (("sun:22",) if quick else ("sun:22", "UV-A")):
                light0 = get_light(light_name)
                worst, bad, checked = 0.0, 0, 0
                for scale in scales:
                    light = replace(light0, irradiance_w_m2_nm=light0.irradiance_w_m2_nm * scale)
                    renderer.update(light=light)
                    gb = renderer.render_gbuffer()
                    m = gb["mask"]
                    rgb = gb["radiance"][m].astype(np.float64)
                    bad += int(np.sum(~np.isfinite(rgb)))
                    truth = renderer.twin_linear_srgb(gb, m)
                    # relative to each pixel's luminance: a dark channel's rounding counts
                    # against the pixel, not against its own near-zero value
                    luminance = np.maximum(np.abs(truth @ LUMINANCE_WEIGHTS), 1e-300)
                    rel = np.max(np.abs(rgb - truth), axis=1) / luminance
                    worst = max(worst, float(np.max(np.where(np.isfinite(rel), rel, 0.0))))
                    checked += rgb.size
                rows.append(_probe("render_irradiance", checked, worst, bad,
                                   parameter=f"{label}, {light_name}, RGB, "
                                             f"x{min(scales):g}..x{max(scales):g}"))
    finally:
        renderer.release()
    return rows


def band_scaling(ctx, scales) -> list[dict]:
    """16 bands: the frame scales with the light (no saturation in a non-fluorescent cloth):
    frame(s) / s against frame(1), relative."""
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415

    renderer = FrameRenderer(ctx, (48, 27))
    rows = []
    try:
        renderer.update(fabric=load_preset(find_preset("sheer-teal")), bands=16)
        light0 = get_light("D65")
        renderer.update(light=light0)
        unit = renderer.render_gbuffer()["radiance"].astype(np.float64)
        mask = np.any(unit != 0, axis=-1)
        worst, bad = 0.0, 0
        for scale in scales:
            renderer.update(light=replace(light0, irradiance_w_m2_nm=light0.irradiance_w_m2_nm * scale))
            frame = renderer.render_gbuffer()["radiance"].astype(np.float64)
            bad += int(np.sum(~np.isfinite(frame)))
            y = np.abs(unit[mask]).max(axis=1)
            worst = max(worst, float(np.max(np.abs(frame[mask] / scale - unit[mask]).max(axis=1) / y)))
        rows.append(_probe("render_band_scaling", mask.sum() * 3 * len(scales), worst, bad,
                           parameter=f"sheer-teal, D65, 16 bands, x{min(scales):g}..x{max(scales):g}"))
    finally:
        renderer.release()
    return rows


def cloth_sweep(quick: bool) -> list[dict]:
    from catalog.cloth import ClothParams, ClothSimulation  # noqa: PLC0415

    cases = []
    for k in (10.0, 1e3, 1e5, 1e7):
        cases.append((f"stretch={k:g} N/m", {"stretch_stiffness_n_m": k}, FRAME_DT_S))
    for b in (0.0, 100.0):
        cases.append((f"bend={b:g} N/m", {"bend_stiffness_n_m": b}, FRAME_DT_S))
    for dt in (1 / 1000, 1 / 10):
        cases.append((f"dt={dt:g} s", {}, dt))
    cases.append(("wind=30 m/s", {"wind_speed_m_s": 30.0}, FRAME_DT_S))
    cases.append(("stretch=1e7, wind=30, dt=0.1", {"stretch_stiffness_n_m": 1e7,
                                                   "wind_speed_m_s": 30.0}, 1 / 10))
    if quick:
        cases = [cases[0], cases[3], cases[6], cases[-1]]
    from benchmarks.cloth import fastest_backend  # noqa: PLC0415

    backend = fastest_backend()
    grid = (8, 10) if quick or backend == "numpy" else (16, 20)
    frames = 10 if quick or backend == "numpy" else 40
    rows = []
    for label, changes, dt in cases:
        params = ClothParams(grid_w=grid[0], grid_h=grid[1],
                             **{"wind_speed_m_s": 1.0, **changes})
        sim = ClothSimulation(params, backend=backend)
        sim.run(frames, dt)
        x, v = sim.positions(), sim.velocities()
        bad = int(np.sum(~np.isfinite(x)) + np.sum(~np.isfinite(v))) + int(not sim.finite)
        strain = sim.state.max_stretch_seen
        rows.append(_probe("cloth", x.size + v.size, strain / params.max_stretch, bad,
                           parameter=f"{label} ({backend})", max_strain=float(strain)))
    return rows


@own_context_unless_given   # without ctx: its own, released after (the caller's current again)
def run(quick: bool = False, ctx=None) -> dict:

    scales = QUICK_SCALES if quick else SCALES
    rows = hg_glsl(ctx) + hg_float64() + fluorescence_sweep(scales) \
        + render_sweep(ctx, scales, quick) + band_scaling(ctx, scales) + cloth_sweep(quick)
    per_probe = {}
    for r in rows:
        p = per_probe.setdefault(r["probe"], {"checked": 0, "worst_rel_error": 0.0, "non_finite": 0})
        p["checked"] += r["checked"]
        if math.isfinite(r["worst_rel_error"]):
            p["worst_rel_error"] = max(p["worst_rel_error"], r["worst_rel_error"])
        p["non_finite"] += r["non_finite"]
    total_bad = sum(r["non_finite"] for r in rows)
    return {"rows": rows, "summary": {"per_probe": per_probe, "non_finite": total_bad,
                                      "bar_met": total_bad == 0},
            "settings": {"scales": list(scales), "g": list(G_EDGES)}}


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py);
#: `python -m benchmarks.stability` writes it (the same section as `catalog bench --sections stability`).
RESULT_JSON = "benchmarks/bench_stability.json"


#: What each probe sweeps, for the tables.
PROBE_LABELS = {
    "hg_glsl": "HG in float32 GLSL (`probe_hg.comp`) vs float64, g = -0.99999 .. 0.99999, theta 0 .. pi",
    "hg_float64": "HG in float64, abs(g) up to 1 - 1e-15, both catalog.optics.btdf forms; sphere integral",
    "fluorescence": "physical fluorescence vs closed form, irradiance 1e-6 .. 1e6 x D65 (saturation)",
    "render_irradiance": "renderer float32 RGB vs float64 reference, light x1e-6 .. x1e6, tau 0 and 20, "
                         "g +-0.999, sun:22 and UV-A",
    "render_band_scaling": "16-band frame scales with the light over 12 decades",
    "cloth": "cloth: stretch 10 .. 1e7 N/m, bend 0 .. 100, dt 1/1000 .. 1/10 s, wind up to 30 m/s "
             "(largest spring strain / the limit)",
}


def markdown_tables(result: dict) -> dict[str, str]:
    """``bench_stability`` (every probe, docs/bench.md) and ``bench_stability_brief``
    (BENCHMARKS.md)."""
    from benchmarks.results import fmt  # noqa: PLC0415

    summary, rows = result["summary"], result["rows"]

    def worst_row(probe: str, keep=lambda r: True) -> dict:
        mine = [r for r in rows if r["probe"] == probe and keep(r)
                and math.isfinite(r["worst_rel_error"])]
        return max(mine, key=lambda r: r["worst_rel_error"])

    def g_of(row) -> float:
        return abs(float(row["parameter"].split("=")[1].split(",")[0]))

    lines = ["| probe | values | worst relative error | where | non-finite |", "|---|---|---|---|---|"]
    for probe, v in summary["per_probe"].items():
        worst = worst_row(probe)
        where = worst["parameter"]
        error = fmt(v["worst_rel_error"])
        if probe == "hg_glsl":
            inner = worst_row(probe, lambda r: g_of(r) <= 0.9999)
            error = f"{fmt(inner['worst_rel_error'])} for abs(g) <= 0.9999, {error}"
        lines.append(f"| {PROBE_LABELS.get(probe, probe)} | {v['checked']} | {error} | {where} | "
                     f"{v['non_finite']} |")
    bad = [r for r in rows if r["non_finite"]]
    verdict = (f"**Bar {'met' if summary['bar_met'] else 'NOT met'}: {summary['non_finite']} "
               "non-finite values**" + ("" if not bad else " (" + "; ".join(
                   f"{r['probe']}: {r['parameter']}: {r['non_finite']}" for r in bad) + ")") + ".")
    cloth = worst_row("cloth")
    photons = max((r.get("photons_created", 0) for r in rows if r["probe"] == "fluorescence"),
                  default=0)
    per = summary["per_probe"]
    brief = (f"{verdict} HG in float32 GLSL: "
             f"{fmt(worst_row('hg_glsl', lambda r: g_of(r) <= 0.9999)['worst_rel_error'])} for "
             f"abs(g) <= 0.9999; renderer float32 vs float64: "
             f"{fmt(per['render_irradiance']['worst_rel_error'])}; fluorescence over 12 decades of "
             f"irradiance: {fmt(per['fluorescence']['worst_rel_error'])}, photons created: {photons}; "
             f"the cloth's largest spring strain: {fmt(cloth['max_strain'])} ({cloth['parameter']}).")
    return {"bench_stability": "\n".join(lines) + "\n\n" + verdict, "bench_stability_brief": brief}


if __name__ == "__main__":
    from benchmarks.results import section_main  # noqa: PLC0415

    raise SystemExit(section_main("stability"))
