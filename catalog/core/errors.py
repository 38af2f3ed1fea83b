"""Errors the user can act on: one line naming the file, line, field or option."""

from __future__ import annotations

from pathlib import Path


class CatalogError(Exception):
    """A refusal with a one-line, user-facing message. The CLI prints it and exits 2."""


class InputError(CatalogError):
    """Bad input data: names the file (and line, or field) and the problem.

    >>> str(InputError("no header", path="a.csv", line=1))
    'a.csv:1: no header'
    """

    def __init__(self, problem: str, *, path: str | Path | None = None,
                 line: int | None = None, field: str | None = None):
        self.problem = problem
        self.path = None if path is None else str(path)
        self.line = line
        self.field = field
        where = self.path or ""
        if line is not None:
            where = f"{where}:{line}" if where else f"line {line}"
        if field is not None:
            where = f"{where}: {field}" if where else field
        super().__init__(f"{where}: {problem}" if where else problem)


class EnvironmentFailure(CatalogError):
    """The machine lacks something the command needs (a library, a device): not the
    user's input. The CLI prints the one line and exits :attr:`exit_code` (3)."""

    exit_code = 3
