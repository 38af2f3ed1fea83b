"""The figures of docs/bispectral.md about the data and the colour refinement.

    .venv/bin/python -m benchmarks.bispectral_refinement [--json-out FILE]

writes benchmarks/bispectral_refinement.json (needs the validation data's bispectral
matrices, ``--data``/CATALOG_DATA; about a minute on one core), from which
tools/docs_figures.py makes the docs' blocks:

1. ``bispectral-data``: each matrix's measurement noise sigma (the fit's robust spread of
   the far anti-Stokes entries), the mean of its anti-Stokes entries beyond the
   reflectance band (a positive mean is an offset, not noise), and its negative entries on
   the Stokes side under UV excitation (below 400 nm).
2. ``bispectral-refinement-cv``: the reflectance tolerance of
   :func:`catalog.optics.bispectral.matrix.refine_for_colour` by 5-fold leave-group-out
   cross-validation on the training lights alone (:data:`FOLDS`): mean Delta E 2000 of the
   physical mode on the held-out lights, 8 matrices x every training light held out once.
3. ``bispectral-refinement-moves``: how far the default refinement moves the least-squares
   fit (reflectance, phi x a_peak, the entries' rms residual in noise sigmas).
4. ``bispectral-refinement-variants``: the goal set (8 matrices x GOAL_LIGHTS, mean /
   max) and the study lights UV-A and sun:500 for the least-squares fit, the default
   refinement, the entries weighted 3 times more, no reflectance tolerance, and the
   training set without some of its lights; ``bispectral-refinement-study-lights``: the default refinement against the
   least-squares fit under those two lights, the cases it makes better and worse;
   ``bispectral-refinement-whites``: what the refinement changes on the brightened whites,
   and both fits against the matrices without their anti-Stokes part;
   ``bispectral-islands-where``: the absorption islands the single-band rule drops.
"""

from __future__ import annotations

import sys

import numpy as np


RESULT_JSON = "benchmarks/bispectral_refinement.json"

#: The cross-validation folds: groups of similar training lights held out together.
FOLDS = {"warm Planckians": ("planck:2200", "planck:2500", "planck:3300"),
         "cool Planckians and daylights": ("planck:4000", "planck:5000", "planck:6500",
                                           "D50", "D55", "D75"),
         "FL1-6": ("FL1", "FL3", "FL4", "FL6"),
         "FL7-12": ("FL7", "FL8", "FL10", "FL12"),
         "LEDs": ("LED-B1", "LED-B2", "LED-B3", "LED-B5", "LED-BH1", "LED-RGB1", "LED-V1",
                  "LED-V2")}
#: Reflectance tolerances compared (None: no refinement, the least-squares fit).
TOLERANCES = (None, 0.0, 0.0025, 0.005, 0.01, 0.02)
#: UV excitation, nm: the Stokes-side entries below it that are negative are counted.
UV_BELOW_NM = 400.0
#: The brightened white plastics, whose anti-Stokes entries carry an offset.
WHITES = ("CIBA12", "CIPLAW10")
#: Where the refinement moves the whites' reflectance (nm): up in the blue, down in the orange.
WHITE_BANDS_NM = {"blue": (440.0, 500.0), "orange": (590.0, 630.0)}
#: The study lights outside the goal set that the variants are also scored under.
EXTRA_LIGHTS = ("UV-A", "sun:500")


def physical_delta_e(matrix, fit, light_name: str, reference=None) -> float:
    """Delta E 2000 of the physical mode of ``fit`` against the exact result of
    ``reference`` (default ``matrix``; the study's formula:
    catalog.optics.bispectral.study.method_xyz's ``physical``)."""
    from catalog.optics.bispectral import study  # noqa: PLC0415
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid  # noqa: PLC0415
    from catalog.optics.colorimetry import delta_e_2000  # noqa: PLC0415
    from catalog.optics.fluorescence import emitted_exitance_w_m2_nm  # noqa: PLC0415

    light = study.light_irradiance(light_name)
    exact = study._xyz(exact_exitance_on_grid(matrix if reference is None else reference, light))
    white = study.white_xyz(light, exact)
    model = study._xyz(fit.reflectance_on_grid() * light
                       + emitted_exitance_w_m2_nm(fit.material(), light))
    return float(delta_e_2000(model, exact, white))


