"""The one place a GL context is created.

- :func:`create_headless_context`: a standalone EGL context (no display; Mesa llvmpipe in CI,
  a GPU's EGL where there is one);
- :func:`wrap_window_context`: the context of a window the caller made current (glfw).

Both require OpenGL 4.3 (compute shaders, std430). Failures are one-line EnvironmentFailures (exit 3).
"""

from __future__ import annotations

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


def egl_device_count() -> int | None:
    """How many EGL devices (GPUs, or Mesa's software device) this process can see, through
    ``eglQueryDevicesEXT``; None when libEGL or the extension is missing."""
    import ctypes  # noqa: PLC0415
    import ctypes.util  # noqa: PLC0415

    try:
        lib = ctypes.CDLL(ctypes.util.find_library("EGL") or "libEGL.so.1")
    except OSError:
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
