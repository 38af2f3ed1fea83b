"""Fluorescence under UV and violet light: the data's noise floor and the banded model.

    .venv/bin/python -m benchmarks.uv_fluorescence [--quick] [--no-frame] [--out benchmarks/bench_uv.json]

(also ``catalog bench --sections uv``). Needs the eight measured matrices
(the validation data's bispectral/ folder, --data or $CATALOG_DATA); docs/bispectral.md reads the tables it makes.

1. **Noise floor** (per matrix and TEST light): how far the exact colour itself moves
   under the data's own uncertainty: (a) the off-diagonal noise re-drawn at the matrix's
   measured sigma (``NOISE_DRAWS`` draws, the 95th percentile), (b) the anti-Stokes entries
   beyond the reflectance band kept or dropped, (c) the negative entries on the Stokes side
   (impossible for a passive surface: measurement error) kept or set to 0, (d) everything
   sampled every 10 nm against the interpolated 1 nm evaluation. The four are independent
   sources of error, so the floor of a case is their root sum of squares (as independent
   uncertainty components combine); the largest single part is reported beside it.
2. **Model choice**: each candidate of :func:`catalog.optics.bispectral.bands.all_candidates`
   (rank 1 = today's separable fit, then 2-14 excitation bands, then the 14 bands with the
   measured residual kept at rank 1, 2, 4, 8, 16 or whole) is scored on SELECTION_LIGHTS
   only, disjoint from the TEST lights and the GOAL lights; the rule: the fewest stored
   numbers whose mean Delta E 2000 on the selection lights is within ``CHOICE_TOLERANCE``
   (1%) of the best candidate's (see there for the history of that number). The rule is
   the one of the first part of the issue, unchanged; the residual candidates were added
   after that part's test scores were known (docs/bispectral.md says so).
3. **Scores** of every candidate on TEST, GOAL and HELD_OUT lights, with the bounds stated
   here first: TEST mean <= 1.5 and every case within its noise floor; GOAL mean <= 0.5,
   max <= 1.0; HELD_OUT mean not above the separable fit's.
4. **Cost**: numbers stored per material, CPU time of the per-(material, light)
   pre-integration (the renderer's shader takes the same uniforms whatever the model), and
   (:func:`frame_cost`, unless ``--no-frame``) the whole frame of a banded fabric against
   today's single-band one, side by side in one run.
"""

from __future__ import annotations

import math

import numpy as np

from catalog.gl.context import own_context_unless_given

#: The issue's test lights (UV and violet, the reddened sun, the HP lamps, a 2000 K flame).
TEST_LIGHTS = ("UV-A", "UV-385", "LED-405", "LED-violet-white", "sun:500", "HP1", "HP2",
               "planck:2000")
#: Lights the model is CHOSEN on: none of TEST_LIGHTS, none of the goal lights.
#: ``narrow:NNN`` is a Gaussian lamp at NNN nm, 12 nm FWHM, 10 W m^-2.
SELECTION_LIGHTS = ("narrow:375", "narrow:395", "narrow:415", "sun:300", "sun:400", "HP3",
                    "HP4", "HP5", "planck:1800", "FL3.15")
#: Bounds, stated before scoring (issue 15).
TEST_MEAN_BOUND = 1.5
GOAL_MEAN_BOUND, GOAL_MAX_BOUND = 0.5, 1.0
#: Re-drawn noise: draws per (matrix, light), and the percentile that sets the floor.
NOISE_DRAWS = 30
NOISE_PERCENTILE = 95.0
#: The selection rule's tolerance: fewest bands within this factor of the best mean. Every
#: candidate costs the shader the same (pre-integrated per light), so error decides; 1%
#: only breaks near-ties in favour of fewer stored spectra. (A first draft used 5%, which
#: picks 7 bands: 1.65 against 1.59 on the selection lights, but it makes the held-out
#: lights worse in the mean; both are in the benchmark JSON.)
CHOICE_TOLERANCE = 1.01


def light_spectrum(name: str) -> np.ndarray:
    """Irradiance on GRID_NM: a library light, ``planck:K`` or ``narrow:NNN``."""
    from catalog.optics.bispectral.matrix import training_light  # noqa: PLC0415
    from catalog.optics.lights import _gaussian  # noqa: PLC0415

    if name.startswith("narrow:"):
        line = _gaussian(float(name.split(":", 1)[1]), 12.0)
        return 10.0 * line / float(np.sum(line))
    return training_light(name)


