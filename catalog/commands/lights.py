"""``catalog lights``: the light library, with levels, UV-A share and how each was made."""

from __future__ import annotations

import argparse

#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
OUTPUT_FILES = ("plot",)
HELP = "list the light library (illuminance, UV-A fraction, description) or plot spectra"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--names", metavar="NAME,NAME,..",
                        help="only these lights (any library name, e.g. D65,A,UV-A,sun:300)")
    parser.add_argument("--plot", metavar="FILE.png",
                        help="draw the spectra of --names (default D65,A,FL2,LED-B4,UV-A,"
                             "LED-warm,sun:22) into FILE")
    parser.add_argument("--normalise", action="store_true",
                        help="plot each spectrum scaled to a peak of 1 (default: absolute)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


PLOT_DEFAULT = "D65,A,FL2,LED-B4,UV-A,LED-warm,sun:22"


def _names(text: str | None, default: list[str]) -> list[str]:
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    if text is None:
        return default
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise CatalogError("--names: give at least one light name")
    return names


def _plot(path: str, lights: list, normalise: bool) -> None:
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    import numpy as np  # noqa: PLC0415

    from catalog.core.atomic import atomic_path  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    fig, ax = plt.subplots(figsize=(7.0, 4.5), dpi=120)
    for light in lights:
        values = light.irradiance_w_m2_nm
        if normalise:
            peak = float(np.max(values))
            values = values / peak if peak > 0 else values
        lx = light.illuminance_lx
        level = f"{lx:,.0f} lx" if lx >= 10 else f"{lx:.2g} lx, {light.total_w_m2:.3g} W/m2"
        ax.plot(GRID_NM, values, lw=1.0, label=f"{light.name} ({level})")
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("relative (peak 1)" if normalise
                  else "spectral irradiance (W m$^{-2}$ nm$^{-1}$)")
    if not normalise:
        ax.set_yscale("log")
        top = max(float(np.max(light.irradiance_w_m2_nm)) for light in lights)
        ax.set_ylim(top * 1e-4 if top > 0 else 1e-6, top * 2 if top > 0 else 1.0)
    ax.set_xlim(float(GRID_NM[0]), float(GRID_NM[-1]))
    ax.axvspan(315, 400, color="violet", alpha=0.08, lw=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    ax.set_title("Light library (UV-A band 315-400 nm shaded)", fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp)
    plt.close(fig)


def run(args) -> int:
    from catalog.core.jsonout import print_json  # noqa: PLC0415
    from catalog.optics.lights import get_light, light_names  # noqa: PLC0415

    if args.plot is not None:
        names = _names(args.names, PLOT_DEFAULT.split(","))
    else:
        names = _names(args.names, light_names())
    lights = [get_light(n) for n in names]
    rows = [{"name": light.name, "illuminance_lx": light.illuminance_lx,
             "total_w_m2": light.total_w_m2, "uva_fraction": light.uva_fraction,
             "description": light.description} for light in lights]
    out: dict = {"lights": rows}
    if args.plot is not None:
        _plot(args.plot, lights, args.normalise)
        out["plot"] = args.plot
    if args.json:
        print_json(out)
        return 0
    width = max(len(r["name"]) for r in rows)
    print(f"{'light':<{width}}  {'lx':>9}  {'W/m2':>8}  {'UV-A':>6}  description")
    for r in rows:
        print(f"{r['name']:<{width}}  {r['illuminance_lx']:9.0f}  {r['total_w_m2']:8.2f}  "
              f"{r['uva_fraction']:6.3f}  {r['description']}")
    if args.plot is not None:
        print(f"wrote {args.plot}")
    return 0
