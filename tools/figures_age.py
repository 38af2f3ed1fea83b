#!/usr/bin/env python3
"""List the published tables older than the code they measure.

    .venv/bin/python tools/figures_age.py            # a warning per stale result; exit 0
    .venv/bin/python tools/figures_age.py --strict   # exit 1 when one is stale

A result (a bench module's committed JSON, tools/docs_figures.py) was measured at the commit
it records (``machine.commit``, benchmarks.results.machine_info), else at the last commit
that changed the JSON file. The code it measures is the module's ``MEASURES`` (paths in the
repository) if it declares them, else the module itself, the catalog modules it imports and,
when it imports the renderer or GL, shaders/ (catalog.core apart from its constants, the
output layer and errors, changes no figure). A result is stale when a later commit changed
any of them: its tables may no longer describe today's code (`make figures` measures again).
CI runs this as a warning: a stale table is a reason to measure, not to stop a merge.
"""

from __future__ import annotations

import argparse
import ast
import importlib
import json
import pkgutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

from docs_figures import _find, result_sources  # noqa: E402


def _git(*args: str) -> str:
    result = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, timeout=60)
    return result.stdout.strip() if result.returncode == 0 else ""


def measured_code(module) -> list[str]:
    """Repository paths whose change makes the module's result stale."""
    declared = getattr(module, "MEASURES", None)
    if declared is not None:
        return sorted(declared)
    path = Path(module.__file__).resolve()
    paths = {str(path.relative_to(ROOT))}
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module]
        elif isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        for name in names:
            if not name.startswith("catalog.") or name.startswith("benchmarks") or \
                    (name.startswith("catalog.core") and name != "catalog.core.constants"):
                continue  # the bench's own helpers, the output layer: no figure changes
            parts = name.split(".")
            candidate = ROOT.joinpath(*parts).with_suffix(".py")
            folder = ROOT.joinpath(*parts)
            if candidate.is_file():
                paths.add(str(candidate.relative_to(ROOT)))
            elif folder.is_dir():
                paths.add(str(folder.relative_to(ROOT)))
            if name.startswith(("catalog.render", "catalog.gl")):
                paths.add("shaders")
    return sorted(paths)


def measured_at(source: str) -> tuple[str | None, str]:
    """(commit, how it is known) of a committed result."""
    path = ROOT / source
    try:
        recorded = _find(json.loads(path.read_text(encoding="utf-8")), "commit")
    except (OSError, ValueError):
        recorded = None
    if isinstance(recorded, str):
        commit = recorded.split("+", 1)[0]
        known = subprocess.run(["git", "cat-file", "-e", f"{commit}^{{commit}}"], cwd=ROOT,
                               capture_output=True, timeout=60).returncode == 0
        if known:
            return commit, "recorded"
    committed = _git("log", "-1", "--format=%h", "--", source)
    return (committed or None), "the JSON's last commit"


def runnable_modules() -> list[str]:
    """Bench modules with a committed result and a ``python -m`` entry that measures it."""
    import benchmarks as bench

    names = []
    for info in pkgutil.iter_modules(bench.__path__):
        module = importlib.import_module(f"benchmarks.{info.name}")
        text = Path(module.__file__).read_text(encoding="utf-8")
        if result_sources(module) and 'if __name__ == "__main__"' in text:
            names.append(info.name)
    return names


def stale_results() -> list[dict]:
    import benchmarks as bench

    out = []
    for info in pkgutil.iter_modules(bench.__path__):
        module = importlib.import_module(f"benchmarks.{info.name}")
        sources = result_sources(module)
        if not sources or getattr(module, "markdown_tables", None) is None:
            continue
        code = measured_code(module)
        for source in sources:
            commit, how = measured_at(source)
            if commit is None:
                continue  # not committed yet: nothing published from it
            changes = _git("log", "--format=%h", f"{commit}..HEAD", "--", *code).split()
            if changes:
                changed = _git("diff", "--name-only", commit, "HEAD", "--", *code).split()
                out.append({"result": source, "module": module.__name__,
                            "measured_at": commit, "known_by": how,
                            "commits_since": len(changes), "changed": changed})
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strict", action="store_true", help="exit 1 when a result is stale")
    parser.add_argument("--json", action="store_true", help="print the list as JSON")
    parser.add_argument("--modules", action="store_true",
                        help="print the bench modules whose main measures a published result "
                             "(what `make figures` runs), one a line")
    args = parser.parse_args(argv)
    if args.modules:
        print("\n".join(runnable_modules()))
        return 0
    stale = stale_results()
    if args.json:
        print(json.dumps(stale, indent=1))
    for entry in stale:
        shown = ", ".join(entry["changed"][:4]) + (" ..." if len(entry["changed"]) > 4 else "")
        print(f"figures_age: warning: {entry['result']} ({entry['module']}) measured at "
              f"{entry['measured_at']} ({entry['known_by']}); {entry['commits_since']} later "
              f"commit(s) changed {shown}", file=sys.stderr)
    print(f"figures_age: {len(stale)} result(s) older than the code they measure",
          file=sys.stderr)
    return 1 if (args.strict and stale) else 0


if __name__ == "__main__":
    sys.exit(main())
