"""A command's inputs, known before its work: the preset it is given and every file the
preset names (spectra, dye, residual, pattern images), registered with the output layer
(:func:`catalog.core.atomic.register_input`) so that no output can replace one of them."""

from __future__ import annotations

import contextlib
import tomllib
from pathlib import Path

from catalog.core.atomic import register_input

#: The keys of a preset that name files: (table, key).
PRESET_FILE_KEYS = (("fluorescence", "excitation"), ("fluorescence", "emission"),
                    ("fluorescence", "residual"), ("dye", "transmittance"),
                    ("pattern", "coverage"), ("pattern", "height"))


def preset_files(path: str | Path) -> list[Path]:
    """The preset file and the files it names (resolved against its folder); what cannot be
    read or parsed is left for the preset's validator to refuse."""
    path = Path(path)
    found = [path]
    with contextlib.suppress(OSError, ValueError, RecursionError, tomllib.TOMLDecodeError,
                             UnicodeDecodeError):
        doc = tomllib.loads(path.read_bytes()[: 1 << 20].decode("utf-8"))
        for table, key in PRESET_FILE_KEYS:
            section = doc.get(table)
            value = section.get(key) if isinstance(section, dict) else None
            if isinstance(value, str) and value and "\x00" not in value:
                found.append(path.parent / value)
    return found


def register_preset_inputs(path: str | Path) -> None:
    """Register the preset file ``path`` and the files it names."""
    for file in preset_files(path):
        register_input(file)
