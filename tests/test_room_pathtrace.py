"""The path tracer loads the room (catalog.pathtrace.scene with ``room``): the furnished
room's surfaces keep their albedo (the textured floor reads brown where it is lit), and a
bad ``--room`` is refused in one line before Mitsuba loads."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.core.errors import InputError


def test_reference_refuses_an_unknown_room():
    from catalog.pathtrace.render import reference_settings

    with pytest.raises(InputError, match="--room.*unknown room 'attic'"):
        reference_settings("lace-fwa", "D65", room="attic")


_LIVING_ROOM_RENDER = """
import json
import numpy as np
from catalog.optics.lights import get_light
from catalog.pathtrace.backend import load_mitsuba
from catalog.pathtrace.render import reference_settings, region_masks, render_radiance
from catalog.pathtrace.scene import build_mitsuba_scene, describe_scene
from catalog.presets import find_preset, load_preset

mi = load_mitsuba()
desc = describe_scene(reference_settings(load_preset(find_preset("lace-fwa")), get_light("D65"),
                                         pitch_deg=30.0, fluorescence="off", room="living"),
                      size=(64, 48))
floor = next(s for s in desc.room_surfaces if s.name == "floor")
scene = build_mitsuba_scene(mi, desc, max_depth=8)
pixels = render_radiance(mi, scene, spp=8)
masks = region_masks(mi, scene, desc)
print(json.dumps({"room": desc.info["room"], "textured": floor.texture is not None,
                  "floor_pixels": int(masks["floor"].sum()),
                  "floor_rgb": [float(v) for v in pixels[masks["floor"]].mean(axis=0)]}))
"""


@pytest.mark.slow
def test_living_room_renders_with_its_albedos():
    """In a process of its own: in the full suite, after many GL and Mitsuba tests in one
    process, this render once ended in a segmentation fault inside Mitsuba's kernel launch
    (not seen alone, nor after tests/test_pathtrace.py; cause not found). A separate process
    keeps such a crash from ending the rest of the suite, and still fails the test."""
    import json
    import subprocess
    import sys

    pytest.importorskip("mitsuba")
    result = subprocess.run([sys.executable, "-c", _LIVING_ROOM_RENDER], capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert report["room"] == "living" and report["textured"]
    assert report["floor_pixels"] > 50
    floor_rgb = report["floor_rgb"]
    # wood (linear ~ 0.55, 0.36, 0.20 x grain) under daylight: red > green > blue
    assert floor_rgb[0] > floor_rgb[1] > floor_rgb[2] > 0
