"""``catalog fluorescence``: the colour and intensity of a fluorescent material under a light.

Paper mode: eq. 1-3 colour (Y = 100, the paper's matrix) and eq. 4 intensity (380-780 nm).
Physical mode (default): the same colour, plus absorbed and emitted photons, the absolute
emitted exitance and radiance, the emission's absolute linear sRGB, and its luminance as a
fraction of a white diffuser under the same light (that fraction is then "intensity").
"""

from __future__ import annotations

import argparse

from catalog.core.constants import FLUORESCENT_MODES

#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
INPUT_FILES = ("excitation", "emission")
OUTPUT_FILES = ("plot",)
HELP = "fluorescence colour (eq. 1-3) and intensity (eq. 4 or physical) of a material under a light"


def _number(text: str) -> float:
    from catalog.core.validate import _DECIMAL  # noqa: PLC0415

    if not _DECIMAL.fullmatch(str(text).strip()):
        raise argparse.ArgumentTypeError(f"must be a plain decimal number, not {str(text)[:20]!r}")
    return float(text)


def _fraction(text: str) -> float:
    value = _number(text)
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"must lie in [0, 1], not {text}")
    return value


def _absorptance(text: str) -> float:
    value = _number(text)
    if not 0.0 < value <= 1.0:
        raise argparse.ArgumentTypeError(f"must lie in (0, 1], not {text}")
    return value


def _saturation(text: str) -> float:
    value = float("inf") if str(text).strip() == "inf" else _number(text)  # inf: no saturation
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0 (photons m^-2 s^-1, or inf), not {text}")
    return value


def _positive(text: str) -> float:
    value = _number(text)
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, not {text}")
    return value


def _illuminance(text: str) -> float:
    from catalog.core.validate import ILLUMINANCE_LX  # noqa: PLC0415

    value = _positive(text)
    if value > ILLUMINANCE_LX[1]:
        raise argparse.ArgumentTypeError(f"must lie in (0, {ILLUMINANCE_LX[1]:g}] lx, not {text}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--excitation", required=True, metavar="E.csv",
                        help="excitation spectrum CSV (wavelength_nm,intensity); normalised to peak 1")
    parser.add_argument("--emission", required=True, metavar="F.csv",
                        help="emission spectrum CSV; energy per nm unless a '# quantity: photons' "
                             "comment says photons")
    parser.add_argument("--light", required=True, metavar="NAME",
                        help="light name: D65, A, FL2, LED-B4, UV-A, LED-warm, sun:22, ... "
                             "(see `catalog lights`)")
    parser.add_argument("--mode", choices=FLUORESCENT_MODES, default="physical",
                        help="paper: eq. 1-4 exactly; physical (default): photons over 300-780 nm")
    parser.add_argument("--illuminance", type=_illuminance, metavar="LX",
                        help="rescale the light to this illuminance (default: the library level)")
    parser.add_argument("--quantum-yield", type=_fraction, metavar="PHI",
                        help="emitted photons per absorbed photon, 0..1 (physical; default 0.6)")
    parser.add_argument("--peak-absorptance", type=_absorptance, metavar="A",
                        help="fraction of photons absorbed at the excitation peak, (0, 1] "
                             "(physical; default 0.5)")
    parser.add_argument("--saturation", type=_saturation, metavar="N_SAT",
                        help="absorbed photons m^-2 s^-1 at which absorption halves; inf = none "
                             "(physical; default 1e28)")
    parser.add_argument("--background-reflectance", type=_positive, default=0.85, metavar="R",
                        help="reflectance of the cloth the emission is judged against "
                             "(physical 'needed' flag; default 0.85)")
    parser.add_argument("--plot", metavar="FILE.png",
                        help="draw excitation, emission and the light (the paper's Figs. 5 and 6)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def _physical_fields(args, excitation, emission, light) -> dict:
    import numpy as np  # noqa: PLC0415

    from catalog.optics import fluorescence as fl  # noqa: PLC0415
    from catalog.optics.colorimetry import xyz_to_linear_srgb  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    options = {}
    if args.quantum_yield is not None:
        options["quantum_yield"] = args.quantum_yield
    if args.peak_absorptance is not None:
        options["peak_absorptance"] = args.peak_absorptance
    if args.saturation is not None:
        options["saturation_photon_irradiance"] = args.saturation
    material = fl.material_from_spectra(excitation, emission, **options)
    irradiance = light.irradiance_w_m2_nm
    absorbed = fl.absorbed_photon_irradiance(material, irradiance)
    emitted = fl.emitted_photon_exitance(material, irradiance)
    exitance = fl.emitted_exitance_w_m2_nm(material, irradiance)
    emission_xyz = fl.exitance_xyz(exitance)
    light_xyz = fl.light_xyz(irradiance)
    illuminance = float(light_xyz[1])
    ratio = float(emission_xyz[1]) / illuminance if illuminance > 0 else float("inf")
    incident_photons = float(np.sum(irradiance / fl.photon_energy_j(GRID_NM)) * fl.GRID_STEP_NM)
    delta_e = fl.fluorescence_delta_e(material, irradiance, args.background_reflectance)
    exitance_w_m2 = float(np.sum(exitance) * fl.GRID_STEP_NM)
    return {
        "intensity": ratio,
        "luminance_ratio": ratio,
        "quantum_yield": material.quantum_yield,
        "peak_absorptance": material.peak_absorptance,
        "saturation_photon_irradiance": material.saturation_photon_irradiance,
        "incident_photons_m2_s": incident_photons,
        "absorbed_photons_m2_s": absorbed,
        "emitted_photons_m2_s": emitted,
        "emitted_exitance_w_m2": exitance_w_m2,
        "emitted_radiance_w_m2_sr": exitance_w_m2 / np.pi,
        "emission_xyz_lm_m2": emission_xyz,
        "emission_luminance_cd_m2": float(emission_xyz[1]) / np.pi,
        "emission_rgb_linear": xyz_to_linear_srgb(emission_xyz),
        "emission_rgb_relative": (xyz_to_linear_srgb(emission_xyz) / illuminance
                                  if illuminance > 0 else None),
        "light_xyz": light_xyz,
        "light_illuminance_lx": illuminance,
        "background_reflectance": args.background_reflectance,
        "delta_e_2000": delta_e,
        "fluorescence_needed": bool(delta_e > fl.NEEDED_DELTA_E),
    }


def _plot(path: str, excitation, emission, light, title: str) -> None:
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    import numpy as np  # noqa: PLC0415

    from catalog.core.atomic import atomic_path  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM, VISIBLE_NM  # noqa: PLC0415

    light_values = light.irradiance_w_m2_nm
    peak = float(np.max(light_values))
    light_relative = light_values / peak if peak > 0 else light_values
    excitation_on_grid = excitation.resample(GRID_NM)
    fig, (ax_ex, ax_em) = plt.subplots(1, 2, figsize=(10.0, 4.0), dpi=110, sharey=True)
    ax_ex.plot(excitation.wavelength_nm, excitation.values, color="tab:purple", label="excitation")
    ax_ex.plot(GRID_NM, light_relative, color="0.4", lw=1.0, label=f"light {light.name}")
    ax_ex.fill_between(GRID_NM, 0, excitation_on_grid * light_relative, color="tab:purple",
                       alpha=0.25, lw=0, label="excitation x light")
    ax_ex.axvspan(float(GRID_NM[0]), VISIBLE_NM[0], color="0.85", alpha=0.5, lw=0, zorder=0,
                  label="left out by eq. 4 (< 380 nm)")
    ax_ex.set_title("Excitation (paper Fig. 6) and the light", fontsize=10)
    ax_em.plot(emission.wavelength_nm, emission.values, color="tab:blue", label="emission")
    ax_em.plot(GRID_NM, light_relative, color="0.4", lw=1.0, label=f"light {light.name}")
    ax_em.set_title("Emission (paper Fig. 5)", fontsize=10)
    for ax in (ax_ex, ax_em):
        ax.set_xlabel("wavelength (nm)")
        ax.set_xlim(float(GRID_NM[0]), float(GRID_NM[-1]))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    ax_ex.set_ylabel("relative (peak 1)")
    ax_ex.set_ylim(0, 1.05)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp)
    plt.close(fig)


