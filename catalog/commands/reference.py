"""``catalog reference``: a path-traced EXR of the snapshot scene (Mitsuba 3, CPU)."""

from __future__ import annotations

from catalog.core.constants import FLUORESCENT_MODES

RESOURCES = ("fabrics",)
#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
INPUT_FILES = ("fabric", "room")
OUTPUT_FILES = ("out",)
HELP = "path-trace the snapshot scene (Mitsuba 3 on the CPU) to a linear EXR: the reference"


def add_arguments(parser) -> None:
    from catalog.commands.roomargs import add_room_argument  # noqa: PLC0415
    from catalog.core import validate  # noqa: PLC0415
    from catalog.core.cliargs import number_type  # noqa: PLC0415

    parser.add_argument("--fabric", required=True, help="preset name (fabrics/NAME.toml) or a .toml path")
    parser.add_argument("--light", default="D65", help="light name (`catalog lights`)")
    parser.add_argument("--frame", type=number_type(0, validate.MAX_FRAME, whole=True), default=0, help="cloth simulation frame (0: the static drape)")
    parser.add_argument("--size", default="320x240", help="WIDTHxHEIGHT in pixels")
    parser.add_argument("--distance", type=number_type(*validate.DISTANCE_M, unit="m", low_open=True),
                        default=2.6, help="camera distance, m")
    parser.add_argument("--yaw", type=number_type(*validate.YAW_DEG, unit="deg"), default=0.0,
                        help="camera yaw, deg")
    parser.add_argument("--pitch", type=number_type(*validate.PITCH_DEG, unit="deg"), default=0.0,
                        help="camera pitch, deg")
    parser.add_argument("--spp", type=number_type(1, 1 << 16, whole=True), default=64,
                        help="samples per pixel (>= 1)")
    parser.add_argument("--seed", type=number_type(0, validate.SEED_MAX, whole=True), default=0,
                        help="sampler seed (independent renders: differ)")
    parser.add_argument("--max-depth", type=number_type(1, 256, whole=True), default=16,
                        help="path length limit (bounces)")
    parser.add_argument("--variant", default="llvm_ad_rgb",
                        help="Mitsuba variant: llvm_ad_rgb (default) or llvm_ad_spectral")
    parser.add_argument("--no-fluorescence", action="store_true", help="without fluorescence")
    parser.add_argument("--mode", choices=FLUORESCENT_MODES, default="physical",
                        help="fluorescence model (default physical)")
    add_room_argument(parser, "box")
    parser.add_argument("--out", required=True, help="FILE.exr (linear radiance)")
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def run(args) -> int:
    import dataclasses  # noqa: PLC0415
    from pathlib import Path  # noqa: PLC0415

    from catalog.core.jsonout import print_json  # noqa: PLC0415
    from catalog.pathtrace.render import (ReferenceRequest, check_options,  # noqa: PLC0415
                                          reference_settings, render_reference)
    from catalog.render.snapshot import parse_size  # noqa: PLC0415

    request = ReferenceRequest(scene=None, size=parse_size(args.size), out=Path(args.out),
                               spp=args.spp, frame=args.frame, variant=args.variant,
                               seed=args.seed, max_depth=args.max_depth)
    check_options(request)   # the path tracer's options first, then the scene
    # the scene value catalog snapshot draws (the camera kept inside the room, as its is),
    # resolved once here: the fabric's tables, the light, the room loaded
    request = dataclasses.replace(request, scene=reference_settings(
        args.fabric, args.light, yaw_deg=args.yaw, pitch_deg=args.pitch, distance_m=args.distance,
        fluorescence="off" if args.no_fluorescence else args.mode, room=args.room, inside=True))
    _, report = render_reference(request, progress=not args.json)
    if args.json:
        print_json(report)
    else:
        print(f"wrote {report['out']} ({report['fabric']} under {report['light']}, "
              f"{report['spp']} spp, {report['render_s']:.1f} s)")
    return 0
