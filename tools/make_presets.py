#!/usr/bin/env python3
"""Regenerate every fabric preset (fabrics/<name>.toml) from fabrics/measurements/ with
``catalog fit``.

    .venv/bin/python tools/make_presets.py [NAME ...] [--out-dir fabrics]
                                           [--measurements fabrics/measurements]
                                           [--table docs-table.md]    (or: make presets)

For each measurement folder with a ``gonio.csv``: ``catalog fit --gonio gonio.csv
--name <folder> --out <out-dir>/<folder>.toml``, adding ``--excitation excitation.csv
--emission emission.csv`` when both are there (the fluorescent fabrics; their spectra
come from tools/make_fluorescent_spectra.py). A dye.csv beside the gonio file is picked
up by ``catalog fit`` itself. Output is deterministic (fixed starts, six significant
digits), so tests/test_presets.py checks that regenerating reproduces the committed files.

``--table FILE`` also writes the per-fabric error table of HG (eq. 7) vs Cook-Torrance,
on all 4800 points and on the paper's 79, in both weightings (docs/fit.md).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

MEASUREMENTS = ROOT / "fabrics" / "measurements"
OUT_DIR = ROOT / "fabrics"


def measurement_folders(measurements: Path, names=()) -> list[Path]:
    folders = sorted(p for p in measurements.iterdir() if (p / "gonio.csv").is_file())
    if names:
        known = {p.name for p in folders}
        unknown = [n for n in names if n not in known]
        if unknown:
            raise SystemExit(f"make_presets: no gonio.csv for {', '.join(unknown)} "
                             f"(known: {', '.join(sorted(known))})")
        folders = [p for p in folders if p.name in names]
    return folders


def fit_argv(folder: Path, out_dir: Path) -> list[str]:
    """The ``catalog fit`` command line for one measurement folder."""
    argv = ["fit", "--gonio", str(folder / "gonio.csv"), "--name", folder.name,
            "--out", str(out_dir / f"{folder.name}.toml"), "--json"]
    excitation, emission = folder / "excitation.csv", folder / "emission.csv"
    if excitation.is_file() and emission.is_file():
        argv += ["--excitation", str(excitation), "--emission", str(emission)]
    return argv


def run_fit(argv: list[str]) -> dict:
    """Run ``catalog`` in this process and return its JSON summary."""
    from catalog.commands.cli import main

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        status = main(argv)
    if status != 0:
        raise SystemExit(f"make_presets: catalog {' '.join(argv)} failed ({status})")
    return json.loads(buffer.getvalue())


def make_presets(measurements: Path = MEASUREMENTS, out_dir: Path = OUT_DIR,
                 names=()) -> list[dict]:
    summaries = [run_fit(fit_argv(folder, out_dir))
                 for folder in measurement_folders(measurements, names)]
    # a fit writes the preset afresh: its [pattern] follows the new LD (tools/make_patterns.py)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from make_patterns import PATTERNS, regenerate

    for summary in summaries:
        if summary["name"] in PATTERNS:
            regenerate(summary["name"], out_dir)
    return summaries


def error_table(measurements: Path = MEASUREMENTS, names=()) -> str:
    """Markdown: rmse of eq. 7 (HG, isotropic as printed) and Cook-Torrance per fabric,
    subset and weighting, and of eq. 7 with the fitted warp/weft anisotropy (the presets'
    fit) on all points."""
    from catalog.fit.fitting import fit_gonio_ct, fit_gonio_hg
    from catalog.fit.gonio import paper_subset_mask, read_gonio

    rows = ["| fabric | points | weighting | HG rmse | CT rmse | CT / HG | HG rel. rms | CT rel. rms "
            "| HG + anisotropy rmse |",
            "|---|---|---|---|---|---|---|---|---|"]
    for folder in measurement_folders(measurements, names):
        data = read_gonio(folder / "gonio.csv")
        for subset in ("all", "79"):
            part = data if subset == "all" else data.subset(paper_subset_mask(data))
            for weighting in ("relative", "none"):
                hg = fit_gonio_hg(part, weighting=weighting, anisotropy=False)   # eq. 7
                ct = fit_gonio_ct(part, weighting=weighting)
                extended = (f"{fit_gonio_hg(part, weighting=weighting, anisotropy=True).rmse:.3e}"
                            if subset == "all" else "-")
                rows.append(f"| {folder.name} | {len(part)} | {weighting} | {hg.rmse:.3e} | "
                            f"{ct.rmse:.3e} | {ct.rmse / hg.rmse:.1f} | "
                            f"{_relative_rms(hg, part):.3f} | {_relative_rms(ct, part):.3f} | "
                            f"{extended} |")
    return "\n".join(rows) + "\n"


def _relative_rms(result, data) -> float:
    relative = (result.predicted - data.transmittance) / data.transmittance
    return float((relative ** 2).mean() ** 0.5)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="fabrics to regenerate (default: all)")
    parser.add_argument("--measurements", type=Path, default=MEASUREMENTS)
    parser.add_argument("--out-dir", type=Path, default=OUT_DIR)
    parser.add_argument("--table", type=Path, help="also write the HG vs CT error table")
    args = parser.parse_args(argv)
    summaries = make_presets(args.measurements, args.out_dir, args.names)
    for summary in summaries:
        print(f"{summary['name']:15s} direct {summary['direct']:.3f}  g {summary['g_diff']:+.3f} "
              f"{summary['g_spec']:+.3f}  rmse HG {summary['rmse']:.3e} CT {summary['ct_rmse']:.3e}"
              f"  -> {summary['out']}")
    if args.table is not None:
        from catalog.core.atomic import write_text_atomic

        write_text_atomic(args.table, error_table(args.measurements, args.names))
        print(f"wrote {args.table}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
