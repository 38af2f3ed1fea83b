"""The tables of docs/fluorescence.md (and README's "which lights need a fluorescence term").

    .venv/bin/python -m benchmarks.fluorescence_tables [--json-out FILE]

writes benchmarks/fluorescence_tables.json (needs the validation data's measured brightener,
``--data``/CATALOG_DATA), from which tools/docs_figures.py makes the tables:

1. Which lights need a fluorescence term: the brightened lace under D65, A, FL2, FL11,
   LED-B4, LED-warm, UV-A and the sun at 22 and 500 km, in paper mode (eq. 4) and
   physical mode (absorbed photons, emitted luminance, Delta E 2000 of the lit cloth).
2. The Delta E 2000 of each fluorescent fabric's emission on a white-lit cloth, per light.
3. The colour error of carrying an out-of-gamut emission to the shader as signed linear
   sRGB, clipped, or desaturated, against the exact spectral result (Delta E 2000).
4. The measured Calcofluor White (eq. 2's F, eq. 4 and the physical mode under D65), and the
   real bispectral matrices (CIPLAW10, CIBA12, TEXTYELL) judged as the lace is: Delta E 2000
   of the lit sample with and without its off-diagonal (fluorescent) entries, and its
   emission's luminance over a white diffuser's, under D65 and LED-B4.
"""

from __future__ import annotations

import sys

import numpy as np

from catalog.core.resources import FABRIC_DIR, data_dir
from catalog.optics import fluorescence as fl
from catalog.optics.colorimetry import delta_e_2000, xyz_to_linear_srgb
from catalog.optics.lights import get_light
from catalog.optics.spectra import GRID_NM, read_spectrum

INTENSITY_LIGHTS = ("D65", "A", "FL2", "FL11", "LED-B4", "LED-warm", "UV-A", "sun:22", "sun:500")
GAMUT_LIGHTS = ("D65", "A", "FL2", "FL11", "LED-B4", "LED-warm", "UV-A", "sun:22", "sun:500")
#: Physical-mode parameters of the catalog's fluorescent fabrics (docs/fluorescence.md).
FABRIC_PARAMETERS = {
    "lace-fwa": {"quantum_yield": 0.6, "peak_absorptance": 0.5},
    "safety-yellow": {"quantum_yield": 0.7, "peak_absorptance": 0.9},
    "fluoro-pink": {"quantum_yield": 0.5, "peak_absorptance": 0.9},
}
#: Reflectance of the white cloth behind/under the emission (a bleached cotton's level).
WHITE_CLOTH = 0.85


def fabric_material(name: str) -> tuple[fl.FluorescentMaterial, object, object]:
    folder = FABRIC_DIR / "measurements" / name
    excitation = read_spectrum(folder / "excitation.csv", normalise=True)
    emission = read_spectrum(folder / "emission.csv", normalise=True)
    return fl.material_from_spectra(excitation, emission, **FABRIC_PARAMETERS[name]), excitation, emission


def calcofluor_material() -> fl.FluorescentMaterial:
    folder = data_dir("brightener")
    excitation = read_spectrum(folder / "calcofluor_white_excitation.csv", normalise=True)
    emission = read_spectrum(folder / "calcofluor_white_emission.csv", normalise=True)
    return fl.material_from_spectra(excitation, emission, **FABRIC_PARAMETERS["lace-fwa"])


def intensity_rows() -> list[dict]:
    material, excitation, _ = fabric_material("lace-fwa")
    rows = []
    for name in INTENSITY_LIGHTS:
        light = get_light(name)
        e = light.irradiance_w_m2_nm
        emitted_xyz = fl.emission_xyz(material, e)
        lux = float(fl.light_xyz(e)[1])
        rows.append({
            "light": name,
            "illuminance_lx": lux,
            "uva_fraction": light.uva_fraction,
            "paper_intensity": fl.paper_intensity(e, excitation.resample(GRID_NM)),
            "absorbed_photons_m2_s": fl.absorbed_photon_irradiance(material, e),
            "emitted_exitance_w_m2": float(np.sum(fl.emitted_exitance_w_m2_nm(material, e))),
            "luminance_ratio": float(emitted_xyz[1]) / lux if lux > 0 else float("inf"),
            "delta_e_2000": fl.fluorescence_delta_e(material, e, WHITE_CLOTH),
            "needed": fl.fluorescence_needed(material, e, WHITE_CLOTH),
        })
    return rows


