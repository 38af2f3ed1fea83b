"""Atomic writes: the target appears whole or not at all."""

from __future__ import annotations

import pytest

from catalog.core.atomic import atomic_path, write_text_atomic


def test_write_replaces_whole_file(tmp_path):
    target = tmp_path / "sub" / "preset.toml"
    write_text_atomic(target, "a = 1\n")
    write_text_atomic(target, "a = 2\n")
    assert target.read_text() == "a = 2\n"
    assert [p.name for p in target.parent.iterdir()] == ["preset.toml"]


def test_failure_leaves_no_file_and_keeps_the_old_one(tmp_path):
    target = tmp_path / "image.png"
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"half")
            raise RuntimeError("renderer failed")
    assert list(tmp_path.iterdir()) == []

    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            assert tmp.suffix == ".png"  # writers choose the format from the suffix
            tmp.write_text("new, half")
            raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["image.png"]


def test_written_file_is_readable_by_others(tmp_path):
    import os
    import stat

    target = tmp_path / "preset.toml"
    write_text_atomic(target, "x = 1\n")
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask
