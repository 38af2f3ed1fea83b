"""The laces' scalloped border along the hem (scalloped_border in tools/lace_motifs.py; the
[pattern] border band, common.glsl HEM_BORDER): the band joins the all-over pattern without a
seam, is cut away below its scallops, and the frame draws the scallops where the band puts them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.presets import load_preset
from catalog.presets.patterns import load_pattern
from catalog.render.frame import FrameRenderer
from catalog.render.settings import orbit

LACES = ("lace-fwa", "raschel-ivory", "tulle-embroidered")
#: The catalog's scallops per pattern repeat across (tools/make_patterns.py PATTERNS).
SCALLOPS = {"lace-fwa": 2, "raschel-ivory": 2, "tulle-embroidered": 4}


def _lowest_covered_rows(coverage: np.ndarray, threshold: float = 0.5) -> np.ndarray:
    """Per column, the first row (from row 0, the hem) whose coverage reaches ``threshold``."""
    covered = coverage >= threshold
    return np.where(covered.any(axis=0), covered.argmax(axis=0), coverage.shape[0])


@pytest.mark.parametrize("name", LACES)
def test_the_band_joins_the_lace_and_is_scalloped(name):
    """Row by row the band's top 8 rows equal the repeat's same rows (16-bit: within 1e-4),
    so no seam shows where it ends; its row 0 (the hem line) has no thread; the lowest thread
    of each column rises and falls with the scallops: one period per scallop (the spectrum's
    peak of the edge profile at SCALLOPS per repeat), cusps at least 3 mm above the arcs'
    lowest points (the finest, the tulle's 2 cm scallops, rise 4.4 mm)."""
    pattern = load_pattern(load_preset(f"fabrics/{name}.toml"))
    band = pattern.border
    rows = band.coverage.shape[0]
    assert band.coverage.shape[1] == pattern.coverage.shape[1]
    assert np.abs(band.coverage[-8:] - pattern.coverage[rows - 8:rows]).max() < 1e-4
    assert np.abs(band.height[-8:] - pattern.height[rows - 8:rows]).max() < 1e-4
    assert band.coverage[0].max() == 0.0
    edge = _lowest_covered_rows(band.coverage)
    spectrum = np.abs(np.fft.rfft(edge - edge.mean()))
    assert int(np.argmax(spectrum[1:]) + 1) == SCALLOPS[name]
    metres_per_row = band.depth_m / rows
    assert (edge.max() - edge.min()) * metres_per_row > 0.003


def _hem_quad():
    """A flat quad facing +z (x -0.9..0.9, y -0.85..1.2 m, z -0.08), its uv's v = 0 at the
    bottom edge: the hem, as the cloth mesh's (catalog/cloth/mesh.py)."""
    positions = np.array([[-0.9, 1.2, -0.08], [0.9, 1.2, -0.08], [-0.9, -0.85, -0.08],
                          [0.9, -0.85, -0.08]])
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    uvs = np.array([[0.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0]])
    tangents = np.tile([1.0, 0.0, 0.0], (4, 1))
    return positions, normals, uvs, tangents, np.array([[0, 2, 1], [1, 2, 3]])


@pytest.mark.gl
@pytest.mark.slow
def test_the_frame_cuts_the_scallops_where_the_band_puts_them(gl):
    """lace-fwa's hem seen straight on from 0.45 m (fov 40 deg, 240 rows: 1.4 mm a pixel). Read
    back: the OIT weight (the curtain's coverage times its depth weight), cloth where it is
    over 5 % of its median. Per column the lowest pixel with cloth traces the scallops: the edge profile's
    spectrum peaks at the scallop pitch (5 cm: 2 per 0.1 m repeat, within one bin), and
    the cusps stand 14 mm (0.28 of the pitch) minus the heavy cord's and the picots' reach
    above the arcs' lowest cloth: 8-16 mm. Without the band (its define off) the hem is
    straight: the profile varies by at most 1 pixel. Above the band both frames agree."""
    size = (320, 240)
    renderer = FrameRenderer(gl, size)
    try:
        renderer.update(fabric="lace-fwa", light="D65")
        renderer.set_mesh(*_hem_quad(), fabric_size_m=(1.8, 2.05))
        renderer.update(ev=12.0)
        distance, fov = 0.45, 40.0
        renderer.update(camera=orbit(0.0, 0.0, distance, target=(0.0, -0.80, -0.08), fov_y_deg=fov))
        metres_per_px = 2 * distance * math.tan(math.radians(fov / 2)) / size[1]
        profiles, frames = [], []
        for with_band in (True, False):
            if not with_band:
                renderer.fabric_pattern.border.release()
                renderer.fabric_pattern.border = None
            renderer.render()
            weight = np.frombuffer(renderer.targets.oit_weight.read(), dtype=np.float32)
            weight = weight.reshape(size[1], size[0])            # row 0: the frame's bottom
            # cloth: a weight over 5 % of the median drawn (the prefiltered mips' far tails
            # leave a trace of coverage below the scallops, a few 1e-4 of it)
            cloth = weight > 0.05 * np.median(weight[weight > 0.0])
            profiles.append(np.where(cloth.any(axis=0), cloth.argmax(axis=0), size[1]))
            frames.append(renderer.read_linear())
    finally:
        renderer.release()
    scalloped, straight = profiles
    assert np.ptp(straight) <= 1
    rise_m = np.ptp(scalloped) * metres_per_px
    assert 0.008 <= rise_m <= 0.016, rise_m
    width_m = size[0] * metres_per_px
    spectrum = np.abs(np.fft.rfft(scalloped - scalloped.mean()))
    peak = int(np.argmax(spectrum[1:]) + 1)
    assert abs(peak - width_m / 0.05) <= 1.0, (peak, width_m / 0.05)
    band_top_row = int(np.ceil(straight.min() + 0.05 / metres_per_px)) + 3
    top = size[1] - band_top_row            # read_linear's rows run from the top
    assert np.abs(frames[0][:top - 2] - frames[1][:top - 2]).max() \
        <= 1e-3 * frames[1][:top - 2].max()


def test_a_bad_border_is_refused_naming_the_field(tmp_path):
    """A border without its depth, or a band narrower than the coverage, is refused with the
    preset's file and the field (the preset's own writer refuses to write either)."""
    import re
    import shutil

    from catalog.core.errors import InputError

    (tmp_path / "patterns").mkdir()
    for suffix in ("", "-height", "-border", "-border-height"):
        shutil.copy(f"fabrics/patterns/tulle-embroidered{suffix}.png", tmp_path / "patterns")
    text = open("fabrics/tulle-embroidered.toml").read()
    for name, edit, message in (
            ("no-depth", lambda t: re.sub(r"\nborder_m = [^\n]*", "", t), "border_m"),
            ("mismatch", lambda t: t.replace('border = "patterns/tulle-embroidered-border.png"',
                                             'border = "patterns/tulle-embroidered.png"'),
             "as wide as the coverage")):
        path = tmp_path / f"{name}.toml"
        edited = edit(text).replace('name = "tulle-embroidered"', f'name = "{name}"')
        assert edited != text
        path.write_text(edited)
        with pytest.raises(InputError, match=message):
            load_pattern(load_preset(path))
