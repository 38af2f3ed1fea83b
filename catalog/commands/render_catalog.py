"""``catalog render-catalog``: every fabric x light x frame x yaw, resumable, in this process
or on Dask workers (docs/batch.md).

Exit status: 0 every image is done; 2 a bad option (one line naming it), nothing written;
3 some fabrics failed (named in the summary and the manifest's ``failed``), the others
finished; a re-run renders only what is missing.
"""

from __future__ import annotations

from catalog.core.constants import FLUORESCENT_MODES

#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
OUTPUT_FOLDERS = ("out",)
INPUT_FILES = ("room",)
HELP = "render a whole catalog (fabrics x lights x frames x yaws) with a resumable manifest"
#: Exit status when some fabrics failed and the rest finished.
EXIT_PARTIAL = 3


def add_arguments(parser) -> None:
    from catalog.commands.roomargs import add_room_argument  # noqa: PLC0415
    from catalog.core import validate  # noqa: PLC0415
    from catalog.core.cliargs import number_type  # noqa: PLC0415
    from catalog.core.fabricargs import CATALOG_LIGHTS, add_fabric_options  # noqa: PLC0415

    add_fabric_options(parser, many=True, legacy_list=True)
    parser.add_argument("--lights", default=CATALOG_LIGHTS, metavar="NAME[,NAME..]",
                        help="comma-separated light names (`catalog lights`)")
    parser.add_argument("--frames", default="0:1",
                        help="START:STOP[:STEP] as a Python slice, STOP excluded (0: the settled "
                             "drape, N: the cloth after N steps of 1/60 s)")
    parser.add_argument("--yaw", default=None,
                        help="camera yaw angles in deg: 0,90,180 or START:STOP:STEP (default: 0)")
    parser.add_argument("--size", default="320x240", help="WIDTHxHEIGHT of each image")
    parser.add_argument("--format", default="png", help="png (display sRGB) or exr (linear)")
    parser.add_argument("--out", required=True, help="output folder (images, manifest.json)")
    parser.add_argument("--workers", type=int, default=None,
                        help="Dask LocalCluster of N worker processes on 127.0.0.1")
    parser.add_argument("--scheduler", default=None,
                        help="address of an existing Dask scheduler (tcp://HOST:PORT)")
    parser.add_argument("--retries", type=int, default=2, help="retries of a failed fabric task")
    parser.add_argument("--lp-threads", type=int, default=None,
                        help="llvmpipe threads per Dask worker (default: cores / workers per host)")
    parser.add_argument("--no-fluorescence", action="store_true", help="render without fluorescence")
    parser.add_argument("--mode", choices=FLUORESCENT_MODES, default="physical",
                        help="fluorescence model")
    parser.add_argument("--bands", type=int, default=3, help="spectral bands: 3, 6, 9, 16")
    parser.add_argument("--pitch", type=number_type(*validate.PITCH_DEG, unit="deg"), default=0.0,
                        help="camera pitch, deg")
    parser.add_argument("--distance", type=number_type(*validate.DISTANCE_M, unit="m", low_open=True),
                        default=2.6, help="camera distance, m")
    parser.add_argument("--exposure", type=number_type(*validate.EXPOSURE), default=1.0,
                        help="exposure multiplier")
    add_room_argument(parser, "box")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--json", action="store_true", help="print the summary as one JSON object")


def run(args) -> int:
    import sys  # noqa: PLC0415

    from catalog.batch import JobSpec, check_engine, render_catalog  # noqa: PLC0415
    from catalog.core.errors import InputError  # noqa: PLC0415
    from catalog.core.jsonout import print_json  # noqa: PLC0415

    check_engine(args.workers, args.scheduler)
    if args.lp_threads is not None and args.lp_threads < 1:
        raise InputError(f"{args.lp_threads} must be >= 1", field="--lp-threads")
    if args.fabric is None:  # left out: every fabric on the search path
        from catalog.presets import list_presets  # noqa: PLC0415

        fabrics = [str(path) for path in list_presets()]
    else:
        fabrics = args.fabric
    spec = JobSpec.create(
        fabrics=fabrics, lights=args.lights, frames=args.frames, yaws=args.yaw,
        size=args.size, image_format=args.format, out_dir=args.out,
        fluorescence="off" if args.no_fluorescence else args.mode, bands=args.bands,
        pitch_deg=args.pitch, distance_m=args.distance, exposure=args.exposure, room=args.room)
    summary = render_catalog(spec, workers=args.workers, scheduler=args.scheduler,
                             retries=args.retries, lp_threads=args.lp_threads,
                             progress=not (args.json or args.no_progress))
    if args.json:
        print_json(summary)
    else:
        rate = summary["images_per_s"]
        print(f"{summary['images']} images: {summary['rendered']} rendered, "
              f"{summary['skipped']} already done, {summary['kept']} kept from an "
              f"interrupted run, {len(summary['failed'])} fabrics failed; "
              f"{summary['wall_s']:.1f} s ({rate or 0:.2f} images/s, {summary['engine']}, "
              f"{summary['workers']} worker{'' if summary['workers'] == 1 else 's'}); "
              f"manifest {summary['manifest']}")
    for fabric, error in summary["failed"].items():
        print(f"catalog render-catalog: fabric {fabric} failed: {error}", file=sys.stderr)
    return EXIT_PARTIAL if summary["failed"] else 0
