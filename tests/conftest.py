"""Shared fixtures. The GL context is created in exactly one place (EGL, standalone)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

# One BLAS thread for the tests and the commands they start: the suite runs on small shared
# machines, where OpenBLAS's spinning threads made an 8-matrix SVD fit 8x slower (21 s
# against 2.7 s for `catalog bispectral CIBA12` at a load of 4 on 2 cores). Set before numpy
# is imported; an explicit setting in the environment wins.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

# The settled drape's disk cache (catalog.cloth.drape_cache) in a folder of this session's
# own, shared by the commands the tests start and removed after: tests neither read a
# user's cache nor leave one behind.
if "CATALOG_CACHE_DIR" not in os.environ:
    import atexit
    import tempfile

    _CACHE = tempfile.mkdtemp(prefix="catalog-test-cache-")
    os.environ["CATALOG_CACHE_DIR"] = _CACHE
    atexit.register(shutil.rmtree, _CACHE, True)

import pytest

from catalog.core.resources import FABRIC_DIR, PROJECT_ROOT, data_dir_candidate, data_missing_reason
from catalog.gl.shaderlib import register_folder

#: Test-only shaders (tests/shaders/) are found by name like the product's.
register_folder(Path(__file__).resolve().parent / "shaders")

#: Why the validation data cannot be read (None when it can): $CATALOG_DATA, else shared/data
#: beside the checkout. It is not part of the repository; CI has it.
DATA_MISSING = data_missing_reason("bispectral") or data_missing_reason("brightener")


def pytest_collection_modifyitems(config, items):
    """``@pytest.mark.data`` tests are skipped, with the reason, without the validation data."""
    if DATA_MISSING is None:
        return
    skip = pytest.mark.skip(reason=DATA_MISSING)
    for item in items:
        if item.get_closest_marker("data") is not None:
            item.add_marker(skip)


#: Test modules that share a session fixture costlier than splitting them is worth (web_site:
#: the web catalog built, 80 s under load): under ``-n 2 --dist loadfile`` they run in one
#: worker as if they were one file, so it is built once. (tests/test_xdist_schedule.py checks
#: that every module using the fixture is listed.)
SHARED_FIXTURE_MODULES = {"web_site": ("tests/test_web.py", "tests/test_web_browser.py",
                                       "tests/test_web_facts.py", "tests/test_web_links.py")}


#: Seconds the longest scopes (a module, or a name of SHARED_FIXTURE_MODULES) took in the
#: full `-n 2 --dist loadfile` suite (the sums of their tests' --durations over 5 s, at
#: 018e387 on the 2-core machine, load ~2.4; the SIGKILL test as polled since). Only an
#: order: the scheduler starts the longest first, so that no hour-long module is left to
#: start last while the other worker idles (longest-first on two workers). Scopes not listed
#: follow in xdist's own order (most tests first). tests/test_xdist_schedule.py checks that
#: every name here is still a scope.
SCOPE_SECONDS = {"tests/test_display_gl.py": 230, "web_site": 180, "tests/test_viewer.py": 110,
                 "tests/test_batch.py": 80, "tests/test_bench.py": 70, "tests/test_presets.py": 60,
                 "tests/test_pathtrace.py": 60, "tests/test_web_lit.py": 60,
                 "tests/test_room_transport.py": 55,
                 "tests/test_patterns.py": 50, "tests/test_viewer_panel.py": 40,
                 "tests/test_adaptation.py": 40, "tests/test_cloth_shadows.py": 35,
                 "tests/test_output_layer.py": 30, "tests/test_cli_hostile.py": 30,
                 "tests/test_bench_accuracy.py": 27, "tests/test_room_placement.py": 26,
                 "tests/test_see_through.py": 24, "tests/test_render_frame.py": 21,
                 "tests/test_render_pattern.py": 18}


def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile``, each module in one worker (its module fixtures made once, its tests
    in their written order), the modules of SHARED_FIXTURE_MODULES together, the scopes of
    SCOPE_SECONDS first, longest first. Other --dist modes are xdist's own. (Not --dist
    loadgroup: xdist 3.8's groups are lost under pytest 9.2, which no longer reads the node id
    xdist rewrites.)"""
    if config.getvalue("dist") != "loadfile":
        return None
    from collections import OrderedDict

    from xdist.scheduler import LoadFileScheduling

    scope_of = {module: name for name, modules in SHARED_FIXTURE_MODULES.items()
                for module in modules}

    class SharedFixtureScheduling(LoadFileScheduling):
        _longest_first = False

        def _split_scope(self, nodeid: str) -> str:
            module = super()._split_scope(nodeid)
            return scope_of.get(module, module)

        def _assign_work_unit(self, node) -> None:
            # the work queue is whole by the first assignment (xdist's schedule() fills it,
            # then assigns); a stable sort keeps xdist's order among the scopes not listed
            if not self._longest_first:
                self._longest_first = True
                order = sorted(self.workqueue, key=lambda scope: -SCOPE_SECONDS.get(scope, 0))
                self.workqueue = OrderedDict((scope, self.workqueue[scope]) for scope in order)
            super()._assign_work_unit(node)

    return SharedFixtureScheduling(config, log)


