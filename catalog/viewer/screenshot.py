"""Screenshots: the window as shown (PNG, sRGB 8-bit) and the scene's linear radiance (EXR).

Written by the renderer's image writer (OpenImageIO, atomically: a crash never leaves half
an image); the fabric, light and mode go into the file's metadata.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from catalog.core.errors import CatalogError


def write_image(path: str | Path, pixels: np.ndarray, metadata: dict[str, str]) -> Path:
    """Write (H, W, 3) pixels, row 0 at the top: float32 -> 32-bit float EXR (the sun's disc
    is far above half-float range), uint8 -> 8-bit PNG. The renderer's writer does it."""
    from catalog.render.imagefile import write_image as write  # noqa: PLC0415

    path = Path(path)
    pixels = np.ascontiguousarray(pixels)
    if pixels.ndim != 3 or pixels.shape[2] != 3:
        raise CatalogError(f"{path}: expected an (H, W, 3) image, got shape {pixels.shape}")
    if pixels.dtype != np.uint8:
        pixels = pixels.astype(np.float32)
    write(path, pixels, metadata)
    return path


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9.-]+", "-", text).strip("-") or "x"


def next_screenshot_stem(folder: Path, fabric: str, light: str) -> Path:
    """``folder/view-NNNN-<fabric>-<light>``: NNNN one above the highest already there."""
    folder.mkdir(parents=True, exist_ok=True)
    numbers = [int(m.group(1)) for p in folder.glob("view-*")
               if (m := re.match(r"view-(\d{4})-", p.name))]
    number = max(numbers, default=0) + 1
    return folder / f"view-{number:04d}-{_slug(fabric)}-{_slug(light)}"