def data_row(matrix, fit) -> dict:
    from catalog.optics.bispectral.matrix import REFLECTANCE_BAND_NM  # noqa: PLC0415

    shift = matrix.stokes_shift_nm()
    values = matrix.values
    excitation = np.broadcast_to(matrix.excitation_nm[None, :], values.shape)
    antistokes = values[shift < -REFLECTANCE_BAND_NM]
    uv_stokes = values[(shift > REFLECTANCE_BAND_NM) & (excitation < UV_BELOW_NM)]
    negative = uv_stokes[uv_stokes < 0]
    return {"matrix": matrix.name, "description": matrix.description,
            "noise_sigma": fit.noise_sigma, "antistokes_mean": float(antistokes.mean()),
            "uv_stokes_negative_count": int(negative.size),
            "uv_stokes_negative_mean": float(negative.mean()) if negative.size else 0.0,
            "uv_stokes_min": float(uv_stokes.min())}


def run() -> dict:
    from catalog.optics.bispectral import study  # noqa: PLC0415
    from catalog.optics.bispectral.matrix import (COLOUR_TRAINING_LIGHTS,  # noqa: PLC0415
                                                  REFLECTANCE_TOLERANCE, fit_separable, list_bfc,
                                                  read_bfc, refine_for_colour)

    held = sorted(light for group in FOLDS.values() for light in group)
    if held != sorted(COLOUR_TRAINING_LIGHTS):
        raise ValueError("the folds must hold every training light once")
    matrices = [read_bfc(p) for p in list_bfc()]
    lsq = [fit_separable(m, colour_lights=None) for m in matrices]

    # 1. the data
    data = [data_row(m, f) for m, f in zip(matrices, lsq)]

    # 2. cross-validation of the reflectance tolerance
    cv = []
    for tolerance in TOLERANCES:
        errors = []
        for fold, lights in FOLDS.items():
            train = tuple(name for name in COLOUR_TRAINING_LIGHTS if name not in lights)
            for m, f in zip(matrices, lsq):
                fit = f if tolerance is None else refine_for_colour(
                    m, f, lights=train, reflectance_tolerance=tolerance)
                errors += [physical_delta_e(m, fit, name) for name in lights]
        cv.append({"tolerance": tolerance, "held_out_mean": float(np.mean(errors)),
                   "cases": len(errors)})

    # 3. what the default refinement moves
    refined = [refine_for_colour(m, f) for m, f in zip(matrices, lsq)]
    moves = []
    for m, f, r in zip(matrices, lsq, refined):
        moves.append({"matrix": m.name,
                      "reflectance_max_abs": float(np.max(np.abs(np.asarray(r.reflectance)
                                                                 - np.asarray(f.reflectance)))),
                      "yield_absorptance_rel": float(r.yield_absorptance / f.yield_absorptance
                                                     - 1.0),
                      "residual_over_noise_change": float(r.residual_over_noise
                                                          - f.residual_over_noise)})

    # the whites: where their reflectance and strength move, their colour under A and D65
    whites = []
    for m, f, r in zip(matrices, lsq, refined):
        if m.name not in WHITES:
            continue
        delta = np.asarray(r.reflectance) - np.asarray(f.reflectance)
        band = {k: (m.emission_nm >= lo) & (m.emission_nm <= hi)
                for k, (lo, hi) in WHITE_BANDS_NM.items()}
        whites.append({"matrix": m.name, "blue_rise": float(delta[band["blue"]].max()),
                       "orange_drop": float(-delta[band["orange"]].min()),
                       "yield_absorptance_rel": float(r.yield_absorptance
                                                      / f.yield_absorptance - 1.0),
                       **{f"{light}_{kind}": physical_delta_e(m, fit, light)
                          for light in ("A", "D65") for kind, fit in (("lsq", f), ("refined", r))}})
    # the absorption islands the single-band rule drops (least squares without the rule)
    islands = {}
    for m, f in zip(matrices, lsq):
        if m.name not in WHITES:
            continue
        free = fit_separable(m, single_band=False, colour_lights=None)
        dropped = (free.absorption_weight > 0) & (f.absorption_weight == 0)
        peak = float(np.max(free.absorption_weight))
        islands[m.name] = [{"nm": float(nm), "of_peak": float(w / peak)} for nm, w in
                           zip(free.excitation_nm[dropped], free.absorption_weight[dropped])]
    # both fits against the matrices without their anti-Stokes part, on the goal set
    cleaned = [study.without_antistokes(m) for m in matrices]
    no_antistokes = {}
    for kind, fits in (("lsq", lsq), ("refined", refined)):
        errors = [physical_delta_e(m, f, name, reference=c)
                  for m, f, c in zip(matrices, fits, cleaned) for name in study.GOAL_LIGHTS]
        worst = int(np.argmax(errors))
        no_antistokes[kind] = {"mean": float(np.mean(errors)), "max": float(np.max(errors)),
                               "max_case": f"{matrices[worst // len(study.GOAL_LIGHTS)].name} "
                                           f"under {study.GOAL_LIGHTS[worst % len(study.GOAL_LIGHTS)]}"}

    # 4. variants scored on the goal set and the two study lights outside it
    def without(names):
        return tuple(n for n in COLOUR_TRAINING_LIGHTS if n not in names)

    planckians = tuple(n for n in COLOUR_TRAINING_LIGHTS if n.startswith("planck:"))
    daylights = ("planck:4000", "planck:5000", "planck:6500", "D50", "D55", "D75")
    variants = {
        "least squares (no refinement)": lsq,
        "refined (default)": refined,
        "refined, entries weighted 3x": [refine_for_colour(m, f, entry_weight=3.0)
                                         for m, f in zip(matrices, lsq)],
        "refined, reflectance tolerance 0": [refine_for_colour(m, f, reflectance_tolerance=0.0)
                                             for m, f in zip(matrices, lsq)],
        "refined without the Planckians at 2200-3300 K": [
            refine_for_colour(m, f, lights=without(FOLDS["warm Planckians"]))
            for m, f in zip(matrices, lsq)],
        "refined without any Planckian": [refine_for_colour(m, f, lights=without(planckians))
                                          for m, f in zip(matrices, lsq)],
        "refined on Planckians and daylights only": [
            refine_for_colour(m, f, lights=tuple(sorted(set(planckians) | set(daylights))))
            for m, f in zip(matrices, lsq)]}
    scored = []
    for label, fits in variants.items():
        goal = [physical_delta_e(m, f, name) for m, f in zip(matrices, fits)
                for name in study.GOAL_LIGHTS]
        extra = {name: {m.name: physical_delta_e(m, f, name) for m, f in zip(matrices, fits)}
                 for name in EXTRA_LIGHTS}
        scored.append({"variant": label, "goal_mean": float(np.mean(goal)),
                       "goal_max": float(np.max(goal)), "extra": extra})
    return {"data": data, "folds": {k: list(v) for k, v in FOLDS.items()},
            "default_tolerance": REFLECTANCE_TOLERANCE, "cross_validation": cv,
            "moves": moves, "whites": whites, "islands": islands, "no_antistokes": no_antistokes,
            "white_bands_nm": WHITE_BANDS_NM, "variants": scored, "extra_lights": list(EXTRA_LIGHTS),
            "goal_lights": list(study.GOAL_LIGHTS)}


