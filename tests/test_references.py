"""Comments, docstrings and docs name only things that exist: every repository path
(``catalog/...``, ``shaders/...``, ``docs/...``, ...) and every dotted name
``catalog.<room>.<module>.<name>`` mentioned in a text file of the repository resolves, so
that a moved or removed module leaves no stale pointer behind.

Resolved statically (no imports): a path must exist; a dotted name must be a module or
package of catalog/, optionally followed by a name defined or imported at the top level of
that module (a class, a function, an assignment) and then attributes of it, which are not
checked further.
"""

from __future__ import annotations

import ast
import functools
import importlib.util
import re
from pathlib import Path

import pytest

from catalog.core.resources import PROJECT_ROOT

ROOTS = ("README.md", "BENCHMARKS.md", "docs", "catalog", "shaders", "tools", "tests")
SUFFIXES = {".py", ".md", ".glsl", ".vert", ".frag", ".comp", ".sh", ".toml", ".js", ".html"}
TOP = ("catalog", "shaders", "tools", "tests", "benchmarks", "fabrics", "docs")
PATH = re.compile(rf"(?<![\w/.-])((?:{'|'.join(TOP)})/[\w./-]*\w)")
DOTTED = re.compile(r"(?<![\w.])catalog((?:\.\w+)+)")
#: What is named on purpose though it is not in the repository, each with its reason.
ALLOWED = {
    "catalog/_data": "the wheel's copy of shaders/ and fabrics/, made at build time (setup.py)",
    "fabrics/measurements/textyell": "docs/bispectral.md: an example --export output folder",
    "benchmarks/viewer_gpu.json": "docs/viewer.md: the output of a run on a GPU, not made yet",
    "benchmarks/gpu_check.json": "docs/gpu.md, tools/gpu_check.sh: the GPU check's output, not made yet (no GPU lent)",
    "catalog/optics/probe.py": "tests/test_architecture.py: a fixture module it writes",
    "catalog/render/probe.py": "tests/test_architecture.py: a fixture module it writes",
    "fabrics/x.toml": "tests/test_cloth.py: a fake preset's path",
}


def _files() -> list[Path]:
    out = []
    for name in ROOTS:
        path = PROJECT_ROOT / name
        candidates = [path] if path.is_file() else sorted(path.rglob("*"))
        out += [p for p in candidates if p.is_file() and p.suffix in SUFFIXES
                and "__pycache__" not in p.parts]
    return out


def _placeholder(text: str) -> bool:
    """``fabrics/NAME.toml``, ``tests/test_web*.py``: a pattern, not a path."""
    return bool(re.search(r"[*{}<>$]|\b[A-Z]{2,}\b", text))


def _allowed(ref: str) -> bool:
    return any(ref == a or ref.startswith(a + "/") for a in ALLOWED)


@functools.lru_cache(maxsize=None)
def _top_level_names(module_file: Path) -> frozenset[str]:
    tree = ast.parse(module_file.read_text(encoding="utf-8"))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                names |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
    return frozenset(names)


def _resolves(parts: list[str]) -> bool:
    """catalog + parts: a module or package, then a top-level name of it."""
    here = PROJECT_ROOT / "catalog"
    for i, part in enumerate(parts):
        if (here / part).is_dir():
            here = here / part
            continue
        if (here / f"{part}.py").is_file():
            rest = parts[i + 1:]
            return not rest or rest[0] in _top_level_names(here / f"{part}.py")
        init = here / "__init__.py"
        return init.is_file() and part in _top_level_names(init)
    return True


@pytest.mark.slow   # reads every text file of the checkout (1.4 s under load)
def test_every_repository_path_named_in_the_repository_exists():
    stale = []
    for file in _files():
        for number, line in enumerate(file.read_text(encoding="utf-8", errors="replace")
                                      .splitlines(), 1):
            for match in PATH.finditer(line):
                ref = match.group(1).rstrip(".")
                if _placeholder(ref + line[match.end():match.end() + 1]) or _allowed(ref) \
                        or (PROJECT_ROOT / ref).exists():
                    continue
                stale.append(f"{file.relative_to(PROJECT_ROOT)}:{number}: {ref}")
    assert not stale, "paths that do not exist:\n" + "\n".join(stale)


