#!/usr/bin/env python3
"""Regenerate the synthetic excitation and emission spectra of the catalog's fluorescent fabrics.

    .venv/bin/python tools/make_fluorescent_spectra.py [--out fabrics/measurements]

writes <out>/<fabric>/excitation.csv and emission.csv for lace-fwa, safety-yellow and
fluoro-pink. Deterministic (closed-form bands, no noise): a test regenerates the files and
compares them byte for byte with the committed ones.

How the shapes are made: each spectrum is a sum of Gaussian bands in wavenumber (cm^-1), a
vibronic progression as organic dyes show it: the 0-0 band and replicas spaced by a
skeletal vibration (~1300-1400 cm^-1), excitation replicas to the blue, emission replicas
to the red (the mirror-image rule). The band positions are then shifted together so that
the peak lands exactly where the source puts it, and the whole is normalised to a peak of 1.
Only the peak positions (and roughly the widths) come from the named sources; the shapes
are ours.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from catalog.optics.spectra import write_spectrum  # noqa: E402  (after the path set-up)

#: Dense sampling used to find the continuous peak of a band sum (nm).
_FINE_STEP_NM = 0.001


@dataclass(frozen=True)
class Band:
    """One Gaussian band in wavenumber: offset from the 0-0 band (cm^-1), width, height."""

    offset_cm: float
    sigma_cm: float
    height: float


@dataclass(frozen=True)
class SyntheticSpectrum:
    kind: str  # "excitation" or "emission"
    start_nm: float
    stop_nm: float
    step_nm: float
    peak_nm: float  # where the spectrum's maximum must land
    origin_nm: float  # first guess of the 0-0 band position
    bands: tuple[Band, ...]
    header: tuple[str, ...]

    def evaluate(self, wavelength_nm: np.ndarray, origin_cm: float) -> np.ndarray:
        wavenumber_cm = 1e7 / wavelength_nm
        total = np.zeros_like(wavelength_nm)
        for band in self.bands:
            centre = origin_cm + band.offset_cm
            total += band.height * np.exp(-0.5 * ((wavenumber_cm - centre) / band.sigma_cm) ** 2)
        return total

    def origin_for_peak(self) -> float:
        """The 0-0 wavenumber that puts the maximum of the band sum at ``peak_nm``.

        A rigid shift of all bands in wavenumber moves the maximum by the same wavenumber
        shift, so one correction is exact; a second pass removes the sampling error.
        """
        fine = np.arange(self.peak_nm - 60.0, self.peak_nm + 60.0, _FINE_STEP_NM)
        origin = 1e7 / self.origin_nm
        for _ in range(3):
            found_nm = fine[int(np.argmax(self.evaluate(fine, origin)))]
            origin += 1e7 / self.peak_nm - 1e7 / found_nm
        return origin

    def sample(self) -> tuple[np.ndarray, np.ndarray]:
        count = int(round((self.stop_nm - self.start_nm) / self.step_nm)) + 1
        wavelength_nm = self.start_nm + self.step_nm * np.arange(count)
        values = self.evaluate(wavelength_nm, self.origin_for_peak())
        values = values / values.max()
        values[values < 1e-6] = 0.0  # below any spectrofluorometer's noise floor
        return wavelength_nm, values


_SYNTHETIC = ("SYNTHETIC spectrum, not a measurement: made by tools/make_fluorescent_spectra.py "
              "as a sum of Gaussian vibronic bands in wavenumber, shifted so the peak lands "
              "at the published wavelength, normalised to a peak of 1.")

SPECTRA: dict[str, tuple[SyntheticSpectrum, SyntheticSpectrum]] = {
    "lace-fwa": (
        SyntheticSpectrum(
            kind="excitation", start_nm=300.0, stop_nm=460.0, step_nm=0.5, peak_nm=375.0,
            origin_nm=392.0,
            bands=(Band(0.0, 550.0, 0.3), Band(1300.0, 950.0, 1.0),
                   Band(2600.0, 1400.0, 0.95), Band(4100.0, 1900.0, 0.5),
                   Band(8600.0, 2200.0, 0.35)),
            header=("lace-fwa: excitation spectrum of the optical brightener (FWA) of a white "
                    "lace-curtain cloth",
                    _SYNTHETIC,
                    "Shaped after Tobitani, Mizushima, Nagata 2014 (FluoroMax-2, emission watched at "
                    "470 nm, 300-460 nm every 0.5 nm, peak 375 nm) and a stilbene brightener's broad "
                    "UV band (vibronic shoulders, S2 band rising below 320 nm, red edge below 2% by 430 nm).",
                    "quantity: relative excitation efficiency per incident photon")),
        SyntheticSpectrum(
            kind="emission", start_nm=350.0, stop_nm=700.0, step_nm=0.5, peak_nm=430.5,
            origin_nm=428.0,
            bands=(Band(0.0, 620.0, 0.9), Band(-1350.0, 600.0, 0.55),
                   Band(-2700.0, 900.0, 0.10), Band(-4000.0, 1500.0, 0.03)),
            header=("lace-fwa: emission spectrum of the optical brightener (FWA) of a white "
                    "lace-curtain cloth",
                    _SYNTHETIC,
                    "Shaped after Tobitani, Mizushima, Nagata 2014 (FluoroMax-2, excited at 340 nm, "
                    "350-700 nm every 0.5 nm, peak 430.5 nm) and a stilbene brightener's emission: "
                    "vibronic shoulder near 455 nm, long red tail.",
                    "quantity: spectral radiant power (energy per nm), relative")),
    ),
    "safety-yellow": (
        SyntheticSpectrum(
            kind="excitation", start_nm=300.0, stop_nm=560.0, step_nm=0.5, peak_nm=457.0,
            origin_nm=470.0,
            bands=(Band(0.0, 1100.0, 0.8), Band(1300.0, 1300.0, 0.75),
                   Band(2600.0, 1600.0, 0.3), Band(9500.0, 2500.0, 0.22)),
            header=("safety-yellow: excitation spectrum of a fluorescent yellow-green textile dye "
                    "of the coumarin family, modelled on Coumarin 6 (Coumarin 540, "
                    "3-(2-benzothiazolyl)-7-(diethylamino)coumarin)",
                    _SYNTHETIC,
                    "Peak from published data: absorption maximum 2.713 eV = 457 nm in ethanol, as "
                    "compiled in Sci. Rep. 8 (2018), doi:10.1038/s41598-018-34813-w (its ref. 5); "
                    "band width (~70 nm FWHM) and a weak UV band are our choice.",
                    "quantity: relative excitation efficiency per incident photon")),
        SyntheticSpectrum(
            kind="emission", start_nm=440.0, stop_nm=700.0, step_nm=0.5, peak_nm=504.0,
            origin_nm=495.0,
            bands=(Band(0.0, 900.0, 0.8), Band(-1300.0, 1000.0, 0.7),
                   Band(-2600.0, 1300.0, 0.25)),
            header=("safety-yellow: emission spectrum of a fluorescent yellow-green textile dye "
                    "of the coumarin family, modelled on Coumarin 6 (Coumarin 540)",
                    _SYNTHETIC,
                    "Peak from published data: photoluminescence maximum 2.460 eV = 504 nm in methanol, "
                    "as compiled in Sci. Rep. 8 (2018), doi:10.1038/s41598-018-34813-w (its ref. 5); "
                    "the vibronic shape and width are our choice.",
                    "quantity: spectral radiant power (energy per nm), relative")),
    ),
    "fluoro-pink": (
        SyntheticSpectrum(
            kind="excitation", start_nm=300.0, stop_nm=620.0, step_nm=0.5, peak_nm=543.0,
            origin_nm=550.0,
            bands=(Band(0.0, 650.0, 1.0), Band(1250.0, 900.0, 0.38),
                   Band(10300.0, 2000.0, 0.12), Band(15500.0, 2500.0, 0.25)),
            header=("fluoro-pink: excitation spectrum of a fluorescent pink textile dye of the "
                    "rhodamine family, modelled on Rhodamine B (C.I. Basic Violet 10)",
                    _SYNTHETIC,
                    "Peak from published data: absorption maximum 543 nm in ethanol (PhotochemCAD, "
                    "Du, Fuh, Li, Corkan, Lindsey, Photochem. Photobiol. 68 (1998) 141, as compiled "
                    "by S. Prahl, omlc.org/spectra/PhotochemCAD); the 0-1 shoulder near 515 nm and "
                    "the UV bands are our choice.",
                    "quantity: relative excitation efficiency per incident photon")),
        SyntheticSpectrum(
            kind="emission", start_nm=505.0, stop_nm=750.0, step_nm=0.5, peak_nm=567.0,
            origin_nm=565.0,
            bands=(Band(0.0, 650.0, 1.0), Band(-1250.0, 900.0, 0.4),
                   Band(-2500.0, 1200.0, 0.08)),
            header=("fluoro-pink: emission spectrum of a fluorescent pink textile dye of the "
                    "rhodamine family, modelled on Rhodamine B (C.I. Basic Violet 10)",
                    _SYNTHETIC,
                    "Peak from published data: fluorescence maximum ~565-570 nm in ethanol (same "
                    "PhotochemCAD compilation); we put it at 567 nm; the shoulder near 610 nm "
                    "(mirror of the absorption's) is our choice.",
                    "quantity: spectral radiant power (energy per nm), relative")),
    ),
}


def write_all(out_dir: Path) -> list[Path]:
    """Write every fabric's excitation.csv and emission.csv under ``out_dir``; return the paths."""
    written = []
    for fabric, spectra in SPECTRA.items():
        for spectrum in spectra:
            wavelength_nm, values = spectrum.sample()
            path = out_dir / fabric / f"{spectrum.kind}.csv"
            comments = list(spectrum.header) + [
                f"{spectrum.start_nm:g}-{spectrum.stop_nm:g} nm every {spectrum.step_nm:g} nm, "
                f"peak {spectrum.peak_nm:g} nm"]
            write_spectrum(path, wavelength_nm, values, comments)
            written.append(path)
    return written


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "fabrics" / "measurements",
                        help="folder that receives <fabric>/excitation.csv and emission.csv")
    args = parser.parse_args(argv)
    for path in write_all(args.out):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
