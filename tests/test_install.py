"""The installable product: what the wheel carries, that an installed copy finds its
shaders and fabrics without the checkout, and that the repository stands alone."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from catalog.core.resources import PROJECT_ROOT

#: Files the wheel must carry inside the package (a sample of each kind).
SHIPPED = ["catalog/_data/shaders/common.glsl", "catalog/_data/shaders/curtain.frag",
           "catalog/_data/fabrics/lace-fwa.toml",
           "catalog/_data/fabrics/measurements/lace-fwa/excitation.csv",
           "catalog/_data/fabrics/measurements/lace-fwa/gonio.csv",
           "catalog/optics/data/reference_tables.npz",
           "catalog/room/data/box.glb", "catalog/room/data/living.glb",
           "catalog/room/data/bedroom.glb"]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    result = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w",
                             str(out), str(PROJECT_ROOT)], capture_output=True, text=True,
                            timeout=600)
    if result.returncode != 0:
        pytest.fail(f"pip wheel failed: {result.stderr[-1500:]}")
    (path,) = out.glob("*.whl")
    return path


@pytest.mark.slow
def test_wheel_carries_shaders_fabrics_tables_and_licence(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    missing = [name for name in SHIPPED if name not in names]
    assert missing == []
    shaders = {Path(n).name for n in names if n.startswith("catalog/_data/shaders/")}
    assert shaders == {p.name for p in (PROJECT_ROOT / "shaders").iterdir() if p.is_file()}
    presets = {Path(n).name for n in names if re.fullmatch(r"catalog/_data/fabrics/[^/]+\.toml", n)}
    assert presets == {p.name for p in (PROJECT_ROOT / "fabrics").glob("*.toml")}
    assert any(n.endswith(".dist-info/LICENSE") or "licenses/LICENSE" in n for n in names)
    assert not any("test" in Path(n).parts[0] for n in names)  # tests stay out
    assert not any(Path(n).parts[0] == "benchmarks" or "/bench/" in n for n in names)  # so do the benchmarks


@pytest.mark.slow
def test_an_installed_copy_finds_its_resources_outside_the_checkout(wheel, tmp_path):
    """The wheel unpacked away from the checkout (as pip installs it), run from another
    folder: shaders, presets and their measurements come from inside the package."""
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    work = tmp_path / "elsewhere"
    work.mkdir()
    code = (
        "import json, catalog\n"
        "from catalog.core import resources as r\n"
        "from catalog.gl.shaderlib import load_source\n"
        "from catalog.presets import find_preset, load_preset, list_presets\n"
        "preset = load_preset(find_preset('lace-fwa'))\n"
        "print(json.dumps({'package': catalog.__file__, 'shaders': str(r.SHADER_DIR),\n"
        "  'fabrics': str(r.FABRIC_DIR), 'checkout': r.IN_CHECKOUT,\n"
        "  'data_default': r.DEFAULT_DATA_DIR, 'presets': len(list_presets()),\n"
        "  'source': len(load_source('curtain.frag', {'N_BANDS': 3, 'NV4': 1})),\n"
        "  'excitation': str(preset.fluorescence.excitation)}))\n")
    env = {"PYTHONPATH": str(site), "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)}
    result = subprocess.run([sys.executable, "-c", code], cwd=work, env=env,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert info["package"].startswith(str(site))
    for key in ("shaders", "fabrics", "excitation"):
        assert info[key].startswith(str(site / "catalog" / "_data")), (key, info[key])
    assert info["checkout"] is False and info["data_default"] is None
    assert info["presets"] == len(list((PROJECT_ROOT / "fabrics").glob("*.toml")))
    assert info["source"] > 1000


def _tracked_text_files() -> list[Path]:
    out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                         cwd=PROJECT_ROOT, capture_output=True, text=True, check=True).stdout
    paths = [PROJECT_ROOT / p for p in out.split("\0") if p]
    return [p for p in paths if p.is_file() and p.suffix in
            {".py", ".md", ".toml", ".sh", ".glsl", ".frag", ".vert", ".comp", ".txt", ".in", ""}]


def test_nothing_refers_to_a_path_outside_the_repository():
    """No README, doc, --help text, comment or script points at a folder beside or above
    the checkout (the validation data is named by --data / $CATALOG_DATA instead)."""
    pattern = re.compile(r"\.\./shared|/work/|shared/(spec|seed)|\.\./\.\./")
    me = Path(__file__).resolve()
    offenders = []
    for path in _tracked_text_files():
        if path.resolve() == me:
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace")
                                      .splitlines(), start=1):
            if pattern.search(line):
                offenders.append(f"{path.relative_to(PROJECT_ROOT)}:{number}: {line.strip()[:80]}")
    assert offenders == []


def test_help_texts_point_inside_the_repository():
    result = subprocess.run([sys.executable, "-c",
                             "from catalog.commands.cli import build_parser\n"
                             "p = build_parser()\n"
                             "subs = p._subparsers._group_actions[0].choices\n"
                             "print(p.format_help()); [print(s.format_help()) for s in subs.values()]"],
                            capture_output=True, text=True, timeout=60, check=True)
    assert "../" not in result.stdout and "shared/spec" not in result.stdout


def test_a_plain_install_brings_every_main_command_and_extras_only_the_optional():
    """`pip install fabric-catalog` alone runs snapshot, sheet, view, fit, simulate,
    fluorescence, sun and web: the design's packages are ordinary dependencies; the extras
    are the path tracer, Dask, the bench's peers and the tests; setup installs them all."""
    import tomllib

    project = tomllib.loads((PROJECT_ROOT / "pyproject.toml").read_text())["project"]

    def names(requirements: list[str]) -> set[str]:
        return {re.split(r"[<>=\[ ;]", req, maxsplit=1)[0].lower() for req in requirements}

    base = names(project["dependencies"])
    assert {"moderngl", "glfw", "imgui-bundle", "pyopengl", "scipy", "colour-science", "pvlib",
            "matplotlib", "openimageio", "trimesh", "numba", "platformdirs"} <= base
    groups = project["optional-dependencies"]
    assert set(groups) == {"pathtrace", "batch", "bench", "test"}
    assert "mitsuba" in names(groups["pathtrace"]) and "dask" in names(groups["batch"])
    from catalog.core.extras import EXTRA_OF

    assert set(EXTRA_OF.values()) <= set(groups)
    setup = (PROJECT_ROOT / "tools" / "setup.sh").read_text()
    assert '-e ".[test,pathtrace,batch' in setup
