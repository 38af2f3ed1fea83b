"""Building a fabric preset from a gonio measurement: the work behind ``catalog fit``.

The identifiable parameters (direct, a_diff, a_spec, g_diff, g_spec) are fitted by
Levenberg-Marquardt (:mod:`catalog.fit.fitting`); rho is the weave's cover factor,
1 - direct (the see-through at normal incidence is the open area), unless given; tau comes
from the dye's luminance-weighted transmittance (``dye.csv`` beside the gonio file, or
``--dye``), else a small default; k_d and k_s follow. Cook-Torrance is fitted to the same
points for comparison. The gonio file's header comments ``display_name:``, ``weave:`` and
``cloth.<key>:`` describe the sample; options override them. Heavy imports (scipy,
matplotlib) happen inside the functions.
"""

from __future__ import annotations

import math

#: tau of an undyed fibre: e^-tau only scales k_d and k_s (not identifiable from one
#: band), so this only fixes how the product is split; a white fibre absorbs little.
DEFAULT_TAU_UNDYED = 0.05
#: rho is kept at least this (a fabric with no threads has nothing to fit).
MIN_RHO = 0.01
#: Significant digits written to the preset (deterministic, diff-friendly files).
DIGITS = 6
#: formats.md's identifiable set (the anisotropy, when fitted, is reported beside it).
IDENTIFIABLE = ("direct", "a_diff", "a_spec", "g_diff", "g_spec")


def fit_preset(args, started_s: float) -> dict:
    """Read ``args.gonio``, fit, write the preset ``args.out`` (and ``args.plot``); the JSON
    summary. ``args`` holds the options of ``catalog fit`` (already checked there)."""
    import tempfile
    import time
    from pathlib import Path

    from catalog.core.atomic import staged_folder
    from catalog.core.errors import InputError
    from catalog.fit.gonio import paper_subset_mask, read_gonio
    from catalog.presets import preset_from_dict, save_preset_dict
    from catalog.presets.bundle import bundle_files

    out = Path(args.out)
    data = read_gonio(args.gonio)
    header = _header_fields(data.comments)
    if args.points == "79":
        mask = paper_subset_mask(data)
        if not data.subset(mask).straight_through.any():
            raise InputError("the paper's subset (light elevation 180, azimuth 0, camera "
                             "azimuth 0/180) is not in this file", path=data.path)
        data = data.subset(mask)

    result = fit_measurement(data, args.weighting, progress=not args.json)
    hg, ct = result["hg"], result["ct"]
    dye_path = _dye_path(args, Path(args.gonio))
    tau = args.tau if args.tau is not None else (
        dye_tau(dye_path) if dye_path is not None else DEFAULT_TAU_UNDYED)
    rho = args.rho if args.rho is not None else max(MIN_RHO, 1.0 - hg.params["direct"])

    doc = preset_document(args, out, data, header, result, rho, tau, dye_path)
    # the preset and copies of every file it names (gonio, spectra, dye, the fitted pattern)
    # in out's own folder N/, staged, and the plot: all of them appear together, or none
    # (catalog.presets.bundle, catalog.core.atomic.commit_together)
    from catalog.core.atomic import commit_together  # noqa: PLC0415

    pattern = _fitted_pattern(args, doc) if getattr(args, "pattern", None) else _weave_pattern(doc)
    with tempfile.TemporaryDirectory() as scratch:
        # drawn once, then bundled like every other file it names
        from catalog.presets.patterns import write_pattern_images

        drawn = Path(scratch) / Path(doc["pattern"]["coverage"]).name
        drawn_height = None
        if pattern.height is not None:
            drawn_height = Path(scratch) / Path(doc["pattern"]["height"]).name
            doc["pattern"]["height"] = str(drawn_height)
        write_pattern_images(pattern, drawn, drawn_height)
        doc["pattern"]["coverage"] = str(drawn)
        with commit_together(), staged_folder(out.parent) as stage:
            staged = stage / out.name
            bundle_files(doc, staged, lambda _key, value: out.parent / value,
                         published_folder=out.parent)
            preset_from_dict(doc, staged)          # refuse before the plot is drawn
            if args.plot:
                plot_fit(data, hg, ct, Path(args.plot), title=doc["display_name"])
            save_preset_dict(doc, staged)
    elapsed = time.perf_counter() - started_s

    summary = json_summary(doc, result, out, elapsed)
    return summary


