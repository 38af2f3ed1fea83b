"""``catalog fit``: fit the woven-cloth HG BTDF (eq. 7) to a gonio measurement and write
the fabric preset.

    catalog fit --gonio G.csv [--excitation E.csv --emission F.csv] --name N --out P.toml
                [--points all|79] [--weighting relative|none] [--plot FIG.png] [--json]

The options are checked here; the fit and the preset are built by
:func:`catalog.fit.preset_build.fit_preset` (the fit room), and the summary printed here.
"""

from __future__ import annotations

from catalog.fit.preset_build import DEFAULT_TAU_UNDYED

#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
INPUT_FILES = ("gonio", "excitation", "emission", "dye", "pattern")
OUTPUT_FILES = ("out", "plot")
HELP = "fit the woven-cloth HG BTDF (eq. 7) to gonio data and write a fabric preset"


def add_arguments(parser) -> None:
    from catalog.core import validate  # noqa: PLC0415
    from catalog.core.cliargs import number_type  # noqa: PLC0415

    parser.add_argument("--gonio", required=True, metavar="G.csv",
                        help="gonio transmittance CSV (formats.md)")
    parser.add_argument("--excitation", metavar="E.csv",
                        help="excitation spectrum of a fluorescent fabric (with --emission)")
    parser.add_argument("--emission", metavar="F.csv",
                        help="emission spectrum of a fluorescent fabric (with --excitation)")
    parser.add_argument("--dye", metavar="D.csv",
                        help="spectral transmittance of the dye, 0..1 (default: dye.csv "
                             "beside the gonio file, if there is one)")
    parser.add_argument("--name", required=True, help="preset name (the file stem)")
    parser.add_argument("--out", required=True, metavar="P.toml", help="preset to write")
    parser.add_argument("--display-name", help="name shown in the catalog "
                        "(default: the gonio header's display_name, else the name)")
    parser.add_argument("--weave", help="weave for the [cloth] table (lace, voile, plain, "
                        "twill, satin; default: the gonio header's weave, else plain)")
    parser.add_argument("--points", choices=("all", "79"), default="all",
                        help="fit all points or the paper's 79-point subset (default all)")
    parser.add_argument("--weighting", choices=("relative", "none"), default="relative",
                        help="relative: each point weighted by 1/value (default); "
                             "none: the paper's plain least squares")
    parser.add_argument("--rho", type=number_type(0.0, 1.0, low_open=True),
                        help="thread density (0, 1] (default: 1 - fitted direct)")
    parser.add_argument("--tau", type=number_type(*validate.TAU), help="absorption optical depth >= 0 "
                        "(default: from the dye, else %g)" % DEFAULT_TAU_UNDYED)
    parser.add_argument("--quantum-yield", type=number_type(0.0, 1.0),
                        help="physical-mode quantum yield of the fluorescence")
    parser.add_argument("--peak-absorptance", type=number_type(0.0, 1.0, low_open=True),
                        help="physical-mode peak absorptance of the fluorescence")
    parser.add_argument("--pattern", metavar="IMAGE",
                        help="the fabric's pattern: a grey tileable coverage image (1 = thread), "
                             "remapped to the fitted open area and written beside the preset as "
                             "patterns/NAME.png with a [pattern] table (needs --pattern-repeat); "
                             "default: the weave's own structure at the fitted open area (a tulle "
                             "net for a lace, a plain weave, a twill or a satin)")
    parser.add_argument("--pattern-repeat", metavar="W[,H]",
                        help="the pattern image's size on the cloth, m (one number: the width, "
                             "the height by the pixel aspect)")
    parser.add_argument("--plot", metavar="FIG.png",
                        help="draw measured vs fitted HG and Cook-Torrance (paper Fig. 11)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    import time
    from pathlib import Path

    from catalog.core.errors import InputError
    from catalog.fit.preset_build import fit_preset

    t0 = time.perf_counter()
    if (args.excitation is None) != (args.emission is None):
        raise InputError("--excitation and --emission go together",
                         field="--emission" if args.emission is None else "--excitation")
    out = Path(args.out)
    if out.suffix != ".toml":
        raise InputError("the preset must be a .toml file", field="--out")
    if out.stem != args.name:
        raise InputError(f"--name {args.name!r} must equal the file stem of --out "
                         f"({out.stem!r})", field="--name")
    if args.rho is not None and not 0 < args.rho <= 1:
        raise InputError(f"{args.rho:g} is out of range (0, 1]", field="--rho")
    if args.tau is not None and not args.tau >= 0:
        raise InputError(f"{args.tau:g} must be >= 0", field="--tau")

    if (getattr(args, "pattern", None) is None) != (getattr(args, "pattern_repeat", None) is None):
        raise InputError("--pattern and --pattern-repeat go together",
                         field="--pattern-repeat" if args.pattern is not None else "--pattern")
    summary = fit_preset(args, t0)
    if args.json:
        from catalog.core.jsonout import print_json
        print_json(summary)
    else:
        _print_summary(summary)
    return 0


def _print_summary(s: dict) -> None:
    ident, err = s["identifiable"], s["stderr"]
    print(f"{s['name']}: {s['points']} points, weighting {s['weighting']}, "
          f"{s['starts']} starts, {s['iterations']} LM evaluations, {s['fit_time_s'] * 1e3:.1f} ms")
    for key in ident:
        print(f"  {key:7s} = {ident[key]:.6g} +- {err[key]:.2g}")
    if "anisotropy" in s:
        print(f"  anisotropy = {s['anisotropy']:.4g} +- {err['anisotropy']:.2g} (warp/weft, "
              "directional lobe)")
    print(f"  rho = {s['rho']:g}, tau = {s['tau']:g} -> k_d = {s['k_d']:.6g}, k_s = {s['k_s']:.6g}")
    if "rgb" in s:
        for key, values in s["rgb"].items():
            print(f"  {key:7s} r,g,b = " + ", ".join(f"{v:.4g}" for v in values))
    better = "HG better" if s["hg_beats_ct"] else "Cook-Torrance better"
    print(f"  rmse HG {s['rmse']:.4g}, Cook-Torrance {s['ct_rmse']:.4g} ({better})")
    print(f"wrote {s['out']}")