def _checked(parts: list[str], before: str, subpackages: set[str]) -> bool:
    """Whether a dotted name is meant as a module path: it starts with a room of catalog/,
    has two parts or more, or follows ``import``, ``from`` or ``:mod:``. ``catalog.entries``
    or ``catalog.png`` alone is a variable named catalog, or a file."""
    return (parts[0] in subpackages or len(parts) >= 2
            or bool(re.search(r"(import|from|:mod:`|:func:`|:class:`)\s*$", before)))


@pytest.mark.slow
def test_every_dotted_catalog_name_resolves():
    subpackages = {p.stem for p in (PROJECT_ROOT / "catalog").iterdir()
                   if (p.is_dir() and (p / "__init__.py").is_file()) or p.suffix == ".py"}
    stale = []
    for file in _files():
        for number, line in enumerate(file.read_text(encoding="utf-8", errors="replace")
                                      .splitlines(), 1):
            for match in DOTTED.finditer(line):
                parts = match.group(1).strip(".").split(".")
                if _checked(parts, line[:match.start()], subpackages) and not _resolves(parts):
                    stale.append(f"{file.relative_to(PROJECT_ROOT)}:{number}: "
                                 f"catalog.{'.'.join(parts)}")
    assert not stale, "dotted names that do not resolve:\n" + "\n".join(stale)


def test_the_checks_catch_a_stale_name():
    assert _resolves(["optics", "btdf", "hg_phase_between"])
    assert not _resolves(["optics", "btdf", "no_such_function"])
    assert not _resolves(["benchsuite", "colour"]) and not _resolves(["reference"])
    assert _checked(["reference"], "from ", set()) and not _checked(["entries"], "x = ", set())
    assert _resolves(["core", "constants", "FRAME_DT_S"])
    assert PATH.search("see benchmarks/report.py.").group(1).rstrip(".") == "benchmarks/report.py"
    assert _placeholder("fabrics/NAME.toml") and not _placeholder("fabrics/lace-fwa.toml")


def _defined_anywhere() -> set[str]:
    """Every function, class, assigned name and assigned attribute in catalog/ and tools/."""
    names = set()
    for file in [*(PROJECT_ROOT / "catalog").rglob("*.py"), *(PROJECT_ROOT / "tools").rglob("*.py")]:
        for node in ast.walk(ast.parse(file.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for target in targets:
                    for part in ast.walk(target):
                        if isinstance(part, ast.Name):
                            names.add(part.id)
                        elif isinstance(part, ast.Attribute):
                            names.add(part.attr)
    return names


@pytest.mark.slow
def test_every_sphinx_role_in_a_docstring_names_something_defined():
    """``:func:`name```, ``:meth:``, ``:class:``, ``:data:``, ``:attr:`` in catalog/: the last
    part of the name is defined somewhere in catalog/ (a removed helper leaves no pointer)."""
    role = re.compile(r":(?:func|meth|class|data|attr|mod):`~?([\w.]+)`")
    defined = _defined_anywhere()
    stale = []
    for file in (PROJECT_ROOT / "catalog").rglob("*.py"):
        for number, line in enumerate(file.read_text(encoding="utf-8").splitlines(), 1):
            for match in role.finditer(line):
                name = match.group(1)
                if name.startswith("catalog."):
                    ok = _resolves(name.split(".")[1:])
                elif name.startswith("."):  # relative to the file's package
                    target = file.parent / name.lstrip(".").replace(".", "/")
                    ok = target.is_dir() or target.with_suffix(".py").is_file()
                elif "." in name and importlib.util.find_spec(name.split(".")[0]) is not None \
                        and name.split(".")[0] != "catalog":
                    ok = True  # another package's (importlib.resources.files, numpy.einsum)
                else:
                    ok = name.split(".")[-1] in defined
                if not ok:
                    stale.append(f"{file.relative_to(PROJECT_ROOT)}:{number}: {match.group(0)}")
    assert not stale, "docstring roles naming nothing:\n" + "\n".join(stale)
