"""One validation per option value and per preset field, shared by every command (light:
no numpy, no GL).

Each bound here is the one the renderer, simulator or fitter can honour; a command that
takes the option uses these, so ``snapshot --distance`` and ``render-catalog --distance``
refuse the same values with the same line. Sizes of files are checked from their headers,
before their contents are read (:func:`check_image_header`, :func:`check_row_count`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from catalog.core.errors import InputError

#: A decimal number as a person writes it: no '_' digit separators (Python's float() takes
#: ``0_029`` as 29), no words (nan, inf, infinity), no hexadecimal, ASCII digits only.
_DECIMAL = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?", re.ASCII)
_WHOLE = re.compile(r"[+-]?\d+", re.ASCII)  # ASCII: int() also reads '１' (fullwidth)

#: The last cloth frame any command simulates (one hour of cloth at 60 frames a second;
#: a frame costs milliseconds to seconds, so a larger number is a typo or an attack).
MAX_FRAME = 216_000
#: Camera distance from the curtain, m (the near plane and the room bound it).
DISTANCE_M = (0.05, 50.0)
#: Exposure multiplier on top of the metered (or --ev) exposure: 20 stops either way; far
#: outside it an 8-bit image is all black or all white.
EXPOSURE = (2.0 ** -20, 2.0 ** 20)
#: Camera angles, deg.
YAW_DEG = (-360.0, 360.0)
PITCH_DEG = (-89.0, 89.0)
#: Sampler seeds (Mitsuba takes an unsigned 32-bit seed).
SEED_MAX = (1 << 32) - 1
#: Illuminance of a light at the fabric, lx (10x the noon sun's 1e5 lx as the top).
ILLUMINANCE_LX = (0.0, 1.0e6)
#: Absorption optical depth of the threads (e^-tau); beyond 50 nothing passes.
TAU = (0.0, 50.0)
#: The largest image a command reads whole (a pattern, an environment): 16384 a side and
#: 64 Mpx in all (about 1 GiB as float32 RGBA).
MAX_INPUT_SIDE_PX = 16384
MAX_INPUT_PIXELS = 1 << 26
#: Image suffixes the plots (matplotlib, Agg) are written in.
PLOT_SUFFIXES = (".png",)


def parse_float(text: str, option: str, *, what: str = "a number") -> float:
    """A finite decimal number; refused (naming ``option``) for '_' separators, words,
    NaN and infinity."""
    raw = str(text).strip()
    if not _DECIMAL.fullmatch(raw):
        raise InputError(f"{str(text)[:24]!r} is not {what} (plain decimal digits)", field=option)
    value = float(raw)
    if not math.isfinite(value):
        raise InputError(f"{str(text)[:24]!r} is too large to be {what}", field=option)
    return value


def parse_whole(text: str, option: str) -> int:
    raw = str(text).strip()
    if not _WHOLE.fullmatch(raw) or len(raw) > 24:
        raise InputError(f"{str(text)[:24]!r} is not a whole number", field=option)
    return int(raw)


def check_range(value: float, option: str, low: float, high: float, *, unit: str = "",
                low_open: bool = False, high_open: bool = False) -> float:
    """``value`` inside the bounds, else one line naming the option and the bound."""
    ok = math.isfinite(value) and (value > low if low_open else value >= low) \
        and (value < high if high_open else value <= high)
    if not ok:
        lo, hi = ("(" if low_open else "["), (")" if high_open else "]")
        raise InputError(f"{value!r} is outside {lo}{low:g}, {high:g}{hi}"
                         + (f" {unit}" if unit else ""), field=option)
    return value


def check_frame(frame, option: str = "--frame") -> int:
    """A cloth frame: a whole number in 0..MAX_FRAME."""
    if isinstance(frame, bool) or not isinstance(frame, int):
        raise InputError(f"{frame!r} is not a whole number", field=option)
    if not 0 <= frame <= MAX_FRAME:
        raise InputError(f"{frame} is outside 0..{MAX_FRAME} (one hour of cloth at 60 "
                         "frames a second)", field=option)
    return frame


def check_seed(seed, option: str = "--seed") -> int:
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= SEED_MAX:
        raise InputError(f"{seed!r} is outside 0..{SEED_MAX} (an unsigned 32-bit seed)",
                         field=option)
    return seed


def check_camera(option_values: dict[str, float | None]) -> None:
    """``--distance``, ``--exposure``, ``--yaw``, ``--pitch`` (whichever are given): the
    same bounds for snapshot, reference, render-catalog and view."""
    bounds = {"--distance": (*DISTANCE_M, "m", True), "--exposure": (*EXPOSURE, "", False),
              "--yaw": (*YAW_DEG, "deg", False), "--pitch": (*PITCH_DEG, "deg", False)}
    for option, value in option_values.items():
        if value is None:
            continue
        low, high, unit, low_open = bounds[option]
        check_range(float(value), option, low, high, unit=unit, low_open=low_open)


def parse_light_list(text: str | None, option: str = "--lights") -> list[str]:
    """``D65,A,sun:22,sun@2026-06-21T12:00,34.7,-120`` -> the light names in order.

    ``sun@DATE,LAT,LON`` keeps its two commas (the two fields after it that are numbers
    belong to it). Refused: an empty list, an empty name between commas, a repeated light.
    """
    if text is None or not str(text).strip():
        raise InputError(f"{text!r}: name at least one light (e.g. D65,A)", field=option)
    fields = [f.strip() for f in str(text).split(",")]
    names: list[str] = []
    i = 0
    while i < len(fields):
        field = fields[i]
        if field.startswith("sun@") and i + 2 < len(fields):
            names.append(",".join(fields[i:i + 3]))
            i += 3
            continue
        names.append(field)
        i += 1
    if any(not name for name in names):
        raise InputError(f"{text!r}: an empty light name between commas", field=option)
    seen = set()
    for name in names:
        if name in seen:
            raise InputError(f"{name!r} is named twice", field=option)
        seen.add(name)
    return names


_FRAME_FIELD = re.compile(r"\{frame(:0?([1-9]\d?)?d)?\}")


def check_frame_template(text: str, option: str = "--out") -> None:
    """A file-name pattern with one ``{frame}`` field (``{frame:04d}``: up to 99 digits);
    any other field, a second one or a huge width is refused before it is formatted."""
    fields = re.findall(r"\{[^{}]*\}", text.replace("{{", "").replace("}}", ""))
    if len(fields) != 1 or not _FRAME_FIELD.fullmatch(fields[0]):
        raise InputError(f"{text[:60]!r} must hold exactly one {{frame}} field, e.g. "
                         "f{frame:04d}.obj (a width of at most 99 digits)", field=option)


def check_plot_path(path, option: str = "--plot", suffixes=PLOT_SUFFIXES) -> Path:
    """A plot's file name must end in an image suffix the writer makes."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise InputError(f"{str(path)!r}: the plot is an image; end the name in "
                         f"{' or '.join(suffixes)}", field=option)
    return path