def run(args) -> int:
    from catalog.optics import fluorescence as fl  # noqa: PLC0415
    from catalog.core.jsonout import print_json  # noqa: PLC0415
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM, read_spectrum  # noqa: PLC0415

    light = get_light(args.light, illuminance_lx=args.illuminance)
    excitation = read_spectrum(args.excitation, normalise=True)
    emission = read_spectrum(args.emission, normalise=True)
    xyz, rgb = fl.paper_colour(emission)  # eq. 1-3
    paper_intensity = fl.paper_intensity(light.irradiance_w_m2_nm,
                                         excitation.resample(GRID_NM))  # eq. 4
    result = {
        "mode": args.mode,
        "light": light.name,
        "excitation": str(args.excitation),
        "emission": str(args.emission),
        "xyz": xyz,
        "rgb": rgb,
        "intensity": paper_intensity,
        "paper_intensity": paper_intensity,
        "excitation_peak_nm": excitation.peak_nm,
        "emission_peak_nm": emission.peak_nm,
    }
    if args.mode == "physical":
        result.update(_physical_fields(args, excitation, emission, light))

    if args.plot:
        _plot(args.plot, excitation, emission, light,
              f"{light.name}, {args.mode} mode: intensity {result['intensity']:.4g}")
    if args.json:
        print_json(result)
        return 0
    print(f"light {light.name} ({light.illuminance_lx:,.0f} lx), mode {args.mode}")
    print(f"  colour (eq. 1-3): XYZ = {xyz[0]:.1f} {xyz[1]:.1f} {xyz[2]:.1f}, "
          f"RGB = {rgb[0]:.1f} {rgb[1]:.1f} {rgb[2]:.1f}")
    print(f"  paper intensity (eq. 4, 380-780 nm): {paper_intensity:.5g}")
    if args.mode == "physical":
        print(f"  absorbed {result['absorbed_photons_m2_s']:.4g} photons m^-2 s^-1, emitted "
              f"{result['emitted_photons_m2_s']:.4g} (quantum yield {result['quantum_yield']:g})")
        print(f"  emitted exitance {result['emitted_exitance_w_m2']:.4g} W m^-2, radiance "
              f"{result['emitted_radiance_w_m2_sr']:.4g} W m^-2 sr^-1, luminance "
              f"{result['emission_luminance_cd_m2']:.4g} cd m^-2")
        print(f"  emission / white diffuser (luminance): {result['luminance_ratio']:.4g}; "
              f"Delta E 2000 on a cloth of reflectance {args.background_reflectance:g}: "
              f"{result['delta_e_2000']:.3g} -> fluorescence "
              f"{'needed' if result['fluorescence_needed'] else 'not needed'}")
    if args.plot:
        print(f"  plot written to {args.plot}")
    return 0
