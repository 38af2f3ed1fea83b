"""What ``catalog import`` does for every source: the lobes, then one self-contained preset.

The source (an image, a U3M) gives a pattern (coverage, height, repeat) and perhaps a dye
and cloth parameters; :func:`btdf_and_cloth` adds the eq. 7 lobes (fitted to ``--gonio``,
or lent by the nearest catalog fabric) and :func:`write_imported_preset` writes
``DIR/N.toml`` with its files in ``DIR/N/``, staged so that all appear together or none.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

#: Significant digits written to the preset.
DIGITS = 6
#: A pattern whose open area is below this, or above 1 minus it, is refused: 0 % open is
#: an opaque cloth (no pattern to import), 100 % open no cloth at all.
MIN_OPEN_AREA = 1.0e-3


def _round(value: float) -> float:
    return float(f"{value:.{DIGITS}g}")


@dataclass
class ImportedFabric:
    """A source read into arrays: coverage (H, W) in [0, 1] (1 = thread), height (H, W) in
    [0, 1] or None, the repeat (u, v) in metres, optional dye transmittance on a grid,
    [cloth] overrides and the [import] table (what was read and what was kept)."""

    coverage: np.ndarray
    height: np.ndarray | None
    repeat_m: tuple[float, float]
    source: Path
    kind: str
    height_m: float | None = None
    dye: tuple[np.ndarray, np.ndarray, list[str]] | None = None   # (nm, T, comments)
    weight_kg_m2: float | None = None
    cloth: dict[str, Any] = field(default_factory=dict)
    import_table: dict[str, Any] = field(default_factory=dict)
    display_name: str | None = None
    lobes: dict[str, Any] | None = None      # eq. 7 lobes the source carries (our own U3M)
    lobes_source: str | None = None


def open_area_of(coverage: np.ndarray) -> float:
    """1 - mean(c) of the coverage as the 16-bit PNG stores it (what the renderer reads)."""
    from catalog.presets.patterns import quantise16  # noqa: PLC0415

    return 1.0 - float(np.mean(quantise16(coverage), dtype=np.float64))


def check_open_area_range(open_area: float, path, field: str) -> None:
    from catalog.core.errors import InputError  # noqa: PLC0415

    if not MIN_OPEN_AREA <= open_area <= 1.0 - MIN_OPEN_AREA:
        raise InputError(f"the pattern is {open_area:.1%} open: an import needs threads and "
                         "holes (between 0.1 % and 99.9 % open)", path=path, field=field)


def btdf_and_cloth(direct: float, weight_kg_m2: float | None, gonio: str | Path | None,
                   carried: dict[str, Any] | None = None, carried_from: str | None = None):
    """([btdf], [cloth], lobes report, [fit]) for a fabric of open area ``direct``: the
    lobes fitted to ``gonio``, else those the source carries, else the nearest fabric's."""
    from catalog.exchange.nearest import distance, lobes_from, nearest_fabric  # noqa: PLC0415

    if gonio is not None:
        from catalog.fit.fitting import split_amplitudes  # noqa: PLC0415
        from catalog.fit.gonio import read_gonio  # noqa: PLC0415
        from catalog.fit.preset_build import (DEFAULT_TAU_UNDYED, _header_fields,  # noqa: PLC0415
                                              cloth_table, fit_measurement)

        data = read_gonio(gonio)
        hg = fit_measurement(data, "relative")["hg"]
        p = hg.params
        rho = max(1.0 - direct, 1e-3)
        k_d, k_s = split_amplitudes(p["a_diff"], p["a_spec"], rho, DEFAULT_TAU_UNDYED)
        btdf = {"direct": direct, "k_d": k_d, "k_s": k_s, "tau": DEFAULT_TAU_UNDYED,
                "rho": rho, "g_diff": p["g_diff"], "g_spec": p["g_spec"]}
        if "anisotropy" in p:
            btdf["anisotropy"] = p["anisotropy"]
        header = _header_fields(data.comments)
        cloth = cloth_table(header.get("weave"), header)
        report = {"lobes_from": "gonio", "gonio": str(gonio), "rmse": hg.rmse,
                  "points": hg.points, "fit_direct": p["direct"]}
        fit = {"rmse": _round(hg.rmse), "points": hg.points, "source": str(Path(gonio).absolute()),
               "weighting": hg.weighting, "direct_from": "the pattern's open area"}
        return btdf, cloth, report, fit
    if carried is not None:
        btdf = {k: float(carried[k]) for k in ("k_d", "k_s", "tau", "g_diff", "g_spec")}
        btdf.update(direct=direct, rho=max(1.0 - direct, 1e-3))
        if isinstance(carried.get("anisotropy"), (int, float)):
            btdf["anisotropy"] = float(carried["anisotropy"])
        return btdf, {}, {"lobes_from": carried_from or "the source"}, {}
    neighbour = nearest_fabric(direct, weight_kg_m2)
    btdf = lobes_from(neighbour, direct)
    cloth = dict(neighbour.table("cloth"))
    report = {"lobes_from": neighbour.name,
              "distance": round(distance(direct, weight_kg_m2, neighbour), 4),
              "neighbour_direct": neighbour.btdf.direct}
    return btdf, cloth, report, {}


