"""Screenshots: the window as shown (PNG, sRGB 8-bit) and the scene's linear radiance (EXR).

Written with OpenImageIO through :func:`catalog.atomic.atomic_path`, so a crash never
leaves half an image; the fabric, light and mode go into the file's metadata.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from catalog.atomic import atomic_path
from catalog.errors import CatalogError


def write_image(path: str | Path, pixels: np.ndarray, metadata: dict[str, str] | None = None
                ) -> Path:
    """Write ``pixels`` (H, W, C), row 0 at the top: uint8 -> 8-bit, float -> half EXR."""
    import OpenImageIO as oiio  # noqa: PLC0415  (heavy-ish; only when saving)

    path = Path(path)
    pixels = np.ascontiguousarray(pixels)
    if pixels.ndim != 3 or pixels.shape[2] not in (3, 4):
        raise CatalogError(f"{path}: expected an (H, W, 3|4) image, got shape {pixels.shape}")
    if pixels.dtype == np.uint8:
        pixel_type = oiio.UINT8
    else:
        pixels = pixels.astype(np.float32)
        pixel_type = oiio.HALF if path.suffix.lower() == ".exr" else oiio.FLOAT
    height, width, channels = pixels.shape
    spec = oiio.ImageSpec(width, height, channels, pixel_type)
    for key, value in (metadata or {}).items():
        spec.attribute(key, str(value))
    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None:
            raise CatalogError(f"{path}: no image writer for this suffix ({oiio.geterror()})")
        if not out.open(str(tmp), spec):
            raise CatalogError(f"{path}: cannot write: {out.geterror()}")
        ok = out.write_image(pixels)
        out.close()
        if not ok:
            raise CatalogError(f"{path}: cannot write: {out.geterror()}")
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
