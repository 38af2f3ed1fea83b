"""The house: which room may import which (docs/architecture.md), checked statically.

Every import statement of every module under catalog/ is read with ``ast`` (lazy imports
inside functions included, since a lazy import still runs when that path runs), mapped to
the room it comes from and the room it reaches, and checked against the design's rules.
Nothing is imported to do this, so the test is fast and sees every branch.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "catalog"

#: Rooms that may import only themselves and the rooms listed (the base of the house).
ONLY = {
    "core": {"core"},
    "gl": {"gl", "core"},
    "optics": {"optics", "core"},
    "presets": {"presets", "core", "optics"},
}

#: (importing room, imported room or top-level module): arrows that must never exist.
FORBIDDEN = [
    ("optics", "render"), ("optics", "viewer"), ("optics", "gl"),   # the physics knows no GL
    ("render", "fit"), ("viewer", "fit"),                           # drawing never fits ...
    ("render", "scipy"), ("viewer", "scipy"),                       # ... nor imports scipy
    ("render", "tools"), ("viewer", "tools"),
    ("cloth", "viewer"), ("cloth", "render"),                       # cloth reaches GL via gl
    ("presets", "render"), ("presets", "viewer"),
    ("render", "pathtrace"), ("viewer", "pathtrace"),               # Mitsuba stays out of frames
    ("render", "exchange"), ("viewer", "exchange"), ("presets", "exchange"),  # formats in/out sit above
]
#: Module pairs allowed to import each other (none: image writing lives in render.imagefile,
#: which both the snapshot and the environment tool use).
KNOWN_CYCLES: set[tuple[str, str]] = set()
#: The one module of the package that may import the benchmarks (top-level ``benchmarks/``,
#: not in the wheel): ``catalog bench`` runs them when a checkout has them.
BENCH_IMPORTERS = {"catalog/commands/bench.py"}


def _module_name(path: Path, package: Path = PACKAGE) -> str:
    parts = list(path.relative_to(package.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _room(module: str) -> str:
    """``catalog.optics.sun.model`` -> ``optics``; ``catalog`` itself -> ``catalog``;
    anything outside the package -> its top-level name (``scipy``)."""
    parts = module.split(".")
    if parts[0] != "catalog":
        return parts[0]
    return parts[1] if len(parts) > 1 else "catalog"


def _imports(path: Path, package_dir: Path = PACKAGE) -> list[tuple[int, str]]:
    """(line, imported module) for every import in the file, relative ones resolved."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    here = _module_name(path, package_dir).split(".")
    package = here if path.name == "__init__.py" else here[:-1]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            found.append((node.lineno, module))
            # ``from catalog import optics`` reaches the optics room
            found += [(node.lineno, f"{module}.{alias.name}") for alias in node.names
                      if module == "catalog"]
    return found


def _edges(package: Path = PACKAGE) -> list[tuple[str, int, str, str]]:
    """(file, line, from room, to room) for every import that crosses a room."""
    edges = []
    for path in sorted(package.rglob("*.py")):
        source = _room(_module_name(path, package))
        for line, module in _imports(path, package):
            target = _room(module)
            if target != source:
                edges.append((path.relative_to(package.parent).as_posix(), line, source, target))
    return edges


EDGES = _edges()
ROOMS = sorted({p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()})


def test_the_rooms_are_there():
    for room in ("core", "optics", "presets", "fit", "gl", "cloth", "render", "viewer",
                 "commands", "exchange", "room"):
        assert room in ROOMS
    # the top level holds only the package's own entry points, no module of a room
    loose = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert loose == ["__init__.py", "__main__.py"]


@pytest.mark.parametrize("room", sorted(ONLY))
def test_base_rooms_import_only_what_is_below_them(room):
    inside = {r for r in ROOMS} | {"catalog"}
    bad = [f"{f}:{line} {src} -> {dst}" for f, line, src, dst in EDGES
           if src == room and dst in inside and dst not in ONLY[room]]
    assert bad == []


def test_no_forbidden_arrow():
    forbidden = set(FORBIDDEN)
    bad = [f"{f}:{line} {src} -> {dst}" for f, line, src, dst in EDGES if (src, dst) in forbidden]
    assert bad == []


