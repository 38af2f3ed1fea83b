"""Shared fixtures. The GL context is created in exactly one place (EGL, standalone)."""

from __future__ import annotations

from pathlib import Path

import pytest

from catalog import FABRIC_DIR, PROJECT_ROOT, SHARED_DATA_DIR

DATA = SHARED_DATA_DIR


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """../shared/data: real measurements by others (read in place, never copied)."""
    if not DATA.is_dir():
        pytest.fail(f"shared data folder missing: {DATA}")
    return DATA


@pytest.fixture(scope="session")
def project_root() -> Path:
    return PROJECT_ROOT


@pytest.fixture(scope="session")
def fabric_dir() -> Path:
    return FABRIC_DIR


# --- GL (the renderer's tests; the only place a test creates a context) -----------------

@pytest.fixture(scope="session")
def gl_context():
    """One headless OpenGL 4.3 context (EGL, Mesa llvmpipe in CI) shared by the GL tests."""
    from catalog.render.context import create_headless_context

    ctx = create_headless_context()
    yield ctx
    ctx.release()


@pytest.fixture
def gl(gl_context):
    """The shared context, checked for no pending GL error before and after each test."""
    assert gl_context.error == "GL_NO_ERROR", f"GL error pending before the test: {gl_context.error}"
    yield gl_context
    assert gl_context.error == "GL_NO_ERROR", f"GL error left by the test: {gl_context.error}"
