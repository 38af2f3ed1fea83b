#!/usr/bin/env python3
"""Make the catalog's gonio measurement sets from a yarn-level model of woven cloth.

    .venv/bin/python tools/make_gonio.py [--out fabrics/measurements] [NAME ...]

Writes ``<out>/<name>/gonio.csv`` on the paper's OGM-3 grid (4800 points, see
catalog/fit/gonio.py) and, for dyed fabrics, ``dye.csv`` (the dye's spectral transmittance)
and per-channel ``r,g,b`` columns. Deterministic: each fabric has its own seed.

The model is deliberately *not* eq. 7, so that fitting eq. 7 to its output is a real fit:

- Threads are cylinders (warp along y, weft along x) of diameter d at spacing s, lying
  in a layer of thickness h (the crimp of the interlacing). Seen along the light's
  direction of travel, the gap between two warp threads shrinks to
  ``s - d / cos(a_x) - h |tan(a_x)|`` (a_x: the travel direction's angle in the x-z
  plane), likewise for the weft: the open-area fraction ``open(t)`` is the product of
  the two. Light through the gaps is seen only straight through (the direct part).
- Light that hits a thread crosses n fibres, n ~ Poisson(lambda / sqrt(cos theta_i)).
  Each crossing keeps a fraction ``albedo`` (per channel for a dyed yarn: the dye's
  transmittance raised to 1/lambda) and bends the ray by refraction; rays entering a
  fibre near its edge are bent strongly, so the deflection is heavy-tailed. After n
  crossings it is a bivariate Student-t (``tail_nu`` degrees of freedom, tails falling
  as angle^-(nu + 2)) around the direction of travel with scales sqrt(n) sigma_x across
  the warp and sqrt(n) sigma_y across the weft (warp and weft fibres bend light across
  their axes by different amounts: the mild warp/weft anisotropy). A fraction of the
  n-times scattered light leaves backwards ((1 - exp(-n / n_back)) / 2). n = 0 (no
  fibre met) joins the direct part. Beyond N_LOBE crossings the light is diffuse:
  Lambertian, half of it forward.
- Inside the yarn, a fraction ``diffuse`` of the light meeting a thread is scattered
  many times among the fibres (the glow of a white yarn): Lambertian, half of it forward,
  attenuated as 2 lambda crossings. The rest follows the crossing model above.
- A constant stray-light floor (flare in the instrument).

The instrument (model.md section 1): the value is the mean of a 40x40 px patch with the
sample over the lamp's reading without it. Each point is measured with a long exposure
(for the skirt) and, where that saturates the 12-bit sensor, with a short one (the peak);
each reading carries photon and read noise, rounding to whole DN on each pixel, and a
per-point lamp flicker; the lamp reference is read once per set.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from catalog.fit.gonio import GonioData, ogm3_grid, write_gonio  # noqa: E402
from catalog.optics.spectra import GRID_NM, write_spectrum  # noqa: E402

#: Crossings above this are treated as diffuse.
N_LOBE = 10

# The instrument.
FULL_WELL_DN = 4095.0          # 12-bit sensor
PIXELS = 40 * 40               # the central patch averaged
READ_NOISE_DN = 2.0
ELECTRONS_PER_DN = 4.0
LONG_GAIN_DN = 1500.0          # DN per unit ratio in the long exposure
SHORT_GAIN_DN = LONG_GAIN_DN / 64.0
FLICKER = 0.004                # lamp flicker per point (relative, 1 sigma)
REFERENCE_NOISE = 0.002        # the once-per-set lamp reading
STRAY_LIGHT = 1.5e-4           # flare floor, ratio units

#: The gonio camera's RGB filters, modelled as Gaussians (centre nm, sigma nm).
CAMERA_FILTERS_NM = ((605.0, 30.0), (540.0, 30.0), (455.0, 25.0))
#: The grey column weights the channels as luminance does (Rec. 709 Y).
GREY_WEIGHTS = np.array([0.2126, 0.7152, 0.0722])


@dataclass(frozen=True)
class YarnFabric:
    """A fabric sample, described at the yarn level (lengths in mm, angles in degrees)."""

    name: str
    display_name: str
    weave: str                   # a weave of catalog.cloth.params.WEAVE_DEFAULTS
    warp_diameter_mm: float
    warp_spacing_mm: float
    weft_diameter_mm: float
    weft_spacing_mm: float
    layer_thickness_mm: float
    crossings: float             # lambda: mean fibre crossings at normal incidence
    albedo: float                # kept per crossing (undyed)
    sigma_x_deg: float           # deflection per crossing across the warp (x)
    sigma_y_deg: float           # ... across the weft (y)
    back_scale: float = 4.0      # n_back
    diffuse: float = 0.3         # of the light hitting threads, the part scattered diffusely
    tail_nu: float = 2.0         # Student-t tail of refracting crossings (fibre edges)
    dye: str | None = None       # name in DYES, or None
    seed: int = 0
    cloth: dict = field(default_factory=dict)   # [cloth] overrides

    @property
    def open_area_normal(self) -> float:
        return ((1 - self.warp_diameter_mm / self.warp_spacing_mm)
                * (1 - self.weft_diameter_mm / self.weft_spacing_mm))


def _sigmoid(wl, centre, width):
    return 1.0 / (1.0 + np.exp(-(wl - centre) / width))


def _gauss(wl, centre, width):
    return np.exp(-0.5 * ((wl - centre) / width) ** 2)


#: Spectral transmittance of one pass through the dyed yarn, 0..1, on GRID_NM.
DYES = {
    # teal: absorbs the red and some violet
    "teal": lambda wl: 0.08 + 0.80 * _gauss(wl, 500.0, 45.0) + 0.1 * _sigmoid(wl, 700.0, 15.0),
    # fluorescent yellow: absorbs the blue that excites it, clear above 520 nm
    "yellow": lambda wl: 0.04 + 0.90 * _sigmoid(wl, 505.0, 9.0),
    # fluorescent pink: absorbs green, passes red and some blue-violet
    "pink": lambda wl: 0.92 - 0.80 * _gauss(wl, 545.0, 32.0) - 0.25 * _gauss(wl, 400.0, 30.0),
    # neutral grey: flat
    "grey": lambda wl: np.full_like(wl, 0.45),
    # ivory: a little blue absorbed
    "ivory": lambda wl: 0.97 - 0.22 * (1 - _sigmoid(wl, 450.0, 20.0)),
    # cream: a warm yellowish white, the violet-blue absorbed up to about 490 nm (an
    # unbleached or cream-dyed cotton's reflectance falls from ~0.85 in the red to ~0.6 at
    # 420 nm); a slight green dip keeps it from reading lemon
    "cream": lambda wl: 0.96 - 0.42 * (1 - _sigmoid(wl, 485.0, 22.0))
                        - 0.03 * _gauss(wl, 540.0, 40.0),
    # natural flax (unbleached linen): an ecru that absorbs across the blue and a little of
    # the green (CIELAB a* ~ 1, b* ~ 8 on screen), less yellow than cream
    "flax": lambda wl: 0.90 - 0.30 * (1 - _sigmoid(wl, 520.0, 45.0)),
    # fully bleached cotton without brightener: what peroxide bleaching leaves of the fibre's
    # natural pigments is an absorption edge tailing from the UV into the blue (reflectance
    # about 0.75 at 400 nm, 0.86 at 460 nm, flat 0.9 above 550 nm with an albedo of 0.9): CIE
    # whiteness 75, ASTM E313 yellowness 5.3 (bleached cottons without brightener: 60-80)
    "bleached-cotton": lambda wl: 1.0 - 0.25 * np.exp(-(wl - 380.0) / 48.0),
    # a white nylon tulle's shading ("bluing") dye: a violet acid dye's weak absorption band
    # round 565 nm takes the yellow-green the fibre's own yellowness would show, so the white
    # reads cool beside an unshaded one
    "violet-shading": lambda wl: 1.0 - 0.10 * _gauss(wl, 565.0, 45.0),
    # a deeper ivory (a Raschel lace's heavier cotton-look yarn): the blue absorbed further into
    # the cyan than the faint ivory
    "ivory-deep": lambda wl: 0.97 - 0.40 * (1 - _sigmoid(wl, 470.0, 30.0)),
}

CATALOG: tuple[YarnFabric, ...] = (
    YarnFabric("lace-fwa", "White lace, brightened", "lace", 0.16, 0.40, 0.14, 0.36, 0.22,
               crossings=3.0, albedo=0.93, sigma_x_deg=7.5, sigma_y_deg=6.0, seed=101),
    YarnFabric("voile-white", "White voile", "voile", 0.12, 0.26, 0.12, 0.25, 0.16,
               crossings=2.5, albedo=0.92, sigma_x_deg=7.5, sigma_y_deg=6.5, seed=102),
    YarnFabric("linen-dense", "Dense linen", "plain", 0.42, 0.46, 0.45, 0.48, 0.55,
               crossings=7.0, albedo=0.90, sigma_x_deg=11.0, sigma_y_deg=9.0, back_scale=3.0,
               dye="flax", seed=103, cloth={"areal_density_kg_m2": 0.19}),
    YarnFabric("sheer-teal", "Teal sheer", "voile", 0.11, 0.25, 0.11, 0.24, 0.15,
               crossings=2.8, albedo=0.95, sigma_x_deg=7.5, sigma_y_deg=6.5, dye="teal",
               seed=104),
    YarnFabric("safety-yellow", "Fluorescent safety yellow mesh", "lace", 0.20, 0.45, 0.20,
               0.45, 0.26, crossings=3.5, albedo=0.94, sigma_x_deg=8.0, sigma_y_deg=8.0,
               dye="yellow", seed=105),
    YarnFabric("fluoro-pink", "Fluorescent pink voile", "voile", 0.13, 0.27, 0.13, 0.26,
               0.17, crossings=2.8, albedo=0.94, sigma_x_deg=8.0, sigma_y_deg=7.0,
               dye="pink", seed=106),
    YarnFabric("organza-ivory", "Ivory organza", "voile", 0.06, 0.14, 0.06, 0.13, 0.08,
               crossings=1.6, albedo=0.97, sigma_x_deg=7.0, sigma_y_deg=6.0, dye="ivory",
               seed=107, cloth={"areal_density_kg_m2": 0.03}),
    YarnFabric("batiste-cream", "Cream batiste", "plain", 0.14, 0.19, 0.14, 0.19, 0.18,
               crossings=4.5, albedo=0.93, sigma_x_deg=8.5, sigma_y_deg=7.5, dye="cream",
               seed=108),
    YarnFabric("net-grey", "Grey net", "lace", 0.10, 0.50, 0.10, 0.50, 0.14,
               crossings=3.0, albedo=0.95, sigma_x_deg=9.0, sigma_y_deg=9.0, dye="grey",
               seed=109, cloth={"areal_density_kg_m2": 0.035}),
    YarnFabric("raschel-ivory", "Ivory Raschel lace", "lace", 0.18, 0.40, 0.16, 0.38, 0.24,
               crossings=3.2, albedo=0.94, sigma_x_deg=8.0, sigma_y_deg=7.0, dye="ivory-deep",
               seed=111, cloth={"areal_density_kg_m2": 0.07}),
    YarnFabric("tulle-embroidered", "White embroidered tulle", "lace", 0.10, 0.40, 0.10,
               0.40, 0.14, crossings=2.5, albedo=0.95, sigma_x_deg=8.0, sigma_y_deg=8.0,
               dye="violet-shading", seed=112, cloth={"areal_density_kg_m2": 0.04}),
    YarnFabric("jacquard-white", "White jacquard", "satin", 0.30, 0.34, 0.28, 0.31, 0.45,
               crossings=6.0, albedo=0.93, sigma_x_deg=10.0, sigma_y_deg=7.0,
               back_scale=3.5, dye="bleached-cotton", seed=110,
               cloth={"areal_density_kg_m2": 0.26}),
)


def camera_channel_weights(grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """(3, n) normalised spectral weights of the camera's R, G, B filters."""
    weights = np.stack([_gauss(grid_nm, c, s) for c, s in CAMERA_FILTERS_NM])
    return weights / weights.sum(axis=1, keepdims=True)


