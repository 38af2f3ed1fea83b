"""``catalog sun``: the sun through the atmosphere (the paper's Fig. 10), and where it is."""

from __future__ import annotations

import argparse

#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
OUTPUT_FILES = ("plot",)
HELP = ("sunlight through the atmosphere: spectra at path lengths (the paper's Fig. 10), "
        "date/place -> zenith -> path, SPECTRL2 comparison")

DEFAULT_PATHS = "22,100,200,300,400,500"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--paths", default=DEFAULT_PATHS, metavar="KM,KM,..",
                        help=f"path lengths through the 22 km layer (default {DEFAULT_PATHS})")
    parser.add_argument("--model", choices=("paper", "clear"), default="paper",
                        help="paper: Rayleigh-only direct beam ('sun:KM', default); clear: "
                             "clear sky on a plane facing the sun ('sun-clear:KM', paths "
                             "22-529 km)")
    parser.add_argument("--plot", metavar="FIG.png", help="draw the spectra (Fig. 10) into FIG")
    parser.add_argument("--date", metavar="YYYY-MM-DD",
                        help="print the solar zenith and path on this date (with --lat)")
    parser.add_argument("--hour", type=float, default=12.0,
                        help="hour of the day, local mean solar time at --lon unless "
                             "--utc-offset is given (default 12)")
    parser.add_argument("--utc-offset", type=float, metavar="H",
                        help="read --hour as clock time at UTC+H (e.g. 9 for Japan)")
    parser.add_argument("--lat", type=float, help="latitude, deg north")
    parser.add_argument("--lon", type=float, default=0.0, help="longitude, deg east (default 0)")
    parser.add_argument("--compare-spectrl2", action="store_true",
                        help="compare the clear sky with pvlib's SPECTRL2 at zenith 0-85 deg")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def _parse_paths(text: str) -> list[float]:
    from catalog.core.errors import CatalogError  # noqa: PLC0415
    from catalog.optics.sun.model import check_path_km  # noqa: PLC0415

    paths = []
    for item in text.split(","):
        item = item.strip()
        try:
            value = float(item)
        except ValueError:
            raise CatalogError(f"--paths: {item!r} is not a number of km") from None
        paths.append(check_path_km(value, "--paths"))
    if not paths:
        raise CatalogError("--paths: give at least one path length (km)")
    return paths


def _when_text(args) -> str:
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    if not 0.0 <= args.hour <= 24.0:
        raise CatalogError(f"--hour {args.hour:g} is outside 0-24")
    hours = int(args.hour)
    minutes = round((args.hour - hours) * 60.0)
    if minutes == 60:
        hours, minutes = hours + 1, 0
    text = f"{args.date}T{hours:02d}:{minutes:02d}" if hours < 24 else f"{args.date}T23:59"
    if args.utc_offset is not None:
        if not -14.0 <= args.utc_offset <= 14.0:
            raise CatalogError(f"--utc-offset {args.utc_offset:g} is outside -14..14 h")
        sign = "+" if args.utc_offset >= 0 else "-"
        off = abs(args.utc_offset)
        text += f"{sign}{int(off):02d}:{round((off - int(off)) * 60):02d}"
    return text


def _position(args) -> dict:
    from catalog.core.errors import CatalogError  # noqa: PLC0415
    from catalog.optics.sun.model import horizon_path_km, sun_position  # noqa: PLC0415

    if args.lat is None:
        raise CatalogError("--date needs --lat (deg north)")
    position = sun_position(_when_text(args), args.lat, args.lon)
    return {"when_utc": position.when_utc, "latitude_deg": position.latitude_deg,
            "longitude_deg": position.longitude_deg, "zenith_deg": position.zenith_deg,
            "path_km": position.path_km, "above_horizon": position.path_km is not None,
            "horizon_path_km": horizon_path_km(),
            "earth_sun_factor": position.earth_sun_factor}


