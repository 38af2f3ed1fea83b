"""A command run without ``ctx=`` in the caller's process leaves the caller's context current.

Making an EGL context makes it current, and releasing it does not undo that: before
catalog.gl.context.headless_context, ``main(["snapshot", ...])`` or ``render_sheet`` without
``ctx=`` left their own context current, and a buffer made earlier in the caller's context then
gave GL_INVALID_OPERATION when written (the tests' shared context, under pytest-xdist). The
reference is EGL's own answer (eglGetCurrentContext) and a round trip through the buffer.
"""

from __future__ import annotations

import numpy as np
import pytest

from catalog.gl.context import _current_egl, _egl, create_headless_context, headless_context

pytestmark = pytest.mark.gl

EGL = _egl()


def _snapshot(tmp_path):
    from catalog.commands.cli import main

    assert main(["snapshot", "--fabric", "voile-white", "--light", "D65", "--size", "16x12",
                 "--out", str(tmp_path / "s.png")]) == 0


def _sheet(tmp_path):
    from catalog.render.sheet import render_sheet

    render_sheet(["D65"], tmp_path / "sheet", (16, 12), fabrics=["voile-white"], progress=False)


def _own_block(tmp_path):
    with headless_context() as own:
        own.buffer(reserve=64).write(np.ones(16, np.float32).tobytes())


def _failing_block(tmp_path):
    with pytest.raises(RuntimeError), headless_context():
        raise RuntimeError("a command failing inside its own context")


def _assert_caller_current(ctx, command, tmp_path):
    ctx.__enter__()                       # the caller's context A, current
    before = _current_egl(EGL)
    assert before[3], "no EGL context current after making A current"
    buffer = ctx.buffer(reserve=64)       # an object of A, made before the command
    command(tmp_path)
    assert _current_egl(EGL) == before, "the command left another EGL context current"
    values = np.arange(16, dtype=np.float32)
    buffer.write(values.tobytes())
    assert ctx.error == "GL_NO_ERROR"     # GL_INVALID_OPERATION when another context was current
    assert np.array_equal(np.frombuffer(buffer.read(), np.float32), values)
    buffer.release()


@pytest.mark.parametrize("command", [_own_block, _failing_block])
def test_a_context_of_its_own_leaves_the_callers_current(gl, command, tmp_path):
    _assert_caller_current(gl, command, tmp_path)


@pytest.mark.slow   # a context, its shaders and the settled drape (1 to 11 s, cache cold)
@pytest.mark.parametrize("command", [_snapshot, _sheet])
def test_a_command_without_ctx_leaves_the_callers_context_current(gl, command, tmp_path):
    _assert_caller_current(gl, command, tmp_path)


def test_no_context_current_before_means_none_after():
    """A caller with no current context has none after (the command's own is unbound and so
    destroyed, not left current)."""
    ctx = create_headless_context()
    display = _current_egl(EGL)[0]
    ctx.release()
    EGL.eglMakeCurrent(display, None, None, None)
    assert _current_egl(EGL) == (None, None, None, None)
    with headless_context() as own:
        assert _current_egl(EGL)[3]
        assert own.error == "GL_NO_ERROR"
    assert _current_egl(EGL) == (None, None, None, None)


def test_a_given_context_is_used_and_kept(gl):
    with headless_context(gl) as same:
        assert same is gl
    assert gl.error == "GL_NO_ERROR"    # not released: it still answers


def _benchmark_run(tmp_path):
    from benchmarks import alpha_to_coverage

    alpha_to_coverage.run()   # a benchmark's function without ctx (its own, as the others)


@pytest.mark.slow   # the benchmark's renders
def test_a_benchmark_without_ctx_leaves_the_callers_context_current(gl, tmp_path):
    _assert_caller_current(gl, _benchmark_run, tmp_path)
