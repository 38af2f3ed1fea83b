"""A missing optional package: one line naming the extra that brings it, exit 3 (an
environment failure), no traceback; and the main commands need no extra at all."""

from __future__ import annotations

import sys

import pytest

from catalog.commands.cli import main
from catalog.core.errors import ENVIRONMENT_EXIT, EnvironmentFailure
from catalog.core.extras import install_hint, missing_message, require


def test_each_optional_module_names_its_extra():
    assert install_hint("mitsuba") == "pip install 'fabric-catalog[pathtrace]'"
    assert install_hint("distributed.client") == "pip install 'fabric-catalog[batch]'"
    assert install_hint("taichi") == "pip install 'fabric-catalog[bench]'"
    # an ordinary dependency gone missing: the package itself
    assert install_hint("moderngl") == "pip install fabric-catalog"
    assert "needs flip_evaluator" in missing_message("flip_evaluator", "FLIP")


def test_require_refuses_a_missing_module_in_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "mitsuba", None)  # import now raises ModuleNotFoundError
    with pytest.raises(EnvironmentFailure) as info:
        require("mitsuba", "the path-traced reference")
    assert info.value.exit_code == ENVIRONMENT_EXIT
    assert str(info.value) == ("the path-traced reference needs mitsuba, which is not "
                               "installed: pip install 'fabric-catalog[pathtrace]'")
    assert require("json").dumps([1]) == "[1]"


def test_render_catalog_workers_without_dask_names_the_batch_extra(monkeypatch, tmp_path,
                                                                   capsys):
    monkeypatch.setitem(sys.modules, "distributed", None)
    out = tmp_path / "out"
    status = main(["render-catalog", "--fabric", "lace-fwa", "--lights", "D65", "--frames",
                   "0:1", "--size", "48x32", "--workers", "2", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == ENVIRONMENT_EXIT
    assert len(err) == 1 and "pip install 'fabric-catalog[batch]'" in err[0], err
    assert "Traceback" not in err[0] and not out.exists()


def test_an_uncaught_missing_module_is_one_line_not_a_traceback(monkeypatch, capsys):
    """Whatever command meets a missing optional package deep inside: one line, exit 3,
    and with --json the same as one JSON object."""
    import catalog.commands.lights as lights

    def needs_mitsuba(args):
        import mitsuba  # noqa: F401

    monkeypatch.setattr(lights, "run", needs_mitsuba)
    monkeypatch.setitem(sys.modules, "mitsuba", None)
    assert main(["lights", "--json"]) == ENVIRONMENT_EXIT
    captured = capsys.readouterr()
    assert captured.err.strip().splitlines() == [
        "catalog lights: error: catalog lights needs mitsuba, which is not installed: "
        "pip install 'fabric-catalog[pathtrace]'"]
    assert '"exit_code": 3' in captured.out
