"""A fabric's own structure: the ``[pattern]`` table of a preset (model.md section 9).

A pattern is one repeat of the cloth: a thread-coverage map c in [0, 1] (1 = thread, 0 = a
hole the background shows through undimmed), an optional thread-height map, and the
physical size of the repeat in metres. It is read from images through OpenImageIO (PNG,
EXR, anything it reads): channel 0 is the coverage, an optional channel 1 the height (or a
separate ``height`` image). The table::

    [pattern]
    coverage = "patterns/lace-fwa.png"   # relative to the preset's folder
    height = "patterns/lace-fwa-height.png"  # optional: thread height, 0..1 of height_m
    repeat_m = [0.1, 0.1005]             # or one number: the width, the height by the pixel aspect
    height_m = 2.0e-4                    # optional: the height that a value of 1 means (m)
    border = "patterns/lace-fwa-border.png"  # optional: the band along the hem (a lace's scallops)
    border_height = "patterns/lace-fwa-border-height.png"   # optional: its thread height
    border_m = 0.05                      # with border: the band's depth up from the hem (m)

The border is a band as wide as the repeat (the coverage's width in pixels, the same u
repeat), its row 0 at the hem, ``border_m`` deep; it replaces the all-over pattern below
``border_m`` from the hem (where the cloth is cut away, below a scallop, its coverage is 0),
so it tiles along u only. The open area of the fit is the all-over's (the band is a strip of
the curtain, not of the cloth the fit measured).

The pattern and the fit agree: the mean open area 1 - mean(c) equals the fitted
``btdf.direct`` (LD) within :data:`OPEN_AREA_TOLERANCE` (relative), checked when a preset
is written and when a pattern is loaded for rendering. The renderer divides the fitted lobes
by mean(c) at thread points, so that averaged over a repeat (or far away, where the mip
chain averages c) the patterned cloth is the fitted cloth.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.errors import InputError

#: |1 - mean(c) - LD| <= OPEN_AREA_TOLERANCE * LD + OPEN_AREA_FLOOR (issue 12: "within 1 %").
OPEN_AREA_TOLERANCE = 0.01
#: Absolute floor of the agreement, for LD = 0 (a 16-bit coverage resolves 1.5e-5).
OPEN_AREA_FLOOR = 1.0e-4
#: Default physical height of a height-map value of 1 (m): a fine yarn's diameter.
DEFAULT_HEIGHT_M = 1.5e-4
#: A repeat is tileable when the seam across its wrapped edges is no stronger than the
#: strongest edge inside it plus TILE_FLOOR (mean absolute jump along the seam).
TILE_FLOOR = 0.02
#: Pattern images larger than this per side are refused (GL texture limits, memory).
MAX_SIDE_PX = 8192


@dataclass(frozen=True)
class HemBorder:
    """The band along the hem: coverage and height (rows, W) float32 in [0, 1], row 0 at the
    hem, ``depth_m`` deep (the pattern's u repeat across)."""

    coverage: np.ndarray
    height: np.ndarray | None
    depth_m: float


#: Rows of a pattern made at a time in float64 (Pattern.slopes, normal_map).
_ROW_BLOCK = 128


@dataclass(frozen=True)
class Pattern:
    """One repeat: coverage (H, W) float32 in [0, 1], row 0 = the top of the image (v = 0
    at the image's bottom row is *not* assumed: texture v runs with image rows, as the
    renderer uploads :meth:`normal_map` row by row); height (H, W) float32 in [0, 1] or None; repeat (u, v) in metres."""

    coverage: np.ndarray
    height: np.ndarray | None
    repeat_m: tuple[float, float]
    height_m: float
    source: str
    border: HemBorder | None = None

    @property
    def mean_coverage(self) -> float:
        return float(np.mean(self.coverage, dtype=np.float64))

    @property
    def open_area(self) -> float:
        """1 - mean(c): the see-through fraction the fit calls LD."""
        return 1.0 - self.mean_coverage

    def slopes(self) -> np.ndarray:
        """(H, W, 2) float32: the height's gradient dh/du, dh/dv in metres per metre along
        the image's x and y (y down the image), periodic central differences. Zero when the
        pattern has no height."""
        h, w = self.coverage.shape
        out = np.zeros((h, w, 2), dtype=np.float32)
        if self.height is None:
            return out
        z = self.height.astype(np.float64) * self.height_m
        px_u = self.repeat_m[0] / w
        px_v = self.repeat_m[1] / h
        for r0 in range(0, h, _ROW_BLOCK):   # a block of rows at a time: float64 temporaries
            rows = np.arange(r0, min(h, r0 + _ROW_BLOCK))   # of a block, not of the image
            zb = z[rows]
            out[rows, :, 0] = (np.roll(zb, -1, axis=1) - np.roll(zb, 1, axis=1)) / (2 * px_u)
            out[rows, :, 1] = (z[(rows + 1) % h] - z[(rows - 1) % h]) / (2 * px_v)
        return out

    def normal_map(self) -> np.ndarray:
        """(H, W, 4) float32 RGBA: the thread's unit normal in the cloth's tangent frame
        (x along u = weft, y along v, z = the cloth normal), alpha = the coverage. A mip chain
        of it averages the normals before they are renormalised (the first moment of LEAN
        mapping, Olano & Baker 2010): far away the slopes cancel and the geometric normal
        remains, so highlights do not sparkle. Made in float64 a block of rows at a time."""
        s32 = self.slopes()
        h, w = s32.shape[:2]
        out = np.empty((h, w, 4), dtype=np.float32)
        for r0 in range(0, h, _ROW_BLOCK):
            s = s32[r0:r0 + _ROW_BLOCK].astype(np.float64)
            n = np.concatenate([-s, np.ones(s.shape[:2] + (1,))], axis=-1)
            n /= np.linalg.norm(n, axis=-1, keepdims=True)
            out[r0:r0 + _ROW_BLOCK, :, :3] = n
        out[..., 3] = self.coverage
        return out

    def border_normal_map(self) -> np.ndarray | None:
        """The hem band's RGBA as :meth:`normal_map` (None without a border). The band does
        not repeat along v: its slopes are taken on the band mirrored about its top row
        (what a clamped edge continues as), so no slope wraps from the hem to the top."""
        b = self.border
        if b is None:
            return None
        rows = b.coverage.shape[0]
        mirrored = Pattern(np.concatenate([b.coverage, b.coverage[::-1]]),
                           None if b.height is None else np.concatenate([b.height, b.height[::-1]]),
                           (self.repeat_m[0], 2.0 * b.depth_m), self.height_m, self.source)
        return mirrored.normal_map()[:rows]


def check_open_area(open_area: float, direct: float, *, path=None, field="pattern.coverage") -> None:
    """Refuse a pattern whose mean open area differs from the fit's LD by more than 1 %."""
    if abs(open_area - direct) > OPEN_AREA_TOLERANCE * direct + OPEN_AREA_FLOOR:
        raise InputError(f"mean open area {open_area:.5f} differs from btdf.direct {direct:.5f} "
                         f"by more than {OPEN_AREA_TOLERANCE:.0%}", path=path, field=field)


def read_image(path: str | Path) -> np.ndarray:
    """(H, W, C) float32 pixels of an image through OpenImageIO (PNG, EXR, ...), integer
    formats scaled to 0..1. Refused with the file and the problem when unreadable or empty."""
    import OpenImageIO as oiio  # noqa: PLC0415

    path = Path(path)
    if not path.is_file():
        raise InputError("no such pattern image", path=path)
    if path.stat().st_size == 0:
        raise InputError("the image file is empty (zero size)", path=path)
    from catalog.core.atomic import register_input  # noqa: PLC0415
    from catalog.core.validate import check_image_header  # noqa: PLC0415

    register_input(path)
    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise InputError(f"cannot read the image: {oiio.geterror().strip() or 'unknown format'}",
                         path=path)
    try:
        spec = image.spec()
        if spec.width <= 0 or spec.height <= 0 or spec.nchannels <= 0:
            raise InputError(f"the image has zero size ({spec.width}x{spec.height}, "
                             f"{spec.nchannels} channels)", path=path)
        check_image_header(path, spec.width, spec.height, spec.nchannels)  # before the pixels
        pixels = image.read_image(format=oiio.FLOAT)
        if pixels is None:
            raise InputError(f"cannot read the pixels: {image.geterror().strip()}", path=path)
    finally:
        image.close()
    pixels = np.asarray(pixels, dtype=np.float32)
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    if pixels.size == 0:
        raise InputError("the image has zero size", path=path)
    return pixels


def _check_values(values: np.ndarray, path, what: str) -> None:
    bad = ~np.isfinite(values)
    if bad.any():
        y, x = np.argwhere(bad)[0]
        raise InputError(f"{what} has {int(bad.sum())} NaN or infinite pixels (first at "
                         f"x={x}, y={y})", path=path)
    if values.min() < -1e-6 or values.max() > 1.0 + 1e-6:
        raise InputError(f"{what} must lie in [0, 1], found {values.min():.4g}..{values.max():.4g}",
                         path=path)


def check_tileable(values: np.ndarray, path, what: str = "coverage", axes=(1, 0)) -> None:
    """Refuse a repeat whose opposite edges do not meet: the seam where the repeat wraps
    (last column to first, last row to first) may be no stronger than the strongest edge
    inside it (the mean absolute jump along a column or row), plus TILE_FLOOR. A ramp, a
    vignette or a crop through the motif makes the seam the strongest jump of all."""
    v = values.astype(np.float64)
    for axis, edges in ((1, "left and right"), (0, "top and bottom")):
        if v.shape[axis] < 2 or axis not in axes:
            continue
        jumps = np.abs(np.diff(v, axis=axis)).mean(axis=1 - axis)   # per interior seam
        first = np.take(v, 0, axis=axis)
        last = np.take(v, -1, axis=axis)
        seam = float(np.mean(np.abs(first - last)))
        strongest = float(jumps.max())
        if seam > strongest + TILE_FLOOR:
            raise InputError(f"{what} is not tileable by its repeat: the {edges} edges differ by "
                             f"{seam:.3f} on average, more than any edge inside "
                             f"({strongest:.3f})", path=path)


def _repeat(value, shape, where) -> tuple[float, float]:
    h, w = shape
    if isinstance(value, bool):
        value = None
    if isinstance(value, (int, float)):
        pair = (float(value), float(value) * h / w)
    elif isinstance(value, list) and len(value) == 2 and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        pair = (float(value[0]), float(value[1]))
    else:
        raise InputError(f"must be a length in metres or two of them [u, v], found {value!r}",
                         path=where, field="pattern.repeat_m")
    if not all(math.isfinite(v) and 0.0 < v <= 10.0 for v in pair):
        raise InputError(f"{list(pair)} must be positive lengths up to 10 m", path=where,
                         field="pattern.repeat_m")
    return pair


def pattern_from_images(coverage_path, repeat_m, height_path=None, height_m=DEFAULT_HEIGHT_M,
                        where=None) -> Pattern:
    """Read a user's pattern: grey coverage (1 channel, or 2 with the height in channel 1;
    RGB or RGBA is refused: convert it to grey so that it is clear which value is thread),
    optional height image (1 channel), the repeat in metres (one number = the image's width,
    or [u, v])."""
    coverage_path = Path(coverage_path)
    pixels = read_image(coverage_path)
    if pixels.shape[2] not in (1, 2):
        raise InputError(f"a coverage image has 1 channel (grey) or 2 (grey, height), found "
                         f"{pixels.shape[2]}: save it as grey", path=coverage_path)
    h, w = pixels.shape[:2]
    if max(h, w) > MAX_SIDE_PX:
        raise InputError(f"the image is {w}x{h}: at most {MAX_SIDE_PX} px a side", path=coverage_path)
    coverage = pixels[..., 0]
    _check_values(coverage, coverage_path, "the coverage")
    check_tileable(coverage, coverage_path, "the coverage")
    height = pixels[..., 1] if pixels.shape[2] == 2 else None
    source = coverage_path
    if height_path is not None:
        height_path = Path(height_path)
        hp = read_image(height_path)
        if hp.shape[2] != 1:
            raise InputError(f"a height image has 1 channel, found {hp.shape[2]}", path=height_path)
        if hp.shape[:2] != (h, w):
            raise InputError(f"the height image is {hp.shape[1]}x{hp.shape[0]}, the coverage "
                             f"{w}x{h}: they must match", path=height_path)
        height = hp[..., 0]
        source = height_path
    if height is not None:
        _check_values(height, source, "the height")
        check_tileable(height, source, "the height")
    if not (isinstance(height_m, (int, float)) and math.isfinite(height_m) and 0 <= height_m < 0.01):
        raise InputError(f"{height_m!r} must be a height in metres in [0, 0.01)", path=where,
                         field="pattern.height_m")
    return Pattern(coverage=np.clip(coverage, 0.0, 1.0).astype(np.float32),
                   height=None if height is None else np.clip(height, 0.0, 1.0).astype(np.float32),
                   repeat_m=_repeat(repeat_m, (h, w), where or coverage_path),
                   height_m=float(height_m), source=str(coverage_path))


def load_pattern(preset, check_fit: bool = True) -> Pattern | None:
    """The preset's ``[pattern]`` (None without one), its open area checked against the
    fit's LD (``check_fit``)."""
    table = preset.table("pattern")
    if not table:
        return None
    where = preset.path
    rel = table.get("coverage")
    if not isinstance(rel, str) or not rel:
        raise InputError("missing required key (the coverage image's path)", path=where,
                         field="pattern.coverage")
    if "repeat_m" not in table:
        raise InputError("missing required key (the repeat in metres)", path=where,
                         field="pattern.repeat_m")
    height_rel = table.get("height")
    if height_rel is not None and not (isinstance(height_rel, str) and height_rel):
        raise InputError("must be a path string", path=where, field="pattern.height")
    pattern = pattern_from_images(preset.resolve(rel), table["repeat_m"],
                                  None if height_rel is None else preset.resolve(height_rel),
                                  table.get("height_m", DEFAULT_HEIGHT_M), where=where)
    if check_fit:
        check_open_area(pattern.open_area, preset.btdf.direct, path=where)
    if table.get("border") is not None:
        pattern = dataclasses.replace(pattern, border=_load_border(preset, table, pattern))
    return pattern


def _load_border(preset, table: dict, pattern: Pattern) -> HemBorder:
    """The [pattern] border band: grey images as wide as the coverage, border_m deep."""
    where = preset.path
    if "border_m" not in table:
        raise InputError("missing required key (the border's depth from the hem in metres)",
                         path=where, field="pattern.border_m")
    depth = table["border_m"]
    if isinstance(depth, bool) or not isinstance(depth, (int, float)) or not math.isfinite(depth) \
            or not 1e-4 <= depth <= 1.0:
        raise InputError(f"must be a depth in metres in [0.0001, 1], found {depth!r}",
                         path=where, field="pattern.border_m")
    width = pattern.coverage.shape[1]
    images = []
    for key in ("border", "border_height"):
        rel = table.get(key)
        if rel is None:
            images.append(None)
            continue
        path = preset.resolve(rel)
        pixels = read_image(path)
        if pixels.shape[2] != 1:
            raise InputError(f"a border image has 1 channel (grey), found {pixels.shape[2]}",
                             path=path)
        if pixels.shape[1] != width or (images and images[0] is not None
                                        and pixels.shape[:2] != images[0].shape):
            raise InputError(f"the border image is {pixels.shape[1]}x{pixels.shape[0]}: it must be "
                             f"as wide as the coverage ({width} px), the height image as the border",
                             path=path)
        _check_values(pixels[..., 0], path, "the border")
        check_tileable(pixels[..., 0], path, "the border", axes=(1,))
        images.append(np.clip(pixels[..., 0], 0.0, 1.0).astype(np.float32))
    return HemBorder(images[0], images[1], float(depth))


def match_open_area(coverage: np.ndarray, direct: float, where=None) -> np.ndarray:
    """``coverage`` remapped as c^gamma (holes stay holes, full thread stays thread, the order
    of every pair of pixels kept) with gamma found by bisection so that 1 - mean = ``direct``
    (the fit's LD) to 1e-6: how ``catalog fit --pattern`` makes a user's image agree with
    the fit. Refused when no gamma can: the image's holes (c = 0) alone are more open than LD,
    or its full-thread pixels (c = 1) alone cover more than 1 - LD."""
    c = np.clip(np.asarray(coverage, dtype=np.float64), 0.0, 1.0)
    holes, threads = float(np.mean(c == 0.0)), float(np.mean(c == 1.0))
    if not holes <= direct <= 1.0 - threads or np.all((c == 0.0) | (c == 1.0)) and \
            abs(1.0 - c.mean() - direct) > OPEN_AREA_TOLERANCE * direct + OPEN_AREA_FLOOR:
        raise InputError(f"the image's holes cover {holes:.3f} and its full threads "
                         f"{threads:.3f} of it: no remap gives the fit's open area "
                         f"(btdf.direct {direct:.4f})", path=where, field="--pattern")
    lo, hi = -12.0, 12.0                    # log2 gamma
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if 1.0 - np.mean(c ** (2.0 ** mid)) < direct:
            lo = mid
        else:
            hi = mid
    return (c ** (2.0 ** (0.5 * (lo + hi)))).astype(np.float32)


def write_pattern_images(pattern: Pattern, coverage_path: Path, height_path: Path | None) -> None:
    """16-bit grey PNGs (or EXR by suffix) of a pattern, written atomically."""
    _write_grey(coverage_path, pattern.coverage)
    if height_path is not None and pattern.height is not None:
        _write_grey(height_path, pattern.height)


def _write_grey(path: Path, values: np.ndarray) -> None:
    import OpenImageIO as oiio  # noqa: PLC0415

    from catalog.core.atomic import atomic_path  # noqa: PLC0415

    path = Path(path)
    h, w = values.shape
    exr = path.suffix.lower() == ".exr"
    spec = oiio.ImageSpec(w, h, 1, oiio.FLOAT if exr else oiio.UINT16)
    spec.channelnames = ("Y",)
    if not exr:
        spec.attribute("png:compressionLevel", 9)
    data = (np.ascontiguousarray(values, dtype=np.float32) if exr
            else np.round(np.clip(values, 0, 1) * 65535.0).astype(np.uint16))
    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(path))
        if out is None:
            raise InputError(f"cannot write: {oiio.geterror()}", path=path)
        ok = out.open(str(tmp), spec) and out.write_image(data[..., None])
        error = out.geterror()
        out.close()
        if not ok:
            raise InputError(f"cannot write: {error}", path=path)


