"""Fluorescence in an RGB engine against the state of the art, on measured Donaldson matrices.

For each of the eight shared matrices (the validation data's bispectral/, catalog.optics.bispectral.matrix) and
every light of the library (catalog.optics.lights.light_names), the colour each representation
gives is compared by CIEDE2000 with the exact spectral result of the matrix (the ground
truth and white of catalog/optics/bispectral/study.py, which also supplies the paper-mode, the
physical-mode and the plain-RGB methods). Added here:

- ``fichet_3x3``, ``fichet_3x3_uv``: the light-independent reduced re-radiation matrix
  (3x3 in the CMF space; 3x4 with a UV band), :mod:`benchmarks.reduction`;
- ``per_light_3x3``: the same reduction with the light's own boxes as basis (exact for
  that light: the reduced form of pre-integrating the measured matrix per pair);
- ``bands_6``, ``bands_9``, ``bands_16``: the renderer's N-band pipeline
  (catalog/render/bands.py) on the physical-mode (separable) material.

Cost columns: the numbers the shader carries for the material under one light, whether
they depend on the light (then they are recomputed on the CPU when the light changes),
and the median CPU time of that computation.

    .venv/bin/python -m benchmarks.fluorescence_rgb [--quick] [--json-out FILE]

writes benchmarks/bench_fluorescence.json (needs the validation data, ``--data``/CATALOG_DATA:
the matrices are not shipped), from which tools/docs_figures.py makes the tables of
docs/bench.md and BENCHMARKS.md.
"""

from __future__ import annotations

import math

import numpy as np

from catalog.core.constants import LUMINOUS_EFFICACY_LM_W as LM_PER_W
from benchmarks.timing import median_seconds

#: method -> (label, numbers the shader carries, recomputed per light?)
METHODS = {
    "ignore": ("ignore fluorescence (RGB albedo x light)", 3, True),
    "paper": ("paper eq. 8, k fitted per material", 7, False),
    "paper_global": ("paper eq. 8, one k", 7, False),
    "physical": ("physical mode, spectral (1 nm)", 481, True),
    "physical_rgb": ("physical mode, RGB pipeline (renderer)", 6, True),
    "rgb_product": ("physical emission + RGB albedo x light", 6, True),
    "bands_6": ("physical mode, 6 bands", 12, True),
    "bands_9": ("physical mode, 9 bands", 18, True),
    "bands_16": ("physical mode, 16 bands", 32, True),
    "fichet_3x3": ("reduced 3x3 (Fichet et al. 2024)", 9, False),
    "fichet_3x3_uv": ("reduced 3x3 + UV band (Fichet et al. 2024)", 12, False),
    "per_light_3x3": ("reduced 3x3, per-light basis (needs the measured matrix)", 9, True),
}
STUDY_METHODS = ("ignore", "paper", "paper_global", "physical", "physical_rgb", "rgb_product")
BAND_COUNTS = (6, 9, 16)


def bands_xyz(models, light: np.ndarray, n_bands: int) -> np.ndarray:
    """XYZ of the physical-mode material through the renderer's N-band pipeline."""
    from catalog.optics.colorimetry import linear_srgb_to_xyz  # noqa: PLC0415
    from catalog.optics.fluorescence import emitted_exitance_w_m2_nm  # noqa: PLC0415
    from catalog.render.bands import band_weights  # noqa: PLC0415

    weights, to_rgb = band_weights(n_bands, light)
    emitted = emitted_exitance_w_m2_nm(models.fit.material(), light)
    values = (weights @ (models.reflectance_fit * light)).astype(np.float32) \
        + (weights @ emitted).astype(np.float32)
    return linear_srgb_to_xyz(to_rgb @ values.astype(np.float64))


class Representations:
    """Every method's XYZ for one matrix; the light-independent reductions computed once."""

    def __init__(self, models):
        from benchmarks import reduction  # noqa: PLC0415

        self.models = models
        self.reduction = reduction
        self.fichet = reduction.fichet_reduced(models.matrix, with_uv=False)
        self.fichet_uv = reduction.fichet_reduced(models.matrix, with_uv=True)
        self.sensors = reduction.cmf_sensors(False)
        self.sensors_uv = reduction.cmf_sensors(True)

    def xyz(self, method: str, light: np.ndarray) -> np.ndarray:
        from catalog.optics.bispectral import study  # noqa: PLC0415

        if method in STUDY_METHODS:
            return study.method_xyz(self.models, method, light)
        if method.startswith("bands_"):
            return bands_xyz(self.models, light, int(method.split("_")[1]))
        if method == "fichet_3x3":
            return LM_PER_W * self.reduction.apply_reduced(self.fichet, self.sensors, light)
        if method == "fichet_3x3_uv":
            return LM_PER_W * self.reduction.apply_reduced(self.fichet_uv, self.sensors_uv, light)
        if method == "per_light_3x3":
            reduced = self.reduction.per_light_reduced(self.models.matrix, light)
            return LM_PER_W * self.reduction.apply_reduced(reduced, self.sensors, light)
        raise ValueError(f"unknown method {method!r}")


