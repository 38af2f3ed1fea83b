"""``catalog export``: a fabric out of the catalog, for other tools.

    catalog export --fabric N [--light L] [--frame F] [--room R] --out FILE.glb|FILE.u3m [--json]

``.glb``: the draped curtain at frame F as glTF 2.0 (positions, normals, UVs in pattern
repeats; base colour, the pattern as alpha, KHR_materials_diffuse_transmission and
KHR_materials_sheen; the preset, light, frame and room under the scene's ``extras``).
``.u3m``: the preset as a U3M 1.1 material (FILE.u3m and its textures in FILE/), which
``catalog import`` reads back to the same fabric (catalog.exchange).
"""

from __future__ import annotations

OUTPUT_FILES = ("out",)
RESOURCES = ("fabrics",)
HELP = "export a fabric: the draped curtain as glTF 2.0 (.glb) or the preset as U3M 1.1 (.u3m)"
#: The longest simulation an export runs before it starts (frames of FRAME_DT_S).
MAX_FRAME = 10000


def add_arguments(parser) -> None:
    from catalog.commands.roomargs import add_room_argument  # noqa: PLC0415
    from catalog.core.cliargs import number_type  # noqa: PLC0415

    parser.add_argument("--fabric", required=True, help="a fabric name or a preset .toml")
    parser.add_argument("--light", default="D65", help="the light the file records (default D65)")
    parser.add_argument("--frame", type=number_type(0, MAX_FRAME, whole=True), default=0,
                        help="the cloth frame (0: the settled drape; default 0)")
    add_room_argument(parser, "box", ": the curtain hangs in its window")
    parser.add_argument("--out", required=True, metavar="FILE.glb|FILE.u3m", help="file to write")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    from pathlib import Path

    from catalog.core.errors import InputError
    from catalog.optics.lights import get_light
    from catalog.presets import find_preset, load_preset

    out = Path(args.out)
    suffix = out.suffix.lower()
    if suffix not in (".glb", ".u3m"):
        raise InputError(f"{out.suffix or '(no suffix)'!r}: write a .glb (glTF 2.0) or a .u3m",
                         field="--out")
    from catalog.exchange.gltf_export import write_glb
    from catalog.room.load import BUILTIN_ROOMS, load_room

    # a built-in name or a room .glb (docs/formats.md, "Rooms"): one that breaks a rule
    # is refused in one line naming the node and the rule, before the simulation. The curtain
    # hangs on the rod of the room's own window (catalog.render.placement); the file records
    # the room's name
    from catalog.render.placement import placement_of_room

    placement = placement_of_room(load_room(args.room))
    room = args.room if args.room in BUILTIN_ROOMS else Path(args.room).name
    get_light(args.light)                       # refused now, before the simulation
    preset = load_preset(find_preset(args.fabric))
    if suffix == ".glb":
        report = write_glb(preset, out, light=args.light, frame=args.frame, room=room,
                           placement=placement)
    else:
        from catalog.exchange.u3m_export import write_u3m

        report = write_u3m(preset, out)
    if args.json:
        from catalog.core.jsonout import print_json

        print_json(report)
    else:
        print(f"wrote {report['out']} ({report['format']}, fabric {report['fabric']})")
    return 0
