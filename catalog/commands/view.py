"""`catalog view`: the interactive viewer in a window (needs a display)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from catalog.core.constants import FLUORESCENCE_MODES as FLUORESCENCE_CHOICES
from catalog.core.cliargs import wxh_type
from catalog.commands.displayargs import add_display_arguments

RESOURCES = ("fabrics",)
#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
INPUT_FILES = ("fabric", "compare", "room")
OUTPUT_FILES = ("screenshot",)
HELP = "browse the fabrics, animated, under any light, in a window (needs a display)"

BAND_CHOICES = (3, 6, 9, 16)


_size = wxh_type("--size", 16, 16384)
_grid = wxh_type("--grid", 2, 1024, unit="particles", example="48x64")


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, found {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, found {value}")
    return value


def _render_scale(text: str) -> float | None:
    if text == "auto":
        return None
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number or 'auto', found {text!r}") from None
    if not 0.25 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"must be within 0.25-1, found {value:g}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from catalog.commands.roomargs import add_room_argument  # noqa: PLC0415
    parser.add_argument("--fabric", help="fabric to show first (preset name or .toml)")
    parser.add_argument("--light", help="light to start with: 'sun' (hour slider), a CIE "
                        "illuminant (D65, A, FL2, LED-B4, ...), UV-A, UV-385, LED-405, "
                        "LED-violet-white, LED-warm, sun:PATH_KM")
    parser.add_argument("--compare", metavar="NAME",
                        help="split screen: this fabric on the right, same light")
    parser.add_argument("--size", type=_size, default=(1280, 720), metavar="WxH",
                        help="window size in pixels (default 1280x720)")
    parser.add_argument("--frames", type=_positive_int, metavar="N",
                        help="run N frames (fixed 1/60 s cloth steps), then exit")
    parser.add_argument("--screenshot", type=Path, metavar="FILE.png",
                        help="with --frames: save the window after the last frame")
    parser.add_argument("--screenshot-dir", type=Path, default=Path("screenshots"),
                        metavar="DIR", help="where the S key saves EXR + PNG (default "
                        "./screenshots)")
    parser.add_argument("--stats", action="store_true",
                        help="log each frame's time and parts (JSON lines on stdout)")
    parser.add_argument("--fluorescence", choices=FLUORESCENCE_CHOICES, default="physical",
                        help="fluorescence mode to start with (default physical)")
    parser.add_argument("--bands", type=int, choices=BAND_CHOICES, default=3,
                        help="spectral bands (3 = RGB)")
    parser.add_argument("--hour", type=float, help="hour of day for the sun (6-18)")
    parser.add_argument("--wind", type=float, metavar="M_S", help="wind speed, m/s")
    parser.add_argument("--grid", type=_grid, default=(96, 56), metavar="WxH",
                        help="cloth particles across x down (default 96x56: the fabric is "
                             "fullness x the rod wide)")
    parser.add_argument("--distance", type=float, default=None, metavar="M",
                        help="camera distance from the curtain, m (0.2-4; the wheel zooms, "
                             "R resets, V the next view; default: the view's)")
    parser.add_argument("--cloth-backend", choices=("auto", "numpy", "cpu", "gpu"),
                        default="auto",
                        help="cloth simulation backend: gpu (compute shaders writing the "
                        "vertex buffer), numpy, cpu (numba: fastest on a CPU, but it imports "
                        "scipy); default auto: gpu on a GPU, numpy on a software rasteriser")
    parser.add_argument("--render-scale", type=_render_scale, metavar="S|auto", default=None,
                        help="scene resolution relative to the window, 0.25-1 (default auto: "
                        "0.5 on a software rasteriser such as llvmpipe, else 1)")
    parser.add_argument("--no-room-light", action="store_true",
                        help="the earlier constant room and flat sky, no glare (docs/room.md)")
    add_room_argument(parser, "living")
    parser.add_argument("--no-panel", action="store_true", help="start with the panel hidden")
    parser.add_argument("--paused", action="store_true", help="start with the cloth paused")
    parser.add_argument("--compare-fluorescence", choices=FLUORESCENCE_CHOICES, default=None,
                        help="with --compare: the right half's fluorescence mode (default: "
                        "the left's); --compare NAME --fabric NAME shows one fabric on | off")
    add_display_arguments(parser)
    from catalog.core.fabricargs import add_fabric_dir_alias, add_fabric_folders  # noqa: PLC0415

    add_fabric_folders(parser)
    add_fabric_dir_alias(parser)


def _forbid_scipy() -> None:
    """Mark scipy absent in the viewer's process.

    Drawing a frame never needs scipy (docs/architecture.md: render and viewer never import the
    tools' fitting code). numba's own import probes for scipy (a version check) and its CPU
    target then loads scipy.linalg's BLAS bindings, a few hundred ms of start-up for nothing;
    with scipy marked absent numba skips both, and an accidental scipy import anywhere in the
    viewer fails loudly instead of silently slowing the start.
    """
    import sys

    sys.modules.setdefault("scipy", None)  # type: ignore[arg-type]


def run(args: argparse.Namespace) -> int:
    _forbid_scipy()
    from catalog.core.errors import CatalogError
    from catalog.viewer.app import ViewerApp, ViewerOptions
    from catalog.viewer.window import (NO_DISPLAY_HINT, NoDisplayError, display_available,
                                       init_glfw)

    from catalog.commands.displayargs import display_choices

    ev, white_balance = display_choices(args)
    if args.screenshot is not None and args.frames is None:
        raise CatalogError("--screenshot needs --frames N (the S key saves screenshots "
                           "in interactive use)")
    if args.hour is not None and not 0.0 <= args.hour <= 24.0:
        raise CatalogError(f"--hour: {args.hour:g} is not an hour of the day (0-24)")
    if args.distance is not None and not (math.isfinite(args.distance)
                                          and 0.2 <= args.distance <= 4.0):
        raise CatalogError(f"--distance: {args.distance:g} m is outside [0.2, 4] m (the viewer's "
                           "room; snapshot and reference allow (0.05, 50])")
    if args.wind is not None and not 0.0 <= args.wind <= 50.0:
        raise CatalogError(f"--wind: {args.wind:g} m/s is outside 0-50 m/s")
    from catalog.room.load import room_path

    room_path(args.room)   # a name or a file (its rules are checked as it loads)
    if not display_available():  # say so before any heavy import or preset read
        raise NoDisplayError("no display (neither DISPLAY nor WAYLAND_DISPLAY is set): "
                             + NO_DISPLAY_HINT)
    init_glfw()  # a named display that cannot be opened: the same one line, exit 2
    fabric, fabric_dir = args.fabric, None  # --fabrics DIR: on the search path (cli)
    if fabric is not None and fabric.endswith(".toml"):  # a preset file: browse its folder
        path = Path(fabric)
        if not path.is_file():
            raise CatalogError(f"--fabric: no such preset file {fabric}")
        fabric, fabric_dir = path.stem, fabric_dir or path.parent
    options = ViewerOptions(
        fabric=fabric, light=args.light, compare=args.compare, size=args.size,
        frames=args.frames, screenshot=args.screenshot, screenshot_dir=args.screenshot_dir,
        stats=args.stats, fluorescence=args.fluorescence, bands=args.bands, hour=args.hour,
        wind_m_s=args.wind, grid=args.grid, distance_m=args.distance,
        cloth_backend=None if args.cloth_backend == "auto" else args.cloth_backend,
        panel=not args.no_panel, paused=args.paused, render_scale=args.render_scale,
        ev100=ev, white_balance=white_balance, compare_fluorescence=args.compare_fluorescence,
        room_light=not args.no_room_light, room=args.room,
        fabric_dir=fabric_dir)
    return ViewerApp(options).run()