def quantise16(values: np.ndarray) -> np.ndarray:
    """What a 16-bit PNG stores and reads back."""
    return (np.round(np.clip(values, 0, 1) * 65535.0) / 65535.0).astype(np.float32)


#: The mip chain's prefilter (:func:`mip_chain`): a Gaussian of this standard deviation in
#: texels of the level being made. Its response at that level's Nyquist frequency is
#: exp(-2 pi^2 s^2 / 4) = 0.089 for s = 0.7 (a 2x2 box's chain passes 0.64 of a frequency
#: just below Nyquist and folds what lies above it: a 1 mm net on ~1 mm texels became stripes).
MIP_SIGMA_TEXELS = 0.7


def _fourier_downsample(image: np.ndarray, size: tuple[int, int], sigma: float) -> np.ndarray:
    """``image`` (h, w) float64, periodic, low-passed by a Gaussian of ``sigma`` of its texels
    and resampled to ``size`` (lh, lw) by keeping the frequencies the smaller image can hold
    (|ky| < lh / 2, |kx| < lw / 2: a set symmetric about 0, so the result is real). One
    channel by a real FFT (the half spectrum, kx >= 0): a sixteenth of the bytes of the
    complex FFT of four channels at once (100 MB for the lace's pattern)."""
    h, w = image.shape
    lh, lw = size
    spectrum = np.fft.rfft2(image)                      # (h, w // 2 + 1), kx = 0 .. w // 2
    ky_all = np.round(np.fft.fftfreq(h) * h).astype(int)
    kx_all = np.arange(w // 2 + 1)
    keep_y, keep_x = np.abs(ky_all) < lh / 2.0, kx_all < lw / 2.0
    fy = (ky_all[keep_y] / h)[:, None]
    fx = (kx_all[keep_x] / w)[None, :]
    gain = np.exp(-2.0 * math.pi ** 2 * sigma ** 2 * (fx ** 2 + fy ** 2))
    small = np.zeros((lh, lw // 2 + 1), dtype=complex)
    small[np.ix_(ky_all[keep_y] % lh, kx_all[keep_x])] = spectrum[np.ix_(keep_y, keep_x)] * gain
    return np.fft.irfft2(small, s=(lh, lw)) * (lh * lw) / (h * w)


def mip_chain(texels: np.ndarray, levels: int | None = None) -> list[np.ndarray]:
    """The mip levels of a periodic (tileable) image (H, W, C), level 0 first, each level's
    size GL's (floor of half the last, at least 1). Level k is level 0 low-passed by a
    periodic Gaussian of MIP_SIGMA_TEXELS of its own texel (2^k level-0 texels), made from
    level k-1 by the Gaussian that adds the missing variance (sigma 1.4 texels for level 1,
    sqrt(1.4^2 - 0.7^2) = 1.21 of level k-1's texels after), resampled by Fourier cropping:
    exact for a repeat, so the mean (the far limit) is kept. Values are clipped to level 0's
    range (the cropped Gaussian rings a little) and the mean the clipping moved is put back.
    Every step is per channel: the chain is made a channel at a time in float64 (one
    channel's float64 copy, not the image's)."""
    texels = np.asarray(texels)
    h, w, channels = texels.shape
    top = int(math.floor(math.log2(max(h, w)))) if levels is None else int(levels)
    sizes = [(max(1, h >> level), max(1, w >> level)) for level in range(1, top + 1)]
    chain = [np.ascontiguousarray(texels, dtype=np.float32)]
    chain += [np.empty(size + (channels,), dtype=np.float32) for size in sizes]
    s = MIP_SIGMA_TEXELS
    for c in range(channels):
        current = texels[..., c].astype(np.float64)
        low, high, mean = current.min(), current.max(), current.mean()
        for level, size in enumerate(sizes, start=1):
            sigma = 2 * s if level == 1 else math.sqrt((2 * s) ** 2 - s ** 2)
            current = _fourier_downsample(current, size, sigma)
            for _ in range(4):   # clip the ringing, then put back the mean the clipping moved
                current = np.clip(current + (mean - current.mean()), low, high)
            chain[level][..., c] = current
    return chain
