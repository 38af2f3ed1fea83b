#!/usr/bin/env python3
"""Fill the generated blocks of README.md, BENCHMARKS.md and docs/*.md from the benchmarks'
committed JSON, so that no figure in the docs is typed by hand.

    .venv/bin/python tools/docs_figures.py           # rewrite the blocks that changed
    .venv/bin/python tools/docs_figures.py --check   # exit 1 naming the stale blocks

A block is the text between ``<!-- generated:NAME -->`` and ``<!-- /generated:NAME -->``.
Its content comes from a module of benchmarks that has ``markdown_tables`` and either
``RESULT_JSON`` (one committed JSON, relative to the repository; ``markdown_tables(result)
-> {NAME: markdown}``) or ``RESULT_JSONS`` (several: ``{KEY: path}``; ``markdown_tables``
then receives ``{KEY: result}``, so a table may span runs, and one more run is one more
entry). A marker whose NAME no module provides is an error (exit 2), as is a JSON file that
is missing, a module with both attributes, a NAME made by two modules, or a JSON file
claimed by two modules (one would overwrite the other's result).
"""

from __future__ import annotations

import argparse
import importlib
import json
import pkgutil
import re
import sys
from pathlib import Path

from catalog.core.atomic import write_text_atomic

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # the benchmarks suite (top-level benchmarks/) beside catalog
BLOCK = re.compile(r"(<!-- generated:(?P<name>[\w.-]+) -->\n)(?P<body>.*?)(\n?<!-- /generated:(?P=name) -->)",
                   re.S)


def documents(root: Path = ROOT) -> list[Path]:
    return [p for p in [root / "README.md", root / "BENCHMARKS.md",
                        *sorted((root / "docs").glob("*.md"))] if p.is_file()]


def result_sources(module) -> list[str]:
    """The committed JSON files a bench module's tables are made from."""
    one, several = getattr(module, "RESULT_JSON", None), getattr(module, "RESULT_JSONS", None)
    return ([one] if one is not None else []) + list((several or {}).values())


def module_tables(module, root: Path = ROOT) -> dict[str, str] | None:
    """NAME -> markdown of one bench module from its committed JSON (None: it has none)."""
    one, several = getattr(module, "RESULT_JSON", None), getattr(module, "RESULT_JSONS", None)
    make = getattr(module, "markdown_tables", None)
    if make is None or (one is None and several is None):
        return None
    if one is not None and several is not None:
        raise SystemExit(f"docs_figures: error: {module.__name__} has both RESULT_JSON and "
                         "RESULT_JSONS")

    def load(source: str) -> dict:
        path = root / source
        if not path.is_file():
            raise SystemExit(f"docs_figures: error: {source}: no such file (run the benchmark)")
        return json.loads(path.read_text(encoding="utf-8"))

    results = {source: load(source) for source in result_sources(module)}
    made = make(results[one]) if one is not None else make({key: results[source]
                                                           for key, source in several.items()})
    note = provenance(results)
    return {name: text.rstrip("\n") + (f"\n\n{note}" if _has_table(text) else "")
            for name, text in made.items()}


def _has_table(text: str) -> bool:
    return any(line.lstrip().startswith("|") for line in text.splitlines())


def _find(data, key: str):
    """The first value of ``key`` anywhere in a JSON result (a run's machine may sit at the
    top or inside each run)."""
    if isinstance(data, dict):
        if key in data:
            return data[key]
        for value in data.values():
            found = _find(value, key)
            if found is not None:
                return found
    elif isinstance(data, list):
        for value in data:
            found = _find(value, key)
            if found is not None:
                return found
    return None


def provenance(results: dict[str, dict]) -> str:
    """One line under a table: the JSON it is made from, the commit and the machine it was
    measured on (as the result recorded them: benchmarks.results.machine_info)."""
    parts = []
    for source, result in results.items():
        machine = _find(result, "machine")
        machine = machine if isinstance(machine, dict) else {}
        commit = machine.get("commit") or _find(result, "commit")
        cores = machine.get("cpu_count") or machine.get("cpus")
        renderer = machine.get("gl_renderer") or machine.get("renderer")
        where = ", ".join(str(p) for p in (f"{cores} cores" if cores else None, renderer) if p)
        parts.append(f"`{source}`: "
                     + (f"commit `{commit}`" if commit else "commit not recorded")
                     + (f", {where}" if where else ", machine not recorded"))
    return "<sub>Measured: " + "; ".join(parts) + " (`make figures` measures again).</sub>"


def tables(root: Path = ROOT) -> dict[str, str]:
    """Every NAME -> markdown the bench modules make from their committed JSON."""
    import benchmarks as bench

    out: dict[str, str] = {}
    owner: dict[str, str] = {}  # JSON path -> the module that writes it
    for info in pkgutil.iter_modules(bench.__path__):
        module = importlib.import_module(f"benchmarks.{info.name}")
        for source in result_sources(module):
            if owner.setdefault(source, module.__name__) != module.__name__:
                raise SystemExit(f"docs_figures: error: {source} is the result of both "
                                 f"{owner[source]} and {module.__name__}")
        made = module_tables(module, root)
        for name, text in (made or {}).items():
            if name in out:
                raise SystemExit(f"docs_figures: error: block {name!r} made by two modules")
            out[name] = text
    return out


def fill(text: str, made: dict[str, str], where: str) -> str:
    def replace(match: re.Match) -> str:
        name = match.group("name")
        if name not in made:
            raise KeyError(f"{where}: <!-- generated:{name} --> has no source "
                           f"(known: {', '.join(sorted(made)) or 'none'})")
        return f"{match.group(1)}{made[name]}\n<!-- /generated:{name} -->"
    return BLOCK.sub(replace, text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="change nothing; exit 1 if a block differs from its JSON")
    args = parser.parse_args(argv)
    made = tables()
    stale = []
    for path in documents():
        text = path.read_text(encoding="utf-8")
        try:
            new = fill(text, made, str(path.relative_to(ROOT)))
        except KeyError as exc:
            print(f"docs_figures: error: {exc.args[0]}", file=sys.stderr)
            return 2
        if new != text:
            stale.append(str(path.relative_to(ROOT)))
            if not args.check:
                write_text_atomic(path, new)
    if args.check and stale:
        print(f"docs_figures: stale generated blocks in {', '.join(stale)} "
              "(run tools/docs_figures.py)", file=sys.stderr)
        return 1
    print(f"docs_figures: {'checked' if args.check else 'updated'} "
          f"{len(stale) if not args.check else 0} file(s); {len(made)} block(s) known")
    return 0


if __name__ == "__main__":
    sys.exit(main())