def test_only_the_bench_command_imports_the_benchmarks():
    """The benchmarks live outside the package (``benchmarks/``); the product imports them
    only in ``catalog bench``, which says in one line when they are not there."""
    bad = [f"{f}:{line} {src} -> benchmarks" for f, line, src, dst in EDGES
           if dst == "benchmarks" and f not in BENCH_IMPORTERS]
    assert bad == []
    assert not (PACKAGE / "bench").exists()


@pytest.mark.slow
def test_no_module_imports_one_that_imports_it():
    """No two modules import each other (lazily or not): a cycle is a room boundary drawn
    in the wrong place (cloth's backends and simulation, cloth and render, once)."""
    graph: dict[str, set[str]] = {}
    modules = {_module_name(p) for p in PACKAGE.rglob("*.py")}
    for path in PACKAGE.rglob("*.py"):
        name = _module_name(path)
        targets = set()
        for _, module in _imports(path):
            # ``from catalog.cloth import mesh`` names the module catalog.cloth.mesh
            targets |= {m for m in (module,) if m in modules}
        graph[name] = targets - {name}
    cycles = sorted({tuple(sorted((a, b))) for a in graph for b in graph[a]
                     if a in graph.get(b, set()) and not (b.startswith(a + ".") or a.startswith(b + "."))})
    assert sorted(set(cycles) - KNOWN_CYCLES) == []


def test_the_checker_sees_a_forbidden_import(tmp_path):
    """The rules can fail: a lazy import of the renderer in an optics module, and a relative
    one of the benchmarks in the renderer, are both seen."""
    package = tmp_path / "catalog"
    (package / "optics").mkdir(parents=True)
    (package / "render").mkdir()
    for init in (package, package / "optics", package / "render"):
        (init / "__init__.py").write_text("")
    (package / "optics" / "probe.py").write_text("def f():\n    from catalog.render import frame\n")
    (package / "render" / "probe.py").write_text("from benchmarks import colour\n")
    edges = _edges(package)
    assert ("catalog/optics/probe.py", 2, "optics", "render") in edges
    assert ("catalog/render/probe.py", 1, "render", "benchmarks") in edges


#: The longest a module of catalog/ may be (docs/GUIDE: small modules with one job each).
MAX_MODULE_LINES = 900
#: The frame's only setters: the geometry it draws (the cloth's mesh, its size and offset, the
#: rings), which the cloth simulation hands it. What a user chooses (light, fabric, camera,
#: exposure, white balance, bands, fluorescence, anti-aliasing, room lighting, glare,
#: shadow-map size, curtain, lamps, sky, environment) is one FrameSettings value given to
#: FrameRenderer(..., settings) or FrameRenderer.update (issue 31); earlier variants of the
#: method are in git history, not behind switches: any other setter fails.
FRAME_SETTERS = {"set_mesh", "set_fabric_size", "set_mesh_offset", "set_rings"}


def test_no_module_is_over_the_size_limit():
    long = {p.relative_to(PACKAGE.parent).as_posix(): n for p in PACKAGE.rglob("*.py")
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES}
    assert long == {}


def _frame_setters(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    classes = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "FrameRenderer"]
    return {n.name for c in classes for n in c.body
            if isinstance(n, ast.FunctionDef) and n.name.startswith("set_")}


def _setters_by_name(tree) -> list[int]:
    """Lines of ``getattr(x, f"set_...")``: a setter chosen by a string (an ablation switch)."""
    return [node.lineno for node in ast.walk(tree)
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "getattr"
            and len(node.args) >= 2 and isinstance(node.args[1], (ast.JoinedStr, ast.Constant))
            and (ast.unparse(node.args[1]).lstrip("f").strip("'\"").startswith("set_"))]


@pytest.mark.slow   # builds a frame renderer and walks its methods (about 1.1 s)
def test_the_frame_has_no_ablation_switches():
    """FrameRenderer has no setter but the geometry's (FRAME_SETTERS: a user's choices are
    its FrameSettings), and no module picks a setter by its name (the image bench's
    ``getattr(renderer, f"set_{name}")`` of issue 11's switches)."""
    extra = _frame_setters(PACKAGE / "render" / "frame.py") - FRAME_SETTERS
    assert extra == set()
    by_name = {p.relative_to(PACKAGE.parent).as_posix(): lines for p in PACKAGE.rglob("*.py")
               if (lines := _setters_by_name(ast.parse(p.read_text(encoding="utf-8"))))}
    assert by_name == {}


