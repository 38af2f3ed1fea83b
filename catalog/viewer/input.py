"""Keyboard shortcuts and the mouse orbit camera.

Keys (glfw key codes -> actions; :data:`KEY_HELP` is the text of the help overlay):
Left/Right previous/next fabric, L next light, F fluorescence off/paper/physical,
Space pause, S screenshot (EXR and PNG), H help, Tab panel, C curtain open/close,
R reset the view, V next view (room, fabric, close-up), Escape quit. Mouse: drag with the left button to orbit, wheel to zoom.

The glfw module is imported for its key constants only (no window is needed to import it).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import glfw

from catalog.render.camera import (CURTAIN_TARGET, DEFAULT_VIEW, ROOM_MARGIN_M,  # noqa: F401
                                   VIEWS)
from catalog.render.camera import room_limit_m as render_room_limit_m


class Action(enum.Enum):
    PREVIOUS_FABRIC = "previous fabric"
    NEXT_FABRIC = "next fabric"
    NEXT_LIGHT = "next light"
    CYCLE_FLUORESCENCE = "fluorescence off / paper / physical"
    TOGGLE_PAUSE = "pause / run the simulation"
    SCREENSHOT = "screenshot (EXR and PNG)"
    TOGGLE_HELP = "this help"
    TOGGLE_PANEL = "show / hide the panel"
    TOGGLE_CURTAIN = "open / close the curtain"
    RESET_VIEW = "reset the view (the distance --distance gave)"
    NEXT_VIEW = "next view: room / fabric / close-up"
    QUIT = "quit"


#: glfw key -> action, and the key's name in the help overlay.
KEY_ACTIONS: dict[int, tuple[Action, str]] = {
    glfw.KEY_LEFT: (Action.PREVIOUS_FABRIC, "Left"),
    glfw.KEY_RIGHT: (Action.NEXT_FABRIC, "Right"),
    glfw.KEY_L: (Action.NEXT_LIGHT, "L"),
    glfw.KEY_F: (Action.CYCLE_FLUORESCENCE, "F"),
    glfw.KEY_SPACE: (Action.TOGGLE_PAUSE, "Space"),
    glfw.KEY_S: (Action.SCREENSHOT, "S"),
    glfw.KEY_H: (Action.TOGGLE_HELP, "H"),
    glfw.KEY_TAB: (Action.TOGGLE_PANEL, "Tab"),
    glfw.KEY_C: (Action.TOGGLE_CURTAIN, "C"),
    glfw.KEY_R: (Action.RESET_VIEW, "R"),
    glfw.KEY_V: (Action.NEXT_VIEW, "V"),
    glfw.KEY_ESCAPE: (Action.QUIT, "Esc"),
}

KEY_HELP: list[tuple[str, str]] = [(name, action.value) for action, name in KEY_ACTIONS.values()]
KEY_HELP += [("drag", "orbit the camera"), ("wheel", "zoom (down to 0.2 m: the threads)")]


def action_for_key(key: int, action: int) -> Action | None:
    """The viewer action of a key press (and of its auto-repeat for the arrows), or None."""
    entry = KEY_ACTIONS.get(key)
    if entry is None:
        return None
    if action == glfw.PRESS:
        return entry[0]
    if action == glfw.REPEAT and entry[0] in (Action.PREVIOUS_FABRIC, Action.NEXT_FABRIC):
        return entry[0]
    return None


@dataclass
class OrbitCamera:
    """Yaw and pitch about the curtain's centre and the distance to it (the renderer's camera).

    Yaw 0 looks at the curtain from the room side along its normal; pitch is clamped short
    of the poles so the view never flips; the distance stays between ``min_distance_m`` and
    ``max_distance_m`` and inside the room (:func:`room_limit_m`); :meth:`reset` returns to
    the home view (yaw 0, pitch 0, ``home_distance_m``).
    """

    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    distance_m: float = 2.6
    degrees_per_pixel: float = 0.25
    zoom_per_step: float = 0.9  # distance factor per wheel step towards the curtain
    min_pitch_deg: float = -80.0
    max_pitch_deg: float = 80.0
    min_distance_m: float = 0.2
    max_distance_m: float = 12.0
    home_distance_m: float | None = None   # None: the view's own distance
    view_name: str = DEFAULT_VIEW           # catalog.render.camera.VIEWS
    #: the room's catalog.render.placement.Placement (its window and inside); None: the box
    placement: object = None

    @property
    def view(self):
        """The named view composed for the room's window (catalog.render.placement)."""
        if self.placement is None:
            return VIEWS[self.view_name]
        return self.placement.view(self.view_name)

    @property
    def bounds(self):
        """The room's inside, where the camera may go."""
        if self.placement is None:
            from catalog.render.scene import ROOM_BOX  # noqa: PLC0415

            return ROOM_BOX
        return self.placement.interior

    @property
    def target(self) -> tuple[float, float, float]:
        return self.view.target

    @property
    def fov_y_deg(self) -> float:
        return self.view.fov_y_deg

    def reset(self) -> None:
        """Back to the home view: the view's yaw and pitch, at ``home_distance_m``."""
        self.yaw_deg = self.view.yaw_deg
        self.pitch_deg = self.view.pitch_deg
        self.distance_m = self.home_distance_m or self.view.distance_m
        self._keep_inside()

    def next_view(self) -> None:
        """The next of the named views (room, fabric, close-up), at its own distance."""
        names = list(VIEWS)
        self.view_name = names[(names.index(self.view_name) + 1) % len(names)]
        self.home_distance_m = None
        self.reset()

    def _keep_inside(self) -> None:
        limit = min(self.max_distance_m, room_limit_m(self.yaw_deg, self.pitch_deg, self.target, self.bounds))
        self.distance_m = min(limit, max(self.min_distance_m, self.distance_m))

    def drag(self, dx_px: float, dy_px: float) -> None:
        """Mouse moved by (dx, dy) pixels with the button held: orbit."""
        if not (math.isfinite(dx_px) and math.isfinite(dy_px)):
            return
        self.yaw_deg = (self.yaw_deg - dx_px * self.degrees_per_pixel + 180.0) % 360.0 - 180.0
        self.pitch_deg = min(self.max_pitch_deg, max(
            self.min_pitch_deg, self.pitch_deg + dy_px * self.degrees_per_pixel))
        self._keep_inside()

    def distance_limits_m(self) -> tuple[float, float]:
        """The nearest and farthest distance (m) allowed in the current direction."""
        far = min(self.max_distance_m, room_limit_m(self.yaw_deg, self.pitch_deg, self.target, self.bounds))
        return self.min_distance_m, max(self.min_distance_m, far)

    def set_distance(self, distance_m: float) -> None:
        """The panel's zoom: this distance (m), kept within the limits and inside the room."""
        if not math.isfinite(distance_m):
            return
        self.distance_m = float(distance_m)
        self._keep_inside()

    def zoom(self, steps: float) -> None:
        """Wheel turned by ``steps`` (positive = towards the curtain)."""
        if not math.isfinite(steps):
            return
        self.distance_m *= self.zoom_per_step ** steps
        self._keep_inside()


