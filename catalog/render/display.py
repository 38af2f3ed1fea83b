"""Scene radiance -> display pixels (docs/display.md): exposure, white balance, tone curve,
gamut compression at constant hue, the sRGB curve.

shaders/tonemap.frag runs this per pixel on the GPU; :func:`display_transform` is its float64
numpy twin (tests compare the two per pixel). The steps, on linear sRGB radiance (cd m^-2):

1. exposure: ``x = k * L`` with ``k = 1 / (1.2 * 2^EV100)`` (the saturation-based exposure
   of ISO 12232 as renderers use it: EV100 = log2(L_avg * 100 / 12.5) puts the metered
   average at 0.104), times a compensation ``2^EXPOSURE_COMPENSATION_EV``;
   ``--ev`` fixes EV100, otherwise :func:`meter_ev100` picks it from a luminance histogram.
2. white balance: a 3x3 in linear sRGB, CAT16 (Li et al. 2017) von Kries from the white of
   the light reaching the viewer to D65 with CAT16's degree of adaptation
   (:func:`white_balance_matrix`, catalog.render.adaptation), the identity for "camera".
3. tone curve on luminance Y only (chromaticity kept): a Michaelis-Menten curve with a power,
   as in ACES 2.0's tonescale, ``y = (x / (x + S0))^G``: mid grey 0.18 -> 0.18, y -> 1
   only as x -> infinity (no hard clip of highlights).
4. gamut compression in OKLab (Ottosson 2020) at constant L and hue: the chroma ratio
   r = C / C_boundary (C_boundary: where the sRGB cube is left along the line from the grey of
   the same L, found by bisection) is kept below ``R_KNEE`` and rolled off above it towards
   ``R_LIMIT`` < 1, so an out-of-gamut emission keeps its hue and lightness and never lands on
   the cube's faces (no channel clipped). The cube is [0, CUBE_TOP]^3: near its top (L -> 1)
   it narrows to the grey, which desaturates highlights toward white.
5. the sRGB transfer curve (IEC 61966-2-1).

The matrices (CAT16, OKLab's two, sRGB's) are colour-science's, copied by program into
``catalog/render/data/display_tables.npz`` (:func:`build_display_tables`; a test regenerates it),
so a frame never imports colour or scipy.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.errors import CatalogError

TABLE_PATH = Path(__file__).resolve().parent / "data" / "display_tables.npz"

#: White balance settings: "room" adapts to the light reaching the viewer (what a person in
#: the room sees after a minute; catalog.render.adaptation), "camera" keeps a fixed D65 balance (what a daylight camera records).
WHITE_BALANCES = ("room", "camera")
DEFAULT_WHITE_BALANCE = "room"
#: Lights whose white lies further than this from the Planckian locus (CIE 1960 uv) are not
#: adapted to (the UV-A lamp's visible part is two violet lines): D65 is kept.
MAX_WHITE_DUV = 0.03
#: Tone curve y = (x / (x + S0))^G: G is the contrast, S0 puts mid grey 0.18 at 0.18.
TONE_G = 1.15
TONE_MID_GREY = 0.18
TONE_S0 = TONE_MID_GREY / TONE_MID_GREY ** (1.0 / TONE_G) - TONE_MID_GREY
#: Gamut compression: chroma ratios below R_KNEE are kept, above it rolled off toward R_LIMIT.
R_KNEE = 0.75
R_LIMIT = 0.96
#: The cube the compression keeps colours in: [0, CUBE_TOP]^3 (below 8-bit 255: a highlight's
#: brightest channel rolls off with the others rather than reaching 255 first).
CUBE_TOP = 0.985
#: Bisection steps for the gamut boundary: 2^-8 of the search interval 1 / R_KNEE, a chroma
#: ratio to 0.5 % (the compression takes the inner end, so it never leaves the cube); each
#: step costs ~3 ms a 640x360 pass on llvmpipe (docs/display.md).
GAMUT_STEPS = 8
#: Auto exposure: log2 luminance histogram (bins over the range, cd m^-2), the part of the
#: frame that is averaged (fractions of the pixels, darkest first), and where the average goes.
HISTOGRAM_BINS = 128
HISTOGRAM_LOG2_RANGE = (-12.0, 24.0)
METER_PERCENTILES = (0.50, 0.97)
#: Exposure compensation (EV) applied on top of the metered or manual EV100: the metered
#: average (0.104 at K = 12.5) goes to 0.36, one stop over mid grey, because the metered part
#: of the frame is the lit curtain, a light-coloured cloth (a camera would leave it grey).
EXPOSURE_COMPENSATION_EV = math.log2(0.36 / (12.5 / 120.0))
#: The auto exposure goes no further than this (a dim room, ~4 cd m^-2 average): a scene that
#: is dark (cloth without brightener under the UV-A lamp) shows dark, not amplified.
AUTO_EV_MIN = 5.0
#: The viewer's adaptation time constant (s) for the auto exposure.
ADAPTATION_TAU_S = 0.6
EV_RANGE = (-6.0, 22.0)


# ---------------------------------------------------------------------------------- tables
def build_display_tables() -> dict[str, np.ndarray]:
    """Copy the matrices from colour-science (slow: imports colour)."""
    import colour  # noqa: PLC0415
    from colour.models import oklab  # noqa: PLC0415

    space = colour.RGB_COLOURSPACES["sRGB"]
    return {
        "cat16": np.asarray(colour.adaptation.CAT_CAT16, dtype=np.float64),
        "oklab_xyz_to_lms": np.asarray(oklab.MATRIX_1_XYZ_TO_LMS, dtype=np.float64),
        "oklab_lms_to_lab": np.asarray(oklab.MATRIX_2_LMS_TO_LAB, dtype=np.float64),
        "srgb_xyz_to_rgb": np.asarray(space.matrix_XYZ_to_RGB, dtype=np.float64),
        "srgb_whitepoint_xy": np.asarray(space.whitepoint, dtype=np.float64),
    }


def write_display_tables(path: Path = TABLE_PATH) -> Path:
    from catalog.core.atomic import atomic_path  # noqa: PLC0415

    tables = build_display_tables()
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            np.savez(handle, **tables)
    return path


@functools.lru_cache(maxsize=1)
def tables() -> dict[str, np.ndarray]:
    if not TABLE_PATH.exists():
        raise CatalogError(f"{TABLE_PATH}: missing; run tools/make_display_tables.py")
    with np.load(TABLE_PATH, allow_pickle=False) as data:
        out = {key: np.array(data[key]) for key in data.files}
    for value in out.values():
        value.setflags(write=False)
    return out


@dataclass(frozen=True)
class Matrices:
    """The per-pixel matrices of tonemap.frag (float64; the shader gets them as float32)."""

    rgb_to_xyz: np.ndarray
    xyz_to_rgb: np.ndarray
    rgb_to_lms: np.ndarray      # OKLab M1 after sRGB -> XYZ
    lms_to_rgb: np.ndarray
    lms_to_lab: np.ndarray      # OKLab M2
    lab_to_lms: np.ndarray
    luminance: np.ndarray       # the Y row of rgb_to_xyz


@functools.lru_cache(maxsize=1)
def matrices() -> Matrices:
    t = tables()
    xyz_to_rgb = t["srgb_xyz_to_rgb"]
    rgb_to_xyz = np.linalg.inv(xyz_to_rgb)
    rgb_to_lms = t["oklab_xyz_to_lms"] @ rgb_to_xyz
    return Matrices(rgb_to_xyz, xyz_to_rgb, rgb_to_lms, np.linalg.inv(rgb_to_lms),
                    t["oklab_lms_to_lab"], np.linalg.inv(t["oklab_lms_to_lab"]),
                    rgb_to_xyz[1].copy())


# ---------------------------------------------------------------------------------- white
def d65_white_xyz() -> np.ndarray:
    x, y = tables()["srgb_whitepoint_xy"]
    return np.array([x / y, 1.0, (1.0 - x - y) / y])


def cat16_xyz_matrix(source_white_xyz, target_white_xyz) -> np.ndarray:
    """Full (D = 1) CAT16 von Kries adaptation, XYZ -> XYZ (both whites on any common scale:
    only their ratios in CAT16's cone space enter)."""
    from catalog.render.adaptation import cat16_matrix  # noqa: PLC0415

    return cat16_matrix(source_white_xyz, target_white_xyz, 1.0, tables()["cat16"])


@functools.lru_cache(maxsize=1)
def _planckian_uv() -> np.ndarray:
    from catalog.optics.colorimetry import spectrum_to_xyz  # noqa: PLC0415
    from catalog.optics.lights import planck_w_m2_nm  # noqa: PLC0415

    temperatures = np.geomspace(1000.0, 40000.0, 400)
    xyz = np.array([spectrum_to_xyz(planck_w_m2_nm(t)) for t in temperatures])
    return _uv(xyz)


def _uv(xyz: np.ndarray) -> np.ndarray:
    x, y, z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    d = x + 15 * y + 3 * z
    return np.stack([4 * x / d, 6 * y / d], axis=-1)


def planckian_distance(white_xyz) -> float:
    """Distance (CIE 1960 uv) from the Planckian locus, 1000..40000 K sampled finely."""
    uv = _uv(np.asarray(white_xyz, dtype=np.float64))
    return float(np.min(np.hypot(*(_planckian_uv() - uv).T)))


def adapts_to(white_xyz, white_balance: str) -> bool:
    """Whether ``white_balance`` adapts to this light's white (see WHITE_BALANCES)."""
    if white_balance not in WHITE_BALANCES:
        raise CatalogError(f"white balance {white_balance!r}: choose one of {', '.join(WHITE_BALANCES)}")
    white = np.asarray(white_xyz, dtype=np.float64)
    return (white_balance == "room" and bool(np.all(np.isfinite(white))) and white[1] > 0
            and planckian_distance(white) <= MAX_WHITE_DUV)


def white_balance_matrix(white_xyz, white_balance: str = DEFAULT_WHITE_BALANCE,
                         degree: float = 1.0) -> np.ndarray:
    """Linear sRGB -> linear sRGB: CAT16 from ``white_xyz`` (the adapting white: the frame
    gives the light reaching the viewer, catalog.render.adaptation) to D65 with degree of
    adaptation ``degree``, or the identity when the setting or the light does not adapt
    (:func:`adapts_to`)."""
    from catalog.render.adaptation import cat16_matrix  # noqa: PLC0415

    if not adapts_to(white_xyz, white_balance):
        return np.eye(3)
    m = matrices()
    return m.xyz_to_rgb @ cat16_matrix(white_xyz, d65_white_xyz(), degree, tables()["cat16"]) @ m.rgb_to_xyz


# ---------------------------------------------------------------------------------- exposure
def exposure_scale(ev100: float) -> float:
    """Radiance (cd m^-2) -> scene value: 2^compensation / (1.2 * 2^EV100)."""
    return 2.0 ** (EXPOSURE_COMPENSATION_EV - ev100) / 1.2


def check_ev(ev100: float) -> float:
    if not (isinstance(ev100, (int, float)) and math.isfinite(ev100)
            and EV_RANGE[0] <= ev100 <= EV_RANGE[1]):
        raise CatalogError(f"--ev {ev100!r}: give an EV100 in {EV_RANGE[0]:g}..{EV_RANGE[1]:g}")
    return float(ev100)


def meter_signal(rgb: np.ndarray) -> np.ndarray:
    """What the auto exposure measures per pixel (cd m^-2 scale): the largest of R, G, B
    (linear sRGB, Y-scaled), as a camera that protects its channels meters. Equal to Y for a
    neutral colour; larger for a saturated one, which also looks brighter than its luminance
    says (Helmholtz-Kohlrausch), most of all a saturated blue (Y is 7 % of the blue primary's
    channel value): metering Y alone exposes a blue glow until it can only be shown pale."""
    return np.maximum(np.asarray(rgb, dtype=np.float64).max(axis=-1), 0.0)


def luminance_histogram(luminance_cd_m2: np.ndarray, weights=None) -> np.ndarray:
    """Counts of log2 of a per-pixel signal in cd m^-2 (Y, or :func:`meter_signal`) in
    HISTOGRAM_BINS bins over HISTOGRAM_LOG2_RANGE (values <= 0 -> the first bin)."""
    y = np.asarray(luminance_cd_m2, dtype=np.float64).ravel()
    lo, hi = HISTOGRAM_LOG2_RANGE
    with np.errstate(divide="ignore", invalid="ignore"):
        log_y = np.where(y > 0, np.log2(np.maximum(y, 1e-300)), lo)
    index = np.clip(((log_y - lo) / (hi - lo) * HISTOGRAM_BINS).astype(int), 0, HISTOGRAM_BINS - 1)
    w = None if weights is None else np.asarray(weights, dtype=np.float64).ravel()
    return np.bincount(index, weights=w, minlength=HISTOGRAM_BINS).astype(np.float64)


def meter_ev100(histogram: np.ndarray) -> float:
    """EV100 from a log2 luminance histogram: the mean log2 Y of the pixels between the
    METER_PERCENTILES (the dark half and the brightest few per cent ignored), K = 12.5."""
    counts = np.asarray(histogram, dtype=np.float64)
    total = counts.sum()
    lo, hi = HISTOGRAM_LOG2_RANGE
    if not total > 0:
        return AUTO_EV_MIN
    width = (hi - lo) / HISTOGRAM_BINS
    centres = lo + (np.arange(counts.size) + 0.5) * width
    below = np.concatenate([[0.0], np.cumsum(counts)[:-1]]) / total
    above = np.cumsum(counts) / total
    p0, p1 = METER_PERCENTILES
    share = np.clip(np.minimum(above, p1) - np.maximum(below, p0), 0.0, None)
    share_total = share.sum()
    mean_log2 = float((share * centres).sum() / share_total) if share_total > 0 else centres[0]
    ev = mean_log2 + math.log2(100.0 / 12.5)
    return float(min(max(ev, AUTO_EV_MIN), EV_RANGE[1]))


def adapt_ev(current: float | None, target: float, dt_s: float | None) -> float:
    """The viewer's exposure after ``dt_s`` seconds of adapting towards ``target`` (EV100);
    ``dt_s`` None (a still image) jumps."""
    if current is None or dt_s is None:
        return float(target)
    return float(target + (current - target) * math.exp(-max(dt_s, 0.0) / ADAPTATION_TAU_S))


# ---------------------------------------------------------------------------------- per pixel
def tone_curve(x: np.ndarray) -> np.ndarray:
    x = np.maximum(np.asarray(x, dtype=np.float64), 0.0)
    return (x / (x + TONE_S0)) ** TONE_G


def _signed_cbrt(v):
    return np.sign(v) * np.abs(v) ** (1.0 / 3.0)


def rgb_to_oklab(rgb: np.ndarray) -> np.ndarray:
    m = matrices()
    return _signed_cbrt(rgb @ m.rgb_to_lms.T) @ m.lms_to_lab.T


def oklab_to_rgb(lab: np.ndarray) -> np.ndarray:
    m = matrices()
    return (lab @ m.lab_to_lms.T) ** 3 @ m.lms_to_rgb.T


def _in_gamut(lab: np.ndarray) -> np.ndarray:
    rgb = oklab_to_rgb(lab)
    return np.all((rgb >= 0.0) & (rgb <= CUBE_TOP), axis=-1)


def lightness_ceiling() -> float:
    """The largest OKLab L kept (a saturated colour's L can exceed its luminance's cube root,
    so its grey would leave the cube): just below the grey CUBE_TOP."""
    return CUBE_TOP ** (1.0 / 3.0) * (1.0 - 1e-4)


def compress_ratio(r: np.ndarray) -> np.ndarray:
    """Chroma ratio r (C / boundary) -> r' < R_LIMIT: identity below R_KNEE, then
    R_KNEE + (R_LIMIT - R_KNEE) u / (1 + u), u = (r - R_KNEE) / (R_LIMIT - R_KNEE)."""
    r = np.asarray(r, dtype=np.float64)
    span = R_LIMIT - R_KNEE
    u = np.maximum(r - R_KNEE, 0.0) / span
    return np.where(r <= R_KNEE, r, R_KNEE + span * u / (1.0 + u))


def gamut_compress(rgb: np.ndarray, steps: int = GAMUT_STEPS) -> np.ndarray:
    """Linear sRGB (luminance in [0, 1), channels anywhere) -> inside the cube, at constant
    OKLab hue and L (L clamped to [0, :func:`lightness_ceiling`]; module docstring, step 4).

    Walked in LMS' (OKLab's cube-rooted LMS): with g = M2^-1 (1, 0, 0) (about (1, 1, 1)), the
    colour at lightness L and chroma scale t on this colour's hue is L g + t (lms' - L_own g).
    ``steps``: bisection steps (the display's table is built with more)."""
    m = matrices()
    rgb = np.asarray(rgb, dtype=np.float64)
    lms = _signed_cbrt(rgb @ m.rgb_to_lms.T)
    own_l = lms @ m.lms_to_lab[0]
    lightness = np.clip(own_l, 0.0, lightness_ceiling())
    grey = m.lab_to_lms[:, 0]   # LMS' of (L, 0, 0) per unit L (1, 1, 1 to 1e-10)
    offset = lms - own_l[..., None] * grey

    def inside(lo_l, off, t):   # channel by channel: numpy's small matmuls are slow
        cubes = [(lo_l * grey[k] + t * off[..., k]) ** 3 for k in range(3)]
        ok = np.ones(lo_l.shape, dtype=bool)
        for row in m.lms_to_rgb:
            channel = row[0] * cubes[0] + row[1] * cubes[1] + row[2] * cubes[2]
            ok &= (channel >= 0.0) & (channel <= CUBE_TOP)
        return ok

    t_hi = 1.0 / R_KNEE
    # in gamut at 1/R_KNEE times its chroma: r <= R_KNEE, kept; a clamped L is rebuilt
    need = (lightness != own_l) | ~inside(lightness, offset, np.full(own_l.shape, t_hi))
    out = np.array(rgb, copy=True)
    if not np.any(need):
        return out
    sub_l, sub_off = lightness[need], offset[need]
    lo = np.zeros(sub_l.shape)
    hi = np.full(sub_l.shape, t_hi)
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        ok = inside(sub_l, sub_off, mid)
        lo = np.where(ok, mid, lo)
        hi = np.where(ok, hi, mid)
    # lo: the largest multiple of the colour's chroma found inside (the boundary from below)
    r = 1.0 / np.maximum(lo, 1e-12)
    scale = compress_ratio(r) / r
    out[need] = ((sub_l[..., None] * grey + scale[..., None] * sub_off) ** 3) @ m.lms_to_rgb.T
    return out


def display_linear(hdr_rgb: np.ndarray, exposure: float, white_balance: np.ndarray) -> np.ndarray:
    """Steps 1-4: radiance (linear sRGB, cd m^-2) -> display-linear sRGB in [0, 1); step 4
    with the boundary read from its table (catalog.render.display_lut), as tonemap.frag."""
    from catalog.render import display_lut  # noqa: PLC0415

    return np.clip(display_lut.gamut_compress(tone_mapped(hdr_rgb, exposure, white_balance)), 0.0, 1.0)


def tone_mapped(hdr_rgb: np.ndarray, exposure: float, white_balance: np.ndarray) -> np.ndarray:
    """Steps 1-3: radiance -> linear sRGB of luminance in [0, 1) (0 where Y <= 0), before the
    gamut compression (:func:`gamut_compress` exactly, or its table)."""
    m = matrices()
    c = (np.asarray(hdr_rgb, dtype=np.float64) * exposure) @ np.asarray(white_balance).T
    y = c @ m.luminance
    positive = y > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(positive[..., None], c * (tone_curve(y) / np.where(positive, y, 1.0))[..., None], 0.0)


def display_transform(hdr_rgb: np.ndarray, exposure: float, white_balance: np.ndarray) -> np.ndarray:
    """The whole display step, as tonemap.frag: uint8-ready sRGB in [0, 1]."""
    from catalog.optics.colorimetry import srgb_encode  # noqa: PLC0415

    return srgb_encode(display_linear(hdr_rgb, exposure, white_balance))


def shader_uniforms(exposure: float, white_balance: np.ndarray) -> dict:
    """tonemap.frag's uniforms (mat3 as column-major float32 bytes)."""
    m = matrices()

    def mat3(a):
        return np.ascontiguousarray(np.asarray(a, dtype=np.float64).T, dtype="f4").tobytes()

    return {"u_exposure": float(exposure), "u_white_balance": mat3(white_balance),
            "u_luminance": tuple(float(v) for v in m.luminance),
            "u_tone": (float(TONE_S0), float(TONE_G))}