def held_out_lights() -> tuple[str, ...]:
    """The library's lights that no fit trained on and no other set here uses."""
    from catalog.optics.bispectral.matrix import COLOUR_TRAINING_LIGHTS  # noqa: PLC0415
    from catalog.optics.bispectral.study import GOAL_LIGHTS  # noqa: PLC0415
    from catalog.optics.lights import light_names  # noqa: PLC0415

    used = set(COLOUR_TRAINING_LIGHTS) | set(GOAL_LIGHTS) | set(TEST_LIGHTS) | set(SELECTION_LIGHTS)
    return tuple(n for n in light_names() if n not in used)


def noise_floor_case(matrix, light: np.ndarray, sigma: float, draws: int) -> dict:
    """The three parts of the noise floor of one (matrix, light) and their maximum."""
    from catalog.optics.bispectral import study as st  # noqa: PLC0415
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid  # noqa: PLC0415
    from catalog.optics.colorimetry import delta_e_2000  # noqa: PLC0415

    redrawn = st.noise_floor(matrix, light, sigma, draws=draws)
    exact = st._xyz(exact_exitance_on_grid(matrix, light))
    white = st.white_xyz(light, exact)
    cleaned = st._xyz(exact_exitance_on_grid(st.without_antistokes(matrix), light))
    antistokes = float(delta_e_2000(cleaned, exact, white))
    clipped = st._xyz(exact_exitance_on_grid(without_negatives(matrix), light))
    negatives = float(delta_e_2000(clipped, exact, white))
    sampling = _Sampling(matrix).delta_e(light, exact, white)
    noise = float(np.percentile(redrawn, NOISE_PERCENTILE))
    return {"noise_p95": noise, "noise_median": float(np.median(redrawn)),
            "antistokes": antistokes, "negatives": negatives, "sampling_10nm": sampling,
            "floor_largest_part": max(noise, antistokes, negatives, sampling),
            "floor": math.hypot(noise, antistokes, negatives, sampling)}


def without_negatives(matrix):
    """The matrix with its negative entries on the Stokes side beyond the reflectance band
    set to 0: a passive surface cannot re-radiate a negative amount, so these are
    measurement error (noise, an over-subtracted dark level) that no physical
    (non-negative) model can follow. The anti-Stokes side is left to the anti-Stokes part of
    the floor, so the two parts touch disjoint entries."""
    from catalog.optics.bispectral.matrix import REFLECTANCE_BAND_NM, DonaldsonMatrix  # noqa: PLC0415

    shift = matrix.stokes_shift_nm()
    values = np.where((shift > REFLECTANCE_BAND_NM) & (matrix.values < 0), 0.0, matrix.values)
    return DonaldsonMatrix(matrix.emission_nm, matrix.excitation_nm, values, matrix.name,
                           matrix.description, matrix.path)


class _Sampling:
    """The study's 10 nm diagnostic for one matrix (``data_10nm``)."""

    def __init__(self, matrix):
        self.matrix = matrix

    def delta_e(self, light, exact, white) -> float:
        from types import SimpleNamespace  # noqa: PLC0415

        from catalog.optics.bispectral import study as st  # noqa: PLC0415

        return float(st._diagnostic_delta_e(SimpleNamespace(matrix=self.matrix), "data_10nm",
                                            light, exact, white))


#: Offsets (emission - excitation, in samples of 10 nm) of the near-diagonal study.
NEAR_OFFSETS = (-3, -2, -1, 1, 2, 3)
#: Columns where none of the eight materials fluoresces measurably (the bandwidth test).
QUIET_FROM_NM = 600.0


def near_diagonal_case(matrix) -> dict:
    """Is the near-diagonal the reflected light smeared by the monochromators' bandpass?

    For each offset k (emission = excitation + 10 k nm) over the quiet columns (excitation
    >= QUIET_FROM_NM, red of every emission here): the median entry, and the median of the
    entry over the reflectance of its excitation column. A smear by a 10 nm triangular
    bandpass would give the same ratio on both sides, about 0.25 at |k| = 1 (triangle
    autocorrelation at one FWHM) and 0 beyond, whatever the material."""
    lo, li = matrix.emission_nm, matrix.excitation_nm
    out = {}
    for k in NEAR_OFFSETS:
        entries, ratios = [], []
        for j, x in enumerate(li):
            if x < QUIET_FROM_NM:
                continue
            i = np.flatnonzero(lo == x + 10 * k)
            d = np.flatnonzero(lo == x)
            if i.size and d.size:
                entries.append(matrix.values[i[0], j])
                ratios.append(matrix.values[i[0], j] / matrix.values[d[0], j])
        out[str(k)] = {"median_entry": float(np.median(entries)),
                       "median_ratio": float(np.median(ratios))}
    return out