def run(quick: bool = False, ctx=None) -> dict:
    from catalog.optics.bispectral import study  # noqa: PLC0415
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid  # noqa: PLC0415
    from catalog.optics.colorimetry import delta_e_2000  # noqa: PLC0415
    from catalog.optics.lights import light_names  # noqa: PLC0415

    lights = study.STUDY_LIGHTS if quick else tuple(light_names())
    irradiance = {name: study.light_irradiance(name) for name in lights}
    all_models = study.reference_models()
    rows = []
    cross_check = 0.0
    for models in all_models:
        reps = Representations(models)
        # our reduction against the bispectral study's own implementation (same idea)
        cross_check = max(cross_check, float(np.max(np.abs(reps.fichet - models.reduced_3x3))
                                             / np.max(np.abs(models.reduced_3x3))))
        for name in lights:
            light = irradiance[name]
            exact = study._xyz(exact_exitance_on_grid(models.matrix, light))
            if not exact[1] > 0:
                continue  # a light with nothing visible and no UV the matrix answers
            white = study.white_xyz(light, exact)
            row = {"material": models.matrix.name, "light": name}
            for method in METHODS:
                row[method] = float(delta_e_2000(reps.xyz(method, light), exact, white))
            rows.append(row)
    # cost: per-light CPU work of each method for one (material, light) pair
    reps = Representations(all_models[0])
    d65 = irradiance.get("D65", study.light_irradiance("D65"))
    cpu_ms = {m: 1e3 * median_seconds(lambda m=m: reps.xyz(m, d65), 3 if quick else 7)
              for m in METHODS}
    return {"rows": rows, "summary": summarise(rows, cpu_ms, study.GOAL_LIGHTS),
            "settings": {"lights": list(lights), "materials": [m.matrix.name for m in all_models],
                         "reduction_vs_bispectral_study_max_rel_diff": cross_check}}


def summarise(rows: list[dict], cpu_ms: dict, goal_lights) -> dict:
    per_method = {}
    goal_rows = [r for r in rows if r["light"] in goal_lights]
    for method, (label, numbers, per_light) in METHODS.items():
        values = np.array([r[method] for r in rows])
        goal = np.array([r[method] for r in goal_rows]) if goal_rows else np.array([math.nan])
        per_method[method] = {
            "label": label, "shader_numbers": numbers, "recomputed_per_light": per_light,
            "cpu_ms_per_light": cpu_ms[method],
            "mean_all_lights": float(np.mean(values)), "p95_all_lights": float(np.percentile(values, 95)),
            "max_all_lights": float(np.max(values)),
            "mean_goal_lights": float(np.mean(goal)), "max_goal_lights": float(np.max(goal)),
        }
    # what the shader should carry: among the representations a real-time shader can hold
    # (at most 16 numbers) and that need only the material's spectra (the catalog has no
    # measured matrices), the lowest mean error over every light
    carriable = {m: v for m, v in per_method.items()
                 if v["shader_numbers"] <= 16 and m != "per_light_3x3"}
    choice = min(carriable, key=lambda m: (carriable[m]["mean_all_lights"], carriable[m]["shader_numbers"]))
    light_independent = {m: v for m, v in carriable.items() if not v["recomputed_per_light"]}
    best_fixed = min(light_independent, key=lambda m: light_independent[m]["mean_all_lights"])
    return {"per_method": per_method, "choice": choice, "best_light_independent": best_fixed,
            "goal_lights": list(goal_lights), "cases": len(rows)}