#: Set (e.g. by .ci/run) to a number of seconds: an unmarked test whose call phase takes
#: longer FAILS, so the fast loop (-m "not slow") stays fast. The rule marks a test slow at
#: 0.5 s; CI fails it at twice that, the margin for run-to-run noise on a 2-core machine
#: (medians of repeated fast-loop runs there vary by about 30 %). Fixture set-up (the one GL
#: context, a module's shared render) is shared work and is not counted.
SLOW_LIMIT_ENV = "CATALOG_UNMARKED_LIMIT_S"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    limit = os.environ.get(SLOW_LIMIT_ENV)
    if not limit or call.when != "call":
        return
    report = outcome.get_result()
    if (report.passed and item.get_closest_marker("slow") is None
            and report.duration > float(limit)):
        report.outcome = "failed"
        report.longrepr = (f"{item.nodeid} took {report.duration:.2f} s without "
                           f"@pytest.mark.slow (limit {float(limit):g} s, ${SLOW_LIMIT_ENV}): "
                           "mark it slow or make it faster")


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The validation data: real measurements by others (read in place, never copied).
    Tests that use it are skipped, with the reason, when it is absent."""
    if DATA_MISSING is not None:
        pytest.skip(DATA_MISSING)
    return data_dir_candidate()


@pytest.fixture(scope="session")
def project_root() -> Path:
    return PROJECT_ROOT


@pytest.fixture(scope="session")
def fabric_dir() -> Path:
    return FABRIC_DIR


# --- GL (the renderer's tests; the only place a test creates a context) -----------------

#: The session's one context once made (:func:`gl_context`); empty before.
_SHARED_GL: list = []


@pytest.fixture(scope="session")
def gl_context():
    """One headless OpenGL 4.3 context (EGL, Mesa llvmpipe in CI) shared by the GL tests."""
    from catalog.gl.context import create_headless_context

    ctx = create_headless_context()
    _SHARED_GL.append(ctx)
    yield ctx
    _SHARED_GL.clear()
    ctx.release()


def _share_gl_context(item) -> None:
    """Make the shared context current again for a test that uses it. A context made in this
    process becomes the thread's current one and stays so (released or not): the shared
    context's calls then go to it, and objects made earlier in the shared context (a module
    fixture's renderer) give GL_INVALID_OPERATION. The commands (``main(["snapshot", ..])``,
    ``render_sheet``, ``build_site``, ``egl_frame``, ``catalog bench`` without ``ctx=``) make
    theirs through catalog.gl.context.headless_context, which makes the caller's current again
    (tests/test_gl_context.py), as do the benchmarks' ``run(ctx=None)`` functions
    (own_context_unless_given); this stays for what does not yet: the cloth's GpuBackend and
    benchmarks.springs12 without ``ctx``, benchmarks.room, benchmarks.results' sections and
    the web benchmark's frames, whose contexts live as long as an object or a section."""
    if _SHARED_GL and "gl_context" in getattr(item, "fixturenames", ()):
        _SHARED_GL[0].__enter__()   # eglMakeCurrent (moderngl: no matching exit needed)


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    _share_gl_context(item)   # before the test's fixtures (a module's shared render) are made


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_call(item):
    _share_gl_context(item)   # a fixture of the test may have made another context current


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_teardown(item):
    _share_gl_context(item)   # the gl fixture's check and fixtures' releases


@pytest.fixture
def lit_recording(gl):
    """A lit-room scene (linen-dense under D65, on a 12x8 drape) recorded by a fresh
    SiteExporter: (exporter, recorded, its structure); the exporter released after."""
    from catalog.render import scene as scene_lib
    from catalog.render import settings as settings_lib
    from catalog.web import export

    exporter = export.SiteExporter(gl)
    try:
        d = scene_lib.draped_curtain(12, 8)
        exporter.use_mesh(d.positions, d.normals, d.uvs, d.tangents, d.indices)
        choice = export.LightChoice(id="D65", label="D65", kind="lamp", hour=None)
        scene = exporter.scene(settings_lib.FrameSettings(fabric="linen-dense").fabric, choice)
        recorded = exporter.record(scene.replace(room_lighting=True), "on")
        yield exporter, recorded, exporter.structures[recorded["structure"]]
    finally:
        exporter.release()