def collapsed_band(matrix):
    """The matrix with its +-10 nm neighbours added onto the diagonal (a line reflectance):
    what a representation without a near-diagonal kernel sees."""
    from catalog.optics.bispectral.matrix import DonaldsonMatrix  # noqa: PLC0415

    shift = matrix.stokes_shift_nm()
    near = np.abs(shift) == matrix.excitation_step_nm
    values = np.where(near, 0.0, matrix.values)
    moved = np.sum(np.where(near, matrix.values, 0.0), axis=1)
    for i, x in enumerate(matrix.emission_nm):
        values[i, np.flatnonzero(matrix.excitation_nm == x)[0]] += moved[i]
    return DonaldsonMatrix(matrix.emission_nm, matrix.excitation_nm, values, matrix.name,
                           matrix.description, matrix.path)


def run(quick: bool = False, ctx=None) -> dict:
    import time  # noqa: PLC0415

    from catalog.optics.bispectral import study as st  # noqa: PLC0415
    from benchmarks.timing import median_seconds  # noqa: PLC0415
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid, fit_separable, list_bfc, read_bfc  # noqa: PLC0415
    from catalog.optics.bispectral.bands import (CANDIDATE_EDGES, RESIDUAL_CANDIDATES,  # noqa: PLC0415
                                                 all_candidates, candidate_settings, fit_banded)
    from catalog.optics.colorimetry import delta_e_2000  # noqa: PLC0415

    held_out = held_out_lights()
    sets = {"test": TEST_LIGHTS, "goal": st.GOAL_LIGHTS, "selection": SELECTION_LIGHTS,
            "held_out": held_out}
    names = tuple(dict.fromkeys(n for s in sets.values() for n in s))
    spectra = {n: light_spectrum(n) for n in names}
    draws = 8 if quick else NOISE_DRAWS
    rows, floors, costs = [], [], {}
    fit_seconds = {}
    near = []
    for path in list_bfc():
        matrix = read_bfc(path)
        collapsed = collapsed_band(matrix)
        near.append({"material": matrix.name, "offsets": near_diagonal_case(matrix)})
        base = fit_separable(matrix)
        cleaned = without_negatives(st.without_antistokes(matrix))
        fits = {}
        for label in all_candidates():
            edges, residual, rank = candidate_settings(label)
            t0 = time.perf_counter()
            fits[label] = fit_banded(matrix, edges, base, residual=residual, residual_rank=rank)
            fit_seconds.setdefault(label, []).append(time.perf_counter() - t0)
        for name in names:
            light = spectra[name]
            exact = st._xyz(exact_exitance_on_grid(matrix, light))
            if not exact[1] > 0:
                continue
            white = st.white_xyz(light, exact)
            row = {"material": matrix.name, "light": name}
            test = name in TEST_LIGHTS
            if test:
                clean = st._xyz(exact_exitance_on_grid(cleaned, light))
                clean_white = st.white_xyz(light, clean)
            if test or name in SELECTION_LIGHTS:  # what a line reflectance loses
                row["near_diagonal_collapsed"] = round(float(delta_e_2000(
                    st._xyz(exact_exitance_on_grid(collapsed, light)), exact, white)), 5)
            for label, fit in fits.items():
                model = st._xyz(fit.exitance_w_m2_nm(light))
                row[label] = round(float(delta_e_2000(model, exact, white)), 5)
                if test:  # the model's own error: against the matrix without its artefacts
                    row[f"{label} vs cleaned"] = round(float(delta_e_2000(model, clean,
                                                                          clean_white)), 5)
            rows.append(row)
            if name in TEST_LIGHTS:
                floors.append({"material": matrix.name, "light": name,
                               **noise_floor_case(matrix, light, base.noise_sigma, draws)})
        if not costs:  # per-light pre-integration cost, one material, D65
            d65 = spectra["D65"]
            for label, fit in fits.items():
                n_components = sum(1 for c in fit.components if np.any(c.absorption > 0))
                costs[label] = {
                    "bands": len(fit.components), "components": n_components,
                    "residual_rank": (None if fit.residual is None else
                                      ("whole" if fit.residual_rank is None else fit.residual_rank)),
                    "stored_numbers": fit.stored_numbers(),
                    "shader_numbers": 6,
                    "cpu_ms_per_light": 1e3 * median_seconds(
                        lambda fit=fit: fit.exitance_w_m2_nm(d65), 3 if quick else 9)}
    for label, seconds in fit_seconds.items():  # fitting the bands once per material
        costs.setdefault(label, {})["fit_s_median"] = float(np.median(seconds))
    return {"rows": rows, "noise_floor": floors, "near_diagonal": near,
            "summary": summarise(rows, floors, costs, sets),
            "settings": {"lights": {k: list(v) for k, v in sets.items()},
                         "candidates": {k: list(v) for k, v in CANDIDATE_EDGES.items()},
                         "residual_candidates": {k: ("whole" if v is None else v)
                                                 for k, v in RESIDUAL_CANDIDATES.items()},
                         "noise_draws": draws, "noise_percentile": NOISE_PERCENTILE,
                         "white": "the light's own XYZ (a perfect white diffuser under it); "
                                  "when the sample is brighter, D65 chromaticity at the "
                                  "sample's Y", "quick": bool(quick)}}