def _rgb_to_xyz_exact(rgb: np.ndarray) -> np.ndarray:
    """The exact inverse of xyz_to_linear_srgb (colour-science's two sRGB matrices are
    rounded separately and invert each other only to ~4e-5, which alone costs Delta E ~0.005)."""
    forward = xyz_to_linear_srgb(np.eye(3)).T  # rgb = forward @ xyz
    return np.linalg.solve(forward, np.asarray(rgb, dtype=np.float64))


def material_rows() -> list[dict]:
    """Delta E 2000 of each fluorescent fabric's emission on its own white-lit cloth."""
    rows = []
    for fabric in FABRIC_PARAMETERS:
        material, excitation, emission = fabric_material(fabric)
        xyz, rgb = fl.paper_colour(emission)
        row = {"fabric": fabric, **FABRIC_PARAMETERS[fabric],
               "paper_rgb": "(" + ", ".join(f"{v:.0f}" for v in rgb) + ")"}
        for name in INTENSITY_LIGHTS:
            e = get_light(name).irradiance_w_m2_nm
            row[name] = fl.fluorescence_delta_e(material, e, WHITE_CLOTH)
        rows.append(row)
    return rows


def carry_errors(material: fl.FluorescentMaterial, irradiance: np.ndarray,
                 background: float) -> dict[str, float]:
    """Delta E 2000 of each carry method against the exact spectral colour.

    The exact colour is the XYZ of (background * E + M). Each method adds its carried
    emission RGB to the RGB of the reflected light; "scene" errors keep the sum as it is
    (a linear EXR holds negatives), "display" clips negatives of the final sum (a screen
    cannot show them). ``display_floor`` is what the display loses on the exact colour
    itself: no way of carrying the emission can do better on a screen. White: a perfect
    diffuser under the light (the emission itself for a light with no visible part).
    """
    reflected_xyz = fl.exitance_xyz(background * irradiance)
    emitted_xyz = fl.emission_xyz(material, irradiance)
    exact_xyz = reflected_xyz + emitted_xyz
    white = fl.light_xyz(irradiance)
    if not white[1] > 0:
        white = emitted_xyz
    emission_rgb = xyz_to_linear_srgb(emitted_xyz)
    reflected_rgb = xyz_to_linear_srgb(reflected_xyz)
    exact_rgb = xyz_to_linear_srgb(exact_xyz)
    errors: dict[str, object] = {}
    for method in fl.CARRY_METHODS:
        carried = reflected_rgb + fl.carry_emission_rgb(emission_rgb, method)
        errors[method] = float(delta_e_2000(_rgb_to_xyz_exact(carried), exact_xyz, white))
        errors[f"{method}_display"] = float(delta_e_2000(
            _rgb_to_xyz_exact(np.maximum(carried, 0.0)), exact_xyz, white))
    errors["display_floor"] = float(delta_e_2000(
        _rgb_to_xyz_exact(np.maximum(exact_rgb, 0.0)), exact_xyz, white))
    errors["signed_display_desaturate"] = float(delta_e_2000(
        _rgb_to_xyz_exact(fl.carry_emission_rgb(exact_rgb, "desaturate")), exact_xyz, white))
    errors["sum_in_gamut"] = bool(np.all(exact_rgb >= 0))
    errors["emission_rgb_relative"] = (emission_rgb / white[1]).tolist()
    return errors


def gamut_rows() -> list[dict]:
    materials = {"lace-fwa": fabric_material("lace-fwa")[0],
                 "calcofluor (measured)": calcofluor_material()}
    rows = []
    for material_name, material in materials.items():
        for background_name, background in (("white cloth 0.85", WHITE_CLOTH), ("black", 0.0)):
            for name in GAMUT_LIGHTS:
                e = get_light(name).irradiance_w_m2_nm
                rows.append({"material": material_name, "background": background_name,
                             "light": name, **carry_errors(material, e, background)})
    return rows


