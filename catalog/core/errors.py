"""Errors the user can act on: one line naming the file, line, field or option."""

from __future__ import annotations

from pathlib import Path


#: Exit status of a refused input (a bad file, field or option).
INPUT_EXIT = 2
#: Exit status of an environment failure: the machine lacks something the command needs
#: (no EGL device, no display, a shader file missing from the installation).
ENVIRONMENT_EXIT = 3


class CatalogError(Exception):
    """A refusal with a one-line, user-facing message. The CLI prints it and exits with
    :attr:`exit_code` (2: the input; :class:`EnvironmentFailure` is 3)."""

    exit_code = INPUT_EXIT


class EnvironmentFailure(CatalogError):
    """Not the input's fault: no EGL device or display, a missing or uncompilable shader."""

    exit_code = ENVIRONMENT_EXIT


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