def open_fraction(travel: np.ndarray, fabric: YarnFabric) -> np.ndarray:
    """Open-area fraction seen along ``travel`` (cylinders with gaps, see the docstring)."""
    cz = travel[..., 2]
    ax = np.arctan2(np.abs(travel[..., 0]), cz)
    ay = np.arctan2(np.abs(travel[..., 1]), cz)
    h = fabric.layer_thickness_mm - 0.5 * (fabric.warp_diameter_mm + fabric.weft_diameter_mm)
    h = max(h, 0.0)
    gap_x = fabric.warp_spacing_mm - fabric.warp_diameter_mm / np.cos(ax) - h * np.tan(ax)
    gap_y = fabric.weft_spacing_mm - fabric.weft_diameter_mm / np.cos(ay) - h * np.tan(ay)
    return (np.clip(gap_x / fabric.warp_spacing_mm, 0, 1)
            * np.clip(gap_y / fabric.weft_spacing_mm, 0, 1))


def deflection_density(travel: np.ndarray, view: np.ndarray, sigma_x: float,
                       sigma_y: float, nu: float | None = None) -> np.ndarray:
    """Anisotropic angular deflection density around ``travel``, per steradian.

    ``nu=None``: a Gaussian of standard deviations sigma_x, sigma_y (radians);
    otherwise a bivariate Student-t with nu degrees of freedom and those scales (tails
    falling as angle^-(nu + 2): strong deflections at fibre edges). Angles are measured
    in a frame whose first axis is the cloth's x projected perpendicular to ``travel``;
    the flat density is carried onto the sphere with theta / sin(theta) so that it keeps
    unit weight for small scales.
    """
    x_axis = np.array([1.0, 0.0, 0.0])
    e1 = x_axis - travel * (travel @ x_axis)[..., None]
    e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
    e2 = np.cross(travel, e1)
    cos_t = np.clip(np.einsum("...i,...i->...", travel, view), -1.0, 1.0)
    theta = np.arccos(cos_t)
    u1 = np.einsum("...i,...i->...", view, e1)
    u2 = np.einsum("...i,...i->...", view, e2)
    radius = np.hypot(u1, u2)
    safe = np.where(radius > 0, radius, 1.0)
    a1 = np.where(radius > 0, theta * u1 / safe, 0.0)
    a2 = np.where(radius > 0, theta * u2 / safe, 0.0)
    r2 = (a1 / sigma_x) ** 2 + (a2 / sigma_y) ** 2
    if nu is None:
        shape = np.exp(-0.5 * r2)
    else:
        shape = (1.0 + r2 / nu) ** (-(nu + 2.0) / 2.0)
    flat = shape / (2 * math.pi * sigma_x * sigma_y)
    sphere = np.where(theta > 1e-8, theta / np.maximum(np.sin(theta), 1e-3), 1.0)
    return flat * sphere


