"""The gamut boundary as a table (docs/display.md, step 4): what tonemap.frag reads instead
of finding the boundary by bisection per pixel.

The compression (display.gamut_compress) keeps a colour's OKLab L and hue and maps its
chroma ratio r = C / C_boundary(L, hue) through display.compress_ratio; only the boundary
needs a search, and it is a function of two variables and of constants (the cube). So it is
tabulated once per process: C_boundary at BOUNDARY_HUE_N hues x BOUNDARY_L_N lightnesses,
read bilinearly; the pixel's own L, hue and chroma stay exact, so a colour is kept or
compressed at exactly its own hue and lightness, and the table's error only moves r (where
the boundary has a corner between two nodes). tests/test_display_lut.py states the bound.

Hue is the "diamond angle" p in [0, 4) of (a, b): a' = a / (|a| + |b|), p = 1 - a' for
b >= 0 and 3 + a' below (continuous, periodic, no arctangent); the texture repeats along it.
L runs over [0, display.lightness_ceiling()].
"""

from __future__ import annotations

import functools

import numpy as np

#: Nodes along the hue (periodic) and the lightness (256: the yellow cusp near L = 0.97 is a
#: corner of C_boundary(L) that 64 rows missed by up to 26 sRGB8 levels; 512 KB of float32).
BOUNDARY_HUE_N = 512
BOUNDARY_L_N = 256
#: Bisection steps for each node's boundary, on [0, BOUNDARY_C_MAX] (sRGB's largest OKLab
#: chroma is about 0.32): 2^-20 of it.
BOUNDARY_STEPS = 20
BOUNDARY_C_MAX = 0.5


def diamond_angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(a, b) -> p in [0, 4): the hue as a position on the diamond |a'| + |b'| = 1."""
    a_unit = a / np.maximum(np.abs(a) + np.abs(b), 1e-30)
    return np.where(b >= 0.0, 1.0 - a_unit, 3.0 + a_unit)


def _diamond_direction(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """p -> the unit vector (a, b) of that hue."""
    a = np.where(p < 2.0, 1.0 - p, p - 3.0)
    b = np.where(p < 2.0, 1.0 - np.abs(a), np.abs(a) - 1.0)
    norm = np.hypot(a, b)
    return a / norm, b / norm


def node_hues() -> np.ndarray:
    """Texel centres along the hue: p_i = 4 (i + 1/2) / N."""
    return 4.0 * (np.arange(BOUNDARY_HUE_N) + 0.5) / BOUNDARY_HUE_N


def node_lightness() -> np.ndarray:
    from catalog.render.display import lightness_ceiling  # noqa: PLC0415

    return np.linspace(0.0, lightness_ceiling(), BOUNDARY_L_N)


def boundary_chroma(lightness: np.ndarray, p: np.ndarray, steps: int = BOUNDARY_STEPS) -> np.ndarray:
    """OKLab chroma where the cube [0, CUBE_TOP]^3 is left along the hue p at L, by bisection
    from the grey (inside for L up to the ceiling)."""
    from catalog.render.display import CUBE_TOP, matrices  # noqa: PLC0415

    m = matrices()
    ua, ub = _diamond_direction(np.asarray(p, dtype=np.float64))
    lightness = np.asarray(lightness, dtype=np.float64)
    lo = np.zeros(np.broadcast(lightness, ua).shape)
    hi = np.full(lo.shape, BOUNDARY_C_MAX)
    grey = [lightness * m.lab_to_lms[k, 0] for k in range(3)]
    hue = [ua * m.lab_to_lms[k, 1] + ub * m.lab_to_lms[k, 2] for k in range(3)]
    for _ in range(steps):   # channel by channel: numpy's small matmuls are slow
        mid = 0.5 * (lo + hi)
        cubes = [(grey[k] + mid * hue[k]) ** 3 for k in range(3)]
        inside = np.ones(lo.shape, dtype=bool)
        for row in m.lms_to_rgb:
            channel = row[0] * cubes[0] + row[1] * cubes[1] + row[2] * cubes[2]
            inside &= (channel >= 0.0) & (channel <= CUBE_TOP)
        lo = np.where(inside, mid, lo)
        hi = np.where(inside, hi, mid)
    return lo


@functools.lru_cache(maxsize=1)
def boundary_table() -> np.ndarray:
    """(BOUNDARY_L_N rows, BOUNDARY_HUE_N columns) float32: C_boundary at each node."""
    table = boundary_chroma(node_lightness()[:, None], node_hues()[None, :]).astype(np.float32)
    table.setflags(write=False)
    return table


def lookup(lightness: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The bilinear read tonemap.frag makes (hue periodic, L clamped to the table)."""
    from catalog.render.display import lightness_ceiling  # noqa: PLC0415

    table = boundary_table().astype(np.float64)
    x = np.asarray(p, dtype=np.float64) / 4.0 * BOUNDARY_HUE_N - 0.5
    i0 = np.floor(x)
    fx = x - i0
    i0 = i0.astype(int) % BOUNDARY_HUE_N
    i1 = (i0 + 1) % BOUNDARY_HUE_N
    y = np.clip(np.asarray(lightness, dtype=np.float64) / lightness_ceiling(), 0.0, 1.0) * (BOUNDARY_L_N - 1)
    j0 = np.clip(np.floor(y), 0, BOUNDARY_L_N - 2).astype(int)
    fy = y - j0
    return ((1 - fy) * ((1 - fx) * table[j0, i0] + fx * table[j0, i1])
            + fy * ((1 - fx) * table[j0 + 1, i0] + fx * table[j0 + 1, i1]))


def gamut_compress(rgb: np.ndarray) -> np.ndarray:
    """display.gamut_compress with the boundary read from the table, as tonemap.frag."""
    from catalog.render.display import R_KNEE, compress_ratio, lightness_ceiling, matrices, _signed_cbrt  # noqa: PLC0415

    m = matrices()
    rgb = np.asarray(rgb, dtype=np.float64)
    lms = _signed_cbrt(rgb @ m.rgb_to_lms.T)
    lab = lms @ m.lms_to_lab.T
    own_l = lab[..., 0]
    lightness = np.clip(own_l, 0.0, lightness_ceiling())
    chroma = np.hypot(lab[..., 1], lab[..., 2])
    r = chroma / np.maximum(lookup(lightness, diamond_angle(lab[..., 1], lab[..., 2])), 1e-12)
    need = (lightness != own_l) | (r > R_KNEE)
    scale = np.where(need, compress_ratio(r) / np.maximum(r, 1e-30), 1.0)
    grey = m.lab_to_lms[:, 0]
    offset = lms - own_l[..., None] * grey
    out = ((lightness[..., None] * grey + scale[..., None] * offset) ** 3) @ m.lms_to_rgb.T
    return np.where(need[..., None], out, rgb)


def shader_uniforms() -> dict:
    """tonemap.frag's boundary uniforms (the texture itself: passes/display.py)."""
    from catalog.render.display import R_KNEE, R_LIMIT, lightness_ceiling, matrices  # noqa: PLC0415

    m = matrices()

    def mat3(a):
        return np.ascontiguousarray(np.asarray(a, dtype=np.float64).T, dtype="f4").tobytes()

    return {"u_rgb_to_lms": mat3(m.rgb_to_lms), "u_lms_to_rgb": mat3(m.lms_to_rgb),
            "u_lms_to_lab": mat3(m.lms_to_lab), "u_lab_grey": tuple(float(v) for v in m.lab_to_lms[:, 0]),
            "u_gamut": (float(R_KNEE), float(R_LIMIT), float(lightness_ceiling()))}
