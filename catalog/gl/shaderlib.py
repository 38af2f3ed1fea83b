"""Shader files: ``#include "name"`` resolved from registered folders, ``#define``s injected.

After moderngl-window's program loader: sources are files (never strings in Python), an
include is searched in the including file's folder and then in the registered folders, and
nesting deeper than :data:`MAX_INCLUDE_DEPTH` is refused (which also catches cycles).
Defines are written right after the ``#version`` line, so a variant is chosen at compile time;
the constants Python and GLSL share (:data:`catalog.core.constants.SHADER_DEFINES`) are
defined in every program, so GLSL never repeats their values.

Dialects: the files are written for desktop GLSL 4.30 (``core``); :data:`DIALECTS` ``"es300"``
emits the GLSL ES 3.00 variant of the same files for WebGL2 (the web catalog): the version line
names version 300 es and default precisions (highp) follow the defines. Nothing else
differs, so a change to a shader file reaches the desktop and the web page alike.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Mapping

from catalog.core.resources import SHADER_DIR
from catalog.core.constants import SHADER_DEFINES
from catalog.core.errors import CatalogError, EnvironmentFailure

#: Deeper nesting than this is an error (an include cycle always reaches it).
MAX_INCLUDE_DEPTH = 8

_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
_VERSION = re.compile(r"^\s*#\s*version\b")
_DEFINE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")

#: Folders searched for shader files, in order.
SEARCH_PATH: list[Path] = [SHADER_DIR]


def register_folder(folder: str | Path) -> None:
    """Add a folder to the search path (searched after those already there)."""
    folder = Path(folder).resolve()
    if folder not in SEARCH_PATH:
        SEARCH_PATH.append(folder)


def find_shader(name: str, near: Path | None = None) -> Path:
    """The file ``name``: next to ``near`` first, then in the registered folders."""
    folders = ([near] if near is not None else []) + SEARCH_PATH
    for folder in folders:
        candidate = folder / name
        if candidate.is_file():
            return candidate
    searched = ", ".join(str(f) for f in folders)
    raise EnvironmentFailure(f"shader file {name!r} not found (searched {searched})")


def _expand(path: Path, depth: int, chain: tuple[str, ...]) -> list[str]:
    if depth > MAX_INCLUDE_DEPTH:
        raise CatalogError(f"shader includes nested deeper than {MAX_INCLUDE_DEPTH} "
                           f"(a cycle?): {' -> '.join(chain)}")
    lines = []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        match = _INCLUDE.match(line)
        if match is None:
            lines.append(line)
            continue
        included = find_shader(match.group(1), near=path.parent)
        lines.append(f"// begin {match.group(1)} (from {path.name}:{number})")
        lines.extend(_expand(included, depth + 1, chain + (included.name,)))
        lines.append(f"// end {match.group(1)}")
    return lines


def _define_lines(defines: Mapping[str, object]) -> list[str]:
    out = []
    for name, value in sorted(defines.items()):
        if not _DEFINE_NAME.match(name):
            raise CatalogError(f"bad shader #define name {name!r}")
        if value is None or value is True:
            out.append(f"#define {name}")
        elif value is False:
            continue
        else:
            out.append(f"#define {name} {value}")
    return out


#: Shader dialects: name -> (version of the version line, lines after the defines).
DIALECTS: dict[str, tuple[str | None, tuple[str, ...]]] = {
    "core": (None, ()),  # the file's own version line (430)
    "es300": ("300 es", ("precision highp float;", "precision highp int;",
                                  "precision highp sampler2D;", "precision highp sampler2DShadow;")),
}


def load_source(name: str, defines: Mapping[str, object] | None = None,
                dialect: str = "core") -> str:
    """The full source of shader file ``name``: includes expanded, ``defines`` injected.

    ``defines`` maps a name to a value (``N_BANDS=6``), or to None/True for a bare
    ``#define NAME``; False leaves it out. ``dialect``: a key of :data:`DIALECTS`.
    """
    if dialect not in DIALECTS:
        raise CatalogError(f"unknown shader dialect {dialect!r}; known: {', '.join(DIALECTS)}")
    version, preamble = DIALECTS[dialect]
    path = find_shader(name)
    lines = _expand(path, 0, (path.name,))
    extra = _define_lines({**SHADER_DEFINES, **(defines or {})}) + list(preamble)
    for index, line in enumerate(lines):
        if _VERSION.match(line):
            head = [f"#version {version}"] if version is not None else lines[index:index + 1]
            return "\n".join(lines[:index] + head + extra + lines[index + 1:]) + "\n"
    raise CatalogError(f"shader file {path} has no #version line")


def glsl_literal(value) -> str:
    """A value as a GLSL constant expression for a #define: a float, a vec2/vec3/vec4 tuple, or
    a float array of 4k values as ``vec4[k](...)``. Floats keep 9 significant digits, which
    round-trips float32 exactly."""
    import numpy as np  # noqa: PLC0415

    def number(x) -> str:
        x = float(np.float32(x))
        if not np.isfinite(x):
            raise CatalogError(f"a shader constant must be finite, got {x}")
        return f"{x:.9e}"

    if isinstance(value, np.ndarray):
        flat = value.astype(np.float32).ravel()
        if flat.size == 0 or flat.size % 4:
            raise CatalogError(f"a vec4 array constant needs 4k values, got {flat.size}")
        chunks = [f"vec4({', '.join(number(v) for v in flat[i:i + 4])})"
                  for i in range(0, flat.size, 4)]
        return f"vec4[{len(chunks)}]({', '.join(chunks)})"
    if isinstance(value, (tuple, list)):
        if len(value) not in (2, 3, 4):
            raise CatalogError(f"a vector constant needs 2 to 4 values, got {len(value)}")
        return f"vec{len(value)}({', '.join(number(v) for v in value)})"
    return number(value)


def create_program(ctx, vertex: str, fragment: str | None = None,
                   defines: Mapping[str, object] | None = None, fragment_outputs=None):
    """A moderngl program from shader files; compile errors become one-line
    EnvironmentFailures (the installed shaders or the driver are at fault, exit 3)."""
    import moderngl  # noqa: PLC0415

    recipe_sink = getattr(ctx, "program_recipe_sink", None)
    if recipe_sink is not None:  # a recording context (catalog.web.record) notes the recipe
        recipe_sink(vertex, fragment, dict(defines or {}))
    sources = {"vertex_shader": load_source(vertex, defines)}
    if fragment is not None:
        sources["fragment_shader"] = load_source(fragment, defines)
    try:
        return ctx.program(**sources, fragment_outputs=fragment_outputs)
    except moderngl.Error as exc:
        first = next((ln for ln in str(exc).splitlines() if "error" in ln.lower()), str(exc))
        raise EnvironmentFailure(f"shader {vertex}+{fragment} failed to compile: {first.strip()}") from None


def create_compute(ctx, name: str, defines: Mapping[str, object] | None = None):
    """A moderngl compute shader from a file."""
    import moderngl  # noqa: PLC0415

    try:
        return ctx.compute_shader(load_source(name, defines))
    except moderngl.Error as exc:
        first = next((ln for ln in str(exc).splitlines() if "error" in ln.lower()), str(exc))
        raise EnvironmentFailure(f"compute shader {name} failed to compile: {first.strip()}") from None