def _fitted_pattern(args, doc):
    """``--pattern IMAGE``: the image read as a coverage, remapped to the fitted open area
    (catalog.presets.patterns.match_open_area) and named in ``doc``'s [pattern] table
    (patterns/NAME.png beside the preset). Returns the pattern to write."""
    from dataclasses import replace
    from pathlib import Path

    from catalog.core.errors import InputError
    from catalog.presets.patterns import match_open_area, pattern_from_images

    try:
        repeat = [float(v) for v in str(args.pattern_repeat).split(",")]
    except ValueError:
        repeat = []
    if len(repeat) not in (1, 2) or not all(math.isfinite(v) and 0 < v <= 10 for v in repeat):
        raise InputError(f"{args.pattern_repeat!r}: one or two lengths in metres (0, 10]",
                         field="--pattern-repeat")
    pattern = pattern_from_images(args.pattern, repeat[0] if len(repeat) == 1 else repeat)
    coverage = match_open_area(pattern.coverage, doc["btdf"]["direct"], where=args.pattern)
    rel = f"patterns/{doc['name']}.png"
    target = Path(args.out).parent / rel
    if target.resolve() == Path(args.pattern).resolve():
        raise InputError("would overwrite the input image; move it first", field="--pattern")
    doc["pattern"] = {"coverage": rel, "repeat_m": [round(v, 8) for v in pattern.repeat_m],
                      "kind": "image"}
    return replace(pattern, coverage=coverage, height=None)


def _weave_pattern(doc):
    """Without ``--pattern``: the default structure of the fabric's weave
    (catalog.presets.weave_patterns.default_pattern: a tulle net for a lace, a plain weave
    for a voile or a plain cloth, a twill or a satin) at the fitted open area, named in
    ``doc``'s [pattern] table (patterns/NAME.png and NAME-height.png beside the preset).
    Returns the pattern to write (16-bit values, as the files will hold)."""
    from catalog.presets.patterns import Pattern, quantise16  # noqa: PLC0415
    from catalog.presets.weave_patterns import default_pattern  # noqa: PLC0415

    name = doc["name"]
    coverage, height, repeat, info = default_pattern(doc["cloth"]["weave"], doc["btdf"]["direct"])
    doc["pattern"] = {"coverage": f"patterns/{name}.png", "height": f"patterns/{name}-height.png",
                      "repeat_m": [round(v, 8) for v in repeat], **info}
    return Pattern(quantise16(coverage), quantise16(height), tuple(repeat), info["height_m"], name)


#: The fit's progress (its starts) shows only when the fit has taken this long (s): it
#: usually takes milliseconds.
FIT_PROGRESS_DELAY_S = 2.0


def fit_measurement(data, weighting: str, progress: bool = False) -> dict:
    """HG (grey and per channel) and Cook-Torrance fits of one measurement. ``progress``:
    their starts on stderr when the fit is slow (FIT_PROGRESS_DELAY_S)."""
    from catalog.core.progress import progress as progress_bar
    from catalog.fit.fitting import SCAN_STARTS, fit_channels, fit_gonio_ct, fit_gonio_hg

    with progress_bar("catalog fit", total=2 * SCAN_STARTS, unit="starts", enabled=progress,
                      delay_s=FIT_PROGRESS_DELAY_S) as bar:
        hg = fit_gonio_hg(data, weighting=weighting, on_start=bar.advance)
        ct = fit_gonio_ct(data, weighting=weighting, on_start=bar.advance)
    channels = None
    if data.rgb is not None:
        anisotropy = hg.params.get("anisotropy")
        channels = fit_channels(data.one_minus_cos, data.straight_through, data.rgb,
                                hg.params["g_diff"], hg.params["g_spec"],
                                direct=hg.params["direct"],
                                spread=None if anisotropy is None else data.anisotropy_spread,
                                anisotropy=anisotropy or 0.0, weighting=weighting)
    return {"hg": hg, "ct": ct, "channels": channels}


