"""``catalog bispectral FILE.BFC``: the separable fit of a measured Donaldson matrix and the
colour error (Delta E 2000) of each fluorescence model against the exact matrix result.

FILE is a BFC-450 matrix file, or the name of one in the validation data's bispectral/ folder
(``CIBA12``; ``--data DIR``). The eight measured matrices there also set eq. 8's global scale,
so the command needs the validation data (docs/formats.md).
``--export DIR`` writes excitation.csv, emission.csv and reflectance.csv there (the
separable fit). With ``--preset BASE`` it writes instead a whole fabric: BASE's cloth with
this matrix's fluorescence as the renderer carries it (the banded model and, unless
``--residual none``, the measured residual): ``DIR/BASE-NAME-banded.toml`` with its spectra
and pattern in ``DIR/BASE-NAME-banded/``, ready for ``--fabrics DIR`` (docs/bispectral.md).
"""

from __future__ import annotations

import argparse

RESOURCES = ("data",)
#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
INPUT_FILES = ("file",)
OUTPUT_FOLDERS = ("export",)
HELP = "fit a bispectral (Donaldson) matrix and show the colour error of each fluorescence model"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", metavar="FILE.BFC",
                        help="a BFC-450 matrix file, or the name of one in the validation data (CIBA12)")
    parser.add_argument("--lights", metavar="NAME,NAME..",
                        help="lights of the Delta E table (default: D65,A,FL2,FL11,LED-B4,UV-A,"
                             "sun:22,sun:500); any library name or planck:K. With --json, "
                             "'lights' gives per light the exact XYZ, the XYZ of the banded "
                             "model the renderer carries, and their Delta E 2000")
    parser.add_argument("--export", metavar="DIR",
                        help="write excitation.csv, emission.csv, reflectance.csv into DIR")
    parser.add_argument("--preset", metavar="BASE",
                        help="with --export: write a fabric preset instead, BASE's cloth "
                             "(a catalog name or a .toml) with this matrix's banded "
                             "fluorescence")
    parser.add_argument("--residual", choices=("whole", "none"), default=None,
                        help="with --preset: keep the measured residual (whole, the "
                             "default: the model reproduces the matrix as measured) or "
                             "render the physical bands alone (none)")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead")


