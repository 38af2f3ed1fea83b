"""The lace's hem band is sampled only by the triangles that reach it (issue 38: the curtain's
cost), and the picture is the one the single draw gave (read-back pixels, relative 1e-5)."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.presets import find_preset, load_preset
from catalog.render.passes.curtain import CurtainPass
from catalog.render.settings import orbit
from catalog.render.snapshot import new_renderer, simulated_curtain

pytestmark = [pytest.mark.gl, pytest.mark.slow]   # two frames and a settled drape

SIZE = (192, 108)


def _frame(gl, monkeypatch, split: bool):
    if not split:
        monkeypatch.setattr(CurtainPass, "_hem_band_split", lambda self, program, coarse: None)
    preset = load_preset(find_preset("lace-fwa"))
    r = new_renderer(gl, SIZE)
    try:
        r.update(fabric=preset, light="D65", camera=orbit(0.0, 0.0, 1.2, target=(0.0, -0.9, 0.15)))
        *mesh, fabric_size = simulated_curtain(preset, 0)
        r.set_mesh(*mesh, fabric_size_m=fabric_size)
        r.render()
        names = r.mesh.hem_band_split(r.fabric_pattern.border_repeats * r.fabric_pattern.repeat_m[1]
                                      / r.mesh.fabric_size_m[1])
        counts = None if names is None else [r.mesh.buffers[n].size // 12 for n in names]
        return r.read_linear(), counts, r.mesh.buffers["index"].size // 12
    finally:
        r.release()
        monkeypatch.undo()


def test_the_hem_band_draw_splits_the_mesh_and_keeps_the_frame(gl, monkeypatch):
    split, counts, total = _frame(gl, monkeypatch, True)
    single, _, _ = _frame(gl, monkeypatch, False)
    assert counts is not None and all(c > 0 for c in counts) and sum(counts) == total
    assert counts[0] < 0.25 * total, f"the band's draw should be a small part of the mesh: {counts}"
    scale = float(np.abs(single).max())
    rel = np.abs(split - single) / np.maximum(np.abs(single), 1e-3 * scale)
    assert rel.max() < 1e-5, f"the split draw changed the frame by {rel.max():.2e} (relative)"
