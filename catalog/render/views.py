"""The named camera views (numpy-free, so that a command's --help can list them).

Each is an orbit camera's composition (catalog.render.camera.OrbitCamera.from_view): the point
it looks at, the direction it looks from, how far, and the lens (vertical field of view).
"""

from __future__ import annotations

from dataclasses import dataclass

from catalog.core.errors import CatalogError

#: The target of the orbit when none is given: the curtain's middle (m).
CURTAIN_TARGET = (0.0, 0.15, -0.08)


@dataclass(frozen=True)
class CameraView:
    """A named composition: where the orbit looks, from which direction and how far, with
    which lens (vertical field of view)."""

    target: tuple[float, float, float]
    yaw_deg: float
    pitch_deg: float
    distance_m: float
    fov_y_deg: float
    about: str


#: The views ``--view`` and the viewer's V key choose from (the first is the default).
#: room: as an interior photograph frames a window: from a corner of the room at eye height
#: (1.25 m above the floor), a wide lens, the window wall, a side wall and the floor's patch
#: of light in view. fabric: the curtain filling the frame. close: the threads at 0.45 m.
VIEWS: dict[str, CameraView] = {
    "room": CameraView((0.0, -0.05, 0.15), 25.0, 6.0, 3.4, 58.0,
                       "the curtain in its window, the walls beside it and the floor"),
    "fabric": CameraView(CURTAIN_TARGET, 0.0, 0.0, 1.5, 50.0, "the curtain filling the frame"),
    "close": CameraView((0.1, 0.3, -0.08), 0.0, 0.0, 0.5, 40.0,
                        "a close-up: the weave or the lace's motifs and net"),
}
DEFAULT_VIEW = "room"


def view_named(name: str) -> CameraView:
    if name not in VIEWS:
        raise CatalogError(f"unknown view {name!r} (known: {', '.join(VIEWS)})")
    return VIEWS[name]


