"""Constants more than one room needs are written once, in catalog/core/constants.py: no other
module of the package writes 683 lm/W, the 1/60 s frame step or the fluorescence modes as
literals of its own (found in the code, not in comments or docstrings)."""

from __future__ import annotations

import ast

import pytest

from catalog.core.resources import PROJECT_ROOT

CONSTANTS = PROJECT_ROOT / "catalog" / "core" / "constants.py"


def _literal_copies(tree: ast.AST) -> list[str]:
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and not isinstance(node.value, bool) \
                and isinstance(node.value, (int, float)) and node.value == 683:
            found.append(f"line {node.lineno}: 683")
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div) \
                and isinstance(node.left, ast.Constant) and isinstance(node.right, ast.Constant) \
                and node.left.value == 1 and node.right.value == 60:
            found.append(f"line {node.lineno}: 1 / 60")
        elif isinstance(node, ast.Tuple) and all(isinstance(e, ast.Constant) for e in node.elts):
            values = tuple(e.value for e in node.elts)
            if values in (("off", "paper", "physical"), ("paper", "physical")):
                found.append(f"line {node.lineno}: {values}")
    return found


@pytest.mark.slow
def test_shared_constants_are_written_once():
    offenders = []
    for path in sorted((PROJECT_ROOT / "catalog").rglob("*.py")):
        if path == CONSTANTS:
            continue
        for where in _literal_copies(ast.parse(path.read_text(encoding="utf-8"))):
            offenders.append(f"{path.relative_to(PROJECT_ROOT)}: {where}")
    assert offenders == [], "use catalog.core.constants:\n" + "\n".join(offenders)


def test_the_check_finds_a_copy():
    tree = ast.parse('DT = 1.0 / 60.0\nK = 683.0\nMODES = ("off", "paper", "physical")\n'
                     'x = "683 lm/W"  # a comment: 683\n')
    assert [w.split(": ", 1)[1] for w in _literal_copies(tree)] == [
        "1 / 60", "683", "('off', 'paper', 'physical')"]
    assert _literal_copies(ast.parse(CONSTANTS.read_text(encoding="utf-8")))  # they live there