def plot(result: dict, folder) -> list:
    """Mean Delta E over all lights per representation, against the numbers it carries."""
    from pathlib import Path  # noqa: PLC0415

    from benchmarks.plots import pyplot, save_figure  # noqa: PLC0415

    plt = pyplot()
    per = result["summary"]["per_method"]
    names = list(per)
    fig, ax = plt.subplots(figsize=(9, 5))
    y = np.arange(len(names))
    ax.barh(y - 0.2, [max(per[m]["mean_all_lights"], 1e-3) for m in names], 0.4,
            label=f"mean, all {len(result['settings']['lights'])} lights")
    ax.barh(y + 0.2, [max(per[m]["mean_goal_lights"], 1e-3) for m in names], 0.4,
            label="mean, D65 A FL2 FL11 LED-B4")
    ax.set_yticks(y, [f"{per[m]['label']} [{per[m]['shader_numbers']}]" for m in names], fontsize=7)
    ax.set_xscale("log")
    ax.set_xlabel(f"Delta E 2000 against the exact matrix result, "
                  f"{len(result['settings']['materials'])} measured matrices\n"
                  "(below 1e-3 drawn at 1e-3)", fontsize=8)
    choice = per[result["summary"]["choice"]]["label"]
    ax.set_title(f"Fluorescence in an RGB engine [numbers carried]\nchoice: {choice}", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return [save_figure(fig, Path(folder) / "bench_fluorescence_rgb.png")]


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/bench_fluorescence.json"
#: Rows of the short table in BENCHMARKS.md, the renderer's last.
BRIEF_METHODS = ("ignore", "paper", "fichet_3x3", "fichet_3x3_uv", "bands_16", "physical_rgb")


def markdown_tables(result: dict) -> dict[str, str]:
    """``fluorescence_representations`` (every method, docs/bench.md), ``fluorescence_brief``
    (BENCHMARKS.md) and ``fluorescence_findings`` (the figures the prose rests on)."""
    from benchmarks.results import fmt  # noqa: PLC0415

    s, st = result["summary"], result["settings"]
    per = s["per_method"]
    n_lights, goal = len(st["lights"]), " ".join(s["goal_lights"])
    choice = s["choice"]

    def bold(method: str, text: str) -> str:
        return f"**{text}**" if method == choice else text

    full = [f"| representation | mean, {goal} | max, same | mean, all {n_lights} lights | p95, all "
            "| max, all | numbers in the shader | recomputed per light | CPU ms per light |",
            "|---|---|---|---|---|---|---|---|---|"]
    for method, v in per.items():
        full.append("| " + " | ".join([
            bold(method, v["label"]), bold(method, fmt(v["mean_goal_lights"])),
            bold(method, fmt(v["max_goal_lights"])), bold(method, fmt(v["mean_all_lights"])),
            fmt(v["p95_all_lights"]), fmt(v["max_all_lights"]), str(v["shader_numbers"]),
            "yes" if v["recomputed_per_light"] else "no", fmt(v["cpu_ms_per_light"])]) + " |")
    full += ["", f"{len(st['materials'])} measured matrices x {n_lights} lights: {s['cases']} cases "
             "(a light whose exact result is black is left out); Delta E 2000 against the exact "
             "matrix result; CPU time: median for one (material, light) pair under D65."]
    brief = ["| representation | mean | max | mean, all lights |", "|---|---|---|---|"]
    for method in BRIEF_METHODS:
        v = per[method]
        brief.append("| " + " | ".join(bold(method, x) for x in (
            v["label"], fmt(v["mean_goal_lights"]), fmt(v["max_goal_lights"]),
            fmt(v["mean_all_lights"]))) + " |")
    brief += ["", f"Mean / max over {goal}; the last column over all {n_lights} library lights "
              f"({len(st['materials'])} Donaldson matrices, {s['cases']} cases)."]
    c, best = per[choice], per[s["best_light_independent"]]
    plain, uv, b16 = per["fichet_3x3"], per["fichet_3x3_uv"], per["bands_16"]
    findings = (
        f"Chosen (lowest mean over every light among the representations of at most 16 numbers "
        f"built from the fabric's spectra): **{c['label']}**, {fmt(c['mean_goal_lights'])} mean / "
        f"{fmt(c['max_goal_lights'])} max on {goal}, {fmt(c['mean_all_lights'])} mean over all "
        f"{n_lights} lights, {c['shader_numbers']} numbers recomputed in "
        f"{fmt(c['cpu_ms_per_light'])} ms when the light or fabric changes. The best "
        f"light-independent representation, {best['label']}: {fmt(best['mean_goal_lights'])} / "
        f"{fmt(best['max_goal_lights'])}, {fmt(best['mean_all_lights'])} over all lights. "
        f"Over all lights the 3x3 without the UV band: {fmt(plain['mean_all_lights'])} mean, "
        f"{fmt(plain['max_all_lights'])} worst, against {fmt(uv['mean_all_lights'])} and "
        f"{fmt(uv['max_all_lights'])} with it. 16 bands ({b16['shader_numbers']} numbers): "
        f"{fmt(b16['mean_all_lights'])} mean over all lights, "
        f"{b16['mean_all_lights'] / c['mean_all_lights']:.1f}x the chosen one's. Our reduction "
        f"on {goal}: {fmt(plain['mean_goal_lights'])} / {fmt(plain['max_goal_lights'])} (3x3), "
        f"{fmt(uv['mean_goal_lights'])} / {fmt(uv['max_goal_lights'])} (with the UV band); "
        f"against the bispectral study's implementation: "
        f"{fmt(st['reduction_vs_bispectral_study_max_rel_diff'])} relative.")
    return {"fluorescence_representations": "\n".join(full),
            "fluorescence_brief": "\n".join(brief), "fluorescence_findings": findings}


if __name__ == "__main__":
    from benchmarks.results import section_main  # noqa: PLC0415

    raise SystemExit(section_main("fluorescence"))
