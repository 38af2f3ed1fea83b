"""The docs read as pages: each under MAX_LINES lines (the guide's rule), and the README opens
with its two commands (the main job; the tests)."""

from __future__ import annotations

import pytest

from catalog.core.resources import PROJECT_ROOT

#: The longest page, lines.
MAX_LINES = 400
PAGES = sorted((PROJECT_ROOT / "docs").glob("*.md")) + [PROJECT_ROOT / "README.md",
                                                       PROJECT_ROOT / "BENCHMARKS.md"]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(PROJECT_ROOT).as_posix())
def test_every_page_is_under_the_line_limit(page):
    lines = page.read_text(encoding="utf-8").count("\n")
    assert lines < MAX_LINES, f"{page.name}: {lines} lines; move a part into a focused page"


def test_the_readme_starts_with_its_two_commands():
    lines = (PROJECT_ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    fence = lines.index("```sh")
    assert fence <= 3, "the commands come first"
    first, second = lines[fence + 1], lines[fence + 2]
    assert "tools/run.sh" in first and "pytest" in second and lines[fence + 3] == "```"
