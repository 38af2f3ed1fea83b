"""The catalog's fitted presets beside the synthetic yarn model they were fitted to: the
preset table of docs/fit.md and the figures its prose rests on.

    .venv/bin/python -m benchmarks.preset_table [--json-out FILE]

Reads every built-in preset (``fabrics/*.toml``: the fit's identifiable parameters and their
standard errors, the anisotropy, tau, fluorescence and per-channel tables) and its gonio
file's header (the generator's weave and open area at normal incidence, written by
tools/make_gonio.py). Writes benchmarks/preset_table.json; tools/docs_figures.py makes the
table and the sentences from it. Nothing is fitted here: ``make presets`` does that.
"""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/preset_table.json"
#: A fabric counts as open when the generator's open area at normal incidence is at least this.
OPEN_AREA_AT_LEAST = 0.2


def gonio_header(path: Path) -> dict[str, str]:
    """``# key: value`` lines at the top of a gonio CSV."""
    header = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        key, sep, value = line[1:].partition(":")
        if sep:
            header[key.strip()] = value.strip()
    return header


def preset_row(path: Path) -> dict:
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    fit = doc.get("fit", {})
    identifiable = fit.get("identifiable", {})
    stderr = fit.get("stderr", {})
    header = gonio_header(path.parent / fit["source"]) if "source" in fit else {}
    rgb = doc.get("btdf", {}).get("rgb")
    return {"preset": doc["name"], "shown_as": doc.get("display_name", doc["name"]),
            "weave": header.get("weave"),
            "open_area_model": float(header["open_area_normal"]) if "open_area_normal" in header else None,
            "direct": identifiable.get("direct"), "direct_se": stderr.get("direct"),
            "a_diff": identifiable.get("a_diff"), "a_spec": identifiable.get("a_spec"),
            "g_diff": identifiable.get("g_diff"), "g_diff_se": stderr.get("g_diff"),
            "g_spec": identifiable.get("g_spec"), "g_spec_se": stderr.get("g_spec"),
            "anisotropy": doc["btdf"].get("anisotropy"), "anisotropy_se": stderr.get("anisotropy"),
            "tau": doc["btdf"].get("tau"), "fluorescent": "fluorescence" in doc,
            "per_channel": rgb is not None,
            "a_spec_rgb": list(rgb["a_spec"]) if rgb and "a_spec" in rgb else None}


def run(fabric_dir: Path | None = None) -> dict:
    from catalog.core.resources import FABRIC_DIR  # noqa: PLC0415

    folder = fabric_dir or FABRIC_DIR
    rows = [preset_row(p) for p in sorted(folder.glob("*.toml"))]
    return {"benchmark": "preset_table", "open_area_at_least": OPEN_AREA_AT_LEAST, "rows": rows}


def markdown_tables(result: dict) -> dict[str, str]:
    rows = [r for r in result["rows"] if r["direct"] is not None]
    lines = ["| preset | shown as | weave | open area (model) | direct (fit) | a_diff | a_spec | g_diff "
             "| g_spec | anisotropy | tau | fluor. | per channel |", "|" + "---|" * 13]
    for r in rows:
        anis = "" if r["anisotropy"] is None else f"{r['anisotropy']:+.3f} ± {r['anisotropy_se']:.3f}"
        lines.append(
            f"| {r['preset']} | {r['shown_as']} | {r['weave'] or ''} | "
            f"{'' if r['open_area_model'] is None else format(r['open_area_model'], '.3f')} | "
            f"{r['direct']:.3f} ± {r['direct_se']:.3f} | {r['a_diff']:.3f} | {r['a_spec']:.3f} | "
            f"{r['g_diff']:.3f} ± {r['g_diff_se']:.3f} | {r['g_spec']:.3f} ± {r['g_spec_se']:.4f} | "
            f"{anis} | {r['tau']:.3f} | {'yes' if r['fluorescent'] else ''} | "
            f"{'rgb' if r['per_channel'] else ''} |")
    threshold = result["open_area_at_least"]
    measured = [r for r in rows if r["open_area_model"] is not None]
    offs = {r["preset"]: (abs(r["direct"] - r["open_area_model"]),
                          abs(r["direct"] - r["open_area_model"]) / r["direct_se"]) for r in measured}
    open_rows = sorted((r for r in measured if r["open_area_model"] >= threshold),
                       key=lambda r: offs[r["preset"]][0])
    dense = [r for r in measured if r["open_area_model"] < threshold]
    worst = open_rows[-1]
    sentence = (f"Open fabrics (open area at least {threshold:g} at normal incidence): the fitted "
                f"`direct` is within {offs[open_rows[-2]['preset']][0]:.3f} of the model's open area "
                f"for {len(open_rows) - 1} of {len(open_rows)}; {worst['preset']} is off by "
                f"{offs[worst['preset']][0]:.3f} ({offs[worst['preset']][1]:.1f} standard errors). "
                f"Dense fabrics ({', '.join(r['preset'] for r in dense)}): off by "
                f"{min(offs[r['preset']][0] for r in dense):.3f}-{max(offs[r['preset']][0] for r in dense):.3f}, "
                f"up to {max(offs[r['preset']][1] for r in dense):.1f} standard errors.")
    by_name = {r["preset"]: r for r in rows}
    aniso = ", ".join(f"{name} {by_name[name]['anisotropy']:+.2f}" for name in
                      ("jacquard-white", "linen-dense", "lace-fwa", "net-grey", "safety-yellow")
                      if name in by_name)
    teal = by_name.get("sheer-teal", {}).get("a_spec_rgb")
    facts = (f"Fitted anisotropy: {aniso}."
             + (f" sheer-teal's a_spec per channel (r, g, b): "
                f"{', '.join(f'{v:.3f}' for v in teal)}." if teal else ""))
    return {"fit-presets": "\n".join(lines), "fit-presets-direct": sentence,
            "fit-presets-facts": facts}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415

    return study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    raise SystemExit(main())