def _header_fields(comments) -> dict[str, str]:
    """``key: value`` header comments of the gonio file."""
    fields = {}
    for comment in comments:
        key, sep, value = comment.partition(":")
        if sep and key.strip() and " " not in key.strip():
            fields[key.strip()] = value.strip()
    return fields


def _dye_path(args, gonio_path):
    from pathlib import Path

    if args.dye is not None:
        return Path(args.dye)
    beside = gonio_path.parent / "dye.csv"
    return beside if beside.exists() else None


def dye_tau(path) -> float:
    """-ln of the dye's luminance-weighted mean transmittance (CIE 1931 ybar, 380-780 nm)."""
    import math

    import numpy as np

    from catalog.optics.colorimetry import cmfs
    from catalog.core.errors import InputError
    from catalog.optics.spectra import GRID_NM, read_spectrum

    spectrum = read_spectrum(path)
    if np.any(spectrum.values > 1.0):
        raise InputError("a dye transmittance must lie in [0, 1]", path=path)
    values = spectrum.resample(GRID_NM)
    ybar = cmfs(GRID_NM)[:, 1]
    visible = GRID_NM >= 380.0
    mean = float(np.sum(ybar[visible] * values[visible]) / np.sum(ybar[visible]))
    if not mean > 0:
        raise InputError("the dye transmits nothing in the visible", path=path)
    return -math.log(mean)


def _round(value: float) -> float:
    return float(f"{value:.{DIGITS}g}")


def _relative(path, folder) -> str:
    import os

    return os.path.relpath(os.path.abspath(path), os.path.abspath(folder)).replace(os.sep, "/")


def preset_document(args, out, data, header, result, rho, tau, dye_path) -> dict:
    """The preset as a dict (formats.md keys plus [btdf.rgb], [cloth], [dye])."""
    from catalog.fit.fitting import split_amplitudes

    hg, ct, channels = result["hg"], result["ct"], result["channels"]
    p = hg.params
    k_d, k_s = split_amplitudes(p["a_diff"], p["a_spec"], rho, tau)
    folder = out.parent
    btdf = {"direct": _round(min(max(p["direct"], 0.0), 1.0)), "k_d": _round(k_d),
            "k_s": _round(k_s), "tau": _round(tau), "rho": _round(rho),
            "g_diff": _round(p["g_diff"]), "g_spec": _round(p["g_spec"])}
    if "anisotropy" in p:       # our extension: the directional lobe's warp/weft spread
        btdf["anisotropy"] = _round(p["anisotropy"])
    if channels is not None:
        btdf["rgb"] = {key: [_round(c["params"][key]) for c in channels]
                       for key in ("direct", "a_diff", "a_spec")}
        btdf["rgb"]["stderr"] = {key: [_round(c["stderr"][key]) for c in channels]
                                 for key in ("direct", "a_diff", "a_spec")
                                 if all(math.isfinite(c["stderr"][key]) for c in channels)}
    fit = {
        "rmse": _round(hg.rmse), "points": hg.points,
        "source": _relative(args.gonio, folder),
        "weighting": hg.weighting,
        "subset": args.points,
        "identifiable": {k: _round(p[k]) for k in IDENTIFIABLE},
        # a standard error the data cannot determine (singular Jacobian) is left out and
        # named, never written as NaN (which no reader of the preset accepts)
        "stderr": {k: _round(v) for k, v in hg.stderr.items() if math.isfinite(v)},
        "weighted_rms": _round(hg.weighted_rms),
        "cook_torrance": {"rmse": _round(ct.rmse), "weighted_rms": _round(ct.weighted_rms),
                          **{k: _round(v) for k, v in ct.params.items()}},
    }
    undetermined = sorted(k for k, v in hg.stderr.items() if not math.isfinite(v))
    if undetermined:
        fit["stderr_undetermined"] = undetermined
    doc = {"schema": 1, "name": args.name,
           "display_name": args.display_name or header.get("display_name") or args.name,
           "btdf": btdf, "fit": fit}
    if args.excitation is not None:
        doc["fluorescence"] = fluorescence_table(args, folder)
    if dye_path is not None:
        doc["dye"] = {"transmittance": _relative(dye_path, folder)}
    doc["cloth"] = cloth_table(args.weave or header.get("weave"), header)
    return doc


