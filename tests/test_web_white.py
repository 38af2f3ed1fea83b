"""The web export's display white (issue 33): the export records its scenes dry (no pixels
drawn), so the white, measured from the frame's drawn HDR target, is measured with a real
frame first whenever its key changes (catalog.web.export.SiteExporter.record). Checked: the
recorded white-balance uniform of a sun scene equals the white a desktop frame of the same
size, cloth and camera measures (within 1e-6), and differs from the previous light's."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.slow
def test_recorded_white_is_measured_from_a_drawn_frame(gl):
    from catalog.presets import find_preset, load_preset
    from catalog.render.frame import FrameRenderer
    from catalog.render.settings import SunHour
    from catalog.render.snapshot import ring_xs_m, simulated_curtain
    from catalog.web import export

    preset = load_preset(find_preset("linen-dense"))
    positions, normals, uvs, tangents, indices, size = simulated_curtain(preset, 0)
    exporter = export.SiteExporter(gl)
    desktop = FrameRenderer(gl, export.RECORD_SIZE)
    try:
        exporter.use_mesh(positions, normals, uvs, tangents, indices)
        whites = {}
        for hour in (8.0, 15.0):
            choice = export.LightChoice(id=f"sun@{hour:g}", label="sun", kind="sun", hour=hour)
            exporter.record(exporter.scene(preset, choice), "on")
            whites[hour] = exporter.renderer.white_balance_matrix()
            export.configure_desktop_frame(desktop)
            desktop.update(fabric=preset, light=SunHour(hour), ev=exporter.renderer.ev100)
            desktop.set_mesh(positions, normals, uvs, tangents, indices)
            desktop.set_mesh_offset((0.0, 0.0, 0.0))
            desktop.render()
            np.testing.assert_allclose(whites[hour], desktop.white_balance_matrix(), atol=1e-6)
        assert np.abs(whites[8.0] - whites[15.0]).max() > 1e-3
    finally:
        desktop.release()
        exporter.release()
