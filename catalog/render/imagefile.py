"""Image files: (H, W, 3) pixels to EXR (linear, float32) or PNG (display, uint8) through
OpenImageIO and the output layer, and the metadata read back. Used by every renderer that
writes a picture (snapshot, sheet, the viewer's screenshot, the environment tool)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from catalog.core.errors import CatalogError


def write_image(path: Path, pixels: np.ndarray, metadata: dict[str, str], *,
                inputs=()) -> None:
    """Write (H, W, 3) pixels with OpenImageIO through the output layer: float32 -> EXR,
    uint8 -> PNG. The file is read back (size and pixels) before it replaces ``path``, so a
    full disk can never leave an empty or truncated image in place of a good one."""
    import OpenImageIO as oiio  # noqa: PLC0415

    from catalog.core.atomic import OutputError, atomic_path  # noqa: PLC0415

    height, width, channels = pixels.shape
    kind = oiio.FLOAT if pixels.dtype == np.float32 else oiio.UINT8
    spec = oiio.ImageSpec(width, height, channels, kind)
    spec.channelnames = ("R", "G", "B")
    for key, value in metadata.items():
        if key == "chromaticities":
            spec.attribute(key, oiio.TypeDesc("float[8]"), tuple(value))
        else:
            spec.attribute(key, str(value))

    def verify(tmp: Path) -> None:
        back = oiio.ImageInput.open(str(tmp))
        if back is None:
            raise OutputError(path, f"the written image does not read back ({oiio.geterror()})")
        try:
            read_spec = back.spec()
            data = back.read_image(0, 0, 0, channels, "float" if kind == oiio.FLOAT else "uint8")
        finally:
            back.close()
        if (read_spec.width, read_spec.height, read_spec.nchannels) != (width, height, channels) \
                or data is None or not np.array_equal(np.asarray(data).reshape(pixels.shape), pixels,
                                                    equal_nan=True):
            raise OutputError(path, "the written image does not read back as written "
                                    "(the disk may be full); the old file is kept")

    raw_bytes = pixels.nbytes
    with atomic_path(path, inputs=inputs, estimate_bytes=raw_bytes, verify=verify) as tmp:
        output = oiio.ImageOutput.create(str(tmp))
        if output is None:
            raise CatalogError(f"cannot write {path}: {oiio.geterror()}")
        ok = output.open(str(tmp), spec) and output.write_image(np.ascontiguousarray(pixels))
        error = output.geterror()
        output.close()
        if not ok:
            raise OutputError(path, error or "the image writer failed")


def exr_colour_metadata() -> dict:
    """What tools need to show our EXR with a standard view (OpenColorIO's built-in config
    ``ocio://default``: the interop ID of its colour space "Linear Rec.709 (sRGB)"; the EXR chromaticities of
    sRGB / Rec.709 with the D65 white, from colour-science's tables)."""
    from catalog.render import display  # noqa: PLC0415

    t = display.tables()
    m = np.linalg.inv(t["srgb_xyz_to_rgb"])  # RGB -> XYZ: the columns are the primaries
    xy = [(col[0] / col.sum(), col[1] / col.sum()) for col in m.T]
    white = tuple(float(v) for v in t["srgb_whitepoint_xy"])
    return {"oiio:ColorSpace": OCIO_LINEAR_SPACE,
            "chromaticities": tuple(float(v) for pair in xy for v in pair) + white}


#: The name of our EXR's colour space in OpenColorIO's built-in config (ocio://default).
OCIO_LINEAR_SPACE = "lin_rec709_scene"   # the interop ID; "Linear Rec.709 (sRGB)" there


def read_metadata(path: str | Path) -> dict[str, str]:
    """The string attributes of an image (to check what a snapshot recorded)."""
    import OpenImageIO as oiio  # noqa: PLC0415

    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise CatalogError(f"cannot read {path}: {oiio.geterror()}")
    spec = image.spec()
    image.close()
    return {attr.name: str(attr.value) for attr in spec.extra_attribs}