def check_image_header(path, width: int, height: int, channels: int, field: str | None = None) -> None:
    """An image's size read from its header, before its pixels are: refused above
    MAX_INPUT_SIDE_PX a side or MAX_INPUT_PIXELS in all."""
    if not (0 < width <= MAX_INPUT_SIDE_PX and 0 < height <= MAX_INPUT_SIDE_PX
            and width * height <= MAX_INPUT_PIXELS and 0 < channels <= 64):
        raise InputError(f"the image is {width}x{height} with {channels} channels: at most "
                         f"{MAX_INPUT_SIDE_PX} px a side and {MAX_INPUT_PIXELS >> 20} Mpx are "
                         "read", path=path, field=field)


def check_row_count(path, rows: int, limit: int, what: str, line: int | None = None) -> None:
    """A count of rows a file's header claims, before the rows are read."""
    if not 0 < rows <= limit:
        raise InputError(f"{what}: {rows:g} is outside 1..{limit}", path=path, line=line)


def frame_memory_check(width: int, height: int, bytes_per_pixel: int, option: str = "--size") -> None:
    """The memory one image of ``width`` x ``height`` takes at ``bytes_per_pixel``, against a
    quarter of physical memory (the same rule snapshot's frame uses)."""
    import os  # noqa: PLC0415

    try:
        budget = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 4
    except (ValueError, OSError, AttributeError):
        budget = 4 << 30
    need = width * height * bytes_per_pixel
    if need > budget:
        raise InputError(f"{width}x{height} needs about {need >> 20} MiB, more than the "
                         f"{budget >> 20} MiB this machine allows; choose a smaller size",
                         field=option)


