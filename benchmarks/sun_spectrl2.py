"""Our clear sky against Bird & Riordan's SPECTRL2 (pvlib's implementation), same
atmosphere, 300-780 nm, per zenith angle (README "The sun against SPECTRL2", docs/lights.md).

    .venv/bin/python -m benchmarks.sun_spectrl2 [--json OUT.json]

Writes benchmarks/sun_spectrl2.json (catalog.optics.sun.spectrl2.comparison_table);
tests/test_sun.py holds the bounds on the same measures.
"""

from __future__ import annotations

import sys


RESULT_JSON = "benchmarks/sun_spectrl2.json"


def run() -> dict:
    from catalog.optics.sun.spectrl2 import comparison_table

    return {"rows": comparison_table(), "atmosphere": "catalog.optics.sun.model.Atmosphere()",
            "diffuse_method": "delta-eddington"}


def markdown_tables(result: dict) -> dict[str, str]:
    """``sun_spectrl2`` (README): direct and global ratios (ours / SPECTRL2) and relative RMS;
    ``sun_spectrl2_full`` (docs/lights.md): with the transmittance RMS and the UV ratio."""
    lines = ["| zenith | path km | direct ratio | direct rel. RMS | global ratio | global rel. RMS |",
             "|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['zenith_deg']:g} | {r['path_km']:.1f} | {r['dni_integral_ratio']:.3f} | "
                     f"{r['dni_rel_rms_400_780']:.3f} | {r['ghi_integral_ratio']:.3f} | "
                     f"{r['ghi_rel_rms_400_780']:.3f} |")
    full = ["| zenith (deg) | path (km) | DNI ratio | DNI rel. RMS | T rel. RMS | GHI ratio | "
            "GHI rel. RMS | UV GHI ratio |", "|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        full.append(f"| {r['zenith_deg']:g} | {r['path_km']:.1f} | {r['dni_integral_ratio']:.3f} | "
                    f"{r['dni_rel_rms_400_780']:.3f} | {r['transmittance_rel_rms_400_780']:.3f} | "
                    f"{r['ghi_integral_ratio']:.3f} | {r['ghi_rel_rms_400_780']:.3f} | "
                    f"{r['uv_ghi_ratio']:.3f} |")
    return {"sun_spectrl2": "\n".join(lines), "sun_spectrl2_full": "\n".join(full)}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415

    return study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    sys.exit(main())
