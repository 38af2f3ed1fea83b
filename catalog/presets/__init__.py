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

from catalog.core.resources import FABRIC_DIR
from catalog.core.errors import InputError

SCHEMA = 1


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
        return (base / relative).resolve()


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
            if not isinstance(rel, str) or not rel:
                raise InputError("must be a path string", path=where, field=f"fluorescence.{key}")
            paths[key] = (base / rel).resolve()
        extra = {k: v for k, v in fl_doc.items()
                 if k not in ("xyz", "rgb", "excitation", "emission")}
        fluorescence = FluorescenceParams(
            xyz=_triple(where, "fluorescence.xyz", _require(where, fl_doc, "xyz", "fluorescence.")),
            rgb=_triple(where, "fluorescence.rgb", _require(where, fl_doc, "rgb", "fluorescence.")),
            excitation=paths["excitation"], emission=paths["emission"], extra=extra)

    return Preset(path=path, name=name, display_name=display_name, btdf=btdf, fit=fit,
                  fluorescence=fluorescence, raw=doc)


def load_preset(path: str | Path) -> Preset:
    """Read and validate one preset file."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise InputError("no such preset file", path=path) from None
    try:
        doc = tomllib.loads(data.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"not valid TOML: {exc}", path=path) from None
    return preset_from_dict(doc, path)


def find_preset(name_or_path: str | Path, fabric_dir: Path = FABRIC_DIR) -> Path:
    """A preset name (``lace-fwa``) or a path to a .toml -> the file's path."""
    candidate = Path(name_or_path)
    if candidate.suffix == ".toml" or candidate.exists():
        if not candidate.exists():
            raise InputError("no such preset file", path=candidate)
        return candidate
    path = fabric_dir / f"{name_or_path}.toml"
    if not path.exists():
        known = ", ".join(sorted(p.stem for p in fabric_dir.glob("*.toml"))) or "none"
        raise InputError(f"unknown fabric {str(name_or_path)!r} (known: {known})",
                         field="--fabric")
    return path


def list_presets(fabric_dir: Path = FABRIC_DIR) -> list[Path]:
    """Preset files in ``fabric_dir``, sorted by name."""
    return sorted(fabric_dir.glob("*.toml"))


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