def _plot(path: str, lights: list, model: str) -> None:
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    from catalog.core.atomic import atomic_path  # noqa: PLC0415
    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    fig, ax = plt.subplots(figsize=(7.0, 4.5), dpi=120)
    cmap = plt.get_cmap("plasma")
    for i, light in enumerate(lights):
        colour = cmap(0.85 * i / max(1, len(lights) - 1))
        ax.plot(GRID_NM, light.irradiance_w_m2_nm, color=colour, lw=1.0,
                label=f"{light.name.split(':', 1)[1]} km")
    what = ("direct beam, Rayleigh only (the paper's model)" if model == "paper"
            else "clear sky on a plane facing the sun")
    ax.set_title(f"Sunlight after atmospheric paths: {what}", fontsize=10)
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("spectral irradiance (W m$^{-2}$ nm$^{-1}$)")
    ax.set_xlim(float(GRID_NM[0]), float(GRID_NM[-1]))
    ax.set_ylim(bottom=0.0)
    ax.grid(alpha=0.3)
    ax.legend(title="path", fontsize=8)
    source = "ASTM G173 extraterrestrial (pvlib); Rayleigh tau (Bodhaine et al. 1999) x L / 22 km"
    if model == "clear":
        source += "; ozone, aerosol (Angstrom), delta-Eddington skylight"
    fig.text(0.01, 0.01, source, fontsize=6, color="0.4")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp)
    plt.close(fig)


def run(args) -> int:
    from catalog.core.jsonout import print_json  # noqa: PLC0415
    from catalog.optics.lights import get_light  # noqa: PLC0415

    out: dict = {}
    if args.date is not None:
        out["position"] = _position(args)
    elif args.lat is not None or args.utc_offset is not None:
        from catalog.core.errors import CatalogError  # noqa: PLC0415
        raise CatalogError("--lat/--utc-offset go with --date")
    if args.compare_spectrl2:
        from catalog.optics.sun.spectrl2 import comparison_table  # noqa: PLC0415
        out["spectrl2"] = comparison_table()
    show_paths = args.plot is not None or (args.date is None and not args.compare_spectrl2)
    if show_paths:
        prefix = "sun:" if args.model == "paper" else "sun-clear:"
        lights = [get_light(f"{prefix}{p:g}") for p in _parse_paths(args.paths)]
        out["model"] = args.model
        out["spectra"] = [_summary(light) for light in lights]
        if args.plot is not None:
            _plot(args.plot, lights, args.model)
            out["plot"] = args.plot
    if args.json:
        print_json(out)
    else:
        _print_text(out)
    return 0


def _summary(light) -> dict:
    import numpy as np  # noqa: PLC0415

    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    e = light.irradiance_w_m2_nm
    blue = float(np.mean(e[(GRID_NM >= 440) & (GRID_NM <= 460)]))
    red = float(np.mean(e[(GRID_NM >= 640) & (GRID_NM <= 660)]))
    return {"name": light.name, "path_km": float(light.name.split(":", 1)[1]),
            "illuminance_lx": light.illuminance_lx, "total_w_m2": light.total_w_m2,
            "uva_fraction": light.uva_fraction,
            "irradiance_380nm_w_m2_nm": float(e[int(np.argmin(np.abs(GRID_NM - 380)))]),
            "blue_red_ratio": blue / red if red > 0 else None}


def _print_text(out: dict) -> None:
    if "position" in out:
        p = out["position"]
        if p["above_horizon"]:
            print(f"{p['when_utc']} UTC at {p['latitude_deg']:g} N {p['longitude_deg']:g} E: "
                  f"solar zenith {p['zenith_deg']:.2f} deg, path {p['path_km']:.1f} km "
                  f"through the 22 km shell (horizon {p['horizon_path_km']:.1f} km)")
        else:
            print(f"{p['when_utc']} UTC at {p['latitude_deg']:g} N {p['longitude_deg']:g} E: "
                  f"solar zenith {p['zenith_deg']:.2f} deg: the sun is below the horizon")
    if "spectrl2" in out:
        print("zenith  path_km  DNI ours/S2  DNI relRMS  T relRMS  GHI ours/S2  GHI relRMS  "
              "UV GHI ours/S2")
        for r in out["spectrl2"]:
            print(f"{r['zenith_deg']:6.0f}  {r['path_km']:7.1f}  {r['dni_integral_ratio']:11.3f}"
                  f"  {r['dni_rel_rms_400_780']:10.3f}  {r['transmittance_rel_rms_400_780']:8.3f}"
                  f"  {r['ghi_integral_ratio']:11.3f}  {r['ghi_rel_rms_400_780']:10.3f}"
                  f"  {r['uv_ghi_ratio']:14.3f}")
    if "spectra" in out:
        print("light            lx        W/m2   UV-A frac  E(380) W/m2/nm  B/R (450/650)")
        for s in out["spectra"]:
            print(f"{s['name']:<14} {s['illuminance_lx']:9.0f}  {s['total_w_m2']:8.1f}  "
                  f"{s['uva_fraction']:9.4f}  {s['irradiance_380nm_w_m2_nm']:14.4g}  "
                  f"{s['blue_red_ratio']:.3f}")
    if "plot" in out:
        print(f"wrote {out['plot']}")