def fluorescence_table(args, folder) -> dict:
    """[fluorescence]: paper colour (eq. 1-3) of the emission and the physical-mode keys."""
    from catalog.optics import fluorescence
    from catalog.optics.spectra import read_spectrum

    read_spectrum(args.excitation, normalise=True)          # refuse a bad file now
    emission = read_spectrum(args.emission, normalise=True)
    xyz, rgb = fluorescence.paper_colour(emission)
    return {
        "xyz": [round(float(v), 4) for v in xyz],
        "rgb": [round(float(v), 4) for v in rgb],
        "excitation": _relative(args.excitation, folder),
        "emission": _relative(args.emission, folder),
        "quantum_yield": (args.quantum_yield if args.quantum_yield is not None
                          else fluorescence.DEFAULT_QUANTUM_YIELD),
        "peak_absorptance": (args.peak_absorptance if args.peak_absorptance is not None
                             else fluorescence.DEFAULT_PEAK_ABSORPTANCE),
        "saturation_photon_irradiance": fluorescence.DEFAULT_SATURATION_PHOTON_IRRADIANCE,
    }


def cloth_table(weave, header) -> dict:
    """[cloth]: the weave's defaults (catalog.cloth.params), overridden by ``cloth.*``
    header fields of the gonio file."""
    from catalog.cloth.params import DEFAULT_WEAVE, WEAVE_DEFAULTS
    from catalog.core.errors import InputError

    weave = weave or DEFAULT_WEAVE
    if weave not in WEAVE_DEFAULTS:
        raise InputError(f"unknown weave {weave!r}; known: {', '.join(WEAVE_DEFAULTS)}",
                         field="--weave")
    density, stretch, bend = WEAVE_DEFAULTS[weave]
    table = {"weave": weave, "areal_density_kg_m2": density,
             "stretch_stiffness_n_m": stretch, "bend_stiffness_n_m": bend}
    for key in ("areal_density_kg_m2", "stretch_stiffness_n_m", "bend_stiffness_n_m"):
        text = header.get(f"cloth.{key}")
        if text is not None:
            try:
                value = float(text)
            except ValueError:
                raise InputError(f"not a number: {text!r}", field=f"cloth.{key}") from None
            if not value > 0:
                raise InputError(f"must be > 0, found {value:g}", field=f"cloth.{key}")
            table[key] = value
    return table


def json_summary(doc, result, out, elapsed) -> dict:
    hg, ct, channels = result["hg"], result["ct"], result["channels"]
    summary = {
        "name": doc["name"], "out": str(out),
        **{k: v for k, v in doc["btdf"].items() if k != "rgb"},
        "identifiable": {k: float(hg.params[k]) for k in IDENTIFIABLE},
        "stderr": {k: float(v) for k, v in hg.stderr.items()},
        "rmse": hg.rmse, "weighted_rms": hg.weighted_rms, "points": hg.points,
        "weighting": hg.weighting,
        "ct_rmse": ct.rmse, "ct_weighted_rms": ct.weighted_rms,
        "cook_torrance": {"params": ct.params, "stderr": ct.stderr, "rmse": ct.rmse},
        "hg_beats_ct": hg.rmse < ct.rmse,
        "iterations": hg.iterations, "evaluations": hg.evaluations, "starts": hg.starts,
        "fit_time_s": hg.time_s, "time_s": elapsed,
        "fluorescence": "fluorescence" in doc,
    }
    if channels is not None:
        summary["rgb"] = {key: [c["params"][key] for c in channels]
                          for key in ("direct", "a_diff", "a_spec")}
        summary["rgb_stderr"] = {key: [c["stderr"][key] for c in channels]
                                 for key in ("direct", "a_diff", "a_spec")}
    return summary


