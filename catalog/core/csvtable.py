"""Reading the project's numeric CSV files (spectra, gonio data) with their bad-input rules.

formats.md: '#' comment lines anywhere, then a header naming the columns exactly, then
rows of finite, non-negative numbers. Every refusal names the file, the line (1-based,
as an editor shows it) and the problem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.errors import InputError
from catalog.core.validate import _DECIMAL

#: Words float() reads that are refused with their own message (NaN, infinite).
_NON_FINITE = ("nan", "+nan", "-nan", "inf", "+inf", "-inf", "infinity", "+infinity", "-infinity")
#: No value of a spectrum, gonio file or dye comes near this; beyond it sums overflow.
MAX_MAGNITUDE = 1e12
#: The largest measurement file read (a spectrum, gonio set or matrix is kilobytes).
MAX_TEXT_BYTES = 64 << 20


@dataclass(frozen=True)
class NumericTable:
    """Columns of a numeric CSV, with the file line each row came from."""

    path: Path
    columns: dict[str, np.ndarray]
    line_numbers: np.ndarray  # int, 1-based line of each row
    comments: tuple[str, ...]  # comment lines without the leading '#', stripped

    def __len__(self) -> int:
        return len(self.line_numbers)


def read_numeric_csv(path: str | Path, required: tuple[str, ...],
                     optional: tuple[str, ...] = (), *, min_rows: int = 2,
                     allow_negative: tuple[str, ...] = ()) -> NumericTable:
    """Read ``path`` whose header is ``required`` followed by any leading run of ``optional``.

    Refuses (InputError naming file and line): a missing file, an empty file, a missing or
    wrong header, a row with the wrong number of fields, a field that is not a number,
    NaN or infinity, a negative value (except in ``allow_negative`` columns), fewer than
    ``min_rows`` rows.
    """
    path = Path(path)
    text = read_text(path)

    comments: list[str] = []
    header: list[str] | None = None
    header_line = 0
    rows: list[list[float]] = []
    line_numbers: list[int] = []
    for line_no, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            comments.append(line[1:].strip())
            continue
        fields = [f.strip() for f in line.split(",")]
        if header is None:
            header, header_line = fields, line_no
            _check_header(path, line_no, header, required, optional)
            continue
        if len(fields) != len(header):
            raise InputError(f"expected {len(header)} fields ({','.join(header)}), "
                             f"found {len(fields)}", path=path, line=line_no)
        values = []
        for name, field in zip(header, fields):
            try:
                if not _DECIMAL.fullmatch(field) and field.lower() not in _NON_FINITE:
                    raise ValueError(field)  # '0_029' is not 0.029 (float() reads 29)
                value = float(field)
            except ValueError:
                # the header matched, so this is a measurement file: a short quote helps find the typo
                raise InputError(f"{name} is not a number: {field[:20]!r}", path=path,
                                 line=line_no) from None
            if math.isnan(value):
                raise InputError(f"{name} is NaN", path=path, line=line_no)
            if math.isinf(value):
                raise InputError(f"{name} is infinite", path=path, line=line_no)
            if abs(value) > MAX_MAGNITUDE:
                raise InputError(f"{name} = {field[:20]} is beyond the {MAX_MAGNITUDE:g} any "
                                 "measurement here reaches", path=path, line=line_no)
            if value < 0 and name not in allow_negative:
                raise InputError(f"{name} is negative ({field[:20]})", path=path, line=line_no)
            values.append(value)
        rows.append(values)
        line_numbers.append(line_no)

    if header is None:
        raise InputError("empty file: no header "
                         f"({','.join(required)}) and no data", path=path, line=1)
    if len(rows) < min_rows:
        raise InputError(f"{len(rows)} data row(s); at least {min_rows} needed",
                         path=path, line=header_line)
    data = np.asarray(rows, dtype=np.float64)
    return NumericTable(path=path,
                        columns={name: data[:, i].copy() for i, name in enumerate(header)},
                        line_numbers=np.asarray(line_numbers, dtype=np.int64),
                        comments=tuple(comments))


def read_text(path: str | Path, encoding: str = "utf-8") -> str:
    """The whole text of a measurement file; a missing, unreadable or undecodable file is an
    InputError naming it."""
    path = Path(path)
    from catalog.core.atomic import register_input  # noqa: PLC0415

    register_input(path)
    try:
        size = path.stat().st_size if path.is_file() else 0
        if size > MAX_TEXT_BYTES:
            raise InputError(f"{size} bytes: a measurement file here is at most "
                             f"{MAX_TEXT_BYTES >> 20} MiB", path=path)
        return path.read_text(encoding=encoding)
    except FileNotFoundError:
        raise InputError("no such file", path=path) from None
    except UnicodeDecodeError as exc:
        raise InputError(f"not a {encoding.upper()} text file ({exc.reason})", path=path) from None
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", path=path) from None


def _check_header(path: Path, line_no: int, header: list[str], required: tuple[str, ...],
                  optional: tuple[str, ...]) -> None:
    expected = ",".join(required)
    if tuple(header[:len(required)]) != required:
        try:
            [float(h) for h in header]
            problem = f"missing header: the first line must be '{expected}'"
        except ValueError:
            # the file's own text is not echoed: it may not be a measurement at all
            problem = f"wrong header: the first line must be '{expected}'"
        raise InputError(problem, path=path, line=line_no)
    extra = tuple(header[len(required):])
    if extra and extra != optional[:len(extra)]:
        raise InputError(f"unexpected columns {','.join(extra)!r} after '{expected}'"
                         + (f" (allowed: {','.join(optional)})" if optional else ""),
                         path=path, line=line_no)
