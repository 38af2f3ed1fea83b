"""Fabrics told apart on the contact sheet (issue 34): every preset shows the colour its name
says, and no two catalog cells look the same.

Read-back pixels of ``catalog sheet`` under D65 (the room's white balance, automatic
exposure, the 8-bit sRGB cells a user sees). CIELAB against the display white (sRGB 1, 1, 1).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from PIL import Image

from catalog.optics.colorimetry import (delta_e_2000, delta_e_2000_lab, linear_srgb_to_xyz,
                                        srgb_decode, xyz_to_lab)
from catalog.presets import list_presets
from catalog.render.sheet import render_sheet

pytestmark = [pytest.mark.gl, pytest.mark.slow]

WHITE_XYZ = linear_srgb_to_xyz(np.ones(3))
CELL = (160, 108)


@pytest.fixture(scope="module")
def cells(gl_context, tmp_path_factory):
    """{fabric: XYZ image (H, W, 3)} of every catalog preset under D65."""
    out = tmp_path_factory.mktemp("sheet") / "sheet"
    report = render_sheet(["D65"], out, CELL, progress=False, ctx=gl_context, labels=False)
    return {image["fabric"]: linear_srgb_to_xyz(srgb_decode(
        np.asarray(Image.open(image["path"]).convert("RGB")) / 255.0))
        for image in report["images"]}


def _curtain_lab(xyz: np.ndarray) -> np.ndarray:
    """Mean CIELAB of the cell's middle (the curtain in front of the window, every fabric)."""
    h, w = xyz.shape[:2]
    middle = xyz[int(0.3 * h):int(0.7 * h), int(0.42 * w):int(0.58 * w)]
    return xyz_to_lab(middle.reshape(-1, 3).mean(0), WHITE_XYZ)


def test_cream_batiste_is_warmer_than_the_voile(cells):
    """The cream batiste's dye (a spectrum absorbing the blue, fabrics/measurements/) puts its
    b* at least 3 above the white voile's, and the voile stays neutral (|a*|, |b*| < 2)."""
    cream, voile = _curtain_lab(cells["batiste-cream"]), _curtain_lab(cells["voile-white"])
    assert cream[2] >= voile[2] + 3.0, (cream, voile)
    assert abs(voile[1]) < 2.0 and abs(voile[2]) < 2.0, voile


def test_ivory_and_flax_read_warm_not_coloured(cells):
    """Ivory organza and natural linen are warm whites: b* between 2 and 20, |a*| < 5."""
    for name in ("organza-ivory", "linen-dense"):
        lab = _curtain_lab(cells[name])
        assert 2.0 <= lab[2] <= 20.0 and abs(lab[1]) < 5.0, (name, lab)


def test_every_catalog_pair_differs_by_two_delta_e(cells):
    """Mean per-pixel CIEDE2000 between any two fabrics' cells is at least 2 (a just
    noticeable difference is about 1): the catalog has no look-alikes."""
    assert len(cells) == len(list_presets())
    worst = min((float(delta_e_2000(cells[a], cells[b], WHITE_XYZ).mean()), a, b)
                for a, b in itertools.combinations(sorted(cells), 2))
    assert worst[0] >= 2.0, worst


def test_every_catalog_pair_differs_in_its_curtains_colour(cells):
    """The same without the drape: CIEDE2000 between the mean colours of two cells' curtains
    (the middle, in front of the window) is at least 2 for every pair, so no two fabrics
    differ only by where their pleats fall. The whites are told apart by their fibres' own
    spectra (tools/make_gonio.py DYES): the bleached cotton's yellowness (jacquard), the nylon
    tulle's violet shading dye, the Raschel's deeper ivory, the lace's brightener, the neutral
    polyester voile. Closest pair measured: 2.27 (net-grey / voile); before the three spectra 0.45
    (tulle / voile), 0.80 (organza / Raschel), 1.17 (jacquard / voile)."""
    labs = {name: _curtain_lab(xyz) for name, xyz in cells.items()}
    worst = min((float(delta_e_2000_lab(labs[a], labs[b])), a, b)
                for a, b in itertools.combinations(sorted(labs), 2))
    assert worst[0] >= 2.0, worst


def test_inset_keeps_the_swatch_brightness_and_frames_it():
    """put_inset: the area-averaged swatch (in linear light) keeps a checkerboard's mean
    linear level (0.5 -> sRGB 188), sits in the lower right corner inside a dark frame, and
    leaves the rest of the cell untouched."""
    from catalog.render.sheet import put_inset

    cell = np.full((96, 128, 3), 100, np.uint8)
    swatch = np.zeros((96, 128, 3), np.uint8)
    swatch[::2, ::2] = swatch[1::2, 1::2] = 255
    put_inset(cell, swatch, 0.5)
    inner = cell[-2 - 48:-2, -2 - 64:-2]
    assert abs(float(inner.mean()) - 188.0) <= 1.0
    assert cell[-2 - 48 - 1, -30, 0] == 16 and cell[-1 - 1, -2 - 64 - 1, 0] == 16
    assert np.all(cell[:40, :60] == 100)