def room_limit_m(yaw_deg: float, pitch_deg: float, target=CURTAIN_TARGET, bounds=None) -> float:
    """How far the orbit camera may be from ``target`` in this direction and stay inside the
    room's box (``bounds``; None: the box's) less ROOM_MARGIN_M
    (catalog.render.camera.room_limit_m), at least 0.2 m."""
    if bounds is None:
        from catalog.render.scene import ROOM_BOX as bounds  # noqa: PLC0415,N811

    return max(render_room_limit_m(target, yaw_deg, pitch_deg, bounds), 0.2)


class MouseOrbit:
    """Turns glfw mouse events into :class:`OrbitCamera` moves.

    ``ui_wants_mouse(x, y)`` is asked on a press and a wheel turn with the pointer's
    window position: over the panel the panel gets the mouse, not the camera. (imgui's own
    ``want_capture_mouse`` alone lags a frame behind a pointer that jumps, so the viewer
    also checks the panel's rectangle.)
    """

    def __init__(self, camera: OrbitCamera, ui_wants_mouse=lambda x, y: False):
        self.camera = camera
        self.ui_wants_mouse = ui_wants_mouse
        self.dragging = False
        self.pointer: tuple[float, float] | None = None
        self._last: tuple[float, float] | None = None

    def button(self, button: int, action: int) -> None:
        if button != glfw.MOUSE_BUTTON_LEFT:
            return
        if action == glfw.PRESS and not self._ui_has_pointer():
            self.dragging = True
            self._last = self.pointer
        elif action == glfw.RELEASE:
            self.dragging = False

    def moved(self, x: float, y: float) -> None:
        if self.dragging and self._last is not None:
            self.camera.drag(x - self._last[0], y - self._last[1])
        self._last = (x, y)
        self.pointer = (x, y)

    def scrolled(self, y_offset: float) -> None:
        if not self._ui_has_pointer():
            self.camera.zoom(y_offset)

    def _ui_has_pointer(self) -> bool:
        x, y = self.pointer if self.pointer is not None else (-1.0, -1.0)
        return bool(self.ui_wants_mouse(x, y))