def yarn_transmittance(fabric: YarnFabric, data: GonioData,
                       albedo_per_channel: np.ndarray) -> np.ndarray:
    """Noise-free ratio for each point and channel: (n, channels)."""
    travel, view = data.travel, data.view
    cos_i = travel[..., 2]
    opening = open_fraction(travel, fabric)
    hit = 1.0 - opening
    lam = fabric.crossings / np.sqrt(cos_i)
    straight = data.straight_through
    sigma_x = math.radians(fabric.sigma_x_deg)
    sigma_y = math.radians(fabric.sigma_y_deg)
    albedo = np.asarray(albedo_per_channel)[None, :]
    thread = hit * (1 - fabric.diffuse)
    poisson = np.exp(-lam)                                   # P(n = 0): no fibre met
    total = ((opening + thread * poisson) * straight)[:, None] * np.ones_like(albedo)
    glow = (hit * fabric.diffuse)[:, None] * albedo ** (2 * fabric.crossings) * 0.5 / math.pi
    kept = poisson.copy()
    for n in range(1, N_LOBE + 1):
        poisson = poisson * lam / n                          # P(n)
        kept += poisson
        forward = 1.0 - 0.5 * (1.0 - math.exp(-n / fabric.back_scale))
        lobe = deflection_density(travel, view, sigma_x * math.sqrt(n),
                                  sigma_y * math.sqrt(n), fabric.tail_nu)
        total += (thread * poisson * forward * lobe)[:, None] * albedo ** n
    # crossings beyond N_LOBE: what survives is diffuse, half of it forward (Lambertian)
    beyond = np.clip(1.0 - kept, 0.0, 1.0)
    diffuse = (thread * beyond)[:, None] * albedo ** (N_LOBE + 2) * 0.5 / math.pi
    return total + diffuse + glow + STRAY_LIGHT


