"""Eq. 7 (HG) against Cook-Torrance on every catalog gonio file: the error tables of
docs/fit.md, docs/fit-table.md and README.md.

    .venv/bin/python -m benchmarks.fit_table [--json-out FILE]     (or: make fit-table)

For each fabric, on all 4800 points and on the paper's 79, in both weightings (relative and
the paper's plain least squares): the rmse of eq. 7 as printed (isotropic) and of
Cook-Torrance, their ratio, each one's relative rms, and on all points the rmse of eq. 7 with
the warp/weft anisotropy (the presets' own fit). Deterministic (fixed starts); writes
benchmarks/fit_table.json, from which tools/docs_figures.py makes the tables.
"""

from __future__ import annotations

import sys
from pathlib import Path

#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/fit_table.json"
SUBSETS = ("all", "79")
WEIGHTINGS = ("relative", "none")


def relative_rms(result, data) -> float:
    """RMS of (model - data) / data."""
    relative = (result.predicted - data.transmittance) / data.transmittance
    return float((relative ** 2).mean() ** 0.5)


def run(measurements: Path | None = None, names=()) -> dict:
    from catalog.core.resources import FABRIC_DIR  # noqa: PLC0415
    from catalog.fit.fitting import fit_gonio_ct, fit_gonio_hg  # noqa: PLC0415
    from catalog.fit.gonio import paper_subset_mask, read_gonio  # noqa: PLC0415

    measurements = measurements or FABRIC_DIR / "measurements"
    folders = sorted(p for p in measurements.iterdir() if (p / "gonio.csv").is_file()
                     and (not names or p.name in names))
    rows = []
    for folder in folders:
        data = read_gonio(folder / "gonio.csv")
        for subset in SUBSETS:
            part = data if subset == "all" else data.subset(paper_subset_mask(data))
            for weighting in WEIGHTINGS:
                hg = fit_gonio_hg(part, weighting=weighting, anisotropy=False)   # eq. 7
                ct = fit_gonio_ct(part, weighting=weighting)
                extended = (float(fit_gonio_hg(part, weighting=weighting, anisotropy=True).rmse)
                            if subset == "all" else None)
                rows.append({"fabric": folder.name, "points": len(part), "weighting": weighting,
                             "hg_rmse": float(hg.rmse), "ct_rmse": float(ct.rmse),
                             "hg_relative_rms": relative_rms(hg, part),
                             "ct_relative_rms": relative_rms(ct, part),
                             "hg_anisotropy_rmse": extended})
    return {"rows": rows}


def _short_e(value: float) -> str:
    """2.41e-2 (three significant digits, the exponent without padding)."""
    mantissa, exponent = f"{value:.2e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def markdown_tables(result: dict) -> dict[str, str]:
    """``fit_table`` (every combination, docs/fit-table.md), ``fit_table_brief`` (4800 and
    79 points, plain least squares, docs/fit.md), ``fit_table_readme`` (README.md) and
    ``fit_table_margins`` (HG against CT over every combination)."""
    rows = result["rows"]
    head = ["| fabric | points | weighting | HG rmse | CT rmse | CT / HG | HG rel. rms | CT rel. rms "
            "| HG + anisotropy rmse |", "|---|---|---|---|---|---|---|---|---|"]

    def line(r: dict) -> str:
        extended = "-" if r["hg_anisotropy_rmse"] is None else f"{r['hg_anisotropy_rmse']:.3e}"
        return (f"| {r['fabric']} | {r['points']} | {r['weighting']} | {r['hg_rmse']:.3e} | "
                f"{r['ct_rmse']:.3e} | {r['ct_rmse'] / r['hg_rmse']:.1f} | "
                f"{r['hg_relative_rms']:.3f} | {r['ct_relative_rms']:.3f} | {extended} |")

    full = head + [line(r) for r in rows]
    # docs/fit.md: each fabric's default fit (relative, all points) and the paper's setting
    # (plain least squares on the 79 points)
    brief = head + [line(r) for r in rows
                    if (r["points"] > 79 and r["weighting"] == "relative")
                    or (r["points"] == 79 and r["weighting"] == "none")]
    plain = {(r["fabric"], r["points"] > 79): r for r in rows if r["weighting"] == "none"}
    fabrics = sorted({r["fabric"] for r in rows}, key=[r["fabric"] for r in rows].index)
    readme = ["| fabric | HG, 4800 | CT, 4800 | HG, 79 | CT, 79 |", "|---|---|---|---|---|"]
    for fabric in fabrics:
        a, b = plain[(fabric, True)], plain[(fabric, False)]
        readme.append(f"| {fabric} | {_short_e(a['hg_rmse'])} | {_short_e(a['ct_rmse'])} | "
                      f"{_short_e(b['hg_rmse'])} | {_short_e(b['ct_rmse'])} |")
    ratios = [(r["ct_rmse"] / r["hg_rmse"], r) for r in rows]
    low, high = min(ratios, key=lambda x: x[0]), max(ratios, key=lambda x: x[0])
    wins = sum(ratio > 1 for ratio, _ in ratios)
    hg_rel = {many: [r["hg_relative_rms"] for r in rows if (r["points"] > 79) == many]
              for many in (True, False)}
    margins = (f"HG has the lower rmse in {wins} of {len(ratios)} combinations; the margin "
               f"(CT / HG) runs from {low[0]:.1f}x ({low[1]['fabric']}, {low[1]['points']} points, "
               f"{low[1]['weighting']} weighting) to {high[0]:.0f}x ({high[1]['fabric']}, "
               f"{high[1]['points']} points, {high[1]['weighting']} weighting). HG's own relative "
               f"rms: {100 * min(hg_rel[True]):.0f}-{100 * max(hg_rel[True]):.0f} % on all points, "
               f"{100 * min(hg_rel[False]):.0f}-{100 * max(hg_rel[False]):.0f} % on the paper's 79.")
    return {"fit_table": "\n".join(full), "fit_table_brief": "\n".join(brief),
            "fit_table_readme": "\n".join(readme), "fit_table_margins": margins}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415

    return study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    sys.exit(main())
