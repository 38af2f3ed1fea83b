"""U3M (Unified 3D Material, Vizoo / Browzwear): read 1.0 and 1.1, write 1.1.

A ``.u3m`` is a JSON file whose texture paths are relative to its folder; a ``.u3ma`` is
the same zipped (the ``.u3m`` at the archive's top, textures inside). The document is
checked against the required fields of the published schemas (u3m1.0 and u3m1.1
``u3m_schema.json``, checks written here): a missing or ill-typed field is refused naming
the file and its JSON path (``material.front.alpha.texture.image.dpi``).

What a preset takes from it (the front side; the back or the side when the front is null):

- ``alpha`` (texture x factor + offset, else the constant): the coverage c; its mean open
  area becomes ``btdf.direct``;
- ``basecolor`` (the thread's colour: the texture's mean over the threads, sRGB-decoded,
  times the factor, else the constant; U3M's colours are linear sRGB): the dye, upsampled to
  a spectrum by Mallett & Yuksel 2019 (``colour.recovery.RGB_to_sd_Mallett2019``: a
  reflectance in [0, 1] whose sRGB colour under D65 is the RGB within 1e-4);
- ``normal`` (tangent-space, 0..1 encoded, OpenGL +y up, ``scale`` on x and y): the
  thread height, integrated from its slopes (Frankot-Chellappa, periodic);
- the texture's physical size ``width`` x ``height`` (mm), or its pixels over ``dpi``:
  ``repeat_m``;
- ``custom.catalog.btdf`` (a U3M this program wrote): the eq. 7 lobes, exactly;
- ``physics`` (1.1): ``weight`` (g/m2) -> ``cloth.areal_density_kg_m2``; the fab file's
  bending and stretch are kept under ``[import]`` (their units are a vendor's; only our own
  ``custom.catalog`` block, written by :func:`write_u3m`, maps back exactly).

Everything else (roughness, sheen, specular constants, names, ids) is kept under [import].
"""

from __future__ import annotations

import json
import math
import re
import zipfile
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np

from catalog.core.errors import InputError

VERSIONS = ("1.0", "1.1")
#: Bounds on what is read: the JSON file, a .u3ma's members and their total.
MAX_JSON_BYTES = 16 << 20
MAX_ARCHIVE_MEMBERS = 256
MAX_ARCHIVE_BYTES = 1 << 30
#: The visualisation keys U3M 1.1 requires on a side (1.0 asks for at least 21 of them).
VISUALISATION_KEYS_11 = (
    "alpha", "anisotropy_value", "anisotropy_rotation", "clearcoat_value", "clearcoat_normal",
    "clearcoat_roughness", "ior", "metalness", "normal", "displacement", "roughness",
    "sheen_value", "sheen_tint", "specular_value", "specular_tint", "subsurface_radius",
    "subsurface_value", "transmission", "basecolor", "subsurface_color", "shader", "preview")
MATERIAL_KEYS = {"1.0": ("name", "id", "created", "modified", "front", "back", "description"),
                 "1.1": ("name", "id", "created", "modified", "front", "back", "side",
                         "physics", "metadata", "description")}
IMAGE_KEYS = ("repeat", "dpi", "path", "width", "height")
UPSAMPLING = "Mallett & Yuksel 2019 (colour.recovery.RGB_to_sd_Mallett2019), linear sRGB"


