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
#: catalog/bench/uv_fluorescence.py (benchmarks/bench_uv.json records the choice).
CHOSEN = "14 bands: every 10 nm below 430"
DEFAULT_EDGES_NM = CANDIDATE_EDGES[CHOSEN]


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
        light = np.asarray(irradiance_w_m2_nm, dtype=np.float64)
        return self.reflectance_on_grid() * light + self.emitted_w_m2_nm(light)

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
               base: SeparableFit | None = None, band_nm: float = REFLECTANCE_BAND_NM) -> BandedFit:
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
    return BandedFit(matrix.name, lo, li, step, edges, reflectance, tuple(components))


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
    return {**main, "bands": entries[:-1]}

