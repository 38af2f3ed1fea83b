"""Fabric presets: ``fabrics/<name>.toml`` <-> a validated, typed :class:`Preset`.

formats.md fixes the required keys; everything else is kept as read (unknown keys
survive a load/save round trip). A missing required key or an out-of-range value is
refused with the file and the key. Presets are written atomically.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from catalog.core.resources import FABRIC_DIR, fabric_dirs
from catalog.core.errors import InputError

SCHEMA = 1
#: A preset is a page of text; a larger file is refused before it is read.
MAX_PRESET_BYTES = 1 << 20


@dataclass(frozen=True)
class BTDFParams:
    """Eq. 7 parameters. Only ``direct``, ``a_diff``, ``a_spec`` and the g's are identifiable."""

    direct: float  # LD: open-area see-through fraction, [0, 1]
    k_d: float  # diffuse transmission coefficient, >= 0
    k_s: float  # directional transmission coefficient, >= 0
    tau: float  # absorption optical depth (e^-tau), >= 0
    rho: float  # thread density from the weave, (0, 1]
    g_diff: float  # HG shape of the diffuse lobe, (-1, 1)
    g_spec: float  # HG shape of the directional lobe, (-1, 1)

    @property
    def a_diff(self) -> float:
        """rho e^-tau k_d: the diffuse lobe's weight (eq. 7)."""
        return self.rho * math.exp(-self.tau) * self.k_d

    @property
    def a_spec(self) -> float:
        """rho e^-tau k_s: the directional lobe's weight (eq. 7)."""
        return self.rho * math.exp(-self.tau) * self.k_s


@dataclass(frozen=True)
class FluorescenceParams:
    """The ``[fluorescence]`` table: paper-mode colour (eq. 1-3) and the spectra behind it."""

    xyz: tuple[float, float, float]
    rgb: tuple[float, float, float]
    excitation: Path  # resolved against the preset's folder
    emission: Path
    extra: dict[str, Any] = field(default_factory=dict)  # physical-mode keys and others


@dataclass(frozen=True)
class Preset:
    path: Path | None
    name: str
    display_name: str
    btdf: BTDFParams
    fit: dict[str, Any]
    fluorescence: FluorescenceParams | None
    raw: dict[str, Any]  # the whole TOML document, unknown keys included

    @property
    def has_fluorescence(self) -> bool:
        return self.fluorescence is not None

    def table(self, key: str) -> dict[str, Any]:
        """An optional top-level table (``cloth``, ``dye``, ...) or {} when absent."""
        value = self.raw.get(key, {})
        return value if isinstance(value, dict) else {}

    def resolve(self, relative: str | Path) -> Path:
        """A path written in the preset, resolved against the preset's folder."""
        base = self.path.parent if self.path is not None else FABRIC_DIR
        return contained_path(self.path or "<preset>", str(relative), base, str(relative))


# name -> (low, high, low_inclusive, high_inclusive)
_BTDF_RANGES: dict[str, tuple[float, float, bool, bool]] = {
    "direct": (0.0, 1.0, True, True),
    "k_d": (0.0, math.inf, True, False),
    "k_s": (0.0, math.inf, True, False),
    "tau": (0.0, math.inf, True, False),
    "rho": (0.0, 1.0, False, True),
    "g_diff": (-1.0, 1.0, False, False),
    "g_spec": (-1.0, 1.0, False, False),
}


#: ``[fluorescence]`` physical-mode keys: the same ranges the renderer's material enforces
#: (catalog.optics.fluorescence.FluorescentMaterial), checked where the preset is read, so a
#: preset that ``catalog fit`` writes is one that ``catalog snapshot`` accepts.
_FLUORESCENCE_RANGES: dict[str, tuple[float, float, bool, bool]] = {
    "peak_absorptance": (0.0, 1.0, False, True),
    "quantum_yield": (0.0, 1.0, True, True),
    "saturation_photon_irradiance": (0.0, math.inf, False, True),
}
#: Folders (os.pathsep-separated) besides a preset's own folder tree that the files a preset
#: names may lie in.
ALLOWED_PATHS_ENV = "CATALOG_PRESET_PATHS"