#: The measured matrices compared with the lace (in the validation data's bispectral/).
REAL_MATRICES = ("CIPLAW10", "CIBA12", "TEXTYELL")
REAL_LIGHTS = ("D65", "LED-B4")


def calcofluor_figures() -> dict:
    """The measured Calcofluor White emission and excitation at the lace's parameters."""
    folder = data_dir("brightener")
    excitation = read_spectrum(folder / "calcofluor_white_excitation.csv", normalise=True)
    emission = read_spectrum(folder / "calcofluor_white_emission.csv", normalise=True)
    material = calcofluor_material()
    e = get_light("D65").irradiance_w_m2_nm
    _, rgb = fl.paper_colour(emission)
    return {"paper_rgb": [float(v) for v in rgb],
            "paper_intensity_d65": fl.paper_intensity(e, excitation.resample(GRID_NM)),
            "absorbed_photons_m2_s_d65": fl.absorbed_photon_irradiance(material, e),
            "emitted_exitance_w_m2_d65": float(np.sum(fl.emitted_exitance_w_m2_nm(material, e))),
            "delta_e_2000_d65": fl.fluorescence_delta_e(material, e, WHITE_CLOTH),
            "needed_led_b4": fl.fluorescence_needed(material, get_light("LED-B4").irradiance_w_m2_nm,
                                                    WHITE_CLOTH)}


def real_matrix_rows() -> list[dict]:
    """Each real matrix under REAL_LIGHTS: Delta E 2000 between the full matrix's response
    and its diagonal alone (white = a perfect diffuser under the light, as for the lace), and
    the re-radiated luminance over the white's."""
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid, find_bfc, read_bfc
    from catalog.optics.bispectral.study import _xyz, light_irradiance

    rows = []
    for name in REAL_MATRICES:
        matrix = read_bfc(find_bfc(name))
        diagonal = np.interp(GRID_NM, matrix.emission_nm, matrix.diagonal())
        row = {"matrix": name}
        for light_name in REAL_LIGHTS:
            light = light_irradiance(light_name)
            exact = _xyz(exact_exitance_on_grid(matrix, light))
            reflected = _xyz(diagonal * light)
            white = _xyz(light)
            row[f"delta_e_2000|{light_name}"] = float(delta_e_2000(exact, reflected, white))
            row[f"emission_over_white|{light_name}"] = float((exact[1] - reflected[1]) / white[1])
        rows.append(row)
    return rows


def _cell(value: object, fmt: str) -> str:
    if isinstance(value, float) and fmt and abs(value) < 1e-9:
        return "0"  # exact to rounding (the sums differ in the last bits only)
    return format(value, fmt) if fmt else str(value)


def _markdown(rows: list[dict], columns: list[tuple[str, str, str]]) -> str:
    lines = ["| " + " | ".join(title for _, title, _ in columns) + " |",
             "|" + "|".join("---" for _ in columns) + "|"]
    for row in rows:
        lines.append("| " + " | ".join(_cell(row[key], fmt) for key, _, fmt in columns) + " |")
    return "\n".join(lines)


INTENSITY_COLUMNS = [
    ("light", "light", ""), ("illuminance_lx", "lx", ".4g"), ("uva_fraction", "UV-A share", ".3f"),
    ("paper_intensity", "paper I (eq. 4)", ".4g"),
    ("absorbed_photons_m2_s", "absorbed photons m^-2 s^-1", ".3g"),
    ("emitted_exitance_w_m2", "emitted W m^-2", ".3g"),
    ("luminance_ratio", "emission / white (Y)", ".3g"),
    ("delta_e_2000", "Delta E 2000", ".3g"), ("needed", "needed", "")]
#: The README's rows (the full set is in docs/fluorescence.md).
BRIEF_LIGHTS = ("D65", "A", "FL2", "LED-B4", "UV-A", "sun:22", "sun:500")
BRIEF_COLUMNS = [
    ("light", "light", ""), ("paper_intensity", "paper I (eq. 4)", ".4f"),
    ("absorbed_photons_m2_s", "absorbed photons m⁻² s⁻¹", ".3g"),
    ("emitted_exitance_w_m2", "emitted W m⁻²", ".3g"), ("delta_e_2000", "Delta E 2000", ".3g"),
    ("needed", "needed", "")]