def test_the_size_and_switch_checks_can_fail(tmp_path):
    """The checks see a setter outside the list and a setter picked by name."""
    probe = tmp_path / "frame.py"
    probe.write_text("class FrameRenderer:\n    def set_room_bounces(self, b):\n        pass\n"
                     "    def set_bands(self, n):\n        pass\n")
    assert _frame_setters(probe) - FRAME_SETTERS == {"set_room_bounces", "set_bands"}
    tree = ast.parse('def f(r, name):\n    getattr(r, f"set_{name}")(True)\n')
    assert _setters_by_name(tree) == [2]


#: Below the edge (issue 31): the renderers draw the resolved scene (FrameSettings, its
#: catalog.presets.fabric.Fabric) and read no file. The packages checked:
BELOW_THE_EDGE = ("render", "pathtrace", "cloth")
#: The modules among them that may read a file, and why.
MAY_READ = {
    "catalog/render/settings.py": "the edge's resolution: a preset name, the environment image",
    "catalog/render/snapshot.py": "the snapshot command: its request resolved (the edge)",
    "catalog/render/sheet.py": "the sheet command: its presets resolved (the edge)",
    "catalog/pathtrace/render.py": "the reference's scene resolved (reference_settings: the edge)",
    "catalog/render/environment.py": "the environment image's reader (settings call it)",
    "catalog/render/imagefile.py": "image files written and read back (the commands' outputs)",
    "catalog/render/display.py": "the display's own tables (package data, not the scene)",
    "catalog/cloth/drape_cache.py": "the drape cache (results kept, not inputs)",
    "catalog/render/room_operators.py": "the room's bundle, a cache of the resolved room: read from the cache (keyed by the loaded Room's hash); only the viewer, which keeps trimesh off its path, names a room and has its file hashed here",
}
#: What reads a file: a call of open(), np.load, json/tomllib/pickle/trimesh.load, an image
#: input's open, a Path's read_text/read_bytes, an imread/read_image/loadtxt, or one of the
#: project's readers (presets, spectra, patterns, residuals, environments, rooms).
_LOADERS = {"load": {"np", "numpy", "json", "tomllib", "pickle", "trimesh"}, "loads": {"tomllib"},
            "open": {"ImageInput", "Image", "gzip", "zipfile", "tarfile", "io"}}
_READ_METHODS = {"read_text", "read_bytes", "imread", "read_image", "loadtxt", "genfromtxt",
                 "fromfile"}
_READERS = {"open", "read_spectrum", "load_preset", "find_preset", "load_pattern",
            "pattern_from_images", "read_residual", "load_environment", "load_room"}


def _file_reads(tree) -> list[tuple[int, str]]:
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        if isinstance(f, ast.Name) and f.id in _READERS:
            found.append((node.lineno, f.id))
        elif isinstance(f, ast.Attribute):
            base = f.value.attr if isinstance(f.value, ast.Attribute) else getattr(f.value, "id", None)
            if f.attr in _READ_METHODS or f.attr in _READERS or base in _LOADERS.get(f.attr, ()):
                found.append((node.lineno, ast.unparse(f)))
    return found


def test_no_file_is_read_below_the_edge():
    """No module of render/, pathtrace/ or cloth/ reads a file but those MAY_READ names; the
    frame, its passes and the scene terms draw what the edge resolved."""
    reads = {}
    for package in BELOW_THE_EDGE:
        for path in sorted((PACKAGE / package).rglob("*.py")):
            name = path.relative_to(PACKAGE.parent).as_posix()
            if name not in MAY_READ and (found := _file_reads(ast.parse(path.read_text(encoding="utf-8")))):
                reads[name] = found
    assert reads == {}


def test_the_file_read_check_can_fail():
    tree = ast.parse("import numpy as np\nfrom pathlib import Path\n"
                     "def f(p):\n    a = np.load(p)\n    b = Path(p).read_text()\n"
                     "    c = open(p)\n    d = read_spectrum(p)\n    e = self.backend.load(p)\n")
    assert [line for line, _ in _file_reads(tree)] == [4, 5, 6, 7]
