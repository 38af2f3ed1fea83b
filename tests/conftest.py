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
