"""A preset as a U3M 1.1 material: ``FILE.u3m`` and its textures in ``FILE/`` beside it.

The front side carries the pattern: ``alpha`` = the coverage (16-bit grey), ``normal`` =
the thread normals of the height map (16-bit RGB, 0..1 encoded, +y up), ``basecolor`` =
the dye's linear sRGB under D65 (colour-science), or a neutral 0.9 for an undyed yarn;
the image's ``width`` x ``height`` (mm) and ``dpi`` give the repeat. Every other map the
schema requires is written with its default constant and no texture. ``physics`` carries
the weight; ``physics.json`` (the fab file) our [cloth] keys under ``custom.catalog``, so
that ``catalog import`` reads back the same fabric. Written staged: all files, or none.
"""

from __future__ import annotations

import hashlib
import json
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

#: The base colour of an undyed yarn (linear sRGB): a white that is not a perfect mirror.
UNDYED_RGB = (0.9, 0.9, 0.9)
#: Defaults of the maps this export does not fill (U3M 1.1 schema's defaults).
SCALAR_DEFAULTS = {"anisotropy_value": 0.0, "anisotropy_rotation": 0.0, "clearcoat_value": 0.0,
                   "clearcoat_roughness": 0.0, "ior": 1.4, "metalness": 0.0, "displacement": 0.0,
                   "roughness": 0.7, "sheen_value": 0.0, "sheen_tint": 0.0, "specular_value": 0.5,
                   "specular_tint": 0.0, "subsurface_radius": 0.0, "subsurface_value": 0.0,
                   "transmission": 0.0}


def uuid4_of(text: str) -> str:
    """A UUID4-shaped (version 4, variant 1) id derived from ``text``: the same fabric
    exports the same id."""
    digest = bytearray(hashlib.sha256(text.encode("utf-8")).digest()[:16])
    digest[6] = (digest[6] & 0x0F) | 0x40
    digest[8] = (digest[8] & 0x3F) | 0x80
    h = digest.hex()
    return f"{h[:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:]}"


def _image(path: str, pixels_wh, repeat_m) -> dict:
    w, h = pixels_wh
    return {"width": round(repeat_m[0] * 1e3, 6), "height": round(repeat_m[1] * 1e3, 6),
            "dpi": {"x": round(w / (repeat_m[0] / 0.0254), 6), "y": round(h / (repeat_m[1] / 0.0254), 6)},
            "path": path, "repeat": {"rotation": 0.0, "mode": "normal"}}


def base_colour_of(preset) -> list[float]:
    """Linear sRGB of the preset's dye under D65, or the undyed white."""
    from catalog.exchange.u3m import rgb_of_spectrum  # noqa: PLC0415
    from catalog.optics.spectra import read_spectrum  # noqa: PLC0415

    rel = preset.table("dye").get("transmittance")
    if rel is None:
        return list(UNDYED_RGB)
    spectrum = read_spectrum(preset.resolve(rel))
    rgb = rgb_of_spectrum(spectrum.wavelength_nm, spectrum.values)
    return [round(float(v), 6) for v in np.clip(rgb, 0.0, 1.0)]


def _write_rgb16(path: Path, rgb: np.ndarray) -> None:
    import OpenImageIO as oiio  # noqa: PLC0415

    from catalog.core.atomic import atomic_path  # noqa: PLC0415
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    h, w, _ = rgb.shape
    spec = oiio.ImageSpec(w, h, 3, oiio.UINT16)
    data = np.round(np.clip(rgb, 0, 1) * 65535).astype(np.uint16)
    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(path))
        if out is None or not (out.open(str(tmp), spec) and out.write_image(data)):
            raise CatalogError(f"{path}: cannot write: {oiio.geterror()}")
        out.close()


def u3m_document(preset, stem: str, pattern) -> dict:
    h, w = pattern.coverage.shape
    front = {key: {"constant": value, "texture": None} for key, value in SCALAR_DEFAULTS.items()}
    front["alpha"] = {"constant": 1.0, "texture": {
        "factor": 1.0, "offset": 0.0, "image": _image(f"{stem}/alpha.png", (w, h), pattern.repeat_m)}}
    front["normal"] = {"constant": {"x": 0.0, "y": 0.0, "z": 1.0}, "texture": None}
    front["clearcoat_normal"] = {"constant": {"x": 0.0, "y": 0.0, "z": 1.0}, "texture": None}
    if pattern.height is not None:
        front["normal"]["texture"] = {"scale": 1.0, "image": _image(f"{stem}/normal.png", (w, h),
                                                                      pattern.repeat_m)}
    colour = base_colour_of(preset)
    front["basecolor"] = {"constant": dict(zip("rgb", colour)), "texture": None}
    front["subsurface_color"] = {"constant": {"r": 1.0, "g": 1.0, "b": 1.0}, "texture": None}
    front["shader"] = "principled"
    front["preview"] = None
    cloth = preset.table("cloth")
    density = cloth.get("areal_density_kg_m2")
    now = datetime.now(timezone.utc).replace(microsecond=0).isoformat().replace("+00:00", "Z")
    return {
        "schema": "1.1",
        "material": {
            "id": uuid4_of(preset.name), "name": preset.display_name,
            "description": f"exported by catalog from the fabric preset {preset.name!r}",
            "created": now, "modified": now,
            "front": front, "back": None, "side": None,
            "physics": {"thickness": None,
                        "weight": None if density is None else round(float(density) * 1e3, 6),
                        "composition": None, "devices": {"fab": f"{stem}/physics.json"},
                        "material_type": {"type": "Woven", "name": None}, "construction": None},
            "metadata": {"catalog_preset": preset.name},
        },
        "custom": {"catalog": {"preset": preset.name, "btdf": dict(preset.table("btdf"))}},
    }


def write_u3m(preset, out: str | Path) -> dict:
    """Write ``out`` (.u3m) and ``out``'s stem folder beside it; a JSON report."""
    from catalog.core.atomic import staged_folder, write_text_atomic  # noqa: PLC0415
    from catalog.core.errors import InputError  # noqa: PLC0415
    from catalog.presets.patterns import load_pattern, write_pattern_images  # noqa: PLC0415

    out = Path(out)
    pattern = load_pattern(preset)
    if pattern is None:
        raise InputError("the fabric has no [pattern]: a U3M needs its alpha texture",
                         path=preset.path, field="pattern")
    stem = out.stem
    doc = u3m_document(preset, stem, pattern)
    cloth = {k: v for k, v in preset.table("cloth").items()
             if k in ("areal_density_kg_m2", "stretch_stiffness_n_m", "bend_stiffness_n_m", "weave")}
    with staged_folder(out.parent, inputs=[preset.path]) as stage:
        write_pattern_images(pattern, stage / stem / "alpha.png", None)
        if pattern.height is not None:
            normals = pattern.normal_map()[..., :3].astype(np.float64)
            normals[..., 1] *= -1.0        # the map's y runs down the image; U3M's +y is up
            _write_rgb16(stage / stem / "normal.png", normals * 0.5 + 0.5)
        write_text_atomic(stage / stem / "physics.json",
                          json.dumps({"custom": {"catalog": cloth}}, indent=2) + "\n")
        write_text_atomic(stage / out.name, json.dumps(doc, indent=2) + "\n")
    return {"out": str(out), "format": "u3m 1.1", "fabric": preset.name,
            "textures": [f"{stem}/alpha.png"] + ([f"{stem}/normal.png"] if pattern.height is not None else []),
            "basecolor_linear_srgb": [doc["material"]["front"]["basecolor"]["constant"][k] for k in "rgb"],
            "repeat_m": list(pattern.repeat_m)}