def _tolerance_label(tolerance) -> str:
    return "no refinement" if tolerance is None else f"{100 * tolerance:g}%"


def markdown_tables(result: dict) -> dict[str, str]:
    """NAME -> markdown (see the module's docstring)."""
    data = ["| matrix | description | noise sigma | mean anti-Stokes entry beyond the band | "
            f"Stokes-side entries under excitation < {UV_BELOW_NM:.0f} nm: negatives, their mean, "
            "the lowest |", "|---|---|---|---|---|"]
    for r in result["data"]:
        data.append(f"| {r['matrix']} | {r['description']} | {r['noise_sigma']:.1e} | "
                    f"{r['antistokes_mean']:.1e} | {r['uv_stokes_negative_count']}, "
                    f"{r['uv_stokes_negative_mean']:.1e}, {r['uv_stokes_min']:.1e} |")
    cv = ["| reflectance tolerance | mean Delta E 2000 on the held-out lights |", "|---|---|"]
    best = min(result["cross_validation"], key=lambda r: r["held_out_mean"])
    for r in result["cross_validation"]:
        chosen = r["tolerance"] is not None and r["tolerance"] == result["default_tolerance"]
        label = _tolerance_label(r["tolerance"]) + (" (default)" if chosen else "")
        value = f"{r['held_out_mean']:.3f}"
        cv.append(f"| {label} | {'**' + value + '**' if r is best else value} |")
    cv.append(f"\n{result['cross_validation'][0]['cases']} cases per row (8 matrices x each "
              "training light held out once); folds: "
              + "; ".join(f"{k} ({', '.join(v)})" for k, v in result["folds"].items()) + ".")
    moves = result["moves"]
    r_max = max(moves, key=lambda m: m["reflectance_max_abs"])
    y_max = max(moves, key=lambda m: abs(m["yield_absorptance_rel"]))
    s_max = max(moves, key=lambda m: abs(m["residual_over_noise_change"]))
    moved = (f"The default refinement against the least-squares fit: R moves by at most "
             f"{r_max['reflectance_max_abs']:.4f} (absolute, {r_max['matrix']}), phi x a_peak "
             f"by at most {100 * abs(y_max['yield_absorptance_rel']):.1f}% ({y_max['matrix']}), "
             f"the entries' rms residual by at most "
             f"{abs(s_max['residual_over_noise_change']):.2f} noise sigma ({s_max['matrix']}).")
    extra = result["extra_lights"]
    names = [r["matrix"] for r in result["data"]]
    listed = result["variants"]
    variants = ["| case | " + " | ".join(v["variant"] for v in listed) + " |",
                "|---|" + "---|" * len(listed),
                "| goal set, mean | " + " | ".join(f"{v['goal_mean']:.3f}" for v in listed) + " |",
                "| goal set, max | " + " | ".join(f"{v['goal_max']:.3f}" for v in listed) + " |"]
    variants += [f"| {name} under {light} | "
                 + " | ".join(f"{v['extra'][light][name]:.2f}" for v in listed) + " |"
                 for light in extra for name in names]
    lsq = next(v for v in listed if v["variant"].startswith("least squares"))
    default = next(v for v in listed if v["variant"] == "refined (default)")
    parts = []
    for light in extra:
        pairs = [(name, lsq["extra"][light][name], default["extra"][light][name]) for name in names]
        better = [p for p in pairs if p[2] < p[1]]
        worse = [p for p in pairs if p[2] >= p[1]]

        def listing(chosen):
            return ", ".join(f"{n} {a:.2f} -> {b:.2f}" for n, a, b in chosen) or "none"
        parts.append(f"under {light} {len(better)} of {len(pairs)} better ({listing(better)}), "
                     f"{len(worse)} worse ({listing(worse)})")
    study_lights = ("The default refinement against the least-squares fit outside the goal "
                    "set, Delta E 2000: " + "; ".join(parts) + ".")
    blue, orange = result["white_bands_nm"]["blue"], result["white_bands_nm"]["orange"]
    w = result["whites"]
    na = result["no_antistokes"]
    white_text = (
        f"The default refinement on the brightened whites ({', '.join(x['matrix'] for x in w)}): "
        f"reflectance at {blue[0]:.0f}-{blue[1]:.0f} nm up by at most "
        f"{max(x['blue_rise'] for x in w):.4f}, at {orange[0]:.0f}-{orange[1]:.0f} nm down by at "
        f"most {max(x['orange_drop'] for x in w):.4f}, phi x a_peak "
        + ", ".join(f"{100 * x['yield_absorptance_rel']:+.1f}%" for x in w)
        + "; Delta E 2000 least squares -> refined under A "
        + ", ".join(f"{x['A_lsq']:.2f} -> {x['A_refined']:.2f}" for x in w)
        + ", under D65 " + ", ".join(f"{x['D65_lsq']:.2f} -> {x['D65_refined']:.2f}" for x in w)
        + ". Against the matrices without their anti-Stokes part (goal set, mean / max): "
        f"least squares {na['lsq']['mean']:.2f} / {na['lsq']['max']:.2f} (max: "
        f"{na['lsq']['max_case']}), refined {na['refined']['mean']:.2f} / "
        f"{na['refined']['max']:.2f} (max: {na['refined']['max_case']}).")
    islands_text = ("Absorption islands kept without the single-band rule (least squares), "
                    "nm and fraction of the absorption peak: " + "; ".join(
                        f"{name} " + ", ".join(f"{i['nm']:.0f} nm {100 * i['of_peak']:.1f}%"
                                               for i in found) if found else f"{name} none"
                        for name, found in result["islands"].items()) + ".")
    return {"bispectral-islands-where": islands_text,
            "bispectral-refinement-whites": white_text,
            "bispectral-refinement-study-lights": study_lights,
            "bispectral-data": "\n".join(data), "bispectral-refinement-cv": "\n".join(cv),
            "bispectral-refinement-moves": moved,
            "bispectral-refinement-variants": "\n".join(variants)}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415

    return study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    sys.exit(main())