def plot_fit(data, hg, ct, path, title: str = "") -> None:
    """Measured points and fitted HG / Cook-Torrance curves against the signed view angle
    (camera azimuth 0: +, 180: -), at light azimuth 0 and the light elevations present
    (180 = the paper's Fig. 11). Written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from catalog.core.atomic import atomic_path
    from catalog.optics.btdf import (cook_torrance_transmittance, hg_phase_one_minus_cos,
                              one_minus_cos_between, woven_one_minus_cos)
    from catalog.core.errors import InputError
    from catalog.fit.gonio import light_direction, view_direction

    elevations = [e for e in (180.0, 155.0) if np.any(
        (np.abs(data.light_elevation_deg - e) < 1e-6) & (np.abs(data.light_azimuth_deg) < 1e-6))]
    if not elevations:
        raise InputError("no points at light azimuth 0 to plot", path=data.path, field="--plot")
    fig, axes = plt.subplots(1, len(elevations), figsize=(6.2 * len(elevations), 4.4),
                             squeeze=False)
    signed_fine = np.linspace(-80.0, 80.0, 641)
    cam_el = 90.0 - np.abs(signed_fine)
    cam_az = np.where(signed_fine >= 0, 0.0, 180.0)
    p, q = hg.params, ct.params
    for ax, elevation in zip(axes[0], elevations):
        sel = ((np.abs(data.light_elevation_deg - elevation) < 1e-6)
               & (np.abs(data.light_azimuth_deg) < 1e-6)
               & ((np.abs(data.camera_azimuth_deg) < 1e-6)
                  | (np.abs(data.camera_azimuth_deg - 180.0) < 1e-6)))
        signed = np.where(np.abs(data.camera_azimuth_deg[sel]) < 1e-6, 1.0, -1.0) \
            * (90.0 - data.camera_elevation_deg[sel])
        straight = data.straight_through[sel]
        ax.semilogy(signed[~straight], data.transmittance[sel][~straight], "k.", ms=4,
                    label="measured")
        if straight.any():
            ax.semilogy(signed[straight], data.transmittance[sel][straight], "k*", ms=8,
                        label="measured, straight through")
        to_light = np.broadcast_to(light_direction(elevation, 0.0), (len(signed_fine), 3))
        view = view_direction(cam_el, cam_az)
        omc = one_minus_cos_between(-to_light, view)
        omc_spec = woven_one_minus_cos(-to_light, view, p.get("anisotropy", 0.0))
        hg_curve = (p["a_diff"] * hg_phase_one_minus_cos(omc, p["g_diff"])
                    + p["a_spec"] * hg_phase_one_minus_cos(omc_spec, p["g_spec"]))
        ct_curve = cook_torrance_transmittance(to_light, view, 0.0, q["k_lambert"],
                                               q["k_spec"], q["roughness"],
                                               straight_through=np.zeros(len(omc), bool))
        hg_name = "HG (eq. 7 + anisotropy)" if "anisotropy" in p else "HG (eq. 7)"
        ax.semilogy(signed_fine, hg_curve, "C0-", label=f"{hg_name}, rmse {hg.rmse:.3g}")
        ax.semilogy(signed_fine, ct_curve, "C3--", label=f"Cook-Torrance, rmse {ct.rmse:.3g}")
        if straight.any():
            peak = p["direct"] + p["a_diff"] * float(hg_phase_one_minus_cos(0.0, p["g_diff"])) \
                + p["a_spec"] * float(hg_phase_one_minus_cos(0.0, p["g_spec"]))
            ax.semilogy([0.0], [peak], "C0o", mfc="none", ms=9, label="HG with direct")
        ax.set_xlabel("view angle from the normal (deg; camera azimuth 0: +, 180: -)")
        ax.set_ylabel("transmittance ratio (per sr)")
        ax.set_title(f"{title}: light elevation {elevation:g} deg, azimuth 0")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110, format="png")
    except OSError as exc:
        raise InputError(f"cannot write the plot: {exc.strerror}", path=path) from None
    finally:
        plt.close(fig)
