"""Self-contained presets: every file a preset names is copied into the preset's own folder.

A preset ``DIR/N.toml`` written by the product (``catalog fit``, ``catalog import``,
``catalog bispectral --export``) keeps its files in ``DIR/N/`` and names them relative to
``DIR`` (``N/measurements/dye.csv``, ``N/patterns/coverage.png``): no path climbs out of the
folder (no ``../``, no absolute path), so moving or zipping ``DIR/N.toml`` with ``DIR/N/``
keeps the fabric working. (Files that already lie inside ``DIR``, like the built-in
catalog's shared ``measurements/<fabric>/``, are named where they lie: moving ``DIR``
keeps them.) :func:`bundle_files` is the one place that does this; the
callers build the document with paths to wherever their inputs lie and hand it here.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path, PurePosixPath
from typing import Any, Callable, Iterator

from catalog.core.errors import InputError

#: (table, key) -> the sub-folder of ``N/`` its file goes to. ``fluorescence.bands[i]``
#: entries carry ``excitation`` and ``emission`` too (see :func:`named_files`).
PATH_KEYS: dict[tuple[str, str], str] = {
    ("fit", "source"): "measurements",
    ("dye", "transmittance"): "measurements",
    ("fluorescence", "excitation"): "measurements",
    ("fluorescence", "emission"): "measurements",
    ("fluorescence", "residual"): "measurements",
    ("pattern", "coverage"): "patterns",
    ("pattern", "height"): "patterns",
    ("pattern", "border"): "patterns",
    ("pattern", "border_height"): "patterns",
    ("import", "source"): "source",      # what ``catalog import`` read (kept for provenance)
}
#: A file a preset names is copied whole; larger ones are refused (a preset's spectra and
#: patterns are kilobytes to a few megabytes).
MAX_FILE_BYTES = 256 << 20


def named_files(doc: dict[str, Any]) -> Iterator[tuple[str, dict, str, str]]:
    """(dotted key, the table holding it, its key in that table, sub-folder) for every
    file path the document names."""
    for (table_name, key), sub in PATH_KEYS.items():
        table = doc.get(table_name)
        if isinstance(table, dict) and isinstance(table.get(key), str):
            yield f"{table_name}.{key}", table, key, sub
    bands = doc.get("fluorescence", {}).get("bands") if isinstance(doc.get("fluorescence"), dict) else None
    if isinstance(bands, list):
        for i, band in enumerate(bands):
            for key in ("excitation", "emission"):
                if isinstance(band, dict) and isinstance(band.get(key), str):
                    yield f"fluorescence.bands[{i}].{key}", band, key, "measurements"


def is_contained(value: str) -> bool:
    """True when a path written in a preset stays inside the preset's folder: relative,
    without ``..``."""
    path = PurePosixPath(value.replace("\\", "/"))
    return not path.is_absolute() and ".." not in path.parts and not value.startswith("~")


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def bundle_files(doc: dict[str, Any], preset_path: str | Path,
                 resolve: Callable[[str, str], Path],
                 published_folder: str | Path | None = None) -> dict[str, Any]:
    """Copy every file ``doc`` names into ``preset_path``'s own folder and point ``doc`` at
    the copies; returns ``doc`` (changed in place). A file already inside the preset's
    folder ``DIR`` (the built-in catalog's ``measurements/`` and ``patterns/``) is named
    where it lies, relative and without ``..``; every other file is copied into ``DIR/N/``.

    ``resolve(dotted_key, value)`` gives the file a value names now (the caller knows what
    it is relative to). A file already inside ``DIR/N/`` stays where it is. Two different
    files with one name get ``-2``, ``-3`` ... before the suffix; the same file named twice
    is copied once. Copies are written atomically (:mod:`catalog.core.atomic`).
    ``published_folder``: where the preset will finally lie when ``preset_path`` is in a
    staging folder (:func:`catalog.core.atomic.staged_folder`); default its own folder.
    """
    from catalog.core.atomic import write_bytes_atomic  # noqa: PLC0415

    preset_path = Path(preset_path)
    folder = preset_path.parent
    name = preset_path.stem
    taken: dict[str, str] = {}     # relative destination -> digest of what lies there
    copied: dict[Path, str] = {}   # source -> relative destination
    for dotted, table, key, sub in list(named_files(doc)):
        # lexically normalised: a folder not made yet may stand before a '..'
        source = Path(os.path.normpath(os.path.abspath(resolve(dotted, table[key]))))
        if not source.is_file():
            raise InputError(f"no such file: {source}", path=preset_path, field=dotted)
        resolved = source.resolve()
        homes = [Path(os.path.abspath(f)) for f in (folder, published_folder) if f is not None]
        home = next((h for h in homes if source.is_relative_to(h)), None)
        if home is not None:
            # already inside the preset's folder (its own N/, or the catalog's shared
            # measurements/ and patterns/ beside it): named as it lies, never climbing out
            table[key] = source.relative_to(home).as_posix()
            continue
        if resolved in copied:
            table[key] = copied[resolved]
            continue
        size = resolved.stat().st_size
        if size > MAX_FILE_BYTES:
            raise InputError(f"{source} has {size} bytes, more than {MAX_FILE_BYTES} a preset "
                             "may carry", path=preset_path, field=dotted)
        digest = _digest(resolved)
        stem, suffix = resolved.stem, resolved.suffix
        candidate, n = f"{name}/{sub}/{resolved.name}", 1
        while candidate in taken and taken[candidate] != digest:
            n += 1
            candidate = f"{name}/{sub}/{stem}-{n}{suffix}"
        if candidate not in taken:
            write_bytes_atomic(folder / candidate, resolved.read_bytes(), inputs=[resolved])
            taken[candidate] = digest
        copied[resolved] = candidate
        table[key] = candidate
    return doc


def outside_paths(doc: dict[str, Any]) -> list[str]:
    """The dotted keys of paths in ``doc`` that leave the preset's folder (for checks)."""
    return [dotted for dotted, table, key, _ in named_files(doc) if not is_contained(table[key])]
