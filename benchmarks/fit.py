"""Fit accuracy against cost: eq. 7 by Levenberg-Marquardt on 79 and on 4800 gonio points,
and by a global optimiser (scipy's differential evolution) on 4800.

Error is measured on the whole 4800-point OGM-3 grid whatever the points fitted: the
plain RMS difference (the paper's measure), the weighted RMS of the fit's own weighting
(relative: 1 / (y + 2 % of the median), :func:`catalog.fit.fitting.noise_scale`) and, on a
synthetic set made from known eq. 7 parameters plus 2 % relative noise, the largest
relative error of the recovered identifiable parameters. The catalog's gonio files come
from a yarn-level model, not from eq. 7, so they have no true parameters: only the
prediction errors are reported for them.

Differential evolution minimises the same weighted sum of squares over bounded
(direct, a_diff, a_spec, g_diff, g_spec), without the final gradient polish (so its own
accuracy is measured), seeded for reproducibility. All three fit eq. 7 as printed
(isotropic: catalog.fit.fitting's optional warp/weft anisotropy is left off).
"""

from __future__ import annotations

import time

import numpy as np

QUICK_FABRICS = ("lace-fwa", "sheer-teal")
#: The synthetic case's true parameters (identifiable set).
SYNTHETIC_TRUTH = {"direct": 0.3, "a_diff": 0.25, "a_spec": 0.35, "g_diff": 0.1, "g_spec": 0.9}
SYNTHETIC_NOISE = 0.02
#: DE bounds: (direct, a_diff, a_spec, g_diff, g_spec).
DE_BOUNDS = ((0.0, 2.0), (0.0, 3.0), (0.0, 3.0), (-0.9, 0.9999), (-0.9, 0.9999))


def synthetic_gonio(seed: int = 7):
    """The OGM-3 grid with eq. 7 values from SYNTHETIC_TRUTH times (1 + 2 % noise)."""
    from catalog.optics.btdf import eq7_transmittance  # noqa: PLC0415
    from catalog.fit.gonio import ogm3_grid  # noqa: PLC0415

    grid = ogm3_grid()
    t = SYNTHETIC_TRUTH
    clean = eq7_transmittance(grid.one_minus_cos, t["direct"], t["a_diff"], t["a_spec"],
                              t["g_diff"], t["g_spec"], grid.straight_through)
    rng = np.random.default_rng(seed)
    return grid.with_values(clean * (1.0 + SYNTHETIC_NOISE * rng.standard_normal(clean.size)))


def predict(data, params: dict) -> np.ndarray:
    from catalog.optics.btdf import eq7_transmittance  # noqa: PLC0415

    return eq7_transmittance(data.one_minus_cos, params["direct"], params["a_diff"],
                             params["a_spec"], params["g_diff"], params["g_spec"],
                             data.straight_through)


def fit_de(data, maxiter: int, seed: int = 1) -> tuple[dict, float, int]:
    """Differential evolution on the weighted eq. 7 residuals: (params, seconds, evaluations)."""
    from scipy.optimize import differential_evolution  # noqa: PLC0415

    from catalog.fit.fitting import noise_scale  # noqa: PLC0415

    inv_scale = 1.0 / noise_scale(data.transmittance, "relative")
    names = ("direct", "a_diff", "a_spec", "g_diff", "g_spec")

    def cost(x):
        residual = (predict(data, dict(zip(names, x))) - data.transmittance) * inv_scale
        return float(residual @ residual)

    start = time.perf_counter()
    result = differential_evolution(cost, DE_BOUNDS, maxiter=maxiter, seed=seed, polish=False,
                                    tol=1e-10, updating="deferred")
    seconds = time.perf_counter() - start
    params = dict(zip(names, map(float, result.x)))
    if params["g_diff"] > params["g_spec"]:  # name the sharper lobe "spec", as catalog.fit.fitting
        params = {"direct": params["direct"], "a_diff": params["a_spec"], "a_spec": params["a_diff"],
                  "g_diff": params["g_spec"], "g_spec": params["g_diff"]}
    return params, seconds, int(result.nfev)


def errors(data, params: dict, truth: dict | None) -> dict:
    from catalog.fit.fitting import noise_scale  # noqa: PLC0415

    predicted = predict(data, params)
    out = {"rmse_4800": float(np.sqrt(np.mean((predicted - data.transmittance) ** 2))),
           "weighted_rms_4800": float(np.sqrt(np.mean(
               ((predicted - data.transmittance) / noise_scale(data.transmittance)) ** 2))),
           "finite": bool(np.all(np.isfinite(predicted)))}
    if truth is not None:
        out["max_rel_param_error"] = float(max(abs(params[k] - v) / abs(v) for k, v in truth.items()))
    return out


def run(quick: bool = False, ctx=None) -> dict:
    from catalog.core.resources import FABRIC_DIR  # noqa: PLC0415
    from catalog.fit.fitting import fit_gonio_hg  # noqa: PLC0415
    from catalog.fit.gonio import paper_subset_mask, read_gonio  # noqa: PLC0415

    cases = [("synthetic eq. 7 (2 % noise)", synthetic_gonio(), SYNTHETIC_TRUTH)]
    folders = sorted(p for p in (FABRIC_DIR / "measurements").iterdir() if (p / "gonio.csv").is_file())
    if quick:
        folders = [p for p in folders if p.name in QUICK_FABRICS]
    cases += [(p.name, read_gonio(p / "gonio.csv"), None) for p in folders]
    maxiter = 60 if quick else 300
    import scipy.optimize  # noqa: F401, PLC0415 - its import (~1 s) is not the fit's time

    rows = []
    for name, data, truth in cases:
        subset = data.subset(paper_subset_mask(data))
        for method, fitted_on in (("LM, 79 points", subset), ("LM, 4800 points", data)):
            start = time.perf_counter()
            result = fit_gonio_hg(fitted_on, anisotropy=False)  # eq. 7 as printed, as DE
            seconds = time.perf_counter() - start
            rows.append({"case": name, "method": method, "points": len(fitted_on),
                         "seconds": seconds, "evaluations": int(result.evaluations),
                         **{k: float(v) for k, v in result.params.items()},
                         **errors(data, result.params, truth)})
        params, seconds, evaluations = fit_de(data, maxiter)
        rows.append({"case": name, "method": f"differential evolution, 4800 points ({maxiter} gen.)",
                     "points": len(data), "seconds": seconds, "evaluations": evaluations,
                     **params, **errors(data, params, truth)})
    return {"rows": rows, "summary": summarise(rows), "settings": {"de_maxiter": maxiter}}


