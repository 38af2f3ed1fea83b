"""The colour-error table of docs/bispectral-results.md: fluorescence models against the measured
Donaldson matrices of the validation data's bispectral/ folder (catalog.optics.bispectral.study).

    .venv/bin/python tools/bispectral_table.py                       # markdown on stdout
    .venv/bin/python tools/bispectral_table.py --json out.json       # also the rows as JSON
    .venv/bin/python tools/bispectral_table.py --update-doc docs/bispectral-results.md

``--update-doc`` replaces what lies between the lines ``<!-- bispectral-table:begin -->``
and ``<!-- bispectral-table:end -->`` of that file (atomically).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

BEGIN = "<!-- bispectral-table:begin -->"
END = "<!-- bispectral-table:end -->"

LABELS = {"ignore": "(a) ignore", "paper": "(b) paper, k per material",
          "paper_global": "(b') paper, one k", "physical": "(c) physical",
          "physical_rgb": "(d) physical, RGB pipeline", "rgb_product": "(d') RGB albedo x light",
          "reduced_3x3": "(e) reduced 3x3", "reduced_3x3_uv": "(e') reduced 3x3 + UV",
          "physical_lsq": "(c) least squares on entries only",
          "physical_no_antistokes": "(c) vs matrix without anti-Stokes part",
          "physical_islands": "(c) with absorption islands",
          "data_antistokes": "data: anti-Stokes part", "data_10nm": "data: 10 nm colour"}


def _fit_table(models) -> list[str]:
    lines = ["| matrix | description | phi x a_peak | phi | a_peak | excitation peak nm | "
             "emission peak nm | rank-1 residual | residual / noise sigma |",
             "|---|---|---|---|---|---|---|---|---|"]
    for m in models:
        f = m.fit
        lines.append(f"| {m.matrix.name} | {m.matrix.description} | {f.yield_absorptance:.3f} | "
                     f"{f.quantum_yield:.3f} | {f.peak_absorptance:.3f} | "
                     f"{f.excitation_peak_nm:.0f} | {f.emission_peak_nm:.0f} | "
                     f"{f.rank1_residual:.3f} | {f.residual_over_noise:.2f} |")
    return lines


def _summary_table(rows, study) -> list[str]:
    goal = study.summarise(rows, study.GOAL_LIGHTS)
    every = study.summarise(rows, study.STUDY_LIGHTS)
    lines = ["| method | mean, 8 x (D65 A FL2 FL11 LED-B4) | max | mean, all 8 lights | max |",
             "|---|---|---|---|---|"]
    for method in study.METHODS + study.DIAGNOSTICS:
        lines.append(f"| {LABELS[method]} | {goal[method]['mean']:.2f} | {goal[method]['max']:.2f} | "
                     f"{every[method]['mean']:.2f} | {every[method]['max']:.2f} |")
    lines += ["", "State of the art on the same 8 matrices x D65, A, FL2, FL11, LED-B4 "
              "(model.md section 8), mean / max:", ""]
    lines += [f"- {name}: {mean} / {peak}" for name, (mean, peak) in study.STATE_OF_THE_ART.items()]
    return lines


def _goal_lines(rows, study) -> list[str]:
    goal = study.summarise(rows, study.GOAL_LIGHTS)["physical"]
    met_mean = goal["mean"] <= study.GOAL_MEAN
    met_max = goal["max"] <= study.GOAL_MAX
    goal_rows = [r for r in rows if r["light"] in study.GOAL_LIGHTS]
    above = [r for r in goal_rows if r["physical"] > study.GOAL_MAX]
    worse_global = [r for r in rows if r["physical"] >= r["paper_global"]]
    worse_local = [r for r in rows if r["light"] != "D65" and r["physical"] >= r["paper"]]
    lines = [f"Goal for (c): mean <= {study.GOAL_MEAN}: {goal['mean']:.2f} "
             f"({'met' if met_mean else 'NOT met'}); max <= {study.GOAL_MAX}: {goal['max']:.2f} "
             f"({'met' if met_max else 'NOT met'})."]
    if above:
        lines.append("Above the max: " + ", ".join(
            f"{r['material']} under {r['light']} {r['physical']:.2f} (the data's anti-Stokes "
            f"part alone: {r['data_antistokes']:.2f})" for r in above) + ".")
    lines.append(f"(c) below (b') one-k paper mode: {len(rows) - len(worse_global)} of {len(rows)} "
                 "cases" + ("" if not worse_global else "; not in: " + ", ".join(
                     f"{r['material']}/{r['light']}" for r in worse_global)) + ".")
    n_local = len([r for r in rows if r["light"] != "D65"])
    lines.append(f"(c) below (b) per-material paper mode away from its calibration light D65: "
                 f"{n_local - len(worse_local)} of {n_local} cases" + ("" if not worse_local else
                 "; not in: " + ", ".join(f"{r['material']}/{r['light']} ({r['physical']:.2f} vs "
                                          f"{r['paper']:.2f})" for r in worse_local)) + ".")
    return lines


def _rows_table(rows, study) -> list[str]:
    columns = study.METHODS + study.DIAGNOSTICS
    lines = ["| matrix | light | " + " | ".join(LABELS[c] for c in columns) + " |",
             "|---|---|" + "---|" * len(columns)]
    for r in rows:
        lines.append(f"| {r['material']} | {r['light']} | "
                     + " | ".join(f"{r[c]:.2f}" for c in columns) + " |")
    return lines


def _noise_table(models, study, draws: int) -> tuple[list[str], dict]:
    import numpy as np

    lines = [f"Noise floor of the data: the exact colour's Delta E 2000 when the off-diagonal "
             f"noise (each matrix's own sigma) is re-drawn, {draws} draws x 8 matrices per light:",
             "", "| light | median | 95th percentile | max |", "|---|---|---|---|"]
    result = {}
    for light_name in study.STUDY_LIGHTS:
        light = study.light_irradiance(light_name)
        values = np.concatenate([study.noise_floor(m.matrix, light, m.fit.noise_sigma, draws,
                                                   seed=i) for i, m in enumerate(models)])
        result[light_name] = {"median": float(np.median(values)),
                              "p95": float(np.percentile(values, 95)), "max": float(values.max())}
        r = result[light_name]
        lines.append(f"| {light_name} | {r['median']:.2f} | {r['p95']:.2f} | {r['max']:.2f} |")
    return lines, result


def build_markdown(models, rows, study, noise_lines=()) -> str:
    parts = ["### Separable fit of each matrix", ""] + _fit_table(models)
    parts += ["", "### Delta E 2000 against the exact matrix result: summary", ""]
    parts += _summary_table(rows, study) + [""] + _goal_lines(rows, study)
    if noise_lines:
        parts += [""] + list(noise_lines)
    parts += ["", "### Per matrix and light", ""] + _rows_table(rows, study)
    return "\n".join(parts) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", metavar="FILE", help="also write the rows and summaries as JSON")
    parser.add_argument("--update-doc", metavar="MD", help="replace the generated part of this file")
    parser.add_argument("--noise-draws", type=int, default=30, metavar="N",
                        help="draws per matrix and light of the noise-floor table (0: skip)")
    args = parser.parse_args(argv)

    from catalog.optics.bispectral import study
    from catalog.core.atomic import write_text_atomic

    models = study.reference_models()
    rows = [row for m in models for row in study.study_material(m, study.STUDY_LIGHTS)]
    noise_lines, noise = _noise_table(models, study, args.noise_draws) if args.noise_draws > 0 else ([], {})
    markdown = build_markdown(models, rows, study, noise_lines)
    sys.stdout.write(markdown)
    if args.json:
        payload = {"rows": rows,
                   "summary_goal_lights": study.summarise(rows, study.GOAL_LIGHTS),
                   "summary_all_lights": study.summarise(rows, study.STUDY_LIGHTS),
                   "fits": [{"matrix": m.matrix.name, "description": m.matrix.description,
                             "yield_absorptance": m.fit.yield_absorptance,
                             "quantum_yield": m.fit.quantum_yield,
                             "peak_absorptance": m.fit.peak_absorptance,
                             "excitation_peak_nm": m.fit.excitation_peak_nm,
                             "emission_peak_nm": m.fit.emission_peak_nm,
                             "rank1_residual": m.fit.rank1_residual,
                             "residual_over_noise": m.fit.residual_over_noise,
                             "paper_scale": m.paper_scale,
                             "paper_scale_global": m.paper_scale_global} for m in models],
                   "noise_floor": noise,
                   "goal": {"mean": study.GOAL_MEAN, "max": study.GOAL_MAX},
                   "state_of_the_art": study.STATE_OF_THE_ART}
        write_text_atomic(args.json, json.dumps(payload, indent=1) + "\n")
    if args.update_doc:
        path = Path(args.update_doc)
        text = path.read_text(encoding="utf-8")
        if BEGIN not in text or END not in text:
            print(f"{path}: no {BEGIN} ... {END} markers", file=sys.stderr)
            return 2
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        write_text_atomic(path, head + BEGIN + "\n" + markdown + END + tail)
    return 0


if __name__ == "__main__":
    sys.exit(main())