MATERIAL_COLUMNS = [
    ("fabric", "fabric", ""), ("quantum_yield", "QY", "g"),
    ("peak_absorptance", "peak absorptance", "g"), ("paper_rgb", "F (eq. 2)", ""),
    *[(name, name, ".3g") for name in INTENSITY_LIGHTS]]
GAMUT_COLUMNS = [
    ("material", "material", ""), ("background", "background", ""), ("light", "light", ""),
    ("signed", "signed", ".1g"), ("clip", "clip", ".3g"), ("desaturate", "desaturate", ".3g"),
    ("sum_in_gamut", "sum in gamut", ""), ("display_floor", "display floor", ".3g"),
    ("signed_display", "signed, display", ".3g"), ("clip_display", "clip, display", ".3g"),
    ("desaturate_display", "desat., display", ".3g"),
    ("signed_display_desaturate", "signed, display desat.", ".3g")]
#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/fluorescence_tables.json"


def run() -> dict:
    return {"intensity": intensity_rows(), "materials": material_rows(), "gamut": gamut_rows(),
            "calcofluor": calcofluor_figures(), "real_matrices": real_matrix_rows(),
            "settings": {"white_cloth": WHITE_CLOTH, "fabrics": FABRIC_PARAMETERS,
                         "needed_above_delta_e": 0.1}}


def markdown_tables(result: dict) -> dict[str, str]:
    """``fluorescence_needed`` (docs/fluorescence.md) and its short form for README
    (``fluorescence_needed_brief``), ``fluorescence_dyes``, ``fluorescence_carry``,
    ``fluorescence_real`` (the real matrices beside the lace) and ``fluorescence_calcofluor``."""
    lace = {r["light"]: r for r in result["intensity"]}
    real = ["| sample | Delta E 2000, D65 | Delta E 2000, LED-B4 | emission / white (Y), D65 |",
            "|---|---|---|---|",
            f"| lace-fwa (the catalog's model, table above) | {lace['D65']['delta_e_2000']:.3g} | "
            f"{lace['LED-B4']['delta_e_2000']:.3g} | {100 * lace['D65']['luminance_ratio']:.1f} % |"]
    for r in result.get("real_matrices", []):
        real.append(f"| {r['matrix']} (measured matrix) | {r['delta_e_2000|D65']:.3g} | "
                    f"{r['delta_e_2000|LED-B4']:.3g} | {100 * r['emission_over_white|D65']:.1f} % |")
    c = result["calcofluor"]
    calcofluor = ("| eq. 2 F (paper's matrix) | eq. 4 I under D65 | absorbed photons m^-2 s^-1, D65 | "
                  "emitted W m^-2, D65 | Delta E 2000 on white cloth, D65 | needed under LED-B4 |\n"
                  "|---|---|---|---|---|---|\n"
                  f"| ({', '.join(f'{v:.2f}' for v in c['paper_rgb'])}) | {c['paper_intensity_d65']:.4g} | "
                  f"{c['absorbed_photons_m2_s_d65']:.3g} | {c['emitted_exitance_w_m2_d65']:.3g} | "
                  f"{c['delta_e_2000_d65']:.2f} | {'yes' if c['needed_led_b4'] else 'no'} |")
    brief = [dict(row, needed="yes" if row["needed"] else "no") for row in result["intensity"]
             if row["light"] in BRIEF_LIGHTS]
    return {"fluorescence_needed": _markdown(result["intensity"], INTENSITY_COLUMNS),
            "fluorescence_needed_brief": _markdown(brief, BRIEF_COLUMNS),
            "fluorescence_dyes": _markdown(result["materials"], MATERIAL_COLUMNS),
            "fluorescence_carry": _markdown(result["gamut"], GAMUT_COLUMNS),
            "fluorescence_real": "\n".join(real), "fluorescence_calcofluor": calcofluor}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415

    return study_main(sys.modules[__name__], argv)


if __name__ == "__main__":
    sys.exit(main())
