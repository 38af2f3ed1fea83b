"""Device diagnostic (not committed): the default program against the float64 reference."""
import numpy as np
import pytest

from catalog.optics import shading_reference as ref
from catalog.render.frame import FrameRenderer
from test_render_frame import SIZE, _relative_error

pytestmark = pytest.mark.gl


@pytest.mark.parametrize("light,mode", [("sun:200", "physical"), ("D65", "physical"), ("sun:200", "off"), ("sun:200", "paper")])
def test_diag(gl, make_preset, light, mode, capsys):
    renderer = FrameRenderer(gl, SIZE)
    renderer.set_fabric(make_preset())
    renderer.set_light(light)
    renderer.set_fluorescence(mode)
    renderer.set_bands(3)
    renderer.set_camera(yaw_deg=20.0, pitch_deg=-10.0, distance_m=2.2)
    g = renderer.render_gbuffer()
    mask = g["mask"]
    reference = ref.reference_linear_srgb(renderer.shading_inputs(), g["position"][mask], g["normal"][mask],
                                          g["tangent"][mask], renderer.camera.position)
    err = _relative_error(g["radiance"][mask].astype(np.float64), reference)
    with capsys.disabled():
        print(f"\nDIAG specialise={renderer.specialise} {light} {mode}: max {err.max():.3e} p99 {np.percentile(err, 99):.3e} median {np.median(err):.3e}")
    renderer.release()