def _non_finite_key(doc: Any, prefix: str = "") -> str | None:
    """The dotted key of the first NaN or infinite number in a parsed TOML document."""
    if isinstance(doc, float) and not math.isfinite(doc):
        return prefix or "<value>"
    if isinstance(doc, dict):
        for key, value in doc.items():
            found = _non_finite_key(value, f"{prefix}.{key}" if prefix else str(key))
            if found:
                return found
    if isinstance(doc, list):
        for i, value in enumerate(doc):
            found = _non_finite_key(value, f"{prefix}[{i}]")
            if found:
                return found
    return None


def contained_path(where, key: str, base: Path, relative: Any) -> Path:
    """``relative`` (a path written in a preset at ``key``) resolved against ``base``.

    Refused unless it stays inside ``base``'s folder tree, a fabric folder (the built-in
    catalog and the user's ``--fabrics`` folders, whose measurements a preset written
    elsewhere may name) or a folder of ``$CATALOG_PRESET_PATHS``: a preset cannot make the
    program read ``/etc/passwd`` or a key file, and the refusal never shows such a file.
    """
    import os  # noqa: PLC0415

    if not isinstance(relative, str) or not relative or "\x00" in relative:
        raise InputError("must be a non-empty path string", path=where, field=key)
    resolved = (base / relative).resolve()
    from catalog.core.atomic import register_input  # noqa: PLC0415

    register_input(resolved)  # an input: no output may replace it
    roots = [base.resolve()] + [Path(p).resolve() for p in fabric_dirs()]
    roots += [Path(p).resolve() for p in
              os.environ.get(ALLOWED_PATHS_ENV, "").split(os.pathsep) if p]
    if not any(resolved.is_relative_to(root) for root in roots):
        raise InputError(f"{relative!r} leaves the preset's folder ({base}); keep measurement "
                         f"files beside the preset or list their folder in ${ALLOWED_PATHS_ENV}",
                         path=where, field=key)
    return resolved


def _number(path, key, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"must be a number, found {value!r}", path=path, field=key)
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"must be finite, found {value}", path=path, field=key)
    return value


def _in_range(path, key, value, low, high, low_inc, high_inc) -> float:
    value = _number(path, key, value)
    ok_low = value >= low if low_inc else value > low
    ok_high = value <= high if high_inc else value < high
    if not (ok_low and ok_high):
        lo = "[" if low_inc else "("
        hi = "]" if high_inc else ")"
        raise InputError(f"{value:g} is out of range {lo}{low:g}, {high:g}{hi}",
                         path=path, field=key)
    return value


def _require(path, table: dict, key: str, prefix: str = ""):
    if key not in table:
        raise InputError("missing required key", path=path, field=prefix + key)
    return table[key]


def _triple(path, key, value) -> tuple[float, float, float]:
    if not isinstance(value, list) or len(value) != 3:
        raise InputError(f"must be a list of 3 numbers, found {value!r}", path=path, field=key)
    return tuple(_number(path, key, v) for v in value)  # type: ignore[return-value]


