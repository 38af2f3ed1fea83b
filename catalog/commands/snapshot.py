"""``catalog snapshot``: render a fabric under a light headless (EGL) to EXR or PNG."""

from __future__ import annotations

from catalog.commands.displayargs import add_display_arguments, display_choices
from catalog.core.constants import FLUORESCENT_MODES

RESOURCES = ("fabrics",)
#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
INPUT_FILES = ("fabric", "environment", "room")
OUTPUT_FILES = ("out",)
HELP = "render a fabric under a light, headless through EGL, to EXR (linear) or PNG (sRGB)"
#: The frame settings refused after the room is loaded, by the option that gave them.
OPTION_OF_FIELD = {"lamps": "--lamp"}


def add_arguments(parser) -> None:
    from catalog.commands.roomargs import add_room_argument  # noqa: PLC0415
    from catalog.core import validate  # noqa: PLC0415
    from catalog.core.cliargs import number_type  # noqa: PLC0415

    parser.add_argument("--fabric", required=True, help="preset name (fabrics/NAME.toml) or a .toml path")
    parser.add_argument("--light", default="D65",
                        help="light name (`catalog lights`: D65, A, FL2, LED-B4, sun:22, ...)")
    parser.add_argument("--hour", type=float, default=None,
                        help="instead of --light: the sun at this hour (local solar time, "
                             "summer solstice, 34.7 N) behind the window")
    parser.add_argument("--size", default="1280x720", help="WIDTHxHEIGHT in pixels")
    parser.add_argument("--frame", type=number_type(0, validate.MAX_FRAME, whole=True), default=0,
                        help="cloth simulation frame (0: the settled drape every simulation starts from)")
    parser.add_argument("--out", required=True, help="FILE.exr (linear) or FILE.png (sRGB)")
    parser.add_argument("--no-fluorescence", action="store_true", help="render without fluorescence")
    parser.add_argument("--mode", choices=FLUORESCENT_MODES, default="physical",
                        help="fluorescence model (default physical)")
    parser.add_argument("--bands", type=int, default=3, help="spectral bands: 3 (RGB), 6, 9, 16")
    from catalog.render.views import DEFAULT_VIEW, VIEWS  # noqa: PLC0415

    parser.add_argument("--view", choices=tuple(VIEWS), default=DEFAULT_VIEW,
                        help="the composition: " + "; ".join(
                            f"{name}: {view.about}" for name, view in VIEWS.items())
                        + f" (default {DEFAULT_VIEW}; --yaw, --pitch, --distance change it)")
    parser.add_argument("--yaw", type=number_type(*validate.YAW_DEG, unit="deg"), default=None,
                        help="camera yaw, deg (default: the view's)")
    parser.add_argument("--pitch", type=number_type(*validate.PITCH_DEG, unit="deg"), default=None,
                        help="camera pitch, deg (default: the view's)")
    parser.add_argument("--distance", type=number_type(*validate.DISTANCE_M, unit="m", low_open=True),
                        default=None, help="camera distance from the view's target, m, kept "
                                           "inside the room (default: the view's)")
    parser.add_argument("--exposure", type=number_type(*validate.EXPOSURE), default=1.0,
                        help="exposure multiplier on top of --ev or the automatic exposure")
    add_display_arguments(parser)
    parser.add_argument("--environment", metavar="FILE.exr", default=None,
                        help="an HDR latitude-longitude image as the view behind the window "
                             "(scaled to the light's sky; default: the procedural clear sky)")
    parser.add_argument("--curtain", choices=("closed", "open"), default="closed",
                        help="open: the curtain drawn aside (the room lit by the window alone)")
    parser.add_argument("--lamp", action="append", default=[], metavar="LIGHT@X,Y,Z",
                        help="a lamp placed in the room (e.g. A@0,1.2,2.5; metres, y up, the "
                             "window at z = -0.2); up to 4")
    parser.add_argument("--no-room-light", action="store_true",
                        help="the earlier constant room instead of the room lit through the curtain")
    add_room_argument(parser, "box")
    parser.add_argument("--no-bloom", action="store_true", help="no glare before the tone map")
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def parse_lamp(text: str) -> tuple[str, tuple[float, float, float]]:
    """``LIGHT@X,Y,Z`` -> (light name, position m); refused in one line naming --lamp."""
    from catalog.core.errors import InputError  # noqa: PLC0415

    name, _, where = text.rpartition("@")
    try:
        position = tuple(float(v) for v in where.split(","))
    except ValueError:
        position = ()
    if not name or len(position) != 3:
        raise InputError(f"{text!r}: write LIGHT@X,Y,Z, e.g. A@0,1.2,2.5", field="--lamp")
    return name, position


def run(args) -> int:
    from pathlib import Path  # noqa: PLC0415

    from catalog.core.errors import InputError  # noqa: PLC0415
    from catalog.core.jsonout import print_json  # noqa: PLC0415
    from catalog.render.settings import SettingsError  # noqa: PLC0415
    from catalog.render.snapshot import SnapshotRequest, parse_size, render_snapshot  # noqa: PLC0415

    from catalog.render.placement import room_placement  # noqa: PLC0415

    ev, white_balance = display_choices(args)
    view = room_placement(args.room).view(args.view)   # composed for the room's own window
    request = SnapshotRequest(
        fabric=args.fabric, light=args.light, size=parse_size(args.size), out=Path(args.out),
        frame=args.frame, fluorescence="off" if args.no_fluorescence else args.mode,
        bands=args.bands, hour=args.hour,
        yaw_deg=view.yaw_deg if args.yaw is None else args.yaw,
        pitch_deg=view.pitch_deg if args.pitch is None else args.pitch,
        distance_m=view.distance_m if args.distance is None else args.distance,
        target=view.target, fov_y_deg=view.fov_y_deg, exposure=args.exposure, ev=ev,
        white_balance=white_balance, environment=args.environment,
        curtain_open=args.curtain == "open", room_light=not args.no_room_light,
        bloom=not args.no_bloom, lamps=tuple(parse_lamp(text) for text in args.lamp),
        room=args.room)
    try:
        report = render_snapshot(request)
    except SettingsError as exc:
        if exc.field not in OPTION_OF_FIELD:
            raise
        raise InputError(exc.problem, field=OPTION_OF_FIELD[exc.field]) from None
    if args.json:
        print_json(report)
    else:
        print(f"wrote {report['out']} ({report['fabric']} under {report['light']}, "
              f"fluorescence {report['fluorescence_variant']}, {report['bands']} bands)")
    return 0
