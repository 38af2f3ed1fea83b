"""The display's white follows the room's lamps (catalog.render.passes.display): a lamp lights
what the viewer sees, so switching one measures the white again, and the web export, which
records every lamp variant of a scene in turn, gets each variant's own white."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = [pytest.mark.gl, pytest.mark.slow]


def test_white_is_measured_again_when_a_lamp_is_switched(gl):
    from catalog.render.frame import FrameRenderer
    from catalog.web.export import room_lamps

    r = FrameRenderer(gl, (48, 32))
    try:
        r.update(fabric="fluoro-pink", light="D65")
        r.update(room_lighting=True)   # the desktop frame: the lamps light the room it sees
        whites = {}
        for lamp in ("none", "A", "LED-B4", "none"):
            r.update(lamps=room_lamps(lamp))
            r.render()
            whites.setdefault(lamp, []).append(np.array(r.white_balance_matrix()))
        # the incandescent lamp's red light is taken out: less red kept than without a lamp
        assert whites["A"][0][0, 0] < whites["none"][0][0, 0] - 1e-3
        assert np.abs(whites["A"][0] - whites["LED-B4"][0]).max() > 1e-3
        np.testing.assert_allclose(whites["none"][1], whites["none"][0], atol=1e-9)  # back again
    finally:
        r.release()
