"""The fabric options every command shares (docs/formats.md, "Command lines"):

- ``--fabric NAME[,NAME..]`` selects fabrics (preset names or .toml paths); left out, a
  command that takes several means every fabric on the search path;
- ``--fabrics DIR`` is always a folder of presets, searched before the built-in catalog
  (repeatable; catalog.commands.cli hands the folders to
  :func:`catalog.core.resources.use_fabrics`).

The second round's ``--fabrics A,B`` list (``sheet``, ``render-catalog``, ``web``) is still
accepted: an item that is not a folder joins the ``--fabric`` selection, with a one-line
notice on stderr. Light: no numpy, no presets read at parse time.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


#: The selection left out: every fabric on the search path.
ALL = None
#: The lights a catalog is rendered under when ``--lights`` is left out (``sheet``,
#: ``render-catalog``, tools/run.sh): daylight, the clear-sky sun (sun:22), a white LED
#: and the UV-A lamp that shows the brighteners. The library has 72 lights
#: (`catalog lights`); "all" of them would be 72 columns nobody asked for.
CATALOG_LIGHTS = "D65,sun:22,LED-B4,UV-A"


def fabric_names(text: str) -> list[str]:
    """``A,B`` -> ["A", "B"]; an empty name between commas or a name given twice is refused
    (argparse names the option)."""
    names = [item.strip() for item in str(text).split(",")]
    if not any(names) or any(not name for name in names):
        raise argparse.ArgumentTypeError(f"{text!r}: an empty fabric name between commas")
    if len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(f"{text!r}: a fabric is named twice")
    return names


class _FabricFolders(argparse.Action):
    """``--fabrics DIR`` (appends). With ``legacy``, an item that is not a folder is taken
    as the old list of fabric names: it joins ``--fabric`` and a notice says so, once."""

    def __init__(self, *args, legacy: bool = False, notice: str | None = None, **kwargs):
        self.legacy = legacy
        self.notice = notice
        super().__init__(*args, **kwargs)

    def __call__(self, parser, namespace, value, option_string=None):
        folders = list(getattr(namespace, self.dest, None) or [])
        if self.notice is not None:  # an old spelling of this option (view's --fabric-dir)
            _notice(parser, self.notice)
        items = [value] if (not self.legacy or Path(value).is_dir()) else \
            [item.strip() for item in str(value).split(",") if item.strip()]
        names = []
        for item in items:
            if self.legacy and not Path(item).is_dir():
                names.append(item)
            else:
                folders.append(Path(item))
        if names:
            _notice(parser, f"--fabrics {value} as a list of fabrics is the old spelling: "
                            f"use --fabric {','.join(names)} (--fabrics names a folder)")
            selected = list(getattr(namespace, "fabric", None) or [])
            selected += [name for name in names if name not in selected]
            namespace.fabric = selected
        setattr(namespace, self.dest, folders or None)


def _notice(parser, text: str) -> None:
    print(f"{parser.prog}: notice: {text}", file=sys.stderr)


class _Selection(argparse.Action):
    """``--fabric A,B``: extends what an old ``--fabrics A,B`` already selected."""

    def __call__(self, parser, namespace, value, option_string=None):
        selected = list(getattr(namespace, self.dest, None) or [])
        selected += [name for name in value if name not in selected]
        setattr(namespace, self.dest, selected)


def add_fabric_options(parser: argparse.ArgumentParser, *, many: bool, required: bool = False,
                       legacy_list: bool = False, what: str | None = None) -> None:
    """``--fabric`` (``many``: NAME[,NAME..], default every fabric; else one NAME_OR_TOML)
    and ``--fabrics DIR``. ``legacy_list``: the old ``--fabrics A,B`` list is accepted."""
    if many:
        parser.add_argument("--fabric", type=fabric_names, action=_Selection, default=ALL,
                            metavar="NAME[,NAME..]", required=required,
                            help=what or "fabrics to render: preset names or .toml paths "
                                 "(default: all, every preset on the search path)")
    else:
        parser.add_argument("--fabric", metavar="NAME_OR_TOML", required=required,
                            help=what or "preset name (fabrics/NAME.toml) or a .toml path")
    add_fabric_folders(parser, legacy_list=legacy_list)


def add_fabric_folders(parser: argparse.ArgumentParser, *, legacy_list: bool = False) -> None:
    from catalog.core.resources import FABRICS_ENV  # noqa: PLC0415

    parser.add_argument("--fabrics", metavar="DIR", action=_FabricFolders, legacy=legacy_list,
                        default=None,
                        help="a folder of your own fabric presets, searched before the "
                             f"built-in catalog (repeatable; default: ${FABRICS_ENV}, then "
                             "the built-in catalog)")


def add_fabric_dir_alias(parser: argparse.ArgumentParser) -> None:
    """``--fabric-dir DIR``, the viewer's old spelling of ``--fabrics DIR`` (a notice)."""
    parser.add_argument("--fabric-dir", metavar="DIR", dest="fabrics", action=_FabricFolders,
                        notice="--fabric-dir is the old spelling of --fabrics DIR",
                        help=argparse.SUPPRESS)
