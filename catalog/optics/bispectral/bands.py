"""Per-band excitation: a bispectral matrix as a few (absorption, emission) pairs.

The separable fit (:func:`catalog.optics.bispectral.matrix.fit_separable`) holds ONE emission spectrum
whatever the exciting wavelength. Under short-wavelength light that breaks: a brightened
white excited at 360 nm does not emit quite what it emits excited at 400 nm, and a pigment
that absorbs at 580 nm may carry a second fluorophore (e.g. in its binder) that only UV
excites. The banded model cuts the excitation axis into bands at ``edges_nm`` and gives
each band k its own pair,

    D_fl(lo, li) = sum_k [li in band k] phi_k a_k(li) (li / lo) p_k(lo) dli

(photon units as in the separable fit: a_k absorptance, p_k emitted photon pdf per nm,
phi_k quantum yield <= 1). The last band (longest wavelengths, the visible) keeps the
colour-refined separable fit exactly: its absorption restricted to that band, its
emission, its reflectance; every shorter band is a rank-1 fit (alternating nonnegative
least squares, the same weights as the separable fit: every entry more than 10 nm off the
diagonal, both sides) to the matrix's columns in that band. With one band the model is
the separable fit; with one band per column it is the matrix (off the reflectance band).

A renderer that pre-integrates per (material, light) pays nothing per frame for the
bands: under one light the components collapse into ONE effective fluorophore
(:meth:`BandedFit.effective_material`), the same numbers the shader already takes.

**The measured residual** (issue 15, second part). What the bands cannot hold is kept
apart as a signed matrix ``residual`` on the matrix's grid: every off-diagonal entry minus
the bands' fluorescence there (the near-diagonal neighbours, the anti-Stokes stray light,
the negative entries of the noisy UV columns), optionally truncated to its leading
``residual_rank`` singular pairs. With a residual, the reflectance is the measured diagonal
less the bands' fluorescence on it (a line; the neighbours are in the residual), so the
model with the full residual is the whole matrix: physical part (non-negative bands,
quantum yield <= 1) + the data's rest, which is not fluorescence and not physical
(docs/bispectral.md, "The measured residual"). Under one light the residual is one signed
spectrum, ``L_res(lo) = sum_li residual(lo, li) E_bin(li)`` (the light's 10 nm bin means, as
the exact result uses them), pre-integrated with the bands.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from catalog.optics.bispectral.matrix import (REFLECTANCE_BAND_NM, DonaldsonMatrix, SeparableFit,
                                _alternating_nnls, fit_separable)
from catalog.optics.spectra import GRID_NM

#: Candidate band edges (nm; a band is [edge_i, edge_i+1)) compared on the selection lights.
CANDIDATE_EDGES = {
    "rank 1 (separable)": (),
    "2 bands: UV / rest (400)": (400.0,),
    "3 bands: UV / violet / rest (390, 420)": (390.0, 420.0),
    "4 bands: UV / violet / blue / rest (380, 400, 430)": (380.0, 400.0, 430.0),
    "5 bands (350, 380, 400, 430)": (350.0, 380.0, 400.0, 430.0),
    "7 bands (340, 360, 380, 400, 420, 440)": (340.0, 360.0, 380.0, 400.0, 420.0, 440.0),
    "14 bands: every 10 nm below 430": tuple(float(e) for e in range(310, 431, 10)),
}

#: The model the renderer carries: the candidate chosen on the selection lights by
#: benchmarks/uv_fluorescence.py (benchmarks/bench_uv.json records the choice).
BANDS_CHOSEN = "14 bands: every 10 nm below 430"
DEFAULT_EDGES_NM = CANDIDATE_EDGES[BANDS_CHOSEN]

#: Candidates with a measured residual (on top of BANDS_CHOSEN): rank of the kept residual
#: (None: the whole residual, every off-diagonal entry). Compared on the selection lights
#: with the band candidates, ordered by the numbers each stores.
RESIDUAL_CANDIDATES = {
    f"{BANDS_CHOSEN} + residual rank 1": 1,
    f"{BANDS_CHOSEN} + residual rank 2": 2,
    f"{BANDS_CHOSEN} + residual rank 4": 4,
    f"{BANDS_CHOSEN} + residual rank 8": 8,
    f"{BANDS_CHOSEN} + residual rank 16": 16,
    f"{BANDS_CHOSEN} + whole residual": None,
}

#: The model the renderer carries: the candidate chosen on the selection lights by
#: benchmarks/uv_fluorescence.py (benchmarks/bench_uv.json records the choice).
CHOSEN = f"{BANDS_CHOSEN} + whole residual"
#: The chosen model's residual rank (None: whole) and whether it has one at all.
DEFAULT_RESIDUAL = True
DEFAULT_RESIDUAL_RANK = RESIDUAL_CANDIDATES[CHOSEN]


def candidate_settings(label: str) -> tuple[tuple[float, ...], bool, int | None]:
    """(band edges, with residual, residual rank) of a candidate label."""
    if label in CANDIDATE_EDGES:
        return CANDIDATE_EDGES[label], False, None
    return DEFAULT_EDGES_NM, True, RESIDUAL_CANDIDATES[label]


def all_candidates() -> list[str]:
    return list(CANDIDATE_EDGES) + list(RESIDUAL_CANDIDATES)


@dataclass(frozen=True)
class Component:
    """One (absorption, emission) pair: phi a(li) = ``absorption`` (photon fraction per
    excitation bin, on the matrix's excitation grid) and p(lo) = ``emission_pdf`` (photons
    per nm on the emission grid, integrating to 1 on GRID_NM after interpolation)."""

    absorption: np.ndarray
    emission_pdf: np.ndarray


@dataclass(frozen=True)
class BandedFit:
    matrix_name: str
    emission_nm: np.ndarray
    excitation_nm: np.ndarray
    excitation_step_nm: float
    edges_nm: tuple[float, ...]
    reflectance: np.ndarray            # R(lo) on emission_nm
    components: tuple[Component, ...]  # one per band, shortest band first
    residual: np.ndarray | None = None  # signed (emission x excitation), per 10 nm bin; 0 on the diagonal
    residual_rank: int | None = None    # None: the whole residual

    def residual_exitance_w_m2_nm(self, irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
        """The residual under a light, W m^-2 nm^-1 on GRID_NM (signed; 0 without one):
        applied to the light's bin means and interpolated from the 10 nm emission grid,
        exactly as the exact result treats off-diagonal entries."""
        if self.residual is None:
            return np.zeros(GRID_NM.size)
        from catalog.optics.bispectral.matrix import bin_irradiance  # noqa: PLC0415

        bins = bin_irradiance(self.excitation_nm, np.asarray(irradiance_w_m2_nm, dtype=np.float64),
                              width_nm=self.excitation_step_nm)
        return np.interp(GRID_NM, self.emission_nm, self.residual @ bins, left=0.0, right=0.0)

    def stored_numbers(self) -> int:
        """Numbers a material stores: each absorbing band's two spectra, + 2, + the residual
        (rank r: r (emission + excitation) samples; whole: its off-diagonal entries)."""
        n = sum(1 for c in self.components if np.any(c.absorption > 0))
        count = n * (self.excitation_nm.size + self.emission_nm.size) + 2
        if self.residual is not None:
            whole = int(np.count_nonzero(self.excitation_nm[None, :] != self.emission_nm[:, None]))
            rank = self.residual_rank
            count += whole if rank is None else min(whole, rank * (self.excitation_nm.size
                                                                   + self.emission_nm.size))
        return int(count)

    def fluorescence_matrix(self) -> np.ndarray:
        energy = (self.excitation_nm[None, :] / self.emission_nm[:, None]) * self.excitation_step_nm
        return sum(np.outer(c.emission_pdf, c.absorption) for c in self.components) * energy

    def materials(self):
        """Each component as a :class:`catalog.optics.fluorescence.FluorescentMaterial`."""
        return tuple(_material(c, self.excitation_nm, self.emission_nm, self.reflectance)
                     for c in self.components if np.any(c.absorption > 0))

    def reflectance_on_grid(self) -> np.ndarray:
        return np.interp(GRID_NM, self.emission_nm, self.reflectance, left=0.0, right=0.0)

    def emitted_w_m2_nm(self, irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
        """Physical-mode emitted exitance (W m^-2 nm^-1 on GRID_NM): the sum over bands."""
        from catalog.optics.fluorescence import emitted_exitance_w_m2_nm  # noqa: PLC0415

        return sum((emitted_exitance_w_m2_nm(m, irradiance_w_m2_nm) for m in self.materials()),
                   np.zeros(GRID_NM.size))

    def exitance_w_m2_nm(self, irradiance_w_m2_nm: np.ndarray) -> np.ndarray:
        """Reflected + emitted + residual (W m^-2 nm^-1 on GRID_NM): the model's exitance,
        with the bands collapsed under the light as the renderer does."""
        light = np.asarray(irradiance_w_m2_nm, dtype=np.float64)
        from catalog.optics.fluorescence import emitted_exitance_w_m2_nm  # noqa: PLC0415

        effective = self.effective_material(light)
        emitted = (emitted_exitance_w_m2_nm(effective, light) if effective is not None
                   else np.zeros(GRID_NM.size))
        return self.reflectance_on_grid() * light + emitted + self.residual_exitance_w_m2_nm(light)

    def effective_material(self, irradiance_w_m2_nm: np.ndarray):
        """The bands collapsed into ONE fluorophore for this light (what the renderer
        carries): :func:`catalog.optics.fluorescence.combine_under_light`."""
        from catalog.optics.fluorescence import combine_under_light  # noqa: PLC0415

        return combine_under_light(self.materials(), irradiance_w_m2_nm)


def _material(component: Component, excitation_nm, emission_nm, reflectance):
    """phi a(li) and p(lo) -> FluorescentMaterial, splitting phi and a as the separable fit
    does: a_peak = 1 - R at the excitation peak (nearest measured R), phi the rest, capped."""
    from catalog.optics.fluorescence import FluorescentMaterial  # noqa: PLC0415

    phi_a = np.interp(GRID_NM, excitation_nm, component.absorption, left=0.0, right=0.0)
    pdf = np.interp(GRID_NM, emission_nm, component.emission_pdf, left=0.0, right=0.0)
    pdf = pdf / float(np.sum(pdf))
    peak_nm = float(excitation_nm[int(np.argmax(component.absorption))])
    a_peak = min(1.0, max(1.0 - float(np.interp(peak_nm, emission_nm, reflectance)), 1e-6))
    product = float(np.max(phi_a))
    phi = min(1.0, product / a_peak)
    a_peak = min(1.0, product / phi) if phi > 0 else a_peak
    absorptance = np.minimum(phi_a / phi, 1.0) if phi > 0 else phi_a
    return FluorescentMaterial(absorptance=absorptance, emission_pdf_per_nm=pdf,
                               quantum_yield=phi, saturation_photon_irradiance=math.inf)


def _pdf_scale(emission_nm: np.ndarray, u: np.ndarray) -> float:
    return float(np.sum(np.interp(GRID_NM, emission_nm, u, left=0.0, right=0.0)))


def fit_banded(matrix: DonaldsonMatrix, edges_nm: tuple[float, ...] = DEFAULT_EDGES_NM,
               base: SeparableFit | None = None, band_nm: float = REFLECTANCE_BAND_NM, *,
               residual: bool = False, residual_rank: int | None = None) -> BandedFit:
    """The banded model of ``matrix`` with excitation band edges ``edges_nm`` (ascending).

    ``base`` (default: :func:`fit_separable`, colour-refined) supplies the last band's pair
    and the reflectance; the reflectance rows near the diagonal then take back whatever
    the new bands' fluorescence changes inside the reflectance band, so R + fluorescence
    still sums to the matrix there.
    """
    base = fit_separable(matrix) if base is None else base
    lo, li = matrix.emission_nm, matrix.excitation_nm
    step = matrix.excitation_step_nm
    energy = (li[None, :] / lo[:, None]) * step
    shift = matrix.stokes_shift_nm()
    weight = (np.abs(shift) > band_nm).astype(np.float64)
    edges = tuple(sorted(float(e) for e in edges_nm))
    bounds = (-math.inf,) + edges + (math.inf,)
    scale = _pdf_scale(lo, base.emission_weight)
    base_pdf = base.emission_weight / scale
    base_abs = base.absorption_weight * scale
    components = []
    for k in range(len(bounds) - 1):
        columns = (li >= bounds[k]) & (li < bounds[k + 1])
        if k == len(bounds) - 2:  # the visible band: the separable fit as it is
            components.append(Component(np.where(columns, base_abs, 0.0), base_pdf))
            continue
        stokes = np.where((shift > band_nm) & columns[None, :], np.maximum(matrix.values, 0.0), 0.0)
        u0 = stokes.sum(axis=1) + 1e-12
        v0 = np.where(columns, stokes.sum(axis=0) + 1e-12, 0.0)
        u, v, _ = _alternating_nnls(matrix.values, weight * columns[None, :], energy, u0, v0,
                                    np.ones(lo.size, bool), columns, 5000, 1e-9)
        area = _pdf_scale(lo, u)
        if not (area > 0 and np.any(v > 0)):
            components.append(Component(np.zeros(li.size), base_pdf))
            continue
        components.append(Component(v * area, u / area))
    banded = BandedFit(matrix.name, lo, li, step, edges, np.array(base.reflectance), tuple(components))
    # reflectance: keep R + fluorescence inside the reflectance band as the base fit had it
    band = np.abs(shift) <= band_nm
    old = np.sum(np.where(band, base.fluorescence_matrix(), 0.0), axis=1)
    new = np.sum(np.where(band, banded.fluorescence_matrix(), 0.0), axis=1)
    reflectance = np.maximum(np.array(base.reflectance) + old - new, 0.0)
    banded = BandedFit(matrix.name, lo, li, step, edges, reflectance, tuple(components))
    return with_residual(matrix, banded, residual_rank) if residual else banded


def with_residual(matrix: DonaldsonMatrix, fit: BandedFit, rank: int | None = None) -> BandedFit:
    """``fit`` with the matrix's measured residual kept (module docstring): the reflectance
    becomes the diagonal less the bands' fluorescence there (clipped at 0; what the clip
    removes is lost; the tests bound it), and ``residual`` every off-diagonal entry less the bands'
    fluorescence, truncated to ``rank`` singular pairs (None: all)."""
    fluorescence = fit.fluorescence_matrix()
    on_diagonal = matrix.stokes_shift_nm() == 0
    rest = np.where(on_diagonal, 0.0, matrix.values - fluorescence)
    if rank is not None:
        if rank < 0:
            raise ValueError(f"residual rank must be >= 0, not {rank}")
        u, s, vt = np.linalg.svd(rest, full_matrices=False)
        rest = (u[:, :rank] * s[:rank]) @ vt[:rank]
    diagonal = np.sum(np.where(on_diagonal, matrix.values - fluorescence, 0.0), axis=1)
    rest.setflags(write=False)
    return BandedFit(fit.matrix_name, fit.emission_nm, fit.excitation_nm, fit.excitation_step_nm,
                     fit.edges_nm, np.maximum(diagonal, 0.0), fit.components, rest, rank)


def band_materials_table(fit: BandedFit, out_dir) -> dict:
    """Write the bands as fabric files and return the preset's ``[fluorescence]`` keys.

    The longest band (the visible one) becomes ``excitation.csv`` / ``emission.csv`` with
    ``quantum_yield`` and ``peak_absorptance``; every shorter band with any absorption
    becomes ``bandK_excitation.csv`` / ``bandK_emission.csv`` and one entry of
    ``bands`` (formats: docs/bispectral.md, "Preset"). Emission files are photon spectra
    (``# quantity: photons per nm``); excitation files peak at 1. Written atomically.
    """
    from pathlib import Path  # noqa: PLC0415

    from catalog.optics.spectra import write_spectrum  # noqa: PLC0415

    out_dir = Path(out_dir)
    source = (f"banded fit of {fit.matrix_name} (catalog.optics.bispectral.bands, excitation band "
              f"edges {', '.join(f'{e:g}' for e in fit.edges_nm) or 'none'} nm); source data: "
              "licence not stated, for testing and validation only")
    entries = []
    components = [(k, c) for k, c in enumerate(fit.components) if np.any(c.absorption > 0)]
    for index, (k, component) in enumerate(components):
        material = _material(component, fit.excitation_nm, fit.emission_nm, fit.reflectance)
        last = index == len(components) - 1
        stem = "" if last else f"band{k + 1}_"
        absorptance = np.interp(fit.excitation_nm, GRID_NM, material.absorptance)
        write_spectrum(out_dir / f"{stem}excitation.csv", fit.excitation_nm,
                       absorptance / float(np.max(absorptance)),
                       [f"excitation (absorption) of band {k + 1}, peak 1", source])
        write_spectrum(out_dir / f"{stem}emission.csv", fit.emission_nm,
                       component.emission_pdf / float(np.max(component.emission_pdf)),
                       ["quantity: photons per nm", f"emitted photon spectrum of band {k + 1}, "
                        "peak 1", source])
        entries.append({"excitation": f"{stem}excitation.csv", "emission": f"{stem}emission.csv",
                        "quantum_yield": round(material.quantum_yield, 6),
                        "peak_absorptance": round(material.peak_absorptance, 6)})
    main = entries[-1]
    table = {**main, "bands": entries[:-1]}
    if fit.residual is not None:
        from catalog.optics.measured_residual import write_residual  # noqa: PLC0415

        rank = "whole" if fit.residual_rank is None else f"rank {fit.residual_rank}"
        write_residual(out_dir / "residual.csv", fit.emission_nm, fit.excitation_nm, fit.residual,
                       fit.excitation_step_nm,
                       [f"measured residual ({rank}) of {fit.matrix_name}: the matrix less its "
                        "banded fit, off the diagonal; signed, not fluorescence", source])
        table["residual"] = "residual.csv"
    return table

