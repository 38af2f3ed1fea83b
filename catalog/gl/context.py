"""The one place a GL context is created.

- :func:`create_headless_context`: a standalone EGL context (no display; Mesa llvmpipe in CI,
  a GPU's EGL where there is one);
- :func:`headless_context`: the caller's context, or one of its own made for a ``with`` block
  and released after it, the thread's current context before it current again;
  :func:`own_context_unless_given`, the same around a function's call (its ``ctx`` argument);
- :func:`wrap_window_context`: the context of a window the caller made current (glfw).

Both require OpenGL 4.3 (compute shaders, std430). Failures are one-line EnvironmentFailures (exit 3).
"""

from __future__ import annotations

import functools
import inspect
from contextlib import contextmanager

from catalog.core.errors import EnvironmentFailure

#: OpenGL version required (4.3: compute shaders for the cloth, std430 buffers).
REQUIRED_GL = 430


def create_headless_context(device_index: int | None = None):
    """A standalone OpenGL 4.3 context through EGL, with no window or display.

    ``device_index``: which EGL device (GPU) to use on a node with several, 0-based in the
    order of ``eglQueryDevicesEXT`` (:func:`egl_device_count` counts them); None: the default.
    """
    import moderngl  # noqa: PLC0415

    options = {} if device_index is None else {"device_index": int(device_index)}
    try:
        return moderngl.create_standalone_context(backend="egl", require=REQUIRED_GL, **options)
    except Exception as exc:  # moderngl/glcontext raise plain Exceptions here
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise EnvironmentFailure(f"no EGL device: cannot create a headless OpenGL {REQUIRED_GL // 100}."
                           f"{REQUIRED_GL // 10 % 10} context ({reason})") from None


@contextmanager
def headless_context(ctx=None, device_index: int | None = None):
    """``ctx`` when given (nothing made or released); otherwise a new standalone context
    (:func:`create_headless_context`) for the ``with`` block, released at its end, when the
    EGL context, display and surfaces current in this thread before it (a caller's, e.g. the
    tests' shared one, or none) are made current again. Making a context makes it current and
    releasing it does not undo that: without this, a command run in the caller's process left
    its own context current, and the caller's next calls went to it (its buffers then gave
    GL_INVALID_OPERATION)."""
    if ctx is not None:
        yield ctx
        return
    egl = _egl()
    before = _current_egl(egl)
    own = create_headless_context(device_index)
    own_display = egl.eglGetCurrentDisplay() if egl is not None else None
    try:
        yield own
    finally:
        own.release()
        if egl is not None:
            _make_current(egl, before, own_display)


def own_context_unless_given(function):
    """``function`` (which takes a ``ctx`` argument) called in :func:`headless_context`: with
    the ``ctx`` it was given, or with one of its own for the call, released after it."""
    signature = inspect.signature(function)

    @functools.wraps(function)
    def call(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        with headless_context(bound.arguments.get("ctx")) as ctx:
            bound.arguments["ctx"] = ctx
            return function(*bound.args, **bound.kwargs)

    return call


#: EGL's names for the draw and read surfaces (eglGetCurrentSurface's argument).
_EGL_DRAW, _EGL_READ = 0x3059, 0x305A


def _egl():
    """libEGL through ctypes, its current-context calls typed; None without it. The library
    moderngl's EGL backend (glcontext) loads: one handle per process, so one thread state."""
    import ctypes  # noqa: PLC0415
    import ctypes.util  # noqa: PLC0415

    try:
        lib = ctypes.CDLL(ctypes.util.find_library("EGL") or "libEGL.so.1")
    except OSError:
        return None
    handle = ctypes.c_void_p
    for name in ("eglGetCurrentContext", "eglGetCurrentDisplay"):
        getattr(lib, name).restype = handle
        getattr(lib, name).argtypes = []
    lib.eglGetCurrentSurface.restype = handle
    lib.eglGetCurrentSurface.argtypes = [ctypes.c_int]
    lib.eglMakeCurrent.restype = ctypes.c_uint
    lib.eglMakeCurrent.argtypes = [handle, handle, handle, handle]
    lib.eglGetError.restype = ctypes.c_int
    return lib


def _current_egl(egl) -> tuple | None:
    """(display, draw, read, context) current in this thread; None without libEGL."""
    if egl is None:
        return None
    return (egl.eglGetCurrentDisplay(), egl.eglGetCurrentSurface(_EGL_DRAW),
            egl.eglGetCurrentSurface(_EGL_READ), egl.eglGetCurrentContext())


def _make_current(egl, state: tuple, own_display) -> None:
    """Make ``state`` (:func:`_current_egl`) current again: a context with its display and
    surfaces, or no context (unbound on ``own_display``, the display of the one released)."""
    display, draw, read, context = state
    if context:
        done = egl.eglMakeCurrent(display, draw, read, context)
    elif own_display:
        done = egl.eglMakeCurrent(own_display, None, None, None)
    else:
        return
    if not done:
        raise EnvironmentFailure("cannot make the caller's EGL context current again after a "
                                 f"command's own (eglMakeCurrent: error {egl.eglGetError():#x})")


def egl_device_count() -> int | None:
    """How many EGL devices (GPUs, or Mesa's software device) this process can see, through
    ``eglQueryDevicesEXT``; None when libEGL or the extension is missing."""
    import ctypes  # noqa: PLC0415

    lib = _egl()
    if lib is None:
        return None
    lib.eglGetProcAddress.restype = ctypes.c_void_p
    lib.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    address = lib.eglGetProcAddress(b"eglQueryDevicesEXT")
    if not address:
        return None
    query = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_int, ctypes.c_void_p,
                             ctypes.POINTER(ctypes.c_int))(address)
    count = ctypes.c_int(0)
    if not query(0, None, ctypes.byref(count)):
        return None
    return int(count.value)


def wrap_window_context():
    """The current window's context (the caller made it current, e.g. with glfw)."""
    import moderngl  # noqa: PLC0415

    try:
        return moderngl.create_context(require=REQUIRED_GL)
    except Exception as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise EnvironmentFailure(f"no usable OpenGL {REQUIRED_GL // 100}.{REQUIRED_GL // 10 % 10} "
                           f"context in the current window ({reason})") from None


def describe(ctx) -> dict:
    """Renderer name and GL version of a context (for reports and JSON output)."""
    return {"renderer": ctx.info.get("GL_RENDERER", "?"), "version": ctx.version_code}
