"""The shader preprocessor: #include resolution with a depth limit, #define injection."""

from __future__ import annotations

import re

import pytest

from catalog.core.resources import PROJECT_ROOT, SHADER_DIR
from catalog.core.errors import CatalogError
from catalog.gl import shaderlib


@pytest.fixture
def shader_folder(tmp_path, monkeypatch):
    monkeypatch.setattr(shaderlib, "SEARCH_PATH", [tmp_path])
    return tmp_path


def test_include_is_expanded_and_defines_follow_version(shader_folder):
    (shader_folder / "a.frag").write_text('#version 430\n#include "b.glsl"\nvoid main() {}\n')
    (shader_folder / "b.glsl").write_text("float b() { return 1.0; }\n")
    source = shaderlib.load_source("a.frag", {"N_BANDS": 6, "SEE_THROUGH": True, "OFF": False})
    lines = source.splitlines()
    assert lines[0] == "#version 430"
    # the shared constants (catalog/core/constants.py) are defined in every program, sorted in
    assert lines[1:5] == ["#define AMBIENT_VIEW_NODES 17", "#define HG_MIRROR_BELOW -0.2",
                          "#define N_BANDS 6", "#define SEE_THROUGH"]
    assert "float b() { return 1.0; }" in lines
    assert "#define OFF" not in source
    assert "#include" not in source


def test_include_cycle_is_refused_in_one_line(shader_folder):
    (shader_folder / "a.frag").write_text('#version 430\n#include "b.glsl"\n')
    (shader_folder / "b.glsl").write_text('#include "c.glsl"\n')
    (shader_folder / "c.glsl").write_text('#include "b.glsl"\n')
    with pytest.raises(CatalogError) as err:
        shaderlib.load_source("a.frag")
    message = str(err.value)
    assert "\n" not in message and "deeper than" in message and "b.glsl -> c.glsl" in message


def test_missing_include_and_missing_version_are_named(shader_folder):
    (shader_folder / "a.frag").write_text('#version 430\n#include "nowhere.glsl"\n')
    with pytest.raises(CatalogError, match="nowhere.glsl"):
        shaderlib.load_source("a.frag")
    (shader_folder / "v.frag").write_text("void main() {}\n")
    with pytest.raises(CatalogError, match="no #version"):
        shaderlib.load_source("v.frag")
    (shader_folder / "d.frag").write_text("#version 430\n")
    with pytest.raises(CatalogError, match="bad shader #define"):
        shaderlib.load_source("d.frag", {"1BAD": 1})


def test_every_program_includes_the_one_common_file():
    programs = [p for p in SHADER_DIR.iterdir() if p.suffix in (".frag", ".comp")
                and not p.name.startswith("cloth_")]
    assert programs
    for program in programs:
        source = shaderlib.load_source(program.name, {"N_BANDS": 3, "NV4": 1,
                                                      "FLUORESCENCE_OFF": True})
        if program.name != "trivial.frag":
            assert "hg_phase_robust" in source, program.name


def test_no_glsl_source_in_python():
    pattern = re.compile(r"#version\s+\d{3}|gl_FragColor|gl_Position\s*=")
    offenders = [str(p.relative_to(PROJECT_ROOT)) for p in (PROJECT_ROOT / "catalog").rglob("*.py")
                 if pattern.search(p.read_text(encoding="utf-8"))]
    assert offenders == []


def test_shared_constants_come_from_python_only():
    """A constant GLSL and Python share is written once, in catalog/core/constants.py: no
    shader assigns HG_MIRROR_BELOW a value of its own, and the compiled source has the
    Python value."""
    from catalog.core.constants import HG_MIRROR_BELOW, SHADER_DEFINES

    for path in SHADER_DIR.rglob("*"):
        if path.suffix in (".glsl", ".frag", ".vert", ".comp"):
            text = path.read_text(encoding="utf-8")
            for name in SHADER_DEFINES:
                assert not re.search(rf"(const\s+\w+\s+{name}\s*=|#define\s+{name}\b)", text), path
    source = shaderlib.load_source("curtain.frag", {"N_BANDS": 3, "NV4": 1})
    assert f"#define HG_MIRROR_BELOW {HG_MIRROR_BELOW}" in source
