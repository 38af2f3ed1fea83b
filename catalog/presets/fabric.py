"""Fabric: a preset with every table it names read, checked and resolved, once.

A :class:`catalog.presets.Preset` is the TOML document (its BTDF lobes, fit, cloth table,
the paths of its files). :func:`resolve_fabric` reads those files (the dye's transmittance,
the fluorescence spectra of every band, the measured residual, the pattern's images) into one
frozen :class:`Fabric`; this module is the one place below the edge where a fabric's files
are read. The edge resolves the fabric when it makes the scene
(:class:`catalog.render.settings.FrameSettings`), and every renderer (the real-time frame, the
reference path tracer, the web export) draws from the resolved tables: a redraw, a change of
light or mode reads no file. One ``Fabric`` per preset object (cached while the preset lives).
"""

from __future__ import annotations

import functools
import weakref
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.errors import InputError
from catalog.optics.spectra import GRID_NM, read_spectrum


@dataclass(frozen=True, eq=False)
class Fabric:
    """A preset's tables, resolved. Spectra on GRID_NM (300-780 nm)."""

    preset: object                       # the catalog.presets.Preset
    #: T(l) of ``[dye] transmittance`` (edge values held), 1 without a dye
    dye_transmittance: np.ndarray
    #: the physical-mode materials (catalog.optics.fluorescence.FluorescentMaterial): the main
    #: band first, then each of ``[fluorescence] bands``; () without ``[fluorescence]``
    fluorescent_materials: tuple
    #: ``[fluorescence] residual`` (catalog.optics.measured_residual), or None
    residual: object
    #: the excitation spectrum normalised to a peak of 1, or None
    excitation_on_grid: np.ndarray | None
    #: the emission spectrum as measured, or None
    emission_on_grid: np.ndarray | None
    #: ``[pattern]`` (catalog.presets.patterns.Pattern), its open area checked against LD; or None
    pattern: object

    @property
    def name(self) -> str:
        return self.preset.name

    @property
    def btdf(self):
        """The eq. 7 lobes (catalog.presets.BTDFParams)."""
        return self.preset.btdf

    @property
    def cloth(self) -> dict:
        """The ``[cloth]`` table (catalog.cloth.params reads it)."""
        return self.preset.table("cloth")


_CACHE: dict[int, tuple] = {}


def resolve_fabric(preset) -> Fabric:
    """The preset's :class:`Fabric` (read once per preset object). A bad or missing file: one
    InputError naming it and the field."""
    if isinstance(preset, Fabric):
        return preset
    hit = _CACHE.get(id(preset))
    if hit is not None and hit[0]() is preset:
        return hit[1]
    fabric = Fabric(preset, _dye(preset), _materials(preset), _residual(preset),
                    *_spectra_on_grid(preset), _pattern(preset))
    key = id(preset)
    _CACHE[key] = (weakref.ref(preset, lambda _ref, key=key, cache=_CACHE: cache.pop(key, None)),
                   fabric)
    return fabric


def _dye(preset) -> np.ndarray:
    rel = preset.table("dye").get("transmittance")
    if rel is None:
        return np.ones(GRID_NM.size)
    spectrum = read_spectrum(preset.resolve(rel))
    values = np.interp(GRID_NM, spectrum.wavelength_nm, spectrum.values)
    if np.any(values > 1.0):
        raise InputError("dye transmittance must lie in [0, 1]", path=spectrum.source,
                         field="intensity")
    return values


@functools.lru_cache(maxsize=32)
def _material(excitation_path: str, emission_path: str, peak_absorptance: float,
              quantum_yield: float, saturation: float):
    from catalog.optics.fluorescence import material_from_spectra  # noqa: PLC0415

    return material_from_spectra(read_spectrum(excitation_path), read_spectrum(emission_path),
                                 peak_absorptance=peak_absorptance, quantum_yield=quantum_yield,
                                 saturation_photon_irradiance=saturation)


def _materials(preset) -> tuple:
    from catalog.optics import fluorescence as fl  # noqa: PLC0415

    if preset.fluorescence is None:
        return ()
    extra = preset.fluorescence.extra
    for path in (preset.fluorescence.excitation, preset.fluorescence.emission):
        if not path.is_file():
            raise InputError("fluorescence spectrum file not found", path=path)
    saturation = float(extra.get("saturation_photon_irradiance",
                                 fl.DEFAULT_SATURATION_PHOTON_IRRADIANCE))
    materials = [_material(str(preset.fluorescence.excitation), str(preset.fluorescence.emission),
                           float(extra.get("peak_absorptance", fl.DEFAULT_PEAK_ABSORPTANCE)),
                           float(extra.get("quantum_yield", fl.DEFAULT_QUANTUM_YIELD)),
                           saturation)]
    base = _base(preset)
    for i, band in enumerate(extra.get("bands") or []):
        where = f"fluorescence.bands[{i}]"
        if not isinstance(band, dict):
            raise InputError("must be a table", path=preset.path, field=where)
        paths = []
        for key in ("excitation", "emission"):
            rel = band.get(key)
            if not isinstance(rel, str) or not rel:
                raise InputError("must be a path string", path=preset.path, field=f"{where}.{key}")
            path = (base / rel).resolve()
            if not path.is_file():
                raise InputError("fluorescence spectrum file not found", path=path,
                                 field=f"{where}.{key}")
            paths.append(str(path))
        numbers = []
        for key in ("peak_absorptance", "quantum_yield"):
            value = band.get(key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value <= 1:
                raise InputError(f"must be a number in (0, 1], not {value!r}", path=preset.path,
                                 field=f"{where}.{key}")
            numbers.append(float(value))
        materials.append(_material(*paths, *numbers, saturation))
    return tuple(materials)


def _base(preset) -> Path:
    return preset.path.parent if preset.path is not None else preset.fluorescence.excitation.parent


@functools.lru_cache(maxsize=32)
def _residual_at(path: str):
    from catalog.optics.measured_residual import read_residual  # noqa: PLC0415

    return read_residual(path)


def _residual(preset):
    if preset.fluorescence is None:
        return None
    rel = preset.fluorescence.extra.get("residual")
    if rel is None:
        return None
    if not isinstance(rel, str) or not rel:
        raise InputError(f"must be a path string, not {rel!r}", path=preset.path,
                         field="fluorescence.residual")
    if not preset.fluorescence.extra.get("bands") and "quantum_yield" not in preset.fluorescence.extra:
        raise InputError("a residual needs the fitted bands it belongs to (quantum_yield, "
                         "peak_absorptance, bands)", path=preset.path, field="fluorescence.residual")
    path = (_base(preset) / rel).resolve()
    if not path.is_file():
        raise InputError("residual file not found", path=path, field="fluorescence.residual")
    return _residual_at(str(path))


def _spectra_on_grid(preset) -> tuple:
    if preset.fluorescence is None:
        return None, None
    excitation = read_spectrum(preset.fluorescence.excitation, normalise=True).resample(GRID_NM)
    emission = read_spectrum(preset.fluorescence.emission).resample(GRID_NM)
    return excitation, emission


def _pattern(preset):
    from catalog.presets.patterns import load_pattern  # noqa: PLC0415

    return load_pattern(preset)