@pytest.fixture
def gl(gl_context):
    """The shared context, checked for no pending GL error before and after each test."""
    # read once: glGetError clears the flag, so a second read in the message would say "no error"
    before = gl_context.error
    assert before == "GL_NO_ERROR", f"GL error pending before the test: {before}"
    yield gl_context
    after = gl_context.error
    assert after == "GL_NO_ERROR", f"GL error left by the test: {after}"


@pytest.fixture
def make_preset(tmp_path):
    """Write a hand-made preset TOML into tmp_path (never into fabrics/) and return its path.

    ``fluorescent=True`` points [fluorescence] at fabrics/measurements/lace-fwa's spectra;
    ``dye`` = a list of (wavelength_nm, transmittance) rows writes a [dye] CSV beside it.
    """
    def make(name="lace-test", *, fluorescent=True, dye=None, extra_btdf="", **btdf):
        values = {"direct": 0.05, "k_d": 0.7, "k_s": 0.5, "tau": 0.25, "rho": 0.8,
                  "g_diff": 0.2, "g_spec": 0.97}
        values.update(btdf)
        lines = ["schema = 1", f'name = "{name}"', f'display_name = "{name}"', "[btdf]"]
        lines += [f"{k} = {v!r}" for k, v in values.items()]
        if extra_btdf:
            lines.append(extra_btdf)
        if fluorescent:
            # the spectra beside the preset: a preset's files must lie in its own folder tree
            folder = FABRIC_DIR / "measurements" / "lace-fwa"
            local = tmp_path / "measurements" / "lace-fwa"
            local.mkdir(parents=True, exist_ok=True)
            for spectrum in ("excitation.csv", "emission.csv"):
                shutil.copyfile(folder / spectrum, local / spectrum)
            lines += ["[fluorescence]", "xyz = [33.0, 100.0, 1700.0]", "rgb = [39.0, -52.0, 1790.0]",
                      'excitation = "measurements/lace-fwa/excitation.csv"',
                      'emission = "measurements/lace-fwa/emission.csv"']
        if dye is not None:
            dye_path = tmp_path / f"{name}-dye.csv"
            dye_path.write_text("wavelength_nm,intensity\n"
                                + "".join(f"{w},{t}\n" for w, t in dye))
            lines += ["[dye]", f'transmittance = "{dye_path}"']
        path = tmp_path / f"{name}.toml"
        path.write_text("\n".join(lines) + "\n")
        return path

    return make


# --- the web catalog (tests/test_web*.py): one small site shared by its tests ----------

@pytest.fixture(scope="session")
def web_site(tmp_path_factory, gl_context):
    """(folder, report) of `catalog web` for two fabrics (one fluorescent, one dyed, with
    different cloth) under D65, UV-A and the sun by hour, recorded in the shared context."""
    from catalog.web.site import build_site

    out = tmp_path_factory.mktemp("web") / "site"
    report = build_site(out, fabrics="fluoro-pink,linen-dense", lights="D65,UV-A,sun-by-hour",
                        ctx=gl_context)
    return out, report


# ---- figures the docs quote from test runs ------------------------------------------------
#: NAME -> value measured by a test in this session (benchmarks/tested_figures.py).
_FIGURES: dict[str, object] = {}


@pytest.fixture
def record_figure():
    """``record_figure(NAME, value)``: keep a figure a test measured (a number, list or dict of
    them). With CATALOG_RECORD_FIGURES=FILE.json set, the session merges every recorded figure
    into that file at its end (benchmarks/tested_figures.json is where the docs' tables come
    from: benchmarks/tested_figures.py); otherwise nothing is written."""
    def record(name: str, value) -> None:
        _FIGURES[name] = value
    return record


def pytest_sessionfinish(session, exitstatus):
    target = os.environ.get("CATALOG_RECORD_FIGURES")
    if not target or not _FIGURES:
        return
    import fcntl
    import json

    from catalog.core.atomic import write_text_atomic

    path = Path(target)
    # each pytest-xdist worker merges its own figures: one at a time (a lock on the folder)
    folder = os.open(path.resolve().parent, os.O_RDONLY)
    try:
        fcntl.flock(folder, fcntl.LOCK_EX)
        merged = json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}
        merged.setdefault("figures", {}).update(_FIGURES)
        merged["figures"] = dict(sorted(merged["figures"].items()))
        write_text_atomic(path, json.dumps(merged, indent=1, default=float) + "\n")
    finally:
        os.close(folder)   # and the lock with it