def write_imported_preset(fabric: ImportedFabric, name: str, out_dir: str | Path,
                          gonio: str | Path | None = None) -> dict:
    """Write ``out_dir/name.toml`` and ``out_dir/name/``; returns the JSON report."""
    from catalog.core.atomic import staged_folder  # noqa: PLC0415
    from catalog.optics.spectra import write_spectrum  # noqa: PLC0415
    from catalog.presets import save_preset_dict  # noqa: PLC0415
    from catalog.presets.bundle import bundle_files  # noqa: PLC0415
    from catalog.presets.patterns import DEFAULT_HEIGHT_M, Pattern, write_pattern_images  # noqa: PLC0415

    from catalog.core.errors import InputError  # noqa: PLC0415

    out_dir = Path(out_dir)
    own = (out_dir / name).resolve()
    for given in (fabric.source, gonio):
        if given is not None and (Path(given).resolve().is_relative_to(own)
                                  or Path(given).resolve() == own.with_suffix(".toml")):
            raise InputError(f"{given} lies in the folder this import writes ({own}): an input "
                             "is never overwritten; choose another --name or --out", field="--out")
    direct = _round(open_area_of(fabric.coverage))
    check_open_area_range(direct, fabric.source, "coverage")
    btdf, cloth, lobes, fit = btdf_and_cloth(direct, fabric.weight_kg_m2, gonio,
                                             fabric.lobes, fabric.lobes_source)
    cloth.update(fabric.cloth)
    doc: dict[str, Any] = {
        "schema": 1, "name": name, "display_name": fabric.display_name or name,
        "btdf": {k: _round(v) for k, v in btdf.items()},
    }
    if fit:
        doc["fit"] = fit
    doc["cloth"] = cloth
    pattern = {"coverage": f"{name}/patterns/coverage.png",
               "repeat_m": [_round(v) for v in fabric.repeat_m],
               "height_m": fabric.height_m if fabric.height_m is not None else DEFAULT_HEIGHT_M}
    if fabric.height is not None:
        pattern["height"] = f"{name}/patterns/height.png"
    doc["pattern"] = pattern
    imported = {"kind": fabric.kind, "source": str(fabric.source.absolute()),
                "open_area": direct, **{k: v for k, v in lobes.items() if k != "gonio"},
                **fabric.import_table}
    with staged_folder(out_dir, inputs=[fabric.source]) as stage:
        files = stage / name
        write_pattern_images(Pattern(fabric.coverage, fabric.height, fabric.repeat_m,
                                     pattern["height_m"], str(fabric.source)),
                             files / "patterns" / "coverage.png",
                             None if fabric.height is None else files / "patterns" / "height.png")
        if fabric.dye is not None:
            nm, values, comments = fabric.dye
            write_spectrum(files / "measurements" / "dye.csv", nm, values, comments)
            doc["dye"] = {"transmittance": f"{name}/measurements/dye.csv"}
        doc["import"] = imported
        bundle_files(doc, stage / f"{name}.toml",
                     lambda _key, value: Path(value) if Path(value).is_absolute() else stage / value,
                     published_folder=out_dir)
        save_preset_dict(doc, stage / f"{name}.toml")
    report = {"name": name, "out": str(out_dir / f"{name}.toml"), "kind": fabric.kind,
              "source": str(fabric.source), "open_area": direct, "direct": doc["btdf"]["direct"],
              "repeat_m": pattern["repeat_m"], "pixels": list(fabric.coverage.shape[::-1]),
              "height": fabric.height is not None, "dye": fabric.dye is not None,
              **lobes, "btdf": doc["btdf"], "cloth": cloth,
              "import": {k: v for k, v in fabric.import_table.items()}}
    return report