def _stats(values) -> dict:
    values = np.asarray(values, dtype=np.float64)
    return {"mean": float(np.mean(values)), "max": float(np.max(values)),
            "p95": float(np.percentile(values, 95))}


def summarise(rows, floors, costs, sets) -> dict:
    from catalog.optics.bispectral.bands import all_candidates  # noqa: PLC0415

    labels = all_candidates()  # ordered by the numbers each stores, fewest first
    per = {}
    for label in labels:
        per[label] = {name: _stats([r[label] for r in rows if r["light"] in lights])
                      for name, lights in sets.items()}
        per[label]["test_vs_cleaned"] = _stats([r[f"{label} vs cleaned"] for r in rows
                                                if r["light"] in sets["test"]])
        per[label].update(costs.get(label, {}))
    best = min(per[label]["selection"]["mean"] for label in labels)
    choice = next(label for label in labels  # fewest stored numbers first
                  if per[label]["selection"]["mean"] <= CHOICE_TOLERANCE * best)
    floor_of = {(f["material"], f["light"]): f["floor"] for f in floors}
    test_rows = [r for r in rows if r["light"] in sets["test"]]
    over = [{"material": r["material"], "light": r["light"], "delta_e_2000": r[choice],
             "floor": floor_of[(r["material"], r["light"])]}
            for r in test_rows if r[choice] > floor_of[(r["material"], r["light"])]]
    largest = {(f["material"], f["light"]): f["floor_largest_part"] for f in floors}
    over_largest = [r for r in test_rows if r[choice] > largest[(r["material"], r["light"])]]
    baseline = labels[0]
    chosen = per[choice]
    verdict = {
        "test_mean": chosen["test"]["mean"], "test_mean_met": chosen["test"]["mean"] <= TEST_MEAN_BOUND,
        "test_mean_vs_cleaned": chosen["test_vs_cleaned"]["mean"],
        "cases_over_floor": over,
        "cases_over_largest_part": len(over_largest),
        "max_excess_over_largest_part": max((r[choice] - largest[(r["material"], r["light"])]
                                             for r in over_largest), default=0.0),
        "goal_mean": chosen["goal"]["mean"], "goal_max": chosen["goal"]["max"],
        "goal_met": chosen["goal"]["mean"] <= GOAL_MEAN_BOUND and chosen["goal"]["max"] <= GOAL_MAX_BOUND,
        "held_out_mean": chosen["held_out"]["mean"],
        "held_out_mean_rank1": per[baseline]["held_out"]["mean"],
        "held_out_not_worse": chosen["held_out"]["mean"] <= per[baseline]["held_out"]["mean"] + 1e-9,
    }
    per_light_floor = {}
    for name in sets["test"]:
        chosen_cases = [f for f in floors if f["light"] == name]
        per_light_floor[name] = {
            part: _stats([f[part] for f in chosen_cases])
            for part in ("noise_p95", "antistokes", "negatives", "sampling_10nm",
                         "floor_largest_part", "floor")}
    return {"per_candidate": per, "choice": choice, "baseline": baseline, "verdict": verdict,
            "noise_floor_per_light": per_light_floor,
            "bounds": {"test_mean": TEST_MEAN_BOUND, "goal_mean": GOAL_MEAN_BOUND,
                       "goal_max": GOAL_MAX_BOUND, "choice_tolerance": CHOICE_TOLERANCE}}


def _f(x: float) -> str:
    return f"{x:.2f}"


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/bench_uv.json"