def preset_from_dict(doc: dict[str, Any], path: Path | None = None) -> Preset:
    """Validate a parsed preset document (``path`` only names the file in errors)."""
    where = path if path is not None else "<preset>"
    schema = _require(where, doc, "schema")
    if schema != SCHEMA:
        raise InputError(f"unsupported schema {schema!r} (this version reads {SCHEMA})",
                         path=where, field="schema")
    name = _require(where, doc, "name")
    if not isinstance(name, str) or not name:
        raise InputError("must be a non-empty string", path=where, field="name")
    if path is not None and path.stem != name:
        raise InputError(f"{name!r} differs from the file stem {path.stem!r}",
                         path=where, field="name")
    display_name = _require(where, doc, "display_name")
    if not isinstance(display_name, str):
        raise InputError("must be a string", path=where, field="display_name")

    from catalog.core.validate import WEAVES, check_preset_tables  # noqa: PLC0415

    check_preset_tables(doc, where, WEAVES)
    bad = _non_finite_key(doc)
    if bad is not None:
        raise InputError("must be a finite number (NaN and inf are refused)", path=where, field=bad)
    dye = doc.get("dye")
    if dye is not None and not isinstance(dye, dict):
        raise InputError("must be a table", path=where, field="dye")
    if dye and "transmittance" in dye:
        contained_path(where, "dye.transmittance",
                       path.parent if path is not None else FABRIC_DIR, dye["transmittance"])
    btdf_doc = _require(where, doc, "btdf")
    if not isinstance(btdf_doc, dict):
        raise InputError("must be a table", path=where, field="btdf")
    values = {key: _in_range(where, f"btdf.{key}", _require(where, btdf_doc, key, "btdf."),
                             *bounds)
              for key, bounds in _BTDF_RANGES.items()}
    btdf = BTDFParams(**values)

    fit = doc.get("fit", {})
    if not isinstance(fit, dict):
        raise InputError("must be a table", path=where, field="fit")

    fluorescence = None
    fl_doc = doc.get("fluorescence")
    if fl_doc is not None:
        if not isinstance(fl_doc, dict):
            raise InputError("must be a table", path=where, field="fluorescence")
        base = path.parent if path is not None else FABRIC_DIR
        paths = {}
        for key in ("excitation", "emission"):
            rel = _require(where, fl_doc, key, "fluorescence.")
            paths[key] = contained_path(where, f"fluorescence.{key}", base, rel)
        extra = {k: v for k, v in fl_doc.items()
                 if k not in ("xyz", "rgb", "excitation", "emission")}
        for key, bounds in _FLUORESCENCE_RANGES.items():
            if key in extra:
                extra[key] = _in_range(where, f"fluorescence.{key}", extra[key], *bounds)
        if "residual" in extra:  # a measured residual (docs/formats.md): a file, checked here
            rel = extra["residual"]
            if not isinstance(rel, str) or not rel:
                raise InputError(f"must be a path string, not {rel!r}", path=where,
                                 field="fluorescence.residual")
            from catalog.optics.measured_residual import read_residual  # noqa: PLC0415

            read_residual(contained_path(where, "fluorescence.residual", base, rel))
        fluorescence = FluorescenceParams(
            xyz=_triple(where, "fluorescence.xyz", _require(where, fl_doc, "xyz", "fluorescence.")),
            rgb=_triple(where, "fluorescence.rgb", _require(where, fl_doc, "rgb", "fluorescence.")),
            excitation=paths["excitation"], emission=paths["emission"], extra=extra)

    return Preset(path=path, name=name, display_name=display_name, btdf=btdf, fit=fit,
                  fluorescence=fluorescence, raw=doc)


def load_preset(path: str | Path) -> Preset:
    """Read and validate one preset file."""
    path = Path(path)
    from catalog.core.atomic import register_input  # noqa: PLC0415

    register_input(path)
    try:
        if path.is_file() and path.stat().st_size > MAX_PRESET_BYTES:
            raise InputError(f"{path.stat().st_size} bytes: a preset is at most "
                             f"{MAX_PRESET_BYTES >> 10} KiB", path=path)
        data = path.read_bytes()
    except FileNotFoundError:
        raise InputError("no such preset file", path=path) from None
    except IsADirectoryError:
        raise InputError("is a folder, not a preset file", path=path) from None
    except OSError as exc:
        raise InputError(f"cannot read: {(exc.strerror or str(exc)).lower()}", path=path) from None
    try:
        doc = tomllib.loads(data.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"not valid TOML: {exc}", path=path) from None
    except RecursionError:
        raise InputError("not valid TOML: nested too deeply", path=path) from None
    try:
        return preset_from_dict(doc, path)
    except RecursionError:
        raise InputError("nested too deeply", path=path) from None


