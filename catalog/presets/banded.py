"""A catalog fabric carrying a measured matrix's fluorescence: the banded model (and, when
the fit keeps it, the measured residual) on a base fabric's cloth.

``catalog bispectral FILE.BFC --preset BASE --export DIR`` writes one with
:func:`banded_preset`; the benchmark and the tests use it on the validation matrices in
temporary folders (those matrices are not shipped, so no built-in fabric is made this way).
What the preset takes from the matrix: the ``[fluorescence]`` table (bands, quantum yields,
absorptances, residual; and the paper mode's eq. 1-3 colour, from the bands' emission under
D65). What it keeps from BASE: the cloth, the BTDF and its colour, the pattern and, when
BASE has one, the saturation (BASE need not fluoresce).
"""

from __future__ import annotations

from pathlib import Path


def banded_preset(base_preset, fit, folder, name: str | None = None):
    """A preset like ``base_preset`` whose physical-mode fluorescence is ``fit``'s bands
    (a :class:`catalog.optics.bispectral.bands.BandedFit`), written as ``folder/NAME.toml``
    with its files in ``folder/NAME/`` (NAME by default ``BASE-MATRIX-banded``); returns the
    loaded :class:`catalog.presets.Preset`.

    The preset is self-contained (:mod:`catalog.presets.bundle`): the bands' spectra are
    written into ``folder/NAME/``, the base's pattern images and dye are copied
    beside them, so two fabrics exported into one folder never share, or overwrite, each
    other's files, and the folder can be moved.
    """
    from catalog.optics.bispectral.bands import band_materials_table  # noqa: PLC0415
    from catalog.presets import preset_to_dict, save_preset_dict  # noqa: PLC0415
    from catalog.presets.bundle import bundle_files  # noqa: PLC0415

    folder = Path(folder)
    name = name or f"{base_preset.name}-{fit.matrix_name.lower()}-banded"
    files = folder / name
    files.mkdir(parents=True, exist_ok=True)
    doc = preset_to_dict(base_preset)
    doc["name"] = name
    doc["display_name"] = f"{base_preset.display_name} ({fit.matrix_name}, {len(fit.components)} bands)"
    doc.pop("fit", None)
    fluorescence = {k: v for k, v in doc.get("fluorescence", {}).items()
                    if k == "saturation_photon_irradiance"}
    xyz, rgb = paper_colour_of(fit)
    fluorescence.update(xyz=[round(float(v), 4) for v in xyz],
                        rgb=[round(float(v), 4) for v in rgb])
    table = band_materials_table(fit, files)
    for entry in [table] + table["bands"]:  # the bands' files, where they were written
        for key in ("excitation", "emission"):
            entry[key] = str(files / entry[key])
    if "residual" in table:
        table["residual"] = str(files / table["residual"])
    fluorescence.update(table)
    doc["fluorescence"] = fluorescence
    # the base's files (pattern, dye) are named relative to the base's folder
    base_folder = Path(base_preset.path).parent if base_preset.path is not None else folder
    target = folder / f"{name}.toml"
    bundle_files(doc, target, lambda _key, value: base_folder / value)
    return save_preset_dict(doc, target)


def paper_colour_of(fit):
    """Paper eq. 1-3 colour of ``fit``'s fluorescence: its emitted energy spectrum under
    D65 (all bands; the residual is not fluorescence and is left out)."""
    from catalog.optics.fluorescence import paper_colour  # noqa: PLC0415
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM, Spectrum  # noqa: PLC0415

    emitted = fit.emitted_w_m2_nm(get_light("D65").irradiance_w_m2_nm)
    return paper_colour(Spectrum(GRID_NM, emitted, f"{fit.matrix_name} bands under D65"))