class _Checker:
    """Field checks that name the file and the JSON path."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, where: str, problem: str):
        raise InputError(problem, path=self.path, field=where)

    def table(self, value, where: str, nullable: bool = False):
        if value is None and nullable:
            return None
        if not isinstance(value, dict):
            self.fail(where, f"must be an object{' or null' if nullable else ''}, found "
                             f"{type(value).__name__}")
        return value

    def keys(self, table: dict, keys, where: str) -> None:
        for key in keys:
            if key not in table:
                self.fail(f"{where}.{key}", "missing required field")

    def number(self, value, where: str, low: float | None = None, high: float | None = None) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(where, f"must be a number, found {value!r}")
        if (low is not None and value < low) or (high is not None and value > high):
            self.fail(where, f"{value!r} is out of range [{low}, {high}]")
        return float(value)

    def rgb(self, value, where: str) -> np.ndarray:
        table = self.table(value, where)
        self.keys(table, ("r", "g", "b"), where)
        return np.array([self.number(table[k], f"{where}.{k}", 0.0, 1.0) for k in "rgb"])


def _relative_path(checker: _Checker, value, where: str) -> str:
    if not isinstance(value, str) or not value:
        checker.fail(where, f"must be a relative file path, found {value!r}")
    posix = PurePosixPath(value)
    if posix.is_absolute() or ".." in posix.parts or "\\" in value or value.startswith("~") \
            or re.match(r"^[A-Za-z]:", value):
        checker.fail(where, f"{value!r} must be a relative POSIX path inside the material")
    return value


class _Source:
    """The files of a .u3m (its folder) or a .u3ma (its archive, read bounded)."""

    def __init__(self, path: Path, scratch: Path):
        self.path = path
        self.scratch = scratch
        self.archive = None
        if path.suffix.lower() == ".u3ma":
            try:
                self.archive = zipfile.ZipFile(path)
            except (zipfile.BadZipFile, OSError) as exc:
                raise InputError(f"not a U3MA (zip) archive: {exc}", path=path) from None
            infos = self.archive.infolist()
            if len(infos) > MAX_ARCHIVE_MEMBERS or sum(i.file_size for i in infos) > MAX_ARCHIVE_BYTES:
                raise InputError(f"the archive holds {len(infos)} files, "
                                 f"{sum(i.file_size for i in infos)} bytes unpacked: more than "
                                 f"{MAX_ARCHIVE_MEMBERS} files or {MAX_ARCHIVE_BYTES} bytes",
                                 path=path)
            tops = [i.filename for i in infos if i.filename.lower().endswith(".u3m")
                    and "/" not in i.filename.strip("/")]
            if len(tops) != 1:
                raise InputError(f"a U3MA holds one .u3m at its top, found {len(tops)}", path=path)
            self.json_name = tops[0]

    def json_text(self) -> str:
        if self.archive is not None:
            info = self.archive.getinfo(self.json_name)
            if info.file_size > MAX_JSON_BYTES:
                raise InputError(f"{self.json_name} has {info.file_size} bytes", path=self.path)
            data = self.archive.read(info)
        else:
            if not self.path.is_file():
                raise InputError("no such file", path=self.path)
            if self.path.stat().st_size > MAX_JSON_BYTES:
                raise InputError(f"more than {MAX_JSON_BYTES} bytes: not a U3M", path=self.path)
            data = self.path.read_bytes()
        try:
            return data.decode("utf-8-sig")
        except UnicodeDecodeError:
            raise InputError("not UTF-8 JSON", path=self.path) from None

    def file(self, relative: str, where: str) -> Path:
        """A local path to the file a field names (extracted from an archive)."""
        if self.archive is not None:
            try:
                info = self.archive.getinfo(relative)
            except KeyError:
                raise InputError(f"no such texture {relative!r} in the archive", path=self.path,
                                 field=where) from None
            target = self.scratch / PurePosixPath(relative).name
            target.write_bytes(self.archive.read(info))
            return target
        local = self.path.parent / relative
        if not local.is_file():
            raise InputError(f"no such texture {relative!r} (looked for {local})",
                             path=self.path, field=where)
        return local


def read_document(source: _Source) -> dict:
    checker = _Checker(source.path)
    try:
        doc = json.loads(source.json_text())
    except json.JSONDecodeError as exc:
        raise InputError(f"not valid JSON: {exc}", path=source.path) from None
    checker.table(doc, "<document>")
    for key in ("schema", "material", "custom"):
        if key not in doc:
            checker.fail(key, "missing required field")
    version = str(doc["schema"])
    if version not in VERSIONS:
        checker.fail("schema", f"{doc['schema']!r}: this reader knows U3M {', '.join(VERSIONS)}")
    material = checker.table(doc["material"], "material")
    checker.keys(material, MATERIAL_KEYS[version], "material")
    if not isinstance(material["name"], str) or not material["name"]:
        checker.fail("material.name", "must be a non-empty string")
    sides = [s for s in ("front", "back", "side") if material.get(s) is not None]
    if not sides:
        checker.fail("material.front", "no side has visuals (front, back and side are null)")
    for side in sides:
        _check_visualisation(checker, material[side], f"material.{side}", version)
    if version == "1.1" and material.get("physics") is not None:
        physics = checker.table(material["physics"], "material.physics")
        checker.keys(physics, ("thickness", "weight", "composition", "devices", "material_type",
                               "construction"), "material.physics")
    return doc


def _check_visualisation(checker: _Checker, side, where: str, version: str) -> None:
    checker.table(side, where)
    if version == "1.1":
        checker.keys(side, VISUALISATION_KEYS_11, where)
    elif len(side) < 21:
        checker.fail(where, f"U3M 1.0 asks for at least 21 maps on a side, found {len(side)}")
    for key in ("alpha", "basecolor", "normal"):
        entry = side.get(key)
        if entry is None:
            if version == "1.1":
                checker.fail(f"{where}.{key}", "must be an object (U3M 1.1 disallows null)")
            continue
        checker.table(entry, f"{where}.{key}")
        checker.keys(entry, ("constant", "texture"), f"{where}.{key}")
        texture = checker.table(entry["texture"], f"{where}.{key}.texture", nullable=True)
        if texture is None:
            continue
        required = {"alpha": ("factor", "offset", "image"), "basecolor": ("factor", "image", "mode"),
                    "normal": ("scale", "image") if version == "1.1" else ("factor", "offset", "image")}[key]
        checker.keys(texture, required, f"{where}.{key}.texture")
        image = checker.table(texture["image"], f"{where}.{key}.texture.image")
        checker.keys(image, IMAGE_KEYS, f"{where}.{key}.texture.image")
        _relative_path(checker, image["path"], f"{where}.{key}.texture.image.path")
        for dim in ("width", "height"):
            checker.number(image[dim], f"{where}.{key}.texture.image.{dim}", 0.0)
        dpi = image["dpi"]
        if version == "1.1":
            table = checker.table(dpi, f"{where}.{key}.texture.image.dpi")
            checker.keys(table, ("x", "y"), f"{where}.{key}.texture.image.dpi")
            for axis in ("x", "y"):
                checker.number(table[axis], f"{where}.{key}.texture.image.dpi.{axis}", 0.0)
        else:
            checker.number(dpi, f"{where}.{key}.texture.image.dpi", 0.0)


def _front(material: dict) -> tuple[str, dict]:
    for side in ("front", "back", "side"):
        if material.get(side) is not None:
            return side, material[side]
    raise AssertionError("checked in read_document")


def _dpi_xy(image: dict) -> tuple[float, float]:
    dpi = image["dpi"]
    return (float(dpi["x"]), float(dpi["y"])) if isinstance(dpi, dict) else (float(dpi), float(dpi))


def _texture_pixels(source: _Source, image: dict, where: str) -> tuple[np.ndarray, Path]:
    from catalog.exchange.image_import import image_header  # noqa: PLC0415
    from catalog.presets.patterns import read_image  # noqa: PLC0415

    local = source.file(image["path"], f"{where}.path")
    try:
        image_header(local)
    except InputError as exc:
        raise InputError(f"{image['path']!r}: {exc.problem}", path=source.path,
                         field=f"{where}.path") from None
    return read_image(local), local


def _physical_size(source: _Source, image: dict, shape, where: str, repeat_m) -> tuple[tuple[float, float], str]:
    from catalog.exchange.image_import import check_dpi, check_repeat  # noqa: PLC0415

    h, w = shape
    dpi_x, dpi_y = _dpi_xy(image)
    if repeat_m is not None:
        repeat = (float(repeat_m), float(repeat_m) * h / w)
        check_repeat(repeat, source.path, "--repeat-m")
        return repeat, "--repeat-m"
    width_mm, height_mm = float(image["width"]), float(image["height"])
    if width_mm > 0 and height_mm > 0:
        if dpi_x > 0:
            check_dpi(dpi_x, source.path, f"{where}.dpi")
        repeat = (width_mm * 1e-3, height_mm * 1e-3)
        check_repeat(repeat, source.path, f"{where}.width")
        return repeat, f"{where}.width/height (mm)"
    for dpi, axis in ((dpi_x, "x"), (dpi_y, "y")):
        check_dpi(dpi, source.path, f"{where}.dpi" + (f".{axis}" if isinstance(image["dpi"], dict) else ""))
    repeat = (w / dpi_x * 0.0254, h / dpi_y * 0.0254)
    check_repeat(repeat, source.path, f"{where}.dpi")
    return repeat, f"{where}.dpi"


def _srgb_decode(values: np.ndarray) -> np.ndarray:
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


def dye_from_rgb(rgb_linear) -> tuple[np.ndarray, np.ndarray]:
    """(wavelength nm, reflectance 0..1): the Mallett-Yuksel 2019 spectrum of a linear sRGB."""
    from colour.recovery import RGB_to_sd_Mallett2019  # noqa: PLC0415

    sd = RGB_to_sd_Mallett2019(np.clip(np.asarray(rgb_linear, dtype=np.float64), 0.0, 1.0))
    return np.asarray(sd.wavelengths, dtype=np.float64), np.clip(sd.values, 0.0, 1.0)


def rgb_of_spectrum(wavelength_nm: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Linear sRGB of a reflectance spectrum under D65 (white = a flat 1): the inverse of
    :func:`dye_from_rgb` (colour-science's CIE 1931 observer, 380-780 nm at 5 nm)."""
    import colour  # noqa: PLC0415

    from colour.recovery import SPECTRAL_SHAPE_sRGB_MALLETT2019 as shape  # noqa: PLC0415

    # on the upsampling's own grid (380-780 nm, 5 nm), where it inverts to 1e-4
    grid = np.asarray(shape.wavelengths, dtype=np.float64)
    sd = colour.SpectralDistribution(np.interp(grid, wavelength_nm, values), grid)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    illuminant = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    xyz = colour.sd_to_XYZ(sd, cmfs=cmfs, illuminant=illuminant) / 100.0
    return np.asarray(colour.XYZ_to_RGB(xyz, "sRGB", apply_cctf_encoding=False), dtype=np.float64)