def _folders(fabric_dir: Path | None) -> list[Path]:
    return fabric_dirs() if fabric_dir is None else [Path(fabric_dir)]


def find_preset(name_or_path: str | Path, fabric_dir: Path | None = None) -> Path:
    """A preset name (``lace-fwa``) or a path to a .toml -> the file's path. A name is looked
    up in ``fabric_dir``, or by default in the user's fabric folders (``--fabrics``,
    ``$CATALOG_FABRICS``) and then the built-in catalog (the first match wins)."""
    if not str(name_or_path).strip():
        raise InputError("empty fabric name", field="--fabric")
    candidate = Path(name_or_path)
    if candidate.suffix == ".toml" or candidate.is_file():
        if not candidate.exists():
            raise InputError("no such preset file", path=candidate)
        return candidate
    for folder in _folders(fabric_dir):
        path = folder / f"{name_or_path}.toml"
        if path.exists():
            return path
    known = ", ".join(p.stem for p in list_presets(fabric_dir)) or "none"
    raise InputError(f"unknown fabric {str(name_or_path)!r} (known: {known})", field="--fabric")


def list_presets(fabric_dir: Path | None = None) -> list[Path]:
    """Preset files in ``fabric_dir`` (default: every fabric folder, a name found in an
    earlier folder hiding the same name in a later one), sorted by name."""
    found: dict[str, Path] = {}
    for folder in _folders(fabric_dir):
        for path in sorted(folder.glob("*.toml")):
            found.setdefault(path.stem, path)
    return [found[name] for name in sorted(found)]


def preset_to_dict(preset: Preset) -> dict[str, Any]:
    """The document to write: the raw document with the typed fields laid over it."""
    doc = dict(preset.raw)
    doc["schema"] = SCHEMA
    doc["name"] = preset.name
    doc["display_name"] = preset.display_name
    btdf = dict(doc.get("btdf", {}))
    for key in _BTDF_RANGES:
        btdf[key] = getattr(preset.btdf, key)
    doc["btdf"] = btdf
    doc["fit"] = dict(preset.fit)
    if preset.fluorescence is not None:
        fl = dict(doc.get("fluorescence", {}))
        fl.update(preset.fluorescence.extra)
        fl["xyz"] = list(preset.fluorescence.xyz)
        fl["rgb"] = list(preset.fluorescence.rgb)
        fl.setdefault("excitation", str(preset.fluorescence.excitation))
        fl.setdefault("emission", str(preset.fluorescence.emission))
        doc["fluorescence"] = fl
    # key order: the formats.md header first, then tables
    ordered = {k: doc[k] for k in ("schema", "name", "display_name") if k in doc}
    ordered.update({k: v for k, v in doc.items() if k not in ordered and not isinstance(v, dict)})
    ordered.update({k: v for k, v in doc.items() if k not in ordered})
    return ordered


def save_preset_dict(doc: dict[str, Any], path: str | Path) -> Preset:
    """Validate ``doc`` as a preset for ``path`` and write it atomically; return the preset.

    Nothing is written when validation fails, nor when a ``[pattern]`` table's coverage
    misses ``btdf.direct`` by more than 1 % (:func:`catalog.presets.patterns.load_pattern`).
    """
    import tomli_w

    from catalog.core.atomic import write_text_atomic

    path = Path(path)
    preset = preset_from_dict(doc, path)
    if preset.table("pattern"):
        # the pattern's mean open area must equal the fit's LD within 1 % (model.md section 9)
        from catalog.presets.patterns import load_pattern  # noqa: PLC0415

        load_pattern(preset)
    write_text_atomic(path, tomli_w.dumps(preset_to_dict(preset)))
    return preset


__all__ = ["BTDFParams", "FluorescenceParams", "Preset", "load_preset", "find_preset",
           "list_presets", "preset_from_dict", "preset_to_dict", "save_preset_dict",
           "replace"]
