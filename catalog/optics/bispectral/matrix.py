"""Bispectral (Donaldson) radiance-factor matrices: reading, exact rendering, separable fit.

A Donaldson matrix D(lo, li) gives the light a surface sends back at the emission
wavelength lo when lit at the excitation wavelength li: its diagonal is the ordinary
reflectance, its part with lo > li the fluorescence (Stokes emission). Under a light of
spectral irradiance E the surface returns (model.md section 8)

    L(lo) = sum_i D(lo, li) E(li)

in the units of E: the spectral irradiance a perfect white diffuser would have to receive
to look the same (pi times the radiance for a Lambertian surface; a "radiance factor"
spectrum).

The 10 nm sampling. A bispectrometer (here a Labsphere BFC-450) illuminates through a
monochromator of about 10 nm bandpass, stepped every 10 nm: the column at li is the
response to the light inside the bin [li - 5, li + 5] nm. A light sampled finely (our
1 nm grid) must therefore be averaged over each bin, not point-sampled at li: a mercury
line at 404.7 nm belongs wholly to the 400 nm bin and none of it to the 410 nm bin.
:func:`bin_irradiance` does that (trapezoid integral over the bin divided by its width),
and :func:`render_exact` applies the matrix to those bin means.

The separable fit (:func:`fit_separable`) writes the fluorescent part in photon units,

    D_fl(lo, li) = phi a(li) (li / lo) p(lo) dli

(phi: quantum yield, a: absorptance of the fluorophore, p: emitted photon spectrum per nm,
dli: the 10 nm excitation bin; li/lo converts absorbed to emitted energy per photon), so
that it becomes a :class:`catalog.optics.fluorescence.FluorescentMaterial` and the project's
physical mode (``emitted_exitance_w_m2_nm``) reproduces the matrix. By default the
least-squares factors are then refined (:func:`refine_for_colour`, same model) so that the
colours under a set of training lights (:data:`COLOUR_TRAINING_LIGHTS`, none of the
study's goal lights) match the matrix's. docs/bispectral.md gives the figures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from catalog.core.csvtable import read_text
from catalog.core.errors import InputError
from catalog.optics.spectra import GRID_NM

if TYPE_CHECKING:  # pragma: no cover
    from catalog.optics.fluorescence import FluorescentMaterial

def bispectral_dir() -> Path:
    """The validation data's folder of measured matrices (read in place, never copied); a
    one-line input error when it is absent (see :func:`catalog.core.resources.data_dir`)."""
    from catalog.core.resources import data_dir
    return data_dir("bispectral")


#: Lines before the dimension line in a BFC-450 matrix file (the dimension line is line 11).
HEADER_LINES = 10
#: Half width, nm, of the band around the diagonal into which the instrument's 10 nm
#: bandpass spills the ordinary reflectance (entries at |lo - li| <= 10 nm): those entries
#: hold reflectance, not fluorescence, and the separable fit leaves them to the reflectance.
REFLECTANCE_BAND_NM = 10.0
#: A fitted excitation or emission sample is kept only while the matrix entries it
#: predicts rise above this many standard deviations of the measurement noise.
NOISE_SIGMAS = 3.0
#: Lights the colour refinement trains on (:func:`refine_for_colour`): Planckian radiators
#: ("planck:K"), CIE daylights and lamps, none of them a light of the goal set (D65, A,
#: FL2, FL11, LED-B4), so the goal's figures are measured on lights the fit never saw.
COLOUR_TRAINING_LIGHTS = ("planck:2200", "planck:2500", "planck:3300", "planck:4000",
                          "planck:5000", "planck:6500", "D50", "D55", "D75",
                          "FL1", "FL3", "FL4", "FL6", "FL7", "FL8", "FL10", "FL12",
                          "LED-B1", "LED-B2", "LED-B3", "LED-B5", "LED-BH1", "LED-RGB1",
                          "LED-V1", "LED-V2")
#: Relative uncertainty granted to the reflectance in the refinement: R may move by about
#: this fraction of itself (plus the noise of the band sum) at the cost of one unit of
#: colour error; a photometric scale tolerance of the order of a spectrophotometer's.
REFLECTANCE_TOLERANCE = 0.005


@dataclass(frozen=True)
class DonaldsonMatrix:
    """A measured bispectral radiance-factor matrix.

    values[k, j] is D(emission_nm[k], excitation_nm[j]), dimensionless (a radiance factor
    per excitation bin of width ``excitation_step_nm``). Small negative entries are
    measurement noise and are kept as measured.
    """

    emission_nm: np.ndarray
    excitation_nm: np.ndarray
    values: np.ndarray
    name: str
    description: str
    path: str = ""

    @property
    def excitation_step_nm(self) -> float:
        return float(self.excitation_nm[1] - self.excitation_nm[0])

    @property
    def emission_step_nm(self) -> float:
        return float(self.emission_nm[1] - self.emission_nm[0])

    def stokes_shift_nm(self) -> np.ndarray:
        """lo - li for every entry (shape of ``values``): > 0 is Stokes, < 0 anti-Stokes."""
        return self.emission_nm[:, None] - self.excitation_nm[None, :]

    def diagonal(self) -> np.ndarray:
        """The entries with excitation == emission wavelength (on ``emission_nm``)."""
        return self.values[self.stokes_shift_nm() == 0]


# ------------------------------------------------------------------------------ reading

def _numbers(path: Path, line_no: int, fields: list[str], what: str) -> list[float]:
    out = []
    for i, text in enumerate(fields, start=1):
        try:
            value = float(text)
        except ValueError:
            raise InputError(f"{what}: field {i} is not a number", path=path,
                             line=line_no) from None
        if not math.isfinite(value):
            raise InputError(f"{what}: field {i} is not finite", path=path,
                             line=line_no)
        out.append(value)
    return out


#: The most wavelengths one axis of a matrix file may list (1 nm steps over 200-2000 nm);
#: a dimension line claiming more is refused before any row is read.
MAX_AXIS_COUNT = 1801


def _axis(path: Path, line_no: int, start: float, stop: float, step: float, count: float,
          what: str) -> np.ndarray:
    if not (step > 0 and math.isfinite(count) and count == int(count) and count >= 2):
        raise InputError(f"{what} axis: need a step > 0 and a whole count >= 2, got step "
                         f"{step:g}, count {count:g}", path=path, line=line_no)
    if count > MAX_AXIS_COUNT:
        raise InputError(f"{what} axis: the dimension line claims {count:g} wavelengths, more "
                         f"than the {MAX_AXIS_COUNT} a matrix file holds", path=path, line=line_no)
    axis = start + step * np.arange(int(count))
    if abs(axis[-1] - stop) > 1e-6 * step:
        raise InputError(f"{what} axis: {start:g} + {step:g} x ({int(count)} - 1) is "
                         f"{axis[-1]:g}, not the stated end {stop:g}", path=path, line=line_no)
    return axis


def read_bfc(path: str | Path) -> DonaldsonMatrix:
    """Read a BFC-450 matrix file (the layout in docs/formats.md, "Where files are found").

    Ten header lines (the second says ``BFC-450 Matrix File``, lines starting with ';'
    carry the file name, the description, operator, instrument modes, date and time);
    line 11: ``EM_START EM_END EM_STEP EX_COUNT EX_START EX_STEP`` (e.g.
    ``380 780 10 49 300 10``: 41 emission rows 380-780 nm, 49 excitation columns 300-780 nm);
    line 12: ``r:c:`` then the excitation wavelengths; then one row per emission wavelength,
    which starts the row; optionally a final ``EOD``. Any departure is refused with an
    InputError naming the file and line.
    """
    path = Path(path)
    text = read_text(path, encoding="ascii")
    lines = text.splitlines()
    if not lines or not text.strip():
        raise InputError("empty file", path=path)
    if len(lines) < HEADER_LINES + 2:
        raise InputError(f"truncated: {len(lines)} lines, need at least {HEADER_LINES + 2} "
                         "(10 header lines, the dimension line, the r:c: line)", path=path,
                         line=len(lines))
    if "BFC" not in lines[1]:
        raise InputError("not a BFC-450 matrix file (line 2 does not name the BFC instrument)",
                         path=path, line=2)
    comments = [ln.strip()[1:].strip() for ln in lines[2:HEADER_LINES] if ln.strip().startswith(";")]
    # the first comment repeats the file name (not always faithfully); the second describes it
    name = path.stem.upper()
    description = comments[1] if len(comments) > 1 else ""

    dim_line = HEADER_LINES + 1
    dims = lines[HEADER_LINES].split()
    if len(dims) != 6:
        raise InputError(f"dimension line: expected 6 numbers (emission start end step, "
                         f"excitation count start step), found {len(dims)}", path=path,
                         line=dim_line)
    em_start, em_end, em_step, ex_count, ex_start, ex_step = _numbers(path, dim_line, dims,
                                                                      "dimension line")
    emission_nm = _axis(path, dim_line, em_start, em_end, em_step,
                        (em_end - em_start) / em_step + 1 if em_step > 0 else 0, "emission")
    excitation_nm = _axis(path, dim_line, ex_start, ex_start + ex_step * (ex_count - 1),
                          ex_step, ex_count, "excitation")

    col_line = HEADER_LINES + 2
    col_fields = lines[HEADER_LINES + 1].split()
    if not col_fields or col_fields[0] != "r:c:":
        raise InputError("expected the column line 'r:c:' followed by the excitation "
                         "wavelengths", path=path, line=col_line)
    columns = np.array(_numbers(path, col_line, col_fields[1:], "column wavelengths"))
    if columns.size != excitation_nm.size or not np.allclose(columns, excitation_nm):
        raise InputError(f"column wavelengths do not match the dimension line "
                         f"({excitation_nm.size} columns {excitation_nm[0]:g}-"
                         f"{excitation_nm[-1]:g} nm expected, {columns.size} found)",
                         path=path, line=col_line)

    rows = []
    first_row_line = HEADER_LINES + 3
    for k, wavelength in enumerate(emission_nm):
        line_no = first_row_line + k
        if line_no > len(lines) or lines[line_no - 1].strip().upper() == "EOD":
            raise InputError(f"truncated: {k} of {emission_nm.size} emission rows "
                             f"(row for {wavelength:g} nm missing)", path=path,
                             line=min(line_no, len(lines)))
        fields = lines[line_no - 1].split()
        if len(fields) != excitation_nm.size + 1:
            raise InputError(f"row for {wavelength:g} nm: expected {excitation_nm.size + 1} "
                             f"fields (wavelength + {excitation_nm.size} values), found "
                             f"{len(fields)}", path=path, line=line_no)
        numbers = _numbers(path, line_no, fields, f"row for {wavelength:g} nm")
        if abs(numbers[0] - wavelength) > 1e-6:
            raise InputError(f"row starts with {numbers[0]:g} nm, expected {wavelength:g} nm",
                             path=path, line=line_no)
        rows.append(numbers[1:])
    for line_no in range(first_row_line + emission_nm.size, len(lines) + 1):
        rest = lines[line_no - 1].strip()
        if rest and rest.upper() != "EOD":
            raise InputError(f"unexpected content after the {emission_nm.size} emission "
                             f"rows: {rest[:40]!r}", path=path, line=line_no)
    values = np.array(rows, dtype=np.float64)
    for array in (emission_nm, excitation_nm, values):
        array.setflags(write=False)
    return DonaldsonMatrix(emission_nm, excitation_nm, values, name, description, str(path))


def list_bfc(folder: str | Path | None = None) -> list[Path]:
    """The BFC files in ``folder`` (default: the shared data's bispectral/), sorted."""
    folder = bispectral_dir() if folder is None else Path(folder)
    return sorted(p for p in folder.iterdir() if p.suffix.upper() == ".BFC")


def find_bfc(name_or_path: str | Path) -> Path:
    """A BFC file by path, or by name (``CIBA12``) in the shared bispectral/ folder."""
    path = Path(name_or_path)
    if path.is_file():
        return path
    stem = path.name.upper().removesuffix(".BFC")
    from catalog.core.resources import data_missing_reason
    reason = data_missing_reason("bispectral")
    if reason is not None:
        raise InputError(f"no such file, and no matrices to look the name up in ({reason})",
                         path=name_or_path)
    folder = bispectral_dir()
    if folder.is_dir():
        for candidate in list_bfc(folder):
            if candidate.stem.upper() == stem:
                return candidate
        known = ", ".join(p.stem for p in list_bfc(folder))
        raise InputError(f"no such file, and no matrix of that name in {folder} "
                         f"(known: {known})", path=name_or_path)
    raise InputError("no such file", path=name_or_path)


# ---------------------------------------------------------------------------- rendering

def bin_irradiance(centres_nm: np.ndarray, irradiance_w_m2_nm: np.ndarray,
                   grid_nm: np.ndarray = GRID_NM, width_nm: float = 10.0) -> np.ndarray:
    """Mean spectral irradiance over each bin [c - w/2, c + w/2], W m^-2 nm^-1.

    The integral is the trapezoid rule of the (piecewise-linear) light on ``grid_nm``,
    divided by the full bin width. The light is zero outside the grid, as everywhere in
    the project (spectra.resample), so the bins at 300 and 780 nm, half outside GRID_NM,
    hold half of what a flat light gives: the exact result then sees the same light as
    the physical mode, which integrates over the grid only.
    """
    grid_nm = np.asarray(grid_nm, dtype=np.float64)
    light = np.asarray(irradiance_w_m2_nm, dtype=np.float64)
    cumulative = np.concatenate(([0.0], np.cumsum(0.5 * (light[1:] + light[:-1]) * np.diff(grid_nm))))
    lower = np.clip(np.asarray(centres_nm) - width_nm / 2, grid_nm[0], grid_nm[-1])
    upper = np.clip(np.asarray(centres_nm) + width_nm / 2, grid_nm[0], grid_nm[-1])
    integral = np.interp(upper, grid_nm, cumulative) - np.interp(lower, grid_nm, cumulative)
    return integral / width_nm


def render_exact(matrix: DonaldsonMatrix, irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
    """L(lo) = sum_i D(lo, li) E_i on ``matrix.emission_nm`` (model.md section 8).

    E_i is the light's mean over the excitation bin of column i (:func:`bin_irradiance`),
    ``irradiance_w_m2_nm`` is on GRID_NM. The result is in W m^-2 nm^-1: the irradiance a
    perfect white diffuser would need to look the same (pi x radiance).
    """
    light_bins = bin_irradiance(matrix.excitation_nm, irradiance_w_m2_nm,
                                width_nm=matrix.excitation_step_nm)
    return matrix.values @ light_bins


def exact_exitance_on_grid(matrix: DonaldsonMatrix, irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
    """The ground truth the colour study compares against, on GRID_NM (W m^-2 nm^-1).

    The diagonal (ordinary reflectance) is interpolated to 1 nm and multiplied by the light
    at full resolution, so the narrow lines of a fluorescent lamp are reflected where they
    are; every other entry (the re-radiation and the bandpass spill next to the diagonal)
    is applied to the 10 nm bin means as in :func:`render_exact` and the result,
    sampled every 10 nm in emission, is interpolated linearly to 1 nm. Outside the
    emission range (below 380 nm) the returned light is zero: it is invisible anyway.
    """
    light = np.asarray(irradiance_w_m2_nm, dtype=np.float64)
    shift = matrix.stokes_shift_nm()
    off_diagonal = np.where(shift == 0, 0.0, matrix.values)
    light_bins = bin_irradiance(matrix.excitation_nm, light, width_nm=matrix.excitation_step_nm)
    re_radiated = np.interp(GRID_NM, matrix.emission_nm, off_diagonal @ light_bins,
                            left=0.0, right=0.0)
    reflectance = np.interp(GRID_NM, matrix.emission_nm, matrix.diagonal(), left=0.0, right=0.0)
    return reflectance * light + re_radiated


# -------------------------------------------------------------------------- separable fit

@dataclass(frozen=True)
class SeparableFit:
    """D(lo, li) ~ R(lo) [lo = li] + u(lo) v(li) (li / lo) dli, fitted to one matrix.

    u (emission_weight, per nm of emission) and v (absorption_weight) are the rank-1
    factors; only their product is determined. The physical parameters:

    - emission photon pdf p(lo) = u(lo) / integral of u over nm (on GRID_NM after linear
      interpolation), so that phi a(li) = v(li) x that integral;
    - ``yield_absorptance`` = phi x peak absorptance = max(v) x integral of u: the only
      identifiable strength;
    - the split: the fluorophore is assumed to absorb all the light the surface does not
      reflect at the excitation peak, a_peak = 1 - R(peak) (R at the nearest measured
      wavelength, 380 nm for a UV peak), which gives the smallest quantum yield the
      matrix allows, phi = yield_absorptance / a_peak; should that exceed 1, phi = 1 and
      a_peak = yield_absorptance (capped at 1, ``clipped`` set).
    """

    matrix_name: str
    emission_nm: np.ndarray
    excitation_nm: np.ndarray
    excitation_step_nm: float
    reflectance: np.ndarray          # R(lo) on emission_nm, band-corrected, >= 0
    emission_weight: np.ndarray      # u(lo) on emission_nm, >= 0
    absorption_weight: np.ndarray    # v(li) on excitation_nm, >= 0
    fitted_mask: np.ndarray          # the entries the rank-1 part was fitted on
    noise_sigma: float               # robust std of far anti-Stokes entries
    rank1_residual: float            # relative rms residual on the fitted entries
    residual_over_noise: float       # rms residual / noise_sigma on the fitted entries
    yield_absorptance: float         # phi * a_peak
    quantum_yield: float
    peak_absorptance: float
    clipped: bool = False
    iterations: int = 0
    notes: tuple[str, ...] = field(default=())

    def fluorescence_matrix(self) -> np.ndarray:
        """The fitted re-radiation u(lo) v(li) (li / lo) dli on the matrix's grid."""
        return (self.emission_weight[:, None] * self.absorption_weight[None, :]
                * (self.excitation_nm[None, :] / self.emission_nm[:, None])
                * self.excitation_step_nm)

    def model_matrix(self) -> np.ndarray:
        """Reflectance on the diagonal plus the fitted re-radiation everywhere."""
        shift = self.emission_nm[:, None] - self.excitation_nm[None, :]
        return self.fluorescence_matrix() + np.where(shift == 0, self.reflectance[:, None], 0.0)

    @property
    def excitation_peak_nm(self) -> float:
        return float(self.excitation_nm[int(np.argmax(self.absorption_weight))])

    @property
    def emission_peak_nm(self) -> float:
        return float(self.emission_nm[int(np.argmax(self.emission_weight))])

    def reflectance_on_grid(self) -> np.ndarray:
        """R on GRID_NM: linear interpolation, zero outside the emission range (380-780 nm),
        as the exported reflectance.csv reads back and as the exact result treats it."""
        return np.interp(GRID_NM, self.emission_nm, self.reflectance, left=0.0, right=0.0)

    def excitation_on_grid(self) -> np.ndarray:
        """The excitation (absorption) spectrum on GRID_NM, peak 1, zero outside the fit."""
        v = np.interp(GRID_NM, self.excitation_nm, self.absorption_weight, left=0.0, right=0.0)
        return v / float(np.max(v))

    def emission_pdf_on_grid(self) -> np.ndarray:
        """The emitted photon spectrum on GRID_NM, integrating to 1 over nm."""
        u = np.interp(GRID_NM, self.emission_nm, self.emission_weight, left=0.0, right=0.0)
        return u / (float(np.sum(u)) * _grid_step())

    def material(self) -> "FluorescentMaterial":
        """The fit as a physical-mode material (no saturation: the matrix is linear)."""
        from catalog.optics.fluorescence import FluorescentMaterial

        return FluorescentMaterial(absorptance=self.peak_absorptance * self.excitation_on_grid(),
                                   emission_pdf_per_nm=self.emission_pdf_on_grid(),
                                   quantum_yield=self.quantum_yield,
                                   saturation_photon_irradiance=math.inf)


def _grid_step() -> float:
    return float(GRID_NM[1] - GRID_NM[0])


def _keep_peak_run(significant: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """The contiguous run of ``significant`` samples that holds the largest weight."""
    keep = np.zeros_like(significant)
    if not np.any(significant):
        return keep
    peak = int(np.argmax(np.where(significant, weights, -np.inf)))
    i = peak
    while i >= 0 and significant[i]:
        keep[i] = True
        i -= 1
    i = peak + 1
    while i < significant.size and significant[i]:
        keep[i] = True
        i += 1
    return keep


def _alternating_nnls(values: np.ndarray, weight: np.ndarray, energy: np.ndarray,
                      u: np.ndarray, v: np.ndarray, keep_u: np.ndarray, keep_v: np.ndarray,
                      max_iterations: int, tolerance: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Least squares of values ~ u(lo) v(li) energy(lo, li) over weight > 0, u, v >= 0.

    Each half-step is the exact nonnegative least-squares solution for one factor with
    the other fixed (a one-variable problem per row or column, clipped at 0), so the
    masked residual never increases.
    """
    we = weight * energy
    wee = weight * energy * energy
    previous = None
    iterations = 0
    for iterations in range(1, max_iterations + 1):
        num = (we * values) @ v
        den = wee @ (v * v)
        u = np.where(keep_u & (den > 0), np.maximum(num, 0.0) / np.where(den > 0, den, 1.0), 0.0)
        num = u @ (we * values)
        den = (u * u) @ wee
        v = np.where(keep_v & (den > 0), np.maximum(num, 0.0) / np.where(den > 0, den, 1.0), 0.0)
        product = np.outer(u, v)
        if previous is not None:
            change = np.max(np.abs(product - previous)) / max(float(np.max(np.abs(product))), 1e-300)
            if change < tolerance:
                break
        previous = product
    return u, v, iterations


def fit_separable(matrix: DonaldsonMatrix, *, noise_sigmas: float = NOISE_SIGMAS,
                  band_nm: float = REFLECTANCE_BAND_NM, single_band: bool = True,
                  colour_lights: tuple[str, ...] | None = COLOUR_TRAINING_LIGHTS,
                  max_iterations: int = 5000, tolerance: float = 1e-9) -> SeparableFit:
    """Fit reflectance + rank-1 photon-conserving re-radiation to ``matrix``.

    1. The rank-1 part u(lo) v(li) (li / lo) dli is fitted by alternating nonnegative least
       squares to every entry outside the reflectance band (|lo - li| > ``band_nm``), on
       both sides of the diagonal: the separable model emits the same spectrum whatever
       the excitation, so it predicts anti-Stokes entries too, and the measured ones
       (near zero) must hold it down.
    2. Noise: sigma is the robust (median absolute deviation) spread of the entries at
       least 30 nm on the anti-Stokes side, where nothing is emitted. An excitation or
       emission sample whose predicted entries stay below ``noise_sigmas`` x sigma is set
       to 0, and (``single_band``, the default: one fluorophore, one absorption and one
       emission band) only the contiguous run around the peak is kept, so a white
       plastic does not "absorb" at 490-620 nm because the anti-Stokes entries there are
       slightly positive (an instrument artefact: such islands would make it turn red
       light into blue); the fit is repeated on that support until it stops changing.
    3. Reflectance: R(lo) = sum over the band |lo - li| <= ``band_nm`` of (D - fit), i.e.
       the diagonal plus the reflectance the 10 nm bandpass spilled into its neighbours,
       minus the re-radiation the rank-1 part already gives there; clipped at 0.
    4. Unless ``colour_lights`` is None: :func:`refine_for_colour` moves R, u and v (same
       supports, same model) so that the colours under those TRAINING lights (none of the
       goal lights) match the matrix's, while the entries and R stay near the data.
    """
    shift = matrix.stokes_shift_nm()
    values = matrix.values
    lo = matrix.emission_nm
    li = matrix.excitation_nm
    step = matrix.excitation_step_nm
    energy = (li[None, :] / lo[:, None]) * step  # photons -> energy per bin
    weight = (np.abs(shift) > band_nm).astype(np.float64)

    far = values[shift <= -30.0]
    sigma = float(1.4826 * np.median(np.abs(far - np.median(far)))) if far.size else 0.0

    stokes = np.where(shift > band_nm, np.maximum(values, 0.0), 0.0)
    u = stokes.sum(axis=1) + 1e-12
    v = stokes.sum(axis=0) + 1e-12
    keep_u = np.ones(lo.size, dtype=bool)
    keep_v = np.ones(li.size, dtype=bool)
    total_iterations = 0
    for _ in range(10):
        u, v, n = _alternating_nnls(values, weight, energy, u, v, keep_u, keep_v,
                                    max_iterations, tolerance)
        total_iterations += n
        fitted = np.outer(u, v) * energy
        new_keep_v = fitted.max(axis=0) > noise_sigmas * sigma
        new_keep_u = fitted.max(axis=1) > noise_sigmas * sigma
        if single_band:
            new_keep_v = _keep_peak_run(new_keep_v, v)
            new_keep_u = _keep_peak_run(new_keep_u, u)
        if np.array_equal(new_keep_u, keep_u) and np.array_equal(new_keep_v, keep_v):
            break
        keep_u, keep_v = new_keep_u, new_keep_v
        # restart the zeroed samples from a small positive value inside the support
        u = np.where(keep_u, np.maximum(u, 1e-12), 0.0)
        v = np.where(keep_v, np.maximum(v, 1e-12), 0.0)
    if not (np.any(u > 0) and np.any(v > 0)):
        raise InputError("no re-radiation above the measurement noise: the matrix is not "
                         "fluorescent (only its reflectance can be used)", path=matrix.path or None)

    fit = _assemble(matrix, u, v, None, sigma, weight > 0, band_nm, total_iterations, ())
    if colour_lights:
        fit = refine_for_colour(matrix, fit, colour_lights)
    return fit


def _assemble(matrix: DonaldsonMatrix, u: np.ndarray, v: np.ndarray,
              reflectance: np.ndarray | None, sigma: float, fitted_mask: np.ndarray,
              band_nm: float, iterations: int, notes: tuple[str, ...]) -> SeparableFit:
    """Normalise the factors, derive R (unless given), split phi x a_peak, build the fit."""
    shift = matrix.stokes_shift_nm()
    values = matrix.values
    lo = matrix.emission_nm
    li = matrix.excitation_nm
    step = matrix.excitation_step_nm
    energy = (li[None, :] / lo[:, None]) * step
    # scale: u integrates to 1 over nm after interpolation onto GRID_NM
    u_area = float(np.sum(np.interp(GRID_NM, lo, u, left=0.0, right=0.0))) * _grid_step()
    u, v = u / u_area, v * u_area
    fluorescence = np.outer(u, v) * energy
    residual = (values - fluorescence)[fitted_mask]
    rank1_residual = float(np.sqrt(np.sum(residual ** 2) / np.sum(values[fitted_mask] ** 2)))
    residual_over_noise = float(np.sqrt(np.mean(residual ** 2)) / sigma) if sigma > 0 else math.inf

    if reflectance is None:
        band = np.abs(shift) <= band_nm
        reflectance = np.maximum(np.sum(np.where(band, values - fluorescence, 0.0), axis=1), 0.0)

    yield_absorptance = float(np.max(v))  # = phi * a_peak, since u is a pdf
    peak_nm = float(li[int(np.argmax(v))])
    r_at_peak = float(np.interp(peak_nm, lo, matrix.diagonal()))  # 380 nm value below 380
    notes = list(notes)
    peak_absorptance = min(1.0, max(1.0 - r_at_peak, 1e-6))
    quantum_yield = yield_absorptance / peak_absorptance
    clipped = False
    if quantum_yield > 1.0:
        quantum_yield = 1.0
        peak_absorptance = min(1.0, yield_absorptance)
        clipped = yield_absorptance > 1.0
        notes.append("quantum yield at its bound 1: the absorptance takes the rest")
        if clipped:
            notes.append(f"phi * a_peak = {yield_absorptance:.3g} > 1 breaks photon "
                         "conservation for a Lambertian emitter; capped at 1")
    arrays = dict(reflectance=np.array(reflectance, dtype=np.float64), emission_weight=u,
                  absorption_weight=v, fitted_mask=np.array(fitted_mask))
    for array in arrays.values():
        array.setflags(write=False)
    return SeparableFit(matrix_name=matrix.name, emission_nm=lo, excitation_nm=li,
                        excitation_step_nm=step, noise_sigma=sigma,
                        rank1_residual=rank1_residual, residual_over_noise=residual_over_noise,
                        yield_absorptance=yield_absorptance, quantum_yield=float(quantum_yield),
                        peak_absorptance=float(peak_absorptance), clipped=clipped,
                        iterations=iterations, notes=tuple(notes), **arrays)


# --------------------------------------------------------------- colour refinement

def training_light(name: str) -> np.ndarray:
    """A training light's spectral irradiance on GRID_NM (``planck:K`` or a library name).

    ``planck:K`` is a Planckian radiator at K kelvin (500-50000) at 1 000 lx, the level of
    the library's lamps; a bad temperature or an unknown name raises InputError."""
    from catalog.optics.lights import LAMP_LX, get_light, illuminance_lx, planck_w_m2_nm

    if name.startswith("planck:"):
        text = name.split(":", 1)[1]
        try:
            kelvin = float(text)
        except ValueError:
            kelvin = math.nan
        if not (math.isfinite(kelvin) and 500.0 <= kelvin <= 50000.0):
            raise InputError(f"temperature {text!r} is not a number of kelvin in 500-50000 "
                             "(write e.g. 'planck:2000')", field=f"light {name!r}")
        shape = planck_w_m2_nm(kelvin)
        return shape * (LAMP_LX / illuminance_lx(shape))  # a lamp's level, as the library's
    return np.asarray(get_light(name).irradiance_w_m2_nm, dtype=np.float64)


def _interpolation_matrix(samples_nm: np.ndarray) -> np.ndarray:
    """W with W @ y = np.interp(GRID_NM, samples_nm, y, left=0, right=0) for any y."""
    return np.stack([np.interp(GRID_NM, samples_nm, column, left=0.0, right=0.0)
                     for column in np.eye(samples_nm.size)], axis=1)


def refine_for_colour(matrix: DonaldsonMatrix, fit: SeparableFit | None = None,
                      lights: tuple[str, ...] = COLOUR_TRAINING_LIGHTS,
                      reflectance_tolerance: float = REFLECTANCE_TOLERANCE,
                      entry_weight: float = 1.0,
                      max_evaluations: int = 200) -> SeparableFit:
    """Refine a separable fit so that its colours under ``lights`` match the matrix's.

    The model stays the same (one absorption band and one emission band on the supports
    ``fit`` found, Stokes factor li/lo, photons counted, phi <= 1); only its numbers move.
    Least squares (scipy, R, u, v >= 0) of three groups of residuals:

    - the matrix entries the rank-1 part was fitted on, in units of the noise sigma,
      divided by sqrt(their count) (times ``entry_weight``): the data still hold the
      factors;
    - R(lo) - R0(lo) over (sqrt(3) sigma + ``reflectance_tolerance`` x R0), divided by
      sqrt(41): the reflectance stays near the band sum of :func:`fit_separable`;
    - the CIELAB difference between the physical-mode colour of the model and the exact
      colour (:func:`exact_exitance_on_grid`) under each light, white = the light,
      divided by sqrt(the number of lights).

    Colours are linear in R and, per light, bilinear in (u, v), so each light is reduced
    once to a few small matrices. ``reflectance_tolerance`` (0.005) was chosen by
    leave-group-out cross-validation on the training lights alone (docs/bispectral.md).
    A noiseless matrix (sigma below 1e-9 of its largest entry) is returned unchanged.
    """
    from scipy.optimize import least_squares

    from catalog.optics.colorimetry import cmfs, xyz_to_lab

    if not lights:
        raise ValueError("refine_for_colour needs at least one training light")
    fit = fit_separable(matrix, colour_lights=None) if fit is None else fit
    if not fit.noise_sigma > 1e-9 * float(np.max(np.abs(matrix.values))):
        return fit  # a noiseless (synthetic) matrix: the entries already fix the model
    lo, li = fit.emission_nm, fit.excitation_nm
    energy = (li[None, :] / lo[:, None]) * fit.excitation_step_nm
    mask = fit.fitted_mask
    sigma = fit.noise_sigma
    band_count = int(np.max(np.sum(np.abs(matrix.stokes_shift_nm()) <= REFLECTANCE_BAND_NM,
                                   axis=1)))
    r0 = np.array(fit.reflectance)
    r_scale = math.sqrt(band_count) * sigma + reflectance_tolerance * r0
    keep_u, keep_v = fit.emission_weight > 0, fit.absorption_weight > 0

    cmf = np.asarray(cmfs(GRID_NM)) * _grid_step()           # the scale cancels in L*a*b*
    irradiance = np.stack([training_light(name) for name in lights])            # (L, grid)
    w_r, w_u, w_v = (_interpolation_matrix(lo), _interpolation_matrix(lo)[:, keep_u],
                     _interpolation_matrix(li)[:, keep_v])
    reflect = np.einsum("gc,lg,gk->lck", cmf, irradiance, w_r)   # XYZ of R: reflect @ R
    absorb = (irradiance * GRID_NM) @ w_v                       # photons absorbed ~ absorb @ v
    emit = (cmf / GRID_NM[:, None]).T @ w_u                     # XYZ of photons p: emit @ u
    area = w_u.sum(axis=0)                                       # integral of p over nm
    exact = np.stack([_grid_xyz(exact_exitance_on_grid(matrix, e), cmf) for e in irradiance])
    white = irradiance @ cmf
    exact_lab = xyz_to_lab(exact, white)

    n_r, n_u = lo.size, int(keep_u.sum())
    values_fitted = matrix.values[mask]
    n_entries = values_fitted.size

    def unpack(params):
        u = np.zeros(lo.size)
        v = np.zeros(li.size)
        u[keep_u] = params[n_r:n_r + n_u]
        v[keep_v] = params[n_r + n_u:]
        return params[:n_r], u, v

    def residuals(params):
        r, u_in, v_in = params[:n_r], params[n_r:n_r + n_u], params[n_r + n_u:]
        _, u, v = unpack(params)
        entries = (values_fitted - (np.outer(u, v) * energy)[mask]) / sigma
        # reflected + emitted (emitted_exitance_w_m2_nm: phi N_abs p(l) h c / l), per light
        xyz = reflect @ r + np.outer(absorb @ v_in, emit @ u_in / max(float(area @ u_in), 1e-300))
        colour = xyz_to_lab(xyz, white) - exact_lab
        return np.concatenate([entry_weight * entries / math.sqrt(n_entries),
                               (r - r0) / r_scale / math.sqrt(n_r),
                               colour.ravel() / math.sqrt(len(lights))])

    start = np.concatenate([r0, fit.emission_weight[keep_u], fit.absorption_weight[keep_v]])
    scale = np.maximum(start, 1e-3 * float(np.max(start)))
    solution = least_squares(residuals, start, bounds=(0.0, np.inf), x_scale=scale,
                             max_nfev=max_evaluations)
    reflectance, u, v = unpack(solution.x)
    return _assemble(matrix, u, v, reflectance, fit.noise_sigma, mask, REFLECTANCE_BAND_NM,
                     fit.iterations + int(solution.nfev),
                     fit.notes + (f"refined for colour under {len(lights)} training lights",))


def _grid_xyz(spectrum: np.ndarray, cmf: np.ndarray) -> np.ndarray:
    return np.asarray(spectrum, dtype=np.float64) @ cmf


# ------------------------------------------------------------------------------- export

def to_fabric_measurements(matrix: DonaldsonMatrix, out_dir: str | Path,
                           fit: SeparableFit | None = None) -> dict[str, Path]:
    """Write excitation.csv, emission.csv and reflectance.csv (formats.md spectrum CSV).

    excitation: the fitted absorption spectrum, peak 1, on the excitation grid (zero
    outside the fitted support); emission: the fitted emitted PHOTON spectrum, peak 1,
    with a ``# quantity: photons per nm`` line so catalog.optics.fluorescence reads it as photons
    (linear interpolation of these samples reproduces :meth:`SeparableFit.material`
    exactly); reflectance: R(lo), 0..1, on the emission grid. Each file's header names the
    source matrix and the fitted quantum yield and peak absorptance, to pass to
    ``material_from_spectra``. Files are written atomically; the folder is created.
    """
    from catalog.optics.spectra import write_spectrum

    fit = fit_separable(matrix) if fit is None else fit
    out_dir = Path(out_dir)
    source = [f"source: {Path(matrix.path).name or matrix.name} ({matrix.description}), "
              "Labsphere BFC-450 bispectral matrix, S. Gonzalez (RIT 1999)",
              "licence of the source data not stated: for testing and validation only",
              f"separable fit by catalog.optics.bispectral.matrix: quantum_yield = {fit.quantum_yield:.4f}, "
              f"peak_absorptance = {fit.peak_absorptance:.4f} (only their product "
              f"{fit.yield_absorptance:.4f} is measured; a_peak = 1 - R at the excitation peak)",
              f"rank-1 relative residual {fit.rank1_residual:.3f}, "
              f"{fit.residual_over_noise:.2f} x the noise sigma {fit.noise_sigma:.2g}"]
    excitation = fit.absorption_weight / float(np.max(fit.absorption_weight))
    emission = fit.emission_weight / float(np.max(fit.emission_weight))
    paths = {"excitation": out_dir / "excitation.csv", "emission": out_dir / "emission.csv",
             "reflectance": out_dir / "reflectance.csv"}
    write_spectrum(paths["excitation"], fit.excitation_nm, excitation,
                   ["excitation (absorption) spectrum of the fluorophore, peak 1"] + source)
    write_spectrum(paths["emission"], fit.emission_nm, emission,
                   ["quantity: photons per nm",
                    "emitted photon spectrum, peak 1 (independent of the excitation)"] + source)
    write_spectrum(paths["reflectance"], fit.emission_nm, fit.reflectance,
                   ["ordinary reflectance (radiance factor, 0..1): the matrix diagonal plus "
                    "the 10 nm bandpass spill, minus the fitted re-radiation"] + source)
    return paths
