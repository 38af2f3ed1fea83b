"""Spectra: reading spectrum CSV files and putting them on the project's wavelength grid.

formats.md: two columns ``wavelength_nm,intensity``; wavelengths strictly increasing;
values >= 0; linear interpolation onto a 1 nm grid, zero outside the measured range;
excitation and emission spectra normalised to a peak of 1 on load.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.csvtable import read_numeric_csv
from catalog.core.errors import InputError

#: The project's wavelength grid in nm: UV-B/UV-A (where brighteners are excited) to the
#: red end of the visible, 1 nm steps. Every light and material spectrum lives on it.
GRID_NM = np.arange(300.0, 781.0, 1.0)
#: The visible range of the paper's sums (eq. 1-4): 380-780 nm.
VISIBLE_NM = (380.0, 780.0)

SPECTRUM_COLUMNS = ("wavelength_nm", "intensity")


@dataclass(frozen=True)
class Spectrum:
    """A sampled spectrum: ``values`` at ``wavelength_nm`` (strictly increasing)."""

    wavelength_nm: np.ndarray
    values: np.ndarray
    source: str = ""
    comments: tuple[str, ...] = ()

    def resample(self, grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
        """Linear interpolation onto ``grid_nm``; zero outside the measured range."""
        return resample(self.wavelength_nm, self.values, grid_nm)

    def normalised(self) -> "Spectrum":
        """The same spectrum scaled to a peak of 1 (refused if it is zero everywhere)."""
        peak = float(np.max(self.values))
        if not peak > 0:
            raise InputError("spectrum is zero everywhere; cannot normalise to a peak of 1",
                             path=self.source or None)
        return Spectrum(self.wavelength_nm, self.values / peak, self.source, self.comments)

    @property
    def peak_nm(self) -> float:
        return float(self.wavelength_nm[int(np.argmax(self.values))])


def resample(wavelength_nm: np.ndarray, values: np.ndarray,
             grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """Linear interpolation of (wavelength_nm, values) onto ``grid_nm``; 0 outside."""
    return np.interp(np.asarray(grid_nm, dtype=np.float64), wavelength_nm, values,
                     left=0.0, right=0.0)


def read_spectrum(path: str | Path, *, normalise: bool = False) -> Spectrum:
    """Read a spectrum CSV (formats.md), refusing bad input with file and line.

    ``normalise=True`` scales to a peak of 1, as excitation and emission spectra are.
    """
    table = read_numeric_csv(path, SPECTRUM_COLUMNS)
    wl = table.columns["wavelength_nm"]
    steps = np.diff(wl)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        problem = "duplicate wavelength" if steps[bad[0]] == 0 else "wavelengths not increasing"
        raise InputError(f"{problem}: {wl[i]:g} nm after {wl[i - 1]:g} nm", path=path,
                         line=int(table.line_numbers[i]))
    spectrum = Spectrum(wl, table.columns["intensity"], str(path), table.comments)
    if normalise:
        if not np.max(spectrum.values) > 0:
            raise InputError("intensity is zero everywhere; cannot normalise to a peak of 1",
                             path=path, line=int(table.line_numbers[0]))
        spectrum = spectrum.normalised()
    return spectrum


def write_spectrum(path: str | Path, wavelength_nm: np.ndarray, values: np.ndarray,
                   comments: list[str] | tuple[str, ...] = ()) -> None:
    """Write a spectrum CSV atomically (comment lines first, then the exact header)."""
    from catalog.core.atomic import write_text_atomic

    lines = [f"# {c}" for c in comments]
    lines.append(",".join(SPECTRUM_COLUMNS))
    lines += [f"{w:.4f},{v:.8g}" for w, v in zip(wavelength_nm, values)]
    write_text_atomic(path, "\n".join(lines) + "\n")
