"""The display step's command-line options, shared by snapshot, sheet and view.

Values are checked by :func:`display_choices` (one line naming the option, exit 2), not by
argparse (whose refusal prints the usage too)."""

from __future__ import annotations


def add_display_arguments(parser) -> None:
    """``--ev`` and ``--white-balance`` (catalog/render/display.py)."""
    parser.add_argument("--ev", default=None, metavar="EV100",
                        help="fixed camera exposure, EV at ISO 100 (about 9 for a 1000 lx lamp, "
                             "12 for 10000 lx daylight, 15 for the noon sun); default: automatic "
                             "from the frame's luminance histogram")
    parser.add_argument("--white-balance", default="room", metavar="{room,camera}",
                        help="room: adapt to the light's white as a person in the room does "
                             "(CAT16; not for the UV-A lamp); camera: fixed D65 (default room)")


def display_choices(args) -> tuple[float | None, str]:
    """(ev100 or None, white balance) from the parsed options, refused with InputError."""
    from catalog.core.errors import InputError  # noqa: PLC0415
    from catalog.render.snapshot import check_display_choices  # noqa: PLC0415

    ev = args.ev
    if ev is not None:
        try:
            ev = float(ev)
        except ValueError:
            raise InputError(f"{args.ev!r} is not a number (EV100)", field="--ev") from None
    check_display_choices(ev, args.white_balance)
    return ev, args.white_balance
