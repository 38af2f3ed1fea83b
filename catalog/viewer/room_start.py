"""The viewer's room at start-up: its frame bundle (catalog.render.room_operators), built
first when it is not cached, with its progress on stdout (done/total stages, the share
done, the time left: catalog.room.build_progress), before the window opens; then the
room's placement (catalog.render.placement: the curtain's rod and the camera's views).

The build runs in a child process (the viewer marks scipy absent; the build needs it), its
lines passed through as they come. A room the child refuses is one line naming --room."""

from __future__ import annotations

import subprocess
import sys


def bundle_cached(spec) -> bool:
    from catalog.render.room_operators import bundle_path, load  # noqa: PLC0415

    path, key, _name = bundle_path(spec)
    return path.exists() and load(path, key) is not None


def build_with_progress(spec, stream=None) -> None:
    """Build ``spec``'s bundle in a child process, its progress lines echoed on ``stream``
    (stdout) as "catalog view: room NAME: 3/6 direct light, 41 % done, ... left"."""
    from catalog.core.errors import InputError  # noqa: PLC0415

    stream = stream or sys.stdout
    print(f"catalog view: first use of the room {spec!s}: building its light transport "
          "(cached afterwards)", file=stream, flush=True)
    child = subprocess.Popen([sys.executable, "-m", "catalog.render.room_operators", str(spec), "--progress"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, bufsize=1)
    for line in child.stdout:
        print(f"catalog view: {line.rstrip()}", file=stream, flush=True)
    errors = child.stderr.read()
    if child.wait() != 0:
        lines = (errors.strip() or "the room's build failed").splitlines()
        raise InputError(lines[-1], field="--room")


def start_room(spec, stream=None):
    """The placement of the viewer's room ``spec`` (None: the box's special-case room), its
    bundle built first with progress when absent."""
    from catalog.render.placement import BOX, room_placement  # noqa: PLC0415

    if spec is None:
        return BOX
    from catalog.room.load import room_path  # noqa: PLC0415

    room_path(spec)          # an unknown name or a missing file: one line, before any build
    if not bundle_cached(spec):
        build_with_progress(spec, stream)
    return room_placement(spec)
