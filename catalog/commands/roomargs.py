"""The ``--room`` option, shared by every command that draws a room (its help lists the
built-in rooms from the package, so it cannot fall behind them)."""

from __future__ import annotations


def add_room_argument(parser, default: str, more: str = "") -> None:
    """``--room NAME|FILE.glb`` with ``default``; ``more``: what this command adds."""
    from catalog.room import BUILTIN_ROOMS  # noqa: PLC0415  (the package's names only: light)

    parser.add_argument("--room", default=default, metavar="NAME|FILE.glb",
                        help=f"the room: a built-in name ({', '.join(BUILTIN_ROOMS)}) or a room "
                             f".glb (docs/formats.md, Rooms; default {default}){more}")
