"""A computed result kept on disk under its content key: one ``.npz`` file holding the key
and the result's arrays, published atomically, read back only when its key is the one asked
for. The settled drapes (catalog.cloth.drape_cache) and the patterns' mip chains
(catalog.presets.mip_cache) are kept so; their folder is catalog.core.resources.cache_folder.

A file that cannot be read as the key's arrays (torn, edited, foreign) reads as absent, and a
folder that cannot be written costs the computation next time: neither fails a command."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np

#: What a damaged, edited or foreign file raises while it is read (or its arrays are used).
UNREADABLE = (OSError, ValueError, KeyError, EOFError, TypeError, zipfile.BadZipFile)


def read_keyed(path: Path | None, key: str) -> dict[str, np.ndarray] | None:
    """The arrays kept in ``path`` under ``key`` (the key itself left out), or None: no file,
    another key, or not readable."""
    if path is None or not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            if str(data["key"]) != key:
                return None
            return {name: np.array(data[name]) for name in data.files if name != "key"}
    except UNREADABLE:
        return None


def write_keyed(path: Path | None, key: str, arrays: dict) -> Path | None:
    """Publish ``arrays`` under ``key`` in ``path`` atomically; None (and nothing left) when it
    cannot (no cache folder, a read-only or full one)."""
    from catalog.core.atomic import write_bytes_atomic  # noqa: PLC0415
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    if path is None:
        return None
    buffer = io.BytesIO()
    np.savez(buffer, key=np.array(key), **arrays)
    try:
        write_bytes_atomic(path, buffer.getvalue())
    except (CatalogError, OSError):
        return None
    return path
