"""One resolved scene value (issue 31): the FrameSettings the real-time frame draws is the
value the path tracer describes; the reference and the snapshot build it alike."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from catalog.core.errors import CatalogError

#: The fields that make the scene (what the path tracer draws of a FrameSettings).
SCENE_FIELDS = {"fabric", "light", "key_direction_deg", "fluorescence", "camera", "room"}



def _assert_same_inputs(ours, theirs) -> None:
    """Every field of two ShadingInputs equal (names and modes as such, arrays exactly)."""
    for f in dataclasses.fields(ours):
        a, b = getattr(ours, f.name), getattr(theirs, f.name)
        if isinstance(a, (str, type(None))):
            assert a == b, f.name
        else:
            np.testing.assert_array_equal(np.asarray(a, dtype=float), np.asarray(b, dtype=float),
                                          err_msg=f.name)

def _curtain():
    from catalog.render import scene as scene_lib

    d = scene_lib.draped_curtain(12, 8)
    return (d.positions, d.normals, d.uvs, d.tangents, d.indices)


@pytest.mark.slow   # ~2 s: the living room loaded and leak-checked
def test_reference_and_snapshot_of_the_same_arguments_build_the_same_scene(tmp_path):
    """`catalog reference`'s value and `catalog snapshot --view fabric`'s (the reference's
    composition) of the same fabric, light, camera and room differ in no scene field; a
    different yaw or room is seen."""
    from catalog.optics.lights import get_light
    from catalog.pathtrace.render import reference_settings
    from catalog.render import settings as settings_lib
    from catalog.render.snapshot import SnapshotRequest, snapshot_settings, validate
    from catalog.render.views import view_named

    view = view_named("fabric")
    request = SnapshotRequest(fabric="lace-fwa", light="D65", size=(32, 24),
                              out=tmp_path / "a.png", yaw_deg=20.0, pitch_deg=10.0,
                              distance_m=2.6, target=view.target, fov_y_deg=view.fov_y_deg,
                              fluorescence="paper", room="living")
    preset, light = validate(request)
    snapshot = snapshot_settings(request, preset, light)
    reference = reference_settings("lace-fwa", "D65", yaw_deg=20.0, pitch_deg=10.0,
                                   distance_m=2.6, fluorescence="paper", room="living",
                                   inside=True)
    assert settings_lib.changed(snapshot, reference) & SCENE_FIELDS == set()
    assert reference.resolved_room.name == "living" and snapshot.resolved_room is None
    assert reference.room_spec == snapshot.room_spec == "living"
    np.testing.assert_array_equal(reference.camera.position, snapshot.camera.position)
    assert reference.key_light is get_light("D65")
    other = reference_settings("lace-fwa", "D65", yaw_deg=25.0, pitch_deg=10.0,
                               distance_m=2.6, fluorescence="paper", room="box", inside=True)
    assert settings_lib.changed(snapshot, other) & SCENE_FIELDS == {"camera", "room"}


@pytest.mark.parametrize("light", ["D65", "hour9"])
def test_describe_scene_draws_the_settings_value(light):
    """describe_scene takes the frame's value: its key direction (here turned by the user, or
    the sun at 9 h), camera, room and fabric tables are the ones the description holds, and
    its shading inputs are the value's own (FrameSettings.shading_inputs, which the frame's
    scene terms take) field for field."""
    from catalog.pathtrace.render import reference_settings
    from catalog.pathtrace.scene import describe_scene
    from catalog.render.settings import SunHour

    extra = {"key_direction_deg": (35.0, 20.0)} if light == "D65" else {}
    settings = reference_settings("voile-white", SunHour(9.0) if light == "hour9" else light,
                                  yaw_deg=15.0, pitch_deg=5.0, distance_m=1.8, inside=True,
                                  **extra)
    desc = describe_scene(settings, size=(8, 6), curtain=_curtain())
    np.testing.assert_array_equal(desc.key_to_light, settings.key_to_light)
    if light == "hour9":
        elevation = np.degrees(np.arcsin(settings.key_to_light[1]))
        assert elevation == pytest.approx(90.0 - settings.sun.zenith_deg, abs=1e-9)
        assert desc.info["light"] == settings.sun.light_name
    else:
        assert np.degrees(np.arcsin(desc.key_to_light[1])) == pytest.approx(35.0, abs=1e-9)
    np.testing.assert_array_equal(desc.camera_position, settings.camera.position)
    np.testing.assert_array_equal(desc.camera_target, np.asarray(settings.camera.target))
    assert desc.fov_y_deg == settings.camera.fov_y_deg
    assert desc.room_surfaces == tuple(settings.room.surfaces)
    assert desc.info["room"] == settings.room.name == "box"
    assert desc.info["fabric"] == settings.fabric.name
    inputs, _ = settings.shading_inputs()
    _assert_same_inputs(inputs, desc.inputs)


def test_describe_scene_takes_a_resolved_room_only():
    """A room name is resolved at the edge (reference_settings), never by describe_scene."""
    from catalog.pathtrace.scene import describe_scene
    from catalog.render.settings import FrameSettings

    named = FrameSettings(fabric="voile-white", light="D65", room="box")
    with pytest.raises(CatalogError, match="resolved room"):
        describe_scene(named, size=(8, 6), curtain=_curtain())


@pytest.mark.gl
@pytest.mark.slow
def test_the_frame_and_the_path_tracer_draw_one_value(gl):
    """The frame made from the reference's value (its room drawn by the box's light here:
    the transport's bundle is no part of the shading) shades with the inputs the path
    tracer's description holds, from the same camera and key."""
    from catalog.pathtrace.render import reference_settings
    from catalog.pathtrace.scene import describe_scene
    from catalog.render.frame import FrameRenderer

    settings = reference_settings("lace-fwa", "sun:22", yaw_deg=-10.0, distance_m=2.0, inside=True)
    desc = describe_scene(settings, size=(8, 6), curtain=_curtain())
    r = FrameRenderer(gl, (8, 6), settings.replace(room=None))
    try:
        np.testing.assert_array_equal(r.camera.position, desc.camera_position)
        np.testing.assert_array_equal(r.shading_inputs().key_to_light, desc.key_to_light)
        _assert_same_inputs(r.shading_inputs(), desc.inputs)
    finally:
        r.release()


