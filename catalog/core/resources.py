"""Where the project's files are: shaders, the fabric catalog and the validation data.

- Shaders and the built-in fabric catalog ship inside the package: the wheel carries the
  top-level ``shaders/`` and ``fabrics/`` folders as ``catalog/_data/shaders`` and
  ``catalog/_data/fabrics`` (setup.py's build step copies them there), found through
  :func:`importlib.resources.files`. In a checkout (editable install) there is no copy and
  the top-level folders themselves are used.
- A user's own fabric folders come first: ``--fabrics DIR`` (:func:`use_fabrics`), else
  ``$CATALOG_FABRICS`` (folders separated by ``os.pathsep``), then the built-in catalog.
- The measured validation data (brightener spectra, bispectral matrices) is not shipped:
  ``--data DIR`` (:func:`use_data`), else ``$CATALOG_DATA``, else ``shared/data`` beside a
  checkout. :func:`data_dir` says in one line what is missing (exit 2).
"""

from __future__ import annotations

import os
from importlib.resources import files
from pathlib import Path

from catalog.core.errors import InputError

#: Environment variable: the validation data folder (overrides the default beside a checkout).
DATA_ENV = "CATALOG_DATA"
#: Environment variable: the user's fabric folders, searched before the built-in catalog.
FABRICS_ENV = "CATALOG_FABRICS"

#: Environment variable: the folder of the computed results kept between processes (the
#: settled drapes, the patterns' mip chains); ``off`` or empty: none kept.
CACHE_ENV = "CATALOG_CACHE_DIR"

_PACKAGE_DIR = Path(__file__).resolve().parent.parent
#: The checkout's root (meaningful only in a checkout, see :data:`IN_CHECKOUT`).
PROJECT_ROOT = _PACKAGE_DIR.parent
#: True when the package runs from a source checkout (editable install or the tree itself).
IN_CHECKOUT = (PROJECT_ROOT / "pyproject.toml").is_file() and (PROJECT_ROOT / "shaders").is_dir()


def _packaged(name: str) -> Path:
    """``catalog/_data/<name>`` in an installed wheel, else the checkout's top-level folder."""
    shipped = files("catalog").joinpath("_data", name)
    if shipped.is_dir():
        return Path(str(shipped))
    return PROJECT_ROOT / name


SHADER_DIR = _packaged("shaders")
#: The built-in fabric catalog (presets and their measurements).
FABRIC_DIR = _packaged("fabrics")
#: The validation data's default: shared/data beside a checkout (None when installed).
DEFAULT_DATA_DIR = PROJECT_ROOT.parent / "shared" / "data" if IN_CHECKOUT else None

_user_fabrics: list[Path] | None = None
_user_data: Path | None = None


def use_fabrics(folders: list[str | Path] | str | Path | None) -> None:
    """Search these fabric folders (``--fabrics DIR``) before the built-in catalog; None
    goes back to ``$CATALOG_FABRICS``. A folder that does not exist is an input error."""
    global _user_fabrics
    if folders is None:
        _user_fabrics = None
        return
    if isinstance(folders, (str, Path)):
        folders = [folders]
    paths = [Path(f).expanduser() for f in folders]
    for path in paths:
        if not path.is_dir():
            raise InputError("no such fabric folder", field="--fabrics", path=path)
    _user_fabrics = paths


def fabric_dirs() -> list[Path]:
    """The fabric folders in search order: ``--fabrics``, ``$CATALOG_FABRICS``, built-in."""
    if _user_fabrics is not None:
        user = list(_user_fabrics)
    else:
        user = [Path(p).expanduser() for p in os.environ.get(FABRICS_ENV, "").split(os.pathsep)
                if p.strip()]
    return [p for p in user if p != FABRIC_DIR] + [FABRIC_DIR]


def use_data(folder: str | Path | None) -> None:
    """Read the validation data from ``folder`` (``--data DIR``); None goes back to the
    environment variable and the default."""
    global _user_data
    _user_data = None if folder is None else Path(folder).expanduser()


def data_dir_candidate() -> Path | None:
    """Where the validation data would be (it may not exist): --data, $CATALOG_DATA, default."""
    if _user_data is not None:
        return _user_data
    if os.environ.get(DATA_ENV):
        return Path(os.environ[DATA_ENV]).expanduser()
    return DEFAULT_DATA_DIR


def data_missing_reason(subfolder: str = "") -> str | None:
    """None when the validation data (its ``subfolder``) is there; else why not, one line."""
    folder = data_dir_candidate()
    if folder is None:
        return (f"validation data not found: pass --data DIR or set {DATA_ENV} "
                "(it is not shipped with the package)")
    target = folder / subfolder if subfolder else folder
    if not target.is_dir():
        return (f"validation data not found: no folder {target} (pass --data DIR or set "
                f"{DATA_ENV}; it is not shipped with the package)")
    return None


def data_dir(subfolder: str = "") -> Path:
    """The validation data folder (or its ``subfolder``); an input error (exit 2) naming
    what is missing when it is absent."""
    reason = data_missing_reason(subfolder)
    if reason is not None:
        raise InputError(reason, field="--data")
    folder = data_dir_candidate()
    return folder / subfolder if subfolder else folder


def cache_folder(kind: str) -> Path | None:
    """The folder that keeps one ``kind`` of computed result (``drape``, ``mips``): under
    ``$CATALOG_CACHE_DIR``, else the user's cache folder (platformdirs, ``fabric-catalog``);
    None when the cache is off."""
    value = os.environ.get(CACHE_ENV)
    if value is not None:
        return None if value.strip() in ("", "off") else Path(value) / kind
    from platformdirs import user_cache_dir  # noqa: PLC0415

    return Path(user_cache_dir("fabric-catalog", appauthor=False)) / kind
