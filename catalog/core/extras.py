"""Optional packages: which extra of ``fabric-catalog`` brings each, and the one-line refusal
when one is missing.

``pip install fabric-catalog`` brings everything the main commands use (snapshot, sheet,
view, fit, simulate, fluorescence, sun, web). The extras are for what a user may not want:
``pathtrace`` (Mitsuba 3 and FLIP: ``catalog reference``, the image sections of the bench),
``batch`` (Dask: ``render-catalog --workers/--scheduler``), ``bench`` (the cloth
comparison's peers, Taichi and Warp) and ``test``.

>>> missing_message("mitsuba", "catalog reference")
"catalog reference needs mitsuba, which is not installed: pip install 'fabric-catalog[pathtrace]'"
"""

from __future__ import annotations

import importlib

from catalog.core.errors import EnvironmentFailure

#: Top-level module name -> the extra that installs it.
EXTRA_OF: dict[str, str] = {
    "mitsuba": "pathtrace",
    "drjit": "pathtrace",
    "flip_evaluator": "pathtrace",
    "dask": "batch",
    "distributed": "batch",
    "taichi": "bench",
    "warp": "bench",
    "pytest": "test",
    "hypothesis": "test",
    "selenium": "test",
}


def install_hint(module: str) -> str:
    """The pip command that brings ``module``: its extra, or the package itself for an
    ordinary dependency that went missing from the environment."""
    top = module.split(".", 1)[0]
    extra = EXTRA_OF.get(top)
    return f"pip install 'fabric-catalog[{extra}]'" if extra else "pip install fabric-catalog"


def missing_message(module: str, needed_by: str | None = None) -> str:
    top = module.split(".", 1)[0]
    who = needed_by or "this command"
    return f"{who} needs {top}, which is not installed: {install_hint(top)}"


def require(module: str, needed_by: str | None = None):
    """Import and return ``module``; if it is not installed, raise
    :class:`~catalog.core.errors.EnvironmentFailure` (exit 3) naming the extra to install."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.split(".", 1)[0] != module.split(".", 1)[0]:
            raise  # the module is there but one of its own imports is not
        raise EnvironmentFailure(missing_message(module, needed_by)) from None


def available(module: str) -> bool:
    """Whether ``module`` can be imported (no import cost beyond finding it)."""
    import importlib.util  # noqa: PLC0415

    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def failure_for(exc: ModuleNotFoundError, needed_by: str | None = None) -> EnvironmentFailure:
    """The one-line refusal for a ModuleNotFoundError nobody caught on the way up."""
    return EnvironmentFailure(missing_message(exc.name or "a package", needed_by))