#: A case the bands alone make this much worse than the separable fit (Delta E 2000) is
#: listed; a display threshold for the docs' table, set after seeing the figures.
WORSE_LISTED = 0.5
#: A case at least this large (Delta E 2000, bands alone) is listed as a large case.
LARGE_LISTED = 3.0
FLOOR_PART_NAMES = {"noise_p95": "re-drawn noise", "antistokes": "anti-Stokes part",
                    "negatives": "Stokes-side negatives", "sampling_10nm": "10 nm sampling"}


def bands_alone(result: dict) -> str:
    """The physical part alone (BANDS_CHOSEN, no residual) on the TEST lights: per-light
    mean / max against the separable fit's, the cases within their noise floor, the score
    against the cleaned matrices, and a table of the large, worse and above-floor cases."""
    from catalog.optics.bispectral.bands import BANDS_CHOSEN  # noqa: PLC0415

    base = "rank 1 (separable)"
    tests = [r for r in result["rows"] if r["light"] in TEST_LIGHTS]
    if not tests or BANDS_CHOSEN not in tests[0]:
        return "(no bands-alone rows in this run)"
    floors = {(f["material"], f["light"]): f for f in result["noise_floor"]}
    lights = [name for name in TEST_LIGHTS if any(r["light"] == name for r in tests)]

    def stats(key, light):
        values = [r[key] for r in tests if r["light"] == light]
        return f"{_f(float(np.mean(values)))} / {_f(max(values))}"

    within = sum(1 for r in tests if r[BANDS_CHOSEN] <= floors[(r["material"], r["light"])]["floor"])
    cleaned = [r[f"{BANDS_CHOSEN} vs cleaned"] for r in tests]
    text = (f"Bands alone ({BANDS_CHOSEN}) on the TEST lights: mean "
            f"{_f(float(np.mean([r[BANDS_CHOSEN] for r in tests])))} against the separable fit's "
            f"{_f(float(np.mean([r[base] for r in tests])))}; mean / max per light, bands alone "
            "(separable fit): " + "; ".join(f"{name} {stats(BANDS_CHOSEN, name)} "
                                            f"({stats(base, name)})" for name in lights)
            + f". {within} of {len(tests)} cases within their noise floor. Against the matrices "
            f"without their artefacts: mean {_f(float(np.mean(cleaned)))}, max {_f(max(cleaned))}.")
    lines = [text, "", f"The cases of {LARGE_LISTED:g} or more, those worse than the separable "
             f"fit by more than {WORSE_LISTED:g}, and those above their floor:", "",
             "| matrix | light | bands alone | separable fit | floor | its largest part |",
             "|---|---|---|---|---|---|"]
    for r in tests:
        floor = floors[(r["material"], r["light"])]
        if not (r[BANDS_CHOSEN] >= LARGE_LISTED or r[BANDS_CHOSEN] - r[base] > WORSE_LISTED
                or r[BANDS_CHOSEN] > floor["floor"]):
            continue
        part = max(FLOOR_PART_NAMES, key=lambda k: floor[k])
        above = " **(above its floor)**" if r[BANDS_CHOSEN] > floor["floor"] else ""
        lines.append(f"| {r['material']} | {r['light']} | {_f(r[BANDS_CHOSEN])}{above} | "
                     f"{_f(r[base])} | {_f(floor['floor'])} | {FLOOR_PART_NAMES[part]} "
                     f"{_f(floor[part])} |")
    return "\n".join(lines)


