"""A bispectral matrix's measured residual: the signed rest a fabric carries beside its bands.

Issue 15 (docs/bispectral.md, "The measured residual"). A banded fit
(:mod:`catalog.optics.bispectral.bands`) holds the fluorescence as non-negative bands
(quantum yield <= 1); what the measured matrix holds beyond that (the neighbours of the
diagonal, the anti-Stokes stray light, negative entries of noisy UV columns) is a signed
matrix on the measurement's grid. Under a light it is one signed exitance spectrum,

    M_res(lo) = sum_li residual(lo, li) E_bin(li)          [W m^-2 nm^-1]

with E_bin the light's mean over each excitation bin [li - w/2, li + w/2] (the bispectral
ground truth's own treatment of off-diagonal entries), interpolated linearly from the
emission samples to GRID_NM. The renderer pre-integrates it per (material, light) with the
bands (catalog.render.scene), so it costs no frame time.

The file (formats: docs/formats.md, "Measured residual"): comment lines ``# ...``, one of
which is ``# excitation bin width nm: W``; then a header ``emission_nm,<excitation nm>,...``;
then one line per emission wavelength: the wavelength, then the entries (dimensionless:
exitance per nm per unit of the bin's mean irradiance). Axes strictly ascending, entries
finite and within [-1, 1] (a residual is small against a reflectance; anything larger is a
wrong file).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.errors import InputError
from catalog.optics.spectra import GRID_NM

BIN_WIDTH_KEY = "excitation bin width nm:"


@dataclass(frozen=True)
class MeasuredResidual:
    emission_nm: np.ndarray      # (n_lo,)
    excitation_nm: np.ndarray    # (n_li,)
    values: np.ndarray           # (n_lo, n_li), signed, dimensionless per bin
    bin_width_nm: float

    def exitance_w_m2_nm(self, irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
        """M_res on GRID_NM (W m^-2 nm^-1, signed) for an irradiance on GRID_NM."""
        from catalog.optics.bispectral.matrix import bin_irradiance  # noqa: PLC0415

        bins = bin_irradiance(self.excitation_nm, np.asarray(irradiance_w_m2_nm, dtype=np.float64),
                              width_nm=self.bin_width_nm)
        return np.interp(GRID_NM, self.emission_nm, self.values @ bins, left=0.0, right=0.0)


def write_residual(path: str | Path, emission_nm, excitation_nm, values, bin_width_nm: float,
                   comments=()) -> None:
    """Write a residual file atomically (never over an input: callers pick a new path)."""
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    values = np.asarray(values, dtype=np.float64)
    lines = [f"# {c}" for c in comments] + [f"# {BIN_WIDTH_KEY} {bin_width_nm:g}"]
    lines.append("emission_nm," + ",".join(f"{x:g}" for x in excitation_nm))
    for lo, row in zip(emission_nm, values):
        lines.append(f"{lo:g}," + ",".join(f"{v:.6g}" for v in row))
    write_text_atomic(Path(path), "\n".join(lines) + "\n")


def _floats(text: str, path: Path, line: int, what: str) -> list[float]:
    out = []
    for field in text.split(","):
        try:
            value = float(field)
        except ValueError:
            raise InputError(f"{what}: {field.strip()!r} is not a number", path=path, line=line) from None
        if not math.isfinite(value):
            raise InputError(f"{what}: {field.strip()!r} is not finite", path=path, line=line)
        out.append(value)
    return out


def _ascending(axis: list[float], path: Path, line: int, what: str) -> np.ndarray:
    array = np.asarray(axis, dtype=np.float64)
    if array.size == 0 or np.any(np.diff(array) <= 0):
        raise InputError(f"{what} must be strictly ascending", path=path, line=line)
    if array[0] < GRID_NM[0] or array[-1] > GRID_NM[-1]:
        raise InputError(f"{what} must lie in {GRID_NM[0]:g}-{GRID_NM[-1]:g} nm", path=path, line=line)
    return array


def read_residual(path: str | Path) -> MeasuredResidual:
    """Read a residual file, refusing bad input with one line naming file and line."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise InputError(f"cannot read the residual file ({exc.strerror})", path=path) from None
    width = None
    header = None
    emission, rows = [], []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            body = line[1:].strip()
            if body.startswith(BIN_WIDTH_KEY):
                (width,) = _floats(body[len(BIN_WIDTH_KEY):], path, number, "bin width")
                if not width > 0:
                    raise InputError(f"bin width must be > 0 nm, not {width:g}", path=path, line=number)
            continue
        if header is None:
            name, _, rest = line.partition(",")
            if name.strip() != "emission_nm" or not rest:
                raise InputError("header must be 'emission_nm,<excitation nm>,...'", path=path, line=number)
            header = _ascending(_floats(rest, path, number, "excitation axis"), path, number,
                                "excitation axis")
            continue
        numbers = _floats(line, path, number, "row")
        if len(numbers) != header.size + 1:
            raise InputError(f"row has {len(numbers) - 1} entries, the header {header.size}",
                             path=path, line=number)
        entries = np.asarray(numbers[1:])
        if np.any(np.abs(entries) > 1.0):
            raise InputError("residual entries must lie in [-1, 1]", path=path, line=number)
        emission.append(numbers[0])
        rows.append(entries)
    if width is None:
        raise InputError(f"missing '# {BIN_WIDTH_KEY} W' line", path=path)
    if header is None or not rows:
        raise InputError("no header or no rows", path=path)
    emission_nm = _ascending(emission, path, None, "emission wavelengths")
    return MeasuredResidual(emission_nm, header, np.vstack(rows), float(width))
