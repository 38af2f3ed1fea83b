"""``catalog import``: a fabric from the files its maker already has.

    catalog import FILE.u3m|FILE.u3ma|IMAGE.png --name N --out DIR [--repeat-m M]
                   [--threshold T --polarity light-open|dark-open] [--gonio G.csv] [--json]

Writes the self-contained preset ``DIR/N.toml`` with its files in ``DIR/N/``
(catalog.exchange). From an image: light = open (a backlit scan), or with ``--threshold``
the design artwork; its mean open area becomes ``btdf.direct``. From U3M 1.0/1.1: alpha ->
coverage, base colour -> dye, normal -> height, the texture's size -> ``repeat_m``,
physics -> [cloth], the rest under [import]. The lobes: fitted to ``--gonio``, else lent by
the nearest catalog fabric (named in the preset's [import] and the JSON).
"""

from __future__ import annotations

INPUT_FILES = ("file", "gonio")
OUTPUT_FOLDERS = ("out",)
RESOURCES = ("fabrics",)
HELP = "import a fabric from a U3M/U3MA material or a scanned or drawn pattern image"
U3M_SUFFIXES = (".u3m", ".u3ma")
IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".jpg", ".jpeg", ".exr")


def add_arguments(parser) -> None:
    from catalog.core.cliargs import number_type  # noqa: PLC0415

    parser.add_argument("file", metavar="FILE", help="a .u3m / .u3ma material or a pattern image")
    parser.add_argument("--name", required=True, help="the preset's name (its file stem)")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="folder to write DIR/NAME.toml and DIR/NAME/ into")
    parser.add_argument("--repeat-m", type=number_type(0.0, 1e6, unit="m", low_open=True), metavar="M",
                        help="the image's width in metres (one repeat); overrides the "
                             "image's or the U3M's own size")
    parser.add_argument("--threshold", type=number_type(-1e6, 1e6), metavar="T",
                        help="an image is artwork: open where its linear luminance is above "
                             "T (light-open) or below it (dark-open); default: a backlit "
                             "scan, luminance = open fraction")
    parser.add_argument("--polarity", choices=("light-open", "dark-open"), default="light-open",
                        help="which side of the image is open (default light-open)")
    parser.add_argument("--gonio", metavar="G.csv",
                        help="fit the lobes to this gonio measurement (default: the nearest "
                             "catalog fabric's lobes)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    from pathlib import Path

    from catalog.core.errors import InputError

    name = args.name
    if not name or name != Path(name).name or name.startswith(".") or name.endswith(".toml"):
        raise InputError(f"{name!r} must be a plain file stem (no folder, no suffix)",
                         field="--name")
    source = Path(args.file)
    suffix = source.suffix.lower()
    if suffix in U3M_SUFFIXES:
        from catalog.exchange.u3m import read_u3m_fabric

        if args.threshold is not None:
            raise InputError("--threshold is for images; a U3M's alpha is its coverage",
                             field="--threshold")
        fabric = read_u3m_fabric(source, repeat_m=args.repeat_m)
    elif suffix in IMAGE_SUFFIXES:
        from catalog.exchange.image_import import read_image_fabric

        fabric = read_image_fabric(source, repeat_m=args.repeat_m, threshold=args.threshold,
                                   polarity=args.polarity)
    else:
        raise InputError(f"unknown kind {suffix or '(no suffix)'!r}: give a .u3m, .u3ma or an "
                         f"image ({', '.join(IMAGE_SUFFIXES)})", path=source)
    if args.gonio is not None and not Path(args.gonio).is_file():
        raise InputError("no such gonio file", path=args.gonio, field="--gonio")
    from catalog.exchange.imported_preset import write_imported_preset

    report = write_imported_preset(fabric, name, Path(args.out), gonio=args.gonio)
    if args.json:
        from catalog.core.jsonout import print_json

        print_json(report)
    else:
        print(f"{report['name']}: {report['kind']} {report['source']}, "
              f"{report['pixels'][0]}x{report['pixels'][1]} px, open area "
              f"{report['open_area']:.4f}, repeat {report['repeat_m'][0]:.4g} x "
              f"{report['repeat_m'][1]:.4g} m; lobes from {report['lobes_from']}")
        print(f"wrote {report['out']}")
    return 0