@pytest.mark.gl
@pytest.mark.slow
def test_a_web_scene_is_resolved_once_and_drawn_with_each_switch(gl, monkeypatch):
    """The web export makes one value per fabric and light (SiteExporter.scene); recording
    its switches resolves no name again (the light library and the preset reader patched
    to fail) and both frames draw that value's own fabric and key light, differing from it
    only in the switches, the exposure and the recording frame's camera."""
    from catalog.optics import lights
    from catalog.presets import fabric as fabric_lib
    from catalog.render import settings as settings_lib
    from catalog.render import scene as scene_lib
    from catalog.web import export

    exporter = export.SiteExporter(gl)
    try:
        d = scene_lib.draped_curtain(12, 8)
        exporter.use_mesh(d.positions, d.normals, d.uvs, d.tangents, d.indices)
        choice = export.LightChoice(id="sun@10", label="sun at 10 h", kind="sun", hour=10.0)
        scene = exporter.scene(settings_lib.FrameSettings(fabric="voile-white").fabric, choice)

        def refuse(*args, **kw):
            raise AssertionError("a name resolved again while recording")

        monkeypatch.setattr(lights, "get_light", refuse)
        monkeypatch.setattr(fabric_lib, "_dye", refuse)
        metered = exporter.record(scene, "on")
        exporter.record(scene, "off", ev100=metered["ev100"], glare="on")
        for frame in (exporter.meter, exporter.renderer):
            assert frame.settings.fabric is scene.fabric
            assert frame.settings.resolved_fabric is scene.resolved_fabric
            np.testing.assert_array_equal(frame.settings.key_to_light, scene.key_to_light)
        assert exporter.renderer.settings.ev == pytest.approx(metered["ev100"])
        assert settings_lib.changed(scene, exporter.renderer.settings) == {"fluorescence", "bloom", "ev"}
        assert settings_lib.changed(scene, exporter.meter.settings) == set()
    finally:
        exporter.release()