def markdown_tables(result: dict) -> dict[str, str]:
    """Generated blocks: ``uv-noise-floor``, ``uv-models``, ``uv-cases``, ``uv-bands-alone``."""
    s = result["summary"]
    out = {}
    lines = ["| light | re-drawn noise, 95th pct: median / max over 8 | anti-Stokes kept/dropped: "
             "median / max | Stokes-side negatives kept/clipped: median / max | 10 nm vs 1 nm: max | "
             "floor (root sum of squares): min / median / max |", "|---|---|---|---|---|---|"]
    floors = result["noise_floor"]
    for light, parts in s["noise_floor_per_light"].items():
        cases = [f for f in floors if f["light"] == light]
        noise = [f["noise_p95"] for f in cases]
        anti = [f["antistokes"] for f in cases]
        neg = [f["negatives"] for f in cases]
        floor = [f["floor"] for f in cases]
        lines.append(f"| {light} | {_f(np.median(noise))} / {_f(max(noise))} | "
                     f"{_f(np.median(anti))} / {_f(max(anti))} | "
                     f"{_f(np.median(neg))} / {_f(max(neg))} | {_f(parts['sampling_10nm']['max'])} | "
                     f"{_f(min(floor))} / {_f(np.median(floor))} / {_f(max(floor))} |")
    out["uv-noise-floor"] = "\n".join(lines)

    lines = ["| model | bands | stored numbers | CPU ms per light | selection mean / max | "
             "TEST mean / max | TEST vs cleaned matrix: mean / max | GOAL mean / max | "
             "held-out mean |", "|---|---|---|---|---|---|---|---|---|"]
    for label, p in s["per_candidate"].items():
        mark = " **(chosen)**" if label == s["choice"] else ""
        lines.append(f"| {label}{mark} | {p.get('bands', '')} | {p.get('stored_numbers', '')} | "
                     f"{p.get('cpu_ms_per_light', math.nan):.2f} | "
                     f"{_f(p['selection']['mean'])} / {_f(p['selection']['max'])} | "
                     f"{_f(p['test']['mean'])} / {_f(p['test']['max'])} | "
                     f"{_f(p['test_vs_cleaned']['mean'])} / {_f(p['test_vs_cleaned']['max'])} | "
                     f"{_f(p['goal']['mean'])} / {_f(p['goal']['max'])} | {_f(p['held_out']['mean'])} |")
    v = s["verdict"]
    n_held = len(result["settings"]["lights"]["held_out"])
    lines += ["", f"Chosen on the selection lights: **{s['choice']}**. Bounds (stated before "
              f"scoring): TEST mean <= {TEST_MEAN_BOUND}: {_f(v['test_mean'])} "
              f"({'met' if v['test_mean_met'] else 'NOT met'}); GOAL mean <= {GOAL_MEAN_BOUND}, "
              f"max <= {GOAL_MAX_BOUND}: {_f(v['goal_mean'])} / {_f(v['goal_max'])} "
              f"({'met' if v['goal_met'] else 'NOT met'}); {n_held} held-out lights, mean "
              f"{_f(v['held_out_mean'])} against the separable fit's {_f(v['held_out_mean_rank1'])} "
              f"({'not worse' if v['held_out_not_worse'] else 'WORSE'}); TEST cases above their "
              f"noise floor: {len(v['cases_over_floor'])} of "
              f"{sum(1 for r in result['rows'] if r['light'] in TEST_LIGHTS)} (above the largest "
              f"single part of it: {v['cases_over_largest_part']}, by at most "
              f"{_f(v['max_excess_over_largest_part'])}). Against the matrix without its "
              f"artefacts (anti-Stokes part dropped, Stokes-side negative entries at 0), the TEST mean is "
              f"{_f(v['test_mean_vs_cleaned'])}."]
    from catalog.optics.bispectral.bands import BANDS_CHOSEN  # noqa: PLC0415

    bands = s["per_candidate"].get(BANDS_CHOSEN)
    if bands is not None and BANDS_CHOSEN != s["choice"]:
        lines[-1] += (f" The physical part alone ({BANDS_CHOSEN}: non-negative bands, quantum "
                      f"yield <= 1) scores {_f(bands['test']['mean'])} against the raw "
                      f"matrices and {_f(bands['test_vs_cleaned']['mean'])} against the cleaned "
                      "ones: the chosen model's residual carries the data's artefacts, which "
                      "is what brings it to the raw matrix.")
    out["uv-models"] = "\n".join(lines)

    choice, base = s["choice"], s["baseline"]
    from catalog.optics.bispectral.bands import BANDS_CHOSEN  # noqa: PLC0415

    middle = [BANDS_CHOSEN] if BANDS_CHOSEN != choice and BANDS_CHOSEN in s["per_candidate"] else []
    floor_of = {(f["material"], f["light"]): f for f in floors}
    lines = [f"| matrix | light | separable | " + "".join(f"{m} | " for m in middle)
             + f"{choice} (chosen) | noise floor, root sum of squares "
             "(noise / anti-Stokes / negatives / 10 nm) | chosen within |",
             "|---|---|---|" + "---|" * len(middle) + "---|---|---|"]
    for r in result["rows"]:
        if r["light"] not in TEST_LIGHTS:
            continue
        f = floor_of[(r["material"], r["light"])]
        lines.append(f"| {r['material']} | {r['light']} | {_f(r[base])} | "
                     + "".join(f"{_f(r[m])} | " for m in middle) + f"{_f(r[choice])} | "
                     f"{_f(f['floor'])} ({_f(f['noise_p95'])} / {_f(f['antistokes'])} / "
                     f"{_f(f['negatives'])} / "
                     f"{_f(f['sampling_10nm'])}) | {'yes' if r[choice] <= f['floor'] else '**no**'} |")
    out["uv-cases"] = "\n".join(lines)
    out["uv-bands-alone"] = bands_alone(result)
    if "near_diagonal" in result:
        out["uv-near-diagonal"] = near_diagonal_table(result)
    if "frame" in result:
        out["uv-frame"] = frame_table(result["frame"])
    return out