def _poisson_cdf(lam: np.ndarray, k: int) -> np.ndarray:
    term = np.exp(-lam)
    total = term.copy()
    for n in range(1, k + 1):
        term = term * lam / n
        total += term
    return np.minimum(total, 1.0)


def measure(values: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The two-exposure measurement of noise-free ratios (any shape)."""
    values = np.asarray(values, dtype=np.float64)
    reference = 1.0 + REFERENCE_NOISE * rng.standard_normal()
    flicker = 1.0 + FLICKER * rng.standard_normal(values.shape)
    long_read = _exposure(values * flicker, LONG_GAIN_DN, rng)
    short_read = _exposure(values * flicker, SHORT_GAIN_DN, rng)
    merged = np.where(np.isnan(long_read), short_read, long_read)
    return np.maximum(merged, 0.0) / reference


def _exposure(values: np.ndarray, gain_dn: float, rng: np.random.Generator) -> np.ndarray:
    """Mean of PIXELS pixels, each rounded to whole DN and clipped at full well; NaN
    where any pixel saturates (that exposure is then not used). Dark frame subtracted."""
    mean_dn = values * gain_dn
    pixel_sigma = np.sqrt(READ_NOISE_DN ** 2 + mean_dn / ELECTRONS_PER_DN)
    saturated = mean_dn + 4.0 * pixel_sigma >= FULL_WELL_DN
    # The mean of PIXELS dithered, rounded pixels: Gaussian with the pixel variance plus
    # the rounding's 1/12 over PIXELS, itself a multiple of 1/PIXELS DN.
    sigma_mean = np.sqrt((pixel_sigma ** 2 + 1.0 / 12.0) / PIXELS)
    noisy = mean_dn + sigma_mean * rng.standard_normal(values.shape)
    read = np.round(noisy * PIXELS) / PIXELS
    return np.where(saturated, np.nan, read / gain_dn)


def dye_transmittance(fabric: YarnFabric) -> np.ndarray | None:
    return None if fabric.dye is None else np.clip(DYES[fabric.dye](GRID_NM), 0.0, 1.0)


def channel_albedo(fabric: YarnFabric) -> np.ndarray:
    """Per-crossing survival for R, G, B: albedo times the dye's transmittance per crossing
    (transmittance^(1/lambda), so lambda crossings give the dye's transmittance)."""
    dye = dye_transmittance(fabric)
    if dye is None:
        return np.full(3, fabric.albedo)
    per_crossing = dye ** (1.0 / fabric.crossings)
    return fabric.albedo * (camera_channel_weights() @ per_crossing)


def make_measurement(fabric: YarnFabric) -> GonioData:
    grid = ogm3_grid()
    rng = np.random.default_rng(fabric.seed)
    albedo = channel_albedo(fabric)
    clean_rgb = yarn_transmittance(fabric, grid, albedo)
    if fabric.dye is None:
        return grid.with_values(measure(clean_rgb[:, 0], rng))
    grey = clean_rgb @ GREY_WEIGHTS
    return grid.with_values(measure(grey, rng), measure(clean_rgb, rng))


def header_comments(fabric: YarnFabric) -> tuple[str, ...]:
    lines = [
        "synthetic OGM-3 gonio set made by tools/make_gonio.py (yarn-level model, not eq. 7)",
        "value: mean of the central 40x40 px with the sample / without it; two exposures",
        f"display_name: {fabric.display_name}",
        f"weave: {fabric.weave}",
        f"open_area_normal: {fabric.open_area_normal:.4f}",
        f"yarn: warp {fabric.warp_diameter_mm} mm at {fabric.warp_spacing_mm} mm, "
        f"weft {fabric.weft_diameter_mm} mm at {fabric.weft_spacing_mm} mm",
        f"seed: {fabric.seed}",
    ] + [f"cloth.{key}: {value}" for key, value in sorted(fabric.cloth.items())]
    if fabric.dye is not None:
        lines.append("dye: dye.csv (spectral transmittance); r,g,b: camera channels")
    return tuple(lines)


def write_fabric(fabric: YarnFabric, out_dir: Path) -> Path:
    folder = out_dir / fabric.name
    folder.mkdir(parents=True, exist_ok=True)
    dye = dye_transmittance(fabric)
    if dye is not None:
        write_spectrum(folder / "dye.csv", GRID_NM, np.round(dye, 6),
                       [f"spectral transmittance of the {fabric.dye} dye through the yarn, "
                        "0..1 (tools/make_gonio.py)"])
    write_gonio(folder / "gonio.csv", make_measurement(fabric), header_comments(fabric))
    return folder / "gonio.csv"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="fabrics to make (default: all)")
    parser.add_argument("--out", type=Path, default=ROOT / "fabrics" / "measurements")
    args = parser.parse_args(argv)
    known = {f.name: f for f in CATALOG}
    unknown = [n for n in args.names if n not in known]
    if unknown:
        parser.error(f"unknown fabric(s) {', '.join(unknown)} (known: {', '.join(known)})")
    for fabric in CATALOG:
        if args.names and fabric.name not in args.names:
            continue
        path = write_fabric(fabric, args.out)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
