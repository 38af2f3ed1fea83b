"""The glfw window and the moderngl context made from it.

One GL context per process: the window's (GLX on X11). Never create an EGL standalone
context in the same process before it: Mesa then ends the process with an X BadAccess.
The viewer therefore runs in its own process (``catalog view``), and its tests start it
as a subprocess.
"""

from __future__ import annotations

import os

from catalog.core.errors import EnvironmentFailure

#: The renderer's shaders need OpenGL 4.3 (compute shaders, SSBOs).
GL_VERSION = (4, 3)

NO_DISPLAY_HINT = ("render without a window with `catalog snapshot --fabric NAME --light NAME "
                   "--out FILE.png` or `catalog sheet --lights NAME,NAME --out DIR`")


class NoDisplayError(EnvironmentFailure):
    """No display to open a window on (the CLI prints the one line and exits 3: the
    machine lacks something, the input is fine; option values are checked first, exit 2)."""


def display_available() -> bool:
    """True when an X11 or Wayland display is named in the environment."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


class GlfwErrors:
    """Collects glfw's error messages (instead of the glfw package's Python warnings)."""

    def __init__(self):
        self.messages: list[str] = []

    def __call__(self, code: int, description: bytes | str) -> None:
        if isinstance(description, bytes):
            description = description.decode("utf-8", "replace")
        self.messages.append(f"{description} (glfw error {code:#x})")

    def last(self) -> str:
        return self.messages[-1] if self.messages else "no reason given"


#: glfw's error messages of this process (the last one explains a failure).
GLFW_ERRORS = GlfwErrors()


def init_glfw():
    """Start glfw on the display; the glfw module. Raises :class:`NoDisplayError`
    (one line naming the headless commands) when there is no display or glfw cannot open it.
    Calling it again is harmless (glfw.init is idempotent)."""
    if not display_available():
        raise NoDisplayError("no display (neither DISPLAY nor WAYLAND_DISPLAY is set): "
                             + NO_DISPLAY_HINT)
    import glfw  # noqa: PLC0415  (the window's module, imported only by the viewer)

    glfw.set_error_callback(GLFW_ERRORS)
    if not glfw.init():
        raise NoDisplayError(f"cannot open the display ({GLFW_ERRORS.last()}): "
                             + NO_DISPLAY_HINT)
    return glfw


def open_window(size: tuple[int, int], title: str, visible: bool = True):
    """Open a window with an OpenGL 4.3 core context made current (glfw started here).

    Returns ``(glfw module, window)``; failures are :class:`NoDisplayError` lines.
    """
    glfw = init_glfw()
    glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, GL_VERSION[0])
    glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, GL_VERSION[1])
    glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
    glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
    glfw.window_hint(glfw.VISIBLE, visible)
    width, height = size
    window = glfw.create_window(int(width), int(height), title, None, None)
    if not window:
        glfw.terminate()
        raise NoDisplayError(f"cannot open an OpenGL {GL_VERSION[0]}.{GL_VERSION[1]} window "
                             f"({GLFW_ERRORS.last()}): " + NO_DISPLAY_HINT)
    glfw.make_context_current(window)
    return glfw, window