def near_diagonal_table(result: dict) -> str:
    """The ``uv-near-diagonal`` block: entry / reflectance ratios next to the diagonal and
    what collapsing the +-10 nm neighbours onto it costs per light."""
    lines = ["| matrix | " + " | ".join(f"emission - excitation {10 * k:+d} nm"
                                       for k in NEAR_OFFSETS) + " |",
             "|---|" + "---|" * len(NEAR_OFFSETS)]
    for case in result["near_diagonal"]:
        cells = " | ".join(f"{100 * case['offsets'][str(k)]['median_ratio']:+.2f}%"
                           for k in NEAR_OFFSETS)
        lines.append(f"| {case['material']} | {cells} |")
    lines += ["", f"Median over the excitation columns from {QUIET_FROM_NM:.0f} nm (no "
              "fluorescence there) of the entry over the reflectance of its column; a 10 nm "
              "triangular bandpass would put about +25% at both +-10 nm.", "",
              "| light | neighbours +-10 nm collapsed onto the diagonal: Delta E 2000 mean / max "
              "over 8 |", "|---|---|"]
    sets = result["settings"]["lights"]
    for name in list(sets["test"]) + list(sets["selection"]):
        values = [r["near_diagonal_collapsed"] for r in result["rows"]
                  if r["light"] == name and "near_diagonal_collapsed" in r]
        if values:
            kind = "test" if name in sets["test"] else "selection"
            lines.append(f"| {name} ({kind}) | {_f(np.mean(values))} / {_f(max(values))} |")
    return "\n".join(lines)


@own_context_unless_given   # without ctx: its own, released after (the caller's current again)
def frame_cost(size=(640, 360), repeats: int = 7, draws: int = 3, ctx=None) -> dict:
    """Whole-frame time of a single-band fabric against the same fabric carrying the banded
    model, side by side in one run (rounds interleaved; medians), under LED-405, plus the
    CPU time of the per-light pre-integration (what a light change costs).

    The banded fabric is lace-fwa's cloth with CIBA12's chosen banded fit when the measured
    matrices are present (a temporary folder; never shipped), else lace-fwa's own spectra
    given as two bands. Frame times are wall clock; llvmpipe in CI, so noisy: ratios count.
    """
    import statistics  # noqa: PLC0415
    import tempfile  # noqa: PLC0415
    import time  # noqa: PLC0415

    from catalog.optics.bispectral.matrix import bispectral_dir, find_bfc, read_bfc  # noqa: PLC0415
    from catalog.optics.bispectral.bands import fit_banded  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset, preset_from_dict, preset_to_dict  # noqa: PLC0415
    from catalog.gl.context import describe  # noqa: PLC0415
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    single = load_preset(find_preset("lace-fwa"))
    folder = tempfile.mkdtemp(prefix="bench-uv-")
    if (bispectral_dir() / "CIBA12.BFC").is_file():
        from catalog.optics.bispectral.bands import DEFAULT_RESIDUAL, DEFAULT_RESIDUAL_RANK  # noqa: PLC0415
        from catalog.presets.banded import banded_preset  # noqa: PLC0415

        fit = fit_banded(read_bfc(find_bfc("CIBA12")), residual=DEFAULT_RESIDUAL,
                         residual_rank=DEFAULT_RESIDUAL_RANK)
        banded = banded_preset(single, fit, folder)
        what = (f"lace-fwa cloth with CIBA12's {len(fit.components)}-band fit"
                + ("" if fit.residual is None else " and its measured residual"))
    else:
        doc = preset_to_dict(single)
        fl = dict(doc["fluorescence"])
        fl["excitation"] = str(single.fluorescence.excitation)
        fl["emission"] = str(single.fluorescence.emission)
        fl["bands"] = [{"excitation": str(single.fluorescence.excitation),
                        "emission": str(single.fluorescence.emission),
                        "quantum_yield": 0.3, "peak_absorptance": 0.2}]
        doc["fluorescence"] = fl
        banded = preset_from_dict(doc, None)
        what = "lace-fwa with its own spectra as two bands (measured matrices absent)"
    renderers = {}
    for label, preset in (("single band (today)", single), ("banded", banded)):
        renderer = FrameRenderer(ctx, tuple(size))
        renderer.update(fabric=preset, light="LED-405", fluorescence="physical")
        renderer.render()
        renderers[label] = renderer
    ctx.finish()
    samples = {label: [] for label in renderers}
    for _ in range(repeats):
        for label, renderer in renderers.items():
            start = time.perf_counter()
            for _ in range(draws):
                renderer.render()
            ctx.finish()
            samples[label].append((time.perf_counter() - start) / draws)
    light = renderers["banded"].light.irradiance_w_m2_nm
    key = renderers["banded"]._key_to_light
    prepare = {}
    for label, renderer in renderers.items():
        def build(preset=renderer.preset):
            scene_lib.build_shading_inputs(preset, light, key, is_sun=False)
        build()
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            build()
            times.append(time.perf_counter() - start)
        prepare[label] = statistics.median(times)
    for renderer in renderers.values():
        renderer.release()
    base = statistics.median(samples["single band (today)"])
    return {"what": what, "size": list(size), "light": "LED-405", "repeats": repeats,
            "draws": draws, "renderer": describe(ctx)["renderer"],
            "rows": [{"variant": label, "frame_ms": 1e3 * statistics.median(samples[label]),
                      "frame_ratio": statistics.median(samples[label]) / base,
                      "light_change_ms": 1e3 * prepare[label]} for label in renderers]}


