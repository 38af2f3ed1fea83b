"""The view behind the window as an HDR environment image (issue 13): ``--environment FILE.exr``.

The image is latitude-longitude (equirectangular): width = 2 x height, row 0 the zenith, the
last row the nadir, the middle column looking out of the window (-z), x to the right. Its
absolute scale is replaced so that its illuminance agrees with the chosen light: the upper
hemisphere's horizontal illuminance (the integral of Y cos(theta) d omega) is made equal to
the clear sky's of the same sun (catalog/optics/sun/sky.py, catalog.optics.sun.model.clear_sky) or, for a lamp, to
the lit backdrop's (scene.SKY_FRACTION of its illuminance). Read through OpenImageIO; a file
that cannot serve is refused with its name and the problem.

The default (no file) is the project's own procedural clear sky (catalog/optics/sun/sky.py), which
:func:`write_sky_environment` also writes as such an image (tools/make_environment.py).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from catalog.core.constants import LUMA_REC709
from catalog.core.errors import InputError

LUMA = np.array(LUMA_REC709)
#: The smallest image accepted (width x height).
MIN_SIZE = (8, 4)


def load_environment(path: str | Path) -> np.ndarray:
    """The image's linear RGB, float32 (H, W, 3), row 0 = the zenith; refused with the file
    and the problem when it cannot be read or cannot be an environment."""
    import OpenImageIO as oiio  # noqa: PLC0415

    path = Path(path)
    if not path.is_file():
        raise InputError("environment image not found", path=path, field="--environment")
    from catalog.core.atomic import register_input  # noqa: PLC0415
    from catalog.core.validate import check_image_header  # noqa: PLC0415

    register_input(path)
    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise InputError(f"cannot read the image: {oiio.geterror().strip() or 'unknown format'}",
                         path=path, field="--environment")
    try:
        spec = image.spec()
        check_image_header(path, spec.width, spec.height, spec.nchannels, "--environment")
        pixels = image.read_image(0, 0, 0, min(spec.nchannels, 3), oiio.FLOAT)
        error = image.geterror()
    finally:
        image.close()
    if pixels is None:
        raise InputError(f"cannot read the pixels: {error.strip()}", path=path, field="--environment")
    if spec.nchannels < 3:
        raise InputError(f"needs 3 colour channels (R, G, B), has {spec.nchannels}", path=path,
                         field="--environment")
    width, height = spec.width, spec.height
    if width != 2 * height or width < MIN_SIZE[0]:
        raise InputError(f"{width}x{height} is not a latitude-longitude image (width = 2 x "
                         f"height, at least {MIN_SIZE[0]}x{MIN_SIZE[1]})", path=path,
                         field="--environment")
    pixels = np.asarray(pixels, dtype=np.float32).reshape(height, width, 3)
    if not np.all(np.isfinite(pixels)):
        raise InputError("has pixels that are not finite (NaN or infinity)", path=path,
                         field="--environment")
    if np.any(pixels < 0.0):
        raise InputError("has negative radiance", path=path, field="--environment")
    if upper_illuminance(pixels) <= 0.0:
        raise InputError("its sky (the upper half) is black: nothing to scale to the light",
                         path=path, field="--environment")
    return pixels


def directions(height: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions (H, 2H, 3) of the pixel centres and their solid angles (H, 1)."""
    width = 2 * height
    theta = (np.arange(height) + 0.5) * math.pi / height          # from the zenith
    phi = ((np.arange(width) + 0.5) / width - 0.5) * 2 * math.pi  # 0 = out of the window (-z)
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    dirs = np.stack([np.sin(tt) * np.sin(pp), np.cos(tt), -np.sin(tt) * np.cos(pp)], axis=-1)
    solid = (np.sin(theta) * (math.pi / height) * (2 * math.pi / width))[:, None]
    return dirs, solid


def upper_illuminance(pixels: np.ndarray) -> float:
    """The horizontal illuminance (Y units x sr) of the image's upper hemisphere."""
    height = pixels.shape[0]
    dirs, solid = directions(height)
    weight = np.maximum(dirs[..., 1], 0.0) * solid
    return float(np.sum((pixels @ LUMA) * weight))


def write_sky_environment(path: str | Path, to_sun, height: int = 256) -> None:
    """Write the procedural clear sky (catalog/optics/sun/sky.py, the sun's disc left out) as a
    latitude-longitude EXR: the project's own default view, under the project's licence.
    ``to_sun``: the sun's direction (the atmosphere's clear sky) or a ready SkyModel."""
    from catalog.optics.sun.sky import SkyModel, sky_model  # noqa: PLC0415
    from catalog.render.imagefile import write_image  # noqa: PLC0415

    dirs, _ = directions(int(height))
    model = to_sun if isinstance(to_sun, SkyModel) else sky_model(np.asarray(to_sun, dtype=np.float64))
    pixels = model.radiance(dirs).astype(np.float32)
    write_image(Path(path), np.maximum(pixels, 0.0),
                {"catalog:environment": "procedural clear sky (Preetham 1999 scaled to "
                                        "catalog.optics.sun.model.clear_sky)"})
