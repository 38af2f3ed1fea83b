"""A lace from a picture: a backlit scan (light = open) or the design artwork.

The coverage c (1 = thread) is read from the image's luminance: for a backlit scan the
transmitted light is the open fraction, so c = 1 - Y (Y linear, 0..1; sRGB-encoded 8- and
16-bit images are decoded first); with ``--threshold T`` the image is a drawing and each
pixel is open or thread by Y against T, ``--polarity`` saying which side is open. The thread
height is the coverage smoothed over about a yarn's width (a periodic Gaussian of
HEIGHT_BLUR_PX): threads are round, highest mid-yarn. The physical size comes from
``--repeat-m`` or the image's own resolution (PNG pHYs / TIFF dpi).

The image's header is read first: its size is bounded (:data:`MAX_SIDE_PX`) before any
pixel is decoded.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from catalog.core.errors import InputError

#: Larger images are refused before their pixels are read (the pattern texture's limit).
MAX_SIDE_PX = 8192
#: The height map's smoothing (px, Gaussian sigma): a yarn spans a few pixels of a scan.
HEIGHT_BLUR_PX = 1.5
#: A physical size of the repeat outside this (m) is refused: under 1 mm is not a cloth's
#: repeat, over 5 m not a curtain's.
REPEAT_RANGE_M = (1.0e-3, 5.0)
#: Resolutions (dots per inch) outside this are refused as absurd.
DPI_RANGE = (10.0, 20000.0)
POLARITIES = ("light-open", "dark-open")


def image_header(path: str | Path) -> tuple[int, int, int, float | None]:
    """(width, height, channels, dpi or None) from the header alone, refused when it is not
    an image or too large."""
    import OpenImageIO as oiio  # noqa: PLC0415

    path = Path(path)
    if not path.is_file():
        raise InputError("no such image", path=path)
    if path.stat().st_size == 0:
        raise InputError("the image file is empty (zero size)", path=path)
    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise InputError(f"not an image: {oiio.geterror().strip() or 'unknown format'}",
                         path=path)
    try:
        spec = image.spec()
        width, height, channels = spec.width, spec.height, spec.nchannels
        resolution = spec.get_float_attribute("XResolution", 0.0)
        unit = spec.get_string_attribute("ResolutionUnit", "")
    finally:
        image.close()
    if width <= 0 or height <= 0 or channels <= 0:
        raise InputError(f"the image has zero size ({width}x{height})", path=path)
    if max(width, height) > MAX_SIDE_PX:
        raise InputError(f"the image is {width}x{height}: at most {MAX_SIDE_PX} px a side",
                         path=path)
    dpi = None
    if resolution > 0 and unit in ("in", "inch"):
        dpi = resolution
    elif resolution > 0 and unit == "cm":
        dpi = resolution * 2.54
    return width, height, channels, dpi


def _linear_luminance(path: Path, pixels: np.ndarray) -> np.ndarray:
    """Y (Rec. 709 / sRGB primaries) in linear light, 0..1."""
    import OpenImageIO as oiio  # noqa: PLC0415

    image = oiio.ImageInput.open(str(path))
    try:
        spec = image.spec()
        colorspace = spec.get_string_attribute("oiio:ColorSpace", "")
        is_float = spec.format.basetype in (oiio.FLOAT, oiio.HALF, oiio.DOUBLE)
    finally:
        image.close()
    rgb = pixels[..., :3] if pixels.shape[2] >= 3 else pixels[..., :1]
    if not is_float and "linear" not in colorspace.lower():
        rgb = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    if rgb.shape[2] == 3:
        return (rgb @ np.array([0.2126, 0.7152, 0.0722])).astype(np.float64)
    return rgb[..., 0].astype(np.float64)


def periodic_blur(values: np.ndarray, sigma_px: float) -> np.ndarray:
    """Gaussian blur with wrap-around edges (the repeat tiles), by FFT."""
    h, w = values.shape
    fy = np.fft.fftfreq(h)[:, None]
    fx = np.fft.fftfreq(w)[None, :]
    kernel = np.exp(-2.0 * (math.pi * sigma_px) ** 2 * (fx ** 2 + fy ** 2))
    return np.real(np.fft.ifft2(np.fft.fft2(values) * kernel))


def height_from_coverage(coverage: np.ndarray, sigma_px: float = HEIGHT_BLUR_PX) -> np.ndarray:
    """Thread height 0..1: the coverage smoothed, scaled to its own maximum."""
    smooth = periodic_blur(coverage.astype(np.float64), sigma_px) * coverage
    top = float(smooth.max())
    return (smooth / top if top > 0 else smooth).clip(0.0, 1.0).astype(np.float32)


def check_repeat(repeat_m: tuple[float, float], path, field: str) -> None:
    low, high = REPEAT_RANGE_M
    if not all(math.isfinite(v) and low <= v <= high for v in repeat_m):
        raise InputError(f"the repeat {repeat_m[0]:.4g} x {repeat_m[1]:.4g} m is absurd "
                         f"(a repeat lies between {low * 1e3:g} mm and {high:g} m)",
                         path=path, field=field)


def check_dpi(dpi: float, path, field: str) -> None:
    if not (math.isfinite(dpi) and DPI_RANGE[0] <= dpi <= DPI_RANGE[1]):
        raise InputError(f"{dpi:g} dpi is absurd (a scan or texture has "
                         f"{DPI_RANGE[0]:g}-{DPI_RANGE[1]:g})", path=path, field=field)


def read_image_fabric(path: str | Path, repeat_m: float | None = None,
                      threshold: float | None = None, polarity: str = "light-open"):
    """An :class:`~catalog.exchange.imported_preset.ImportedFabric` from an image."""
    from catalog.exchange.imported_preset import ImportedFabric, check_open_area_range  # noqa: PLC0415
    from catalog.presets.patterns import check_tileable, read_image  # noqa: PLC0415

    path = Path(path)
    if polarity not in POLARITIES:
        raise InputError(f"{polarity!r}: choose one of {', '.join(POLARITIES)}", field="--polarity")
    if threshold is not None and not (math.isfinite(threshold) and 0.0 < threshold < 1.0):
        raise InputError(f"{threshold!r} must lie in (0, 1)", field="--threshold")
    width, height, _channels, dpi = image_header(path)
    if repeat_m is not None:
        repeat = (float(repeat_m), float(repeat_m) * height / width)
        check_repeat(repeat, path, "--repeat-m")
        size_from = "--repeat-m"
    elif dpi is not None:
        check_dpi(dpi, path, "resolution (dpi)")
        repeat = (width / dpi * 0.0254, height / dpi * 0.0254)
        check_repeat(repeat, path, "resolution (dpi)")
        size_from = f"the image's resolution, {dpi:g} dpi"
    else:
        raise InputError("the image states no resolution: give its width with --repeat-m",
                         path=path, field="--repeat-m")
    pixels = read_image(path)
    if pixels.shape[2] in (2, 4):          # an alpha channel is not the scan
        pixels = pixels[..., :pixels.shape[2] - 1]
    y = _linear_luminance(path, pixels)
    if not np.all(np.isfinite(y)):
        raise InputError("the image has NaN or infinite pixels", path=path)
    y = y.clip(0.0, 1.0)
    if threshold is None:
        open_fraction = y if polarity == "light-open" else 1.0 - y
        mode = f"backlit scan ({polarity}, linear luminance = open fraction)"
    else:
        open_fraction = (y > threshold) if polarity == "light-open" else (y < threshold)
        open_fraction = open_fraction.astype(np.float64)
        mode = f"artwork (threshold {threshold:g} on linear luminance, {polarity})"
    coverage = (1.0 - open_fraction).astype(np.float32)
    check_open_area_range(float(np.mean(open_fraction)), path, "open area")
    check_tileable(coverage, path, "the coverage")
    return ImportedFabric(
        coverage=coverage, height=height_from_coverage(coverage), repeat_m=repeat,
        source=path, kind="image",
        import_table={"mode": mode, "size_from": size_from,
                      "pixels": [int(width), int(height)],
                      "height_from": f"the coverage smoothed (Gaussian, {HEIGHT_BLUR_PX:g} px)"})