def summarise(rows: list[dict]) -> dict:
    """Per method: median time, median weighted RMS on 4800 points relative to the best of
    the three on the same case, and the synthetic case's parameter error."""
    methods = sorted({r["method"] for r in rows}, key=[r["method"] for r in rows].index)
    best = {}
    for r in rows:
        best[r["case"]] = min(best.get(r["case"], np.inf), r["weighted_rms_4800"])
    out = {}
    for method in methods:
        mine = [r for r in rows if r["method"] == method]
        synthetic = [r for r in mine if "max_rel_param_error" in r]
        out[method] = {
            "median_seconds": float(np.median([r["seconds"] for r in mine])),
            "median_weighted_rms_over_best": float(np.median(
                [r["weighted_rms_4800"] / best[r["case"]] for r in mine])),
            "worst_weighted_rms_over_best": float(np.max(
                [r["weighted_rms_4800"] / best[r["case"]] for r in mine])),
            "synthetic_max_rel_param_error": (synthetic[0]["max_rel_param_error"]
                                              if synthetic else None),
        }
    return {"per_method": out}


def plot(result: dict, folder) -> list:
    from pathlib import Path  # noqa: PLC0415

    from benchmarks.plots import pyplot, save_figure  # noqa: PLC0415

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    markers = ("o", "s", "^")
    for i, method in enumerate(result["summary"]["per_method"]):
        mine = [r for r in result["rows"] if r["method"] == method]
        ax.scatter([r["seconds"] for r in mine], [r["weighted_rms_4800"] for r in mine],
                   marker=markers[i % 3], label=method)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("fit time, s")
    ax.set_ylabel("weighted RMS on all 4800 points")
    ax.set_title("Eq. 7 fit: error against time (one point per fabric)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return [save_figure(fig, Path(folder) / "bench_fit.png")]


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py);
#: `python -m benchmarks.fit` writes it (the same section as `catalog bench --sections fit`).
RESULT_JSON = "benchmarks/bench_fit.json"


def markdown_tables(result: dict) -> dict[str, str]:
    """``bench_fit`` (the three methods, docs/bench.md) and ``bench_fit_brief`` (what they
    show, BENCHMARKS.md)."""
    from benchmarks.results import fmt  # noqa: PLC0415

    per = result["summary"]["per_method"]
    lines = ["| method | median time s | weighted RMS / best, median | worst "
             "| synthetic set: worst relative parameter error |", "|---|---|---|---|---|"]
    for method, v in per.items():
        lines.append(f"| {method} | {fmt(v['median_seconds'])} | "
                     f"{fmt(v['median_weighted_rms_over_best'])} | "
                     f"{fmt(v['worst_weighted_rms_over_best'])} | "
                     f"{fmt(v['synthetic_max_rel_param_error'])} |")
    rows = result["rows"]
    by = {(r["case"], r["method"]): r for r in rows}
    cases = sorted({r["case"] for r in rows}, key=[r["case"] for r in rows].index)
    paper, lm, de = list(per)  # run order: LM 79 points, LM 4800 points, differential evolution
    gap = max(abs(by[(c, lm)]["weighted_rms_4800"] - by[(c, de)]["weighted_rms_4800"])
              / by[(c, de)]["weighted_rms_4800"] for c in cases)
    lm_not_worse = all(by[(c, lm)]["weighted_rms_4800"] <= by[(c, de)]["weighted_rms_4800"] * (1 + 1e-9)
                       for c in cases)
    paper_ratio = {c: by[(c, paper)]["weighted_rms_4800"] / by[(c, lm)]["weighted_rms_4800"]
                   for c in cases}
    worst = max(paper_ratio, key=paper_ratio.get)
    speed = per[de]["median_seconds"] / per[lm]["median_seconds"]
    text = (f"{len(cases)} cases. LM on the whole grid "
            f"{'reaches' if lm_not_worse else 'does NOT always reach'} the global optimiser's "
            f"minimum (largest relative difference in weighted RMS {fmt(gap)}) in "
            f"{fmt(per[lm]['median_seconds'] * 1e3)} ms against {fmt(per[de]['median_seconds'])} s "
            f"({speed:.0f}x, medians). The paper's 79 points cost "
            f"{100 * (per[paper]['median_weighted_rms_over_best'] - 1):.0f} % more weighted error on "
            f"the full grid (median; {100 * (paper_ratio[worst] - 1):.0f} % for {worst}), and "
            f"{fmt(per[paper]['synthetic_max_rel_param_error'])} worst relative parameter error on "
            f"the synthetic set against {fmt(per[lm]['synthetic_max_rel_param_error'])}.")
    return {"bench_fit": "\n".join(lines) + "\n\n" + text, "bench_fit_brief": text}


if __name__ == "__main__":
    from benchmarks.results import section_main  # noqa: PLC0415

    raise SystemExit(section_main("fit"))