def height_from_normals(normal_rgb: np.ndarray, scale: float, repeat_m) -> tuple[np.ndarray, float]:
    """(height 0..1, height_m) from a tangent-space normal map (0..1 encoded, +y up):
    slopes dz/dx = -n_x/n_z, dz/dy_up = -n_y/n_z, integrated periodically
    (Frankot & Chellappa 1988) at the texture's pixel size."""
    n = normal_rgb[..., :3].astype(np.float64) * 2.0 - 1.0
    n[..., :2] *= scale
    nz = np.maximum(n[..., 2], 1e-3)
    h, w = nz.shape
    px_u, px_v = repeat_m[0] / w, repeat_m[1] / h
    p = -n[..., 0] / nz                 # dz/du along +x (image columns)
    q = n[..., 1] / nz                  # dz/dv along +image rows (down) = -(dz/d up)
    fu = np.fft.fftfreq(w, d=px_u)[None, :]
    fv = np.fft.fftfreq(h, d=px_v)[:, None]
    denom = (2j * math.pi) * (fu ** 2 + fv ** 2)
    denom[0, 0] = 1.0
    z_hat = (fu * np.fft.fft2(p) + fv * np.fft.fft2(q)) / denom
    z_hat[0, 0] = 0.0
    z = np.real(np.fft.ifft2(z_hat))
    span = float(z.max() - z.min())
    if span <= 0:
        return np.zeros_like(z, dtype=np.float32), 0.0
    return ((z - z.min()) / span).astype(np.float32), min(span, 0.0099)