# --------------------------------------------------------------------------- preset tables

#: The weaves of a preset's [cloth] table (catalog.cloth.params.WEAVE_DEFAULTS has their
#: defaults; tests/test_cli_hostile.py holds the two lists equal).
WEAVES = ("lace", "voile", "plain", "twill", "satin")
#: The optional tables of a preset (formats.md): each must be a table when present.
PRESET_TABLES = ("btdf", "fit", "fluorescence", "dye", "cloth", "pattern")
#: [cloth] keys: key -> (kind, low, high) with kind "weave", "number".
CLOTH_FIELDS = {
    "areal_density_kg_m2": (1e-4, 10.0), "stretch_stiffness_n_m": (1e-3, 1e9),
    "bend_stiffness_n_m": (0.0, 1e6), "fullness": (1.0, 3.0),
}
#: [pattern] number keys and their bounds.
PATTERN_NUMBERS = {"height_m": (0.0, 0.1), "net_thread_mm": (0.0, 100.0), "border_m": (1e-4, 1.0)}
PATTERN_PATHS = ("coverage", "height", "border", "border_height")


def _is_number(value) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float))


def check_preset_tables(doc: dict, where, weaves) -> None:
    """Types and bounds of the optional tables' fields: a field of the wrong type (a list
    where a name is wanted, a number where a table is) is refused naming it, never ignored."""
    for table in PRESET_TABLES:
        if table in doc and not isinstance(doc[table], dict):
            raise InputError(f"must be a table ([{table}]), found {type(doc[table]).__name__} "
                             f"{str(doc[table])[:30]!r}", path=where, field=table)
    cloth = doc.get("cloth", {})
    if "weave" in cloth and (not isinstance(cloth["weave"], str) or cloth["weave"] not in weaves):
        raise InputError(f"{str(cloth['weave'])[:30]!r}: the weave is one of "
                         f"{', '.join(weaves)}", path=where, field="cloth.weave")
    for key, (low, high) in CLOTH_FIELDS.items():
        if key in cloth:
            _field_in(where, f"cloth.{key}", cloth[key], low, high)
    pattern = doc.get("pattern", {})
    for key in PATTERN_PATHS:
        if key in pattern and not (isinstance(pattern[key], str) and pattern[key]):
            raise InputError(f"must be a path string, found {str(pattern[key])[:30]!r}",
                             path=where, field=f"pattern.{key}")
    if "kind" in pattern and not isinstance(pattern["kind"], str):
        raise InputError("must be a string", path=where, field="pattern.kind")
    for key, (low, high) in PATTERN_NUMBERS.items():
        if key in pattern:
            _field_in(where, f"pattern.{key}", pattern[key], low, high)
    # repeat_m (a length or two) is checked where the pattern is built
    # (catalog.presets.patterns._repeat), with the image it repeats


def _field_in(where, key, value, low, high) -> None:
    if not _is_number(value) or not (math.isfinite(value) and low <= value <= high):
        raise InputError(f"must be a number in [{low:g}, {high:g}], found {str(value)[:30]!r}",
                         path=where, field=key)