def run(args: argparse.Namespace) -> int:
    from catalog.optics.bispectral import bands as bispectral_bands, matrix as bispectral, study
    from catalog.core.errors import InputError

    if args.preset is not None and not args.export:
        raise InputError("needs --export DIR (the folder the fabric is written to)",
                         field="--preset")
    if args.residual is not None and args.preset is None:
        raise InputError("only applies with --preset BASE", field="--residual")
    base = None
    if args.preset is not None:
        from catalog.presets import find_preset, load_preset  # noqa: PLC0415

        base = load_preset(find_preset(args.preset))
    path = bispectral.find_bfc(args.file)
    matrix = bispectral.read_bfc(path)
    lights = study.STUDY_LIGHTS
    if args.lights:
        lights = tuple(name.strip() for name in args.lights.split(",") if name.strip())
        if not lights:
            raise InputError("no light named", field="--lights")
        for name in lights:
            bispectral.training_light(name)  # refuses an unknown name or temperature now
    fit = bispectral.fit_separable(matrix)
    models = study.prepare(matrix, fit)
    # eq. 8's one-k scale is set on the eight reference matrices plus this one
    reference = [m for m in study.reference_models() if m.matrix.name != matrix.name]
    models = study.with_global_paper_scale(reference + [models])[-1]
    rows = study.study_material(models, lights)
    # the model the renderer carries: the chosen one, or with --residual none its bands alone
    with_residual = bispectral_bands.DEFAULT_RESIDUAL and args.residual != "none"
    model_name = bispectral_bands.CHOSEN if with_residual else bispectral_bands.BANDS_CHOSEN
    banded = bispectral_bands.fit_banded(matrix, base=fit, residual=with_residual,
                                         residual_rank=bispectral_bands.DEFAULT_RESIDUAL_RANK)
    per_light = banded_colours(matrix, banded, lights)
    exported = {}
    if args.export:
        from pathlib import Path  # noqa: PLC0415

        from catalog.core.atomic import staged_folder  # noqa: PLC0415

        if base is None:
            with staged_folder(args.export) as stage:  # all three files, or none
                written = bispectral.to_fabric_measurements(matrix, stage, fit)
            exported = {k: str(Path(args.export) / Path(v).name) for k, v in written.items()}
        else:
            from catalog.presets.banded import banded_preset  # noqa: PLC0415

            with staged_folder(args.export) as stage:  # the preset and its files, or none
                made = banded_preset(base, banded, stage)
            exported = {"preset": str(Path(args.export) / Path(made.path).name)}

    fit_info = {"yield_absorptance": fit.yield_absorptance, "quantum_yield": fit.quantum_yield,
                "peak_absorptance": fit.peak_absorptance,
                "excitation_peak_nm": fit.excitation_peak_nm,
                "emission_peak_nm": fit.emission_peak_nm, "rank1_residual": fit.rank1_residual,
                "residual_over_noise": fit.residual_over_noise, "noise_sigma": fit.noise_sigma,
                "notes": list(fit.notes)}
    if args.json:
        from catalog.core.jsonout import print_json

        print_json({"file": str(path), "name": matrix.name, "description": matrix.description,
                    "shape": list(matrix.values.shape), "fit": fit_info,
                    "paper_scale": models.paper_scale,
                    "paper_scale_global": models.paper_scale_global,
                    "delta_e_2000": rows, "methods": list(study.METHODS),
                    "lights": per_light, "model": {
                        "name": model_name,
                        "excitation_band_edges_nm": list(banded.edges_nm),
                        "measured_residual": (None if banded.residual is None else
                                              "whole" if banded.residual_rank is None
                                              else f"rank {banded.residual_rank}"),
                        "stored_numbers": banded.stored_numbers(),
                        "white": WHITE_POINT},
                    "diagnostics": list(study.DIAGNOSTICS), "exported": exported})
        return 0

    print(f"{matrix.name}: {matrix.description} ({path})")
    print(f"  matrix {matrix.values.shape[0]} emission x {matrix.values.shape[1]} excitation, "
          f"noise sigma {fit.noise_sigma:.2g}")
    print(f"  separable fit: phi x a_peak = {fit.yield_absorptance:.3f} "
          f"(phi = {fit.quantum_yield:.3f}, a_peak = {fit.peak_absorptance:.3f}), "
          f"excitation peak {fit.excitation_peak_nm:.0f} nm, emission peak "
          f"{fit.emission_peak_nm:.0f} nm")
    print(f"  rank-1 residual {fit.rank1_residual:.3f} relative, "
          f"{fit.residual_over_noise:.2f} x noise sigma")
    for note in fit.notes:
        print(f"  note: {note}")
    columns = study.METHODS + study.DIAGNOSTICS
    print("\n  Delta E 2000 against the exact matrix result")
    print("  " + f"{'light':<9}" + "".join(f"{c[:14]:>15}" for c in columns))
    for row in rows:
        print("  " + f"{row['light']:<9}" + "".join(f"{row[c]:>15.2f}" for c in columns))
    print(f"\n  banded model ({model_name}, what the renderer carries) "
          "against the exact matrix result")
    for name, entry in per_light.items():
        print(f"  {name:<18} Delta E 2000 {entry['delta_e_2000']:6.2f}")
    for name, file in exported.items():
        print(f"  wrote {name}: {file}")
    return 0


#: The white of every Delta E 2000 here (catalog.optics.bispectral.study.white_xyz).
WHITE_POINT = ("the light's own XYZ (a perfect white diffuser under it); when the sample is "
               "brighter than that, the D65 chromaticity at the sample's Y; XYZ absolute "
               "(683 lm/W x CIE 1931 2 deg at 1 nm: Y in lm m^-2)")


def banded_colours(matrix, banded, lights) -> dict:
    """Per light: exact XYZ (the whole matrix), the model's XYZ as the renderer
    pre-integrates it (the bands as one effective fluorophore per light, plus the measured
    residual's spectrum under that light), Delta E 2000 between them."""
    from catalog.optics.bispectral import study as study  # noqa: PLC0415
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid, training_light  # noqa: PLC0415
    from catalog.optics.colorimetry import delta_e_2000  # noqa: PLC0415

    out = {}
    for name in lights:
        light = training_light(name)
        exact = study._xyz(exact_exitance_on_grid(matrix, light))
        model = study._xyz(banded.exitance_w_m2_nm(light))
        white = study.white_xyz(light, exact)
        out[name] = {"xyz_exact": exact.tolist(), "xyz_model": model.tolist(),
                     "delta_e_2000": float(delta_e_2000(model, exact, white)),
                     "white_xyz": white.tolist()}
    return out