def _resize_nearest(values: np.ndarray, shape) -> np.ndarray:
    h, w = shape
    rows = (np.arange(h) * values.shape[0] // h)
    cols = (np.arange(w) * values.shape[1] // w)
    return values[rows][:, cols]


def read_u3m_fabric(path: str | Path, repeat_m: float | None = None):
    """An :class:`~catalog.exchange.imported_preset.ImportedFabric` from a .u3m / .u3ma."""
    import tempfile  # noqa: PLC0415

    from catalog.exchange.imported_preset import ImportedFabric  # noqa: PLC0415

    path = Path(path)
    if not path.is_file():
        raise InputError("no such file", path=path)
    with tempfile.TemporaryDirectory(prefix="catalog-u3m-") as scratch:
        source = _Source(path, Path(scratch))
        doc = read_document(source)
        return _fabric_from_document(source, doc, repeat_m, ImportedFabric)


def _fabric_from_document(source: _Source, doc: dict, repeat_m, ImportedFabric):
    checker = _Checker(source.path)
    version = str(doc["schema"])
    material = doc["material"]
    side_name, side = _front(material)
    where = f"material.{side_name}"
    imported: dict[str, Any] = {"u3m_schema": version, "material_name": material["name"],
                                "material_id": str(material["id"]), "side": side_name,
                                "dye_upsampling": UPSAMPLING}
    # alpha -> coverage
    alpha = side.get("alpha") or {"constant": 1.0, "texture": None}
    constant_alpha = checker.number(alpha["constant"], f"{where}.alpha.constant", 0.0, 1.0)
    size_image, size_where, shape = None, None, None
    if alpha["texture"] is not None:
        tex = alpha["texture"]
        pixels, _ = _texture_pixels(source, tex["image"], f"{where}.alpha.texture.image")
        grey = pixels[..., :3].mean(axis=2) if pixels.shape[2] >= 3 else pixels[..., 0]
        factor = checker.number(tex["factor"], f"{where}.alpha.texture.factor")
        offset = checker.number(tex["offset"], f"{where}.alpha.texture.offset")
        coverage = np.clip(grey * factor + offset, 0.0, 1.0).astype(np.float32)
        size_image, size_where, shape = tex["image"], f"{where}.alpha.texture.image", coverage.shape
    else:
        coverage = None
    # normal -> height
    normal = side.get("normal")
    normal_pixels = None
    if normal is not None and normal["texture"] is not None:
        tex = normal["texture"]
        normal_pixels, _ = _texture_pixels(source, tex["image"], f"{where}.normal.texture.image")
        if normal_pixels.shape[2] < 3:
            checker.fail(f"{where}.normal.texture.image.path", "a normal map has 3 channels")
        scale = checker.number(tex.get("scale", tex.get("factor", 1.0)), f"{where}.normal.texture.scale")
        if size_image is None:
            size_image, size_where = tex["image"], f"{where}.normal.texture.image"
            shape = normal_pixels.shape[:2]
    if size_image is None:
        checker.fail(f"{where}.alpha.texture", "no alpha or normal texture: nothing gives the "
                                               "pattern (a U3M without holes is not a sheer)")
    repeat, size_from = _physical_size(source, size_image, shape, size_where, repeat_m)
    if coverage is None:
        coverage = np.full(shape, constant_alpha, dtype=np.float32)
    height, height_m = None, None
    if normal_pixels is not None:
        height, height_m = height_from_normals(normal_pixels, scale, repeat)
        if height.shape != coverage.shape:
            height = _resize_nearest(height, coverage.shape)
    # basecolor -> dye
    base = side.get("basecolor")
    dye = None
    if base is not None:
        rgb = checker.rgb(base["constant"], f"{where}.basecolor.constant")
        if base["texture"] is not None:
            tex = base["texture"]
            pixels, _ = _texture_pixels(source, tex["image"], f"{where}.basecolor.texture.image")
            colour_px = _srgb_decode(pixels[..., :3] if pixels.shape[2] >= 3
                                     else np.repeat(pixels[..., :1], 3, axis=2))
            weights = _resize_nearest(coverage, colour_px.shape[:2]).astype(np.float64)
            if weights.sum() <= 0:
                weights = np.ones_like(weights)
            mean = (colour_px * weights[..., None]).sum(axis=(0, 1)) / weights.sum()
            rgb = mean * checker.rgb(tex["factor"], f"{where}.basecolor.texture.factor")
        imported["basecolor_linear_srgb"] = [round(float(v), 6) for v in rgb]
        if np.ptp(rgb) > 1e-3 and rgb.max() > 0:
            nm, values = dye_from_rgb(rgb)
            dye = (nm, values, [f"dye of U3M material {material['name']!r}: base colour "
                                f"{', '.join(f'{v:.4f}' for v in rgb)} (linear sRGB)",
                                f"upsampled by {UPSAMPLING}"])
    # the rest: constants of the other maps
    rest = {}
    for key, entry in side.items():
        if key in ("alpha", "normal", "basecolor") or not isinstance(entry, dict):
            continue
        value = entry.get("constant")
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            rest[key] = float(value)
        elif isinstance(value, dict):
            rest[key] = {k: v for k, v in value.items() if isinstance(v, (int, float))}
    if rest:
        imported["constants"] = rest
    # physics
    cloth, weight = {}, None
    physics = material.get("physics")
    if physics is not None:
        if physics.get("weight") is not None:
            weight = checker.number(physics["weight"], "material.physics.weight", 0.0) * 1e-3
            if weight > 0:
                cloth["areal_density_kg_m2"] = round(weight, 6)
        if physics.get("thickness") is not None:
            imported["thickness_mm"] = checker.number(physics["thickness"], "material.physics.thickness", 0.0)
        fab = (physics.get("devices") or {}).get("fab")
        if isinstance(fab, str) and fab != "null":
            fab = _relative_path(checker, fab, "material.physics.devices.fab")
            cloth_fab, kept = _read_fab(source, fab)
            cloth.update(cloth_fab)
            if kept:
                imported["physics"] = kept
    lobes = _carried_lobes(checker, doc.get("custom"))
    if isinstance(material.get("description"), str) and material["description"]:
        imported["description"] = material["description"]
    return ImportedFabric(coverage=coverage, height=height, repeat_m=repeat, source=source.path,
                          kind=f"u3m {version}", height_m=height_m, dye=dye, weight_kg_m2=weight,
                          cloth=cloth, import_table={**imported, "size_from": size_from},
                          display_name=material["name"], lobes=lobes,
                          lobes_source=None if lobes is None else "u3m custom.catalog.btdf")


def _carried_lobes(checker: _Checker, custom) -> dict | None:
    """The eq. 7 lobes a U3M written by this program carries (``custom.catalog.btdf``)."""
    if not isinstance(custom, dict) or not isinstance(custom.get("catalog"), dict):
        return None
    btdf = custom["catalog"].get("btdf")
    if not isinstance(btdf, dict):
        return None
    where = "custom.catalog.btdf"
    lobes = {key: checker.number(btdf.get(key), f"{where}.{key}", 0.0)
             for key in ("k_d", "k_s", "tau")}
    lobes.update({key: checker.number(btdf.get(key), f"{where}.{key}", -0.999999, 0.999999)
                  for key in ("g_diff", "g_spec")})
    if "anisotropy" in btdf:
        lobes["anisotropy"] = checker.number(btdf["anisotropy"], f"{where}.anisotropy")
    return lobes


def _read_fab(source: _Source, relative: str) -> tuple[dict, dict]:
    """([cloth] keys, what is kept) from a physics file (``physics.json``)."""
    local = source.file(relative, "material.physics.devices.fab")
    if local.stat().st_size > MAX_JSON_BYTES:
        raise InputError(f"{relative} is larger than {MAX_JSON_BYTES} bytes", path=source.path,
                         field="material.physics.devices.fab")
    try:
        doc = json.loads(local.read_text(encoding="utf-8-sig"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{relative}: not valid JSON: {exc}", path=source.path,
                         field="material.physics.devices.fab") from None
    custom = doc.get("custom") if isinstance(doc, dict) else None
    if not isinstance(custom, dict):
        return {}, {}
    cloth, kept = {}, {}
    ours = custom.get("catalog")
    if isinstance(ours, dict):
        for key in ("areal_density_kg_m2", "stretch_stiffness_n_m", "bend_stiffness_n_m", "weave"):
            if key in ours:
                cloth[key] = ours[key]
    for vendor, block in custom.items():
        if vendor == "catalog" or not isinstance(block, dict):
            continue
        kept[vendor] = {k: v for k, v in block.items()
                        if k in ("bend", "stretch", "shear", "mass", "thickness", "friction")
                        and v is not None}
    return cloth, {k: v for k, v in kept.items() if v}
