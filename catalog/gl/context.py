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


def create_headless_context():
    """A standalone OpenGL 4.3 context through EGL, with no window or display."""
    import moderngl  # noqa: PLC0415

    try:
        return moderngl.create_standalone_context(backend="egl", require=REQUIRED_GL)
    except Exception as exc:  # moderngl/glcontext raise plain Exceptions here
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise EnvironmentFailure(f"no EGL device: cannot create a headless OpenGL {REQUIRED_GL // 100}."
                           f"{REQUIRED_GL // 10 % 10} context ({reason})") from None


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