def plot(result: dict, folder) -> list:
    """The Pareto: mean Delta E 2000 (selection, test, test against the cleaned matrices)
    against the spectra each candidate stores; the shader's cost is the same for all."""
    from pathlib import Path  # noqa: PLC0415

    from benchmarks.plots import pyplot, save_figure  # noqa: PLC0415

    plt = pyplot()
    per = result["summary"]["per_candidate"]
    labels = list(per)
    x = [per[k]["stored_numbers"] for k in labels]
    fig, ax = plt.subplots(figsize=(7, 4))
    for key, name in (("selection", "selection lights (the choice)"), ("test", "test lights"),
                      ("test_vs_cleaned", "test lights, matrices without artefacts")):
        ax.plot(x, [per[k][key]["mean"] for k in labels], "o-", label=name)
    chosen = labels.index(result["summary"]["choice"])
    ax.annotate("chosen", (x[chosen], per[labels[chosen]]["selection"]["mean"]),
                textcoords="offset points", xytext=(-10, 12), fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("numbers stored per material (bands x (49 + 41) + 2 + residual); shader: 6 for all")
    ax.set_ylabel("mean Delta E 2000, 8 matrices")
    ax.set_title("Banded fluorescence (+ measured residual): error against stored size", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return [save_figure(fig, Path(folder) / "bench_uv_pareto.png")]


def frame_table(frame: dict) -> str:
    """The ``uv-frame`` block: frame time side by side."""
    lines = [f"| fabric ({frame['light']}, {frame['size'][0]}x{frame['size'][1]}, "
             f"{frame['renderer']}) | frame ms (median) | ratio | light change ms |",
             "|---|---|---|---|"]
    for row in frame["rows"]:
        lines.append(f"| {row['variant']} | {row['frame_ms']:.2f} | {row['frame_ratio']:.3f} | "
                     f"{row['light_change_ms']:.2f} |")
    lines.append(f"\nBanded fabric: {frame['what']}; {frame['repeats']} interleaved rounds of "
                 f"{frame['draws']} frames.")
    return "\n".join(lines)


def main(argv=None) -> int:
    import argparse  # noqa: PLC0415
    from pathlib import Path  # noqa: PLC0415

    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415
    import json  # noqa: PLC0415

    parser = argparse.ArgumentParser(description="UV/violet fluorescence: noise floor and banded model")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default="benchmarks/bench_uv.json")
    parser.add_argument("--no-frame", action="store_true",
                        help="skip the frame-cost part (it needs an OpenGL context)")
    args = parser.parse_args(argv)
    result = run(quick=args.quick)
    if not args.no_frame:
        result["frame"] = frame_cost(repeats=3 if args.quick else 21)
    write_text_atomic(Path(args.out), json.dumps(result, indent=1) + "\n")
    for name, table in markdown_tables(result).items():
        print(f"<!-- generated:{name} -->\n{table}\n<!-- /generated:{name} -->\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
