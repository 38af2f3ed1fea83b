"""``catalog web``: write the static web catalog (no install, no network at run time)."""

from __future__ import annotations

#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
OUTPUT_FOLDERS = ("out",)
INPUT_FILES = ("room",)
HELP = "write a static web catalog (WebGL2, same shaders and light) that opens from file://"


def add_arguments(parser) -> None:
    from catalog.commands.roomargs import add_room_argument  # noqa: PLC0415
    parser.add_argument("--out", required=True,
                        help="folder of the site (DIR/index.html); built beside it and renamed "
                             "when complete; replaces only an earlier site or an empty folder")
    from catalog.core.fabricargs import add_fabric_options  # noqa: PLC0415

    add_fabric_options(parser, many=True, legacy_list=True)
    parser.add_argument("--lights", default=None, metavar="NAME[,NAME..]",
                        help="comma-separated lamps of the light library, and 'sun-by-hour' for "
                             "the sun slider (default: D65,A,FL2,LED-B4,LED-warm,UV-A,sun-by-hour)")
    add_room_argument(parser, "box", "; its transport's web pack is written beside the page "
                                     "(room_pack.js)")
    parser.add_argument("--json", action="store_true", help="print the report as one JSON object")


def run(args) -> int:
    from catalog.core.jsonout import print_json  # noqa: PLC0415
    from catalog.core.validate import parse_light_list  # noqa: PLC0415
    from catalog.web.site import build_site  # noqa: PLC0415

    if args.lights is not None:
        parse_light_list(args.lights, "--lights")  # '' and a repeated light are refused
    fabrics = None if args.fabric is None else ",".join(args.fabric)
    report = build_site(args.out, fabrics=fabrics, lights=args.lights, progress=not args.json,
                        room=args.room)
    if args.json:
        print_json(report)
    else:
        print(f"wrote {report['out']}/index.html: {len(report['fabrics'])} fabrics, "
              f"{len(report['lights'])} lights, {report['scenes']} scenes, "
              f"{report['total_bytes'] / 1e6:.2f} MB ({report['build_s']:.1f} s)")
    return 0
