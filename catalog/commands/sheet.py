"""``catalog sheet``: every fabric under a set of lights, one image each and a grid."""

from __future__ import annotations

from catalog.commands.displayargs import add_display_arguments, display_choices
from catalog.core.constants import FLUORESCENT_MODES

#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
OUTPUT_FOLDERS = ("out",)
INPUT_FILES = ("room",)
HELP = "contact sheet: every fabric x light as PNG images and one grid image"


def add_arguments(parser) -> None:
    from catalog.commands.roomargs import add_room_argument  # noqa: PLC0415
    from catalog.core.fabricargs import CATALOG_LIGHTS, add_fabric_options  # noqa: PLC0415

    parser.add_argument("--lights", default=CATALOG_LIGHTS, metavar="NAME[,NAME..]",
                        help="comma-separated light names (`catalog lights`)")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--size", default="320x240", help="WIDTHxHEIGHT of each image")
    add_fabric_options(parser, many=True, legacy_list=True)
    parser.add_argument("--no-fluorescence", action="store_true", help="render without fluorescence")
    parser.add_argument("--mode", choices=FLUORESCENT_MODES, default="physical",
                        help="fluorescence model")
    parser.add_argument("--bands", type=int, default=3, help="spectral bands: 3, 6, 9, 16")
    add_display_arguments(parser)
    parser.add_argument("--no-labels", action="store_true",
                        help="grid without the fabric (row) and light (column) labels")
    add_room_argument(parser, "living")
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def run(args) -> int:
    from pathlib import Path  # noqa: PLC0415

    from catalog.core.errors import InputError  # noqa: PLC0415
    from catalog.core.jsonout import print_json  # noqa: PLC0415
    from catalog.render.sheet import render_sheet  # noqa: PLC0415
    from catalog.render.snapshot import parse_size  # noqa: PLC0415

    ev, white_balance = display_choices(args)
    from catalog.core.validate import parse_light_list  # noqa: PLC0415

    lights = parse_light_list(args.lights, "--lights")  # sun@DATE,LAT,LON keeps its commas
    report = render_sheet(lights, Path(args.out), parse_size(args.size), fabrics=args.fabric,
                          fluorescence="off" if args.no_fluorescence else args.mode,
                          bands=args.bands, progress=not args.json, ev=ev,
                          white_balance=white_balance, labels=not args.no_labels, room=args.room)
    if args.json:
        print_json(report)
    else:
        print(f"wrote {len(report['images'])} images and {report['grid']}")
    return 0
