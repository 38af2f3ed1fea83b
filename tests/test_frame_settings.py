"""FrameSettings (catalog/render/settings.py): one frozen, validated value of what a user
chooses for a frame, and the table of what a change makes stale."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from catalog.core.errors import CatalogError
from catalog.render import scene as scene_lib
from catalog.render import settings as settings_lib
from catalog.render.settings import FrameSettings, SettingsError, SunHour, orbit

BAD = {
    "fluorescence": "bright", "bands": 5, "exposure": 0.0, "ev": 99.0, "white_balance": "warm",
    "antialiasing": "ssaa", "shadow_map_size": 300, "lamps": [("A", (9.0, 9.0))],
    "patterned": "no", "room_lighting": None, "bloom": 2, "camera": (0.0, 0.0, 2.6),
    "room_update_every": 0, "key_direction_deg": (10.0,), "light": 5, "fabric": 3.0,
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_a_bad_value_names_its_field(name):
    """Each bad value raises one SettingsError (a ValueError and a CatalogError: the CLI's
    exit 2) whose message starts with the field's name."""
    with pytest.raises(SettingsError) as caught:
        FrameSettings(**{name: BAD[name]})
    assert isinstance(caught.value, ValueError) and isinstance(caught.value, CatalogError)
    assert str(caught.value).startswith(f"{name}: ")
    assert "\n" not in str(caught.value)


def test_too_many_lamps_is_refused():
    with pytest.raises(SettingsError, match="^lamps: at most"):
        FrameSettings(lamps=[("A", (0.5, 0.3, 1.5))] * 5)


def test_the_value_is_frozen_and_replaced():
    s = FrameSettings(light="D65")
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.bands = 6
    t = s.replace(bands=6)
    assert (s.bands, t.bands) == (3, 6) and t.key_light is s.key_light


def test_names_are_resolved_once():
    """A light name becomes its Light; SunHour(h) the sun at that hour and its direction
    (scene.sun_at_hour); a lamp's light name its Light; a key direction overrides the light's."""
    s = FrameSettings(light="D65", lamps=[("A", [0.5, 0.3, 1.5])])
    assert s.light.name == "D65" and s.key_light is s.light
    assert s.lamps[0][0].name == "A" and s.lamps[0][1] == (0.5, 0.3, 1.5)
    assert np.allclose(s.key_to_light, scene_lib.key_direction(scene_lib.LAMP_ELEVATION_DEG))
    sun = scene_lib.sun_at_hour(9.0)
    h = s.replace(light=SunHour(9.0))
    assert h.key_light.name == sun.light_name and h.key_light.is_sun
    assert h.sun_hour == {"hour": 9.0, "zenith_deg": sun.zenith_deg, "path_km": sun.path_km,
                          "light": sun.light_name}
    assert np.allclose(h.key_to_light, scene_lib.key_direction(90.0 - sun.zenith_deg, sun.azimuth_deg))
    assert s.sun_hour is None
    k = s.replace(key_direction_deg=(30, 180))
    assert k.key_direction_deg == (30.0, 180.0)
    assert np.allclose(k.key_to_light, scene_lib.key_direction(30.0, 180.0))
    with pytest.raises(SettingsError, match="^--hour: the sun is below the horizon"):
        s.replace(light=SunHour(23.5))   # named as the command line names it


def test_every_field_has_its_row_in_the_stale_table():
    fields = {f.name for f in dataclasses.fields(FrameSettings) if f.init}
    assert set(settings_lib.STALE) == fields


@pytest.mark.parametrize("change, expected", [
    ({"bloom": False}, {"glare"}),
    ({"ev": 9.0}, {"display"}),
    ({"white_balance": "camera"}, {"display"}),
    ({"camera": orbit(10.0, 5.0, 2.0)}, {"view"}),
    ({"bands": 6}, {"scene_terms"}),
    ({"light": "A"}, {"scene_terms", "room_light"}),
    ({"key_direction_deg": (30.0, 0.0)}, {"scene_terms", "room_light"}),
    ({"lamps": [("A", (0.5, 0.3, 1.5))]}, {"room_light"}),
    ({"shadow_map_size": 512}, {"room_targets", "room_light"}),
    ({"antialiasing": "off"}, {"msaa_targets"}),
])
def test_what_a_change_makes_stale(change, expected):
    """Only the parts STALE names for the changed fields; an unchanged value nothing."""
    s = FrameSettings(light="D65")
    assert settings_lib.stale(s, s.replace(**change)) == expected
    assert settings_lib.stale(s, s.replace()) == frozenset()
    assert settings_lib.stale(s, FrameSettings(light=s.light)) == frozenset()


def test_the_same_sun_hour_again_is_no_change():
    s = FrameSettings(light=SunHour(10.0))
    assert settings_lib.changed(s, s.replace(light=SunHour(10.0))) <= {"light"}
    assert settings_lib.changed(s, s.replace(light=SunHour(11.0))) == {"light"}


def test_a_missing_environment_is_refused_when_the_value_is_made(tmp_path):
    with pytest.raises(CatalogError, match="environment image not found"):
        FrameSettings(environment=tmp_path / "missing.exr")


@pytest.fixture
def no_file_reads(monkeypatch):
    """Any open() or Path read from here on fails the test."""
    import builtins
    import io
    from pathlib import Path

    def refuse(*args, **kwargs):
        raise AssertionError(f"a file was read below the edge: {args[:1]}")

    for owner, name in ((builtins, "open"), (io, "open"), (Path, "open"), (Path, "read_text"),
                        (Path, "read_bytes"), (np, "load"), (np, "loadtxt")):
        monkeypatch.setattr(owner, name, refuse)


def _fluorescent_fabric():
    from catalog.presets import find_preset, load_preset

    return load_preset(find_preset("lace-fwa"))


@pytest.mark.slow
def test_the_fabric_is_resolved_once_at_the_edge(request):
    """FrameSettings resolves the fabric's files (catalog.presets.fabric.Fabric: dye,
    fluorescence spectra, pattern); what the frame derives from it afterwards, under any light
    and fluorescence mode, reads no file."""
    from catalog.optics.lights import get_light
    from catalog.presets.fabric import Fabric, resolve_fabric

    preset = _fluorescent_fabric()
    s = FrameSettings(fabric=preset, light="D65")
    assert isinstance(s.resolved_fabric, Fabric) and s.resolved_fabric.preset is preset
    assert resolve_fabric(preset) is s.resolved_fabric
    assert s.resolved_fabric.fluorescent_materials and s.resolved_fabric.pattern is not None
    assert s.resolved_fabric.dye_transmittance.shape == scene_lib.GRID_NM.shape
    uva = get_light("UV-A")
    request.getfixturevalue("no_file_reads")
    for mode in ("off", "paper", "physical"):
        for light in (s.key_light, uva):
            inputs, _ = scene_lib.build_shading_inputs(
                s.fabric, light.irradiance_w_m2_nm, s.key_to_light, is_sun=False,
                fluorescence=mode, viewer_inside=True)
            assert np.all(np.isfinite(inputs.key_irradiance))
    assert s.replace(light=SunHour(10.0), bands=6).resolved_fabric is s.resolved_fabric


def test_the_no_read_fixture_sees_a_read(request):
    """The check above can fail: reading a fabric's spectrum under it is refused."""
    from catalog.optics.spectra import read_spectrum

    preset = _fluorescent_fabric()
    request.getfixturevalue("no_file_reads")
    with pytest.raises(AssertionError, match="below the edge"):
        read_spectrum(preset.fluorescence.emission)


@pytest.mark.slow
def test_the_renderer_redraws_what_the_table_says(gl):
    """FrameRenderer.update acts on settings.STALE: after a frame, a change of the glare or
    the exposure leaves the room's light as it is (LightmapPass.stale false) and the frame
    as it was where nothing changed; a lamp or the curtain makes the room's light stale; the
    frame's read-only views follow the value; a bad value leaves the renderer's settings."""
    from catalog.render.frame import FrameRenderer

    settings = FrameSettings(fabric="voile-white", light="D65", ev=10.0, antialiasing="off",
                             camera=orbit(20.0, 15.0, 2.6, inside=True))
    r = FrameRenderer(gl, (64, 36), settings)
    try:
        r.render()
        first = r.read_linear()
        assert r.update(bloom=False) == {"glare"}
        assert not r.schedule.stale()
        assert r.update(ev=11.0) == {"display"} and r.ev100 == 11.0
        r.render()
        assert np.array_equal(r.read_linear(), first)   # the HDR frame: untouched by either
        assert r.update(lamps=[("A", (0.5, 0.3, 1.5))]) == {"room_light"}
        assert r.schedule.stale()
        r.render()
        assert not r.schedule.stale()
        assert r.update(curtain_open=True) == {"room_light"} and r.curtain_open
        before = r.settings
        with pytest.raises(SettingsError, match="^bands: "):
            r.update(bands=7)
        assert r.settings is before
        with pytest.raises(SettingsError, match="^lamps: .* must lie inside the room"):
            r.update(lamps=[("A", (0.5, 0.3, 9.0))])   # behind the box's back wall (z 4.5 m)
        assert r.settings is before
        assert r.update(before) == frozenset()
    finally:
        r.release()


@pytest.mark.slow   # loads the bedroom's glTF (0.8 s at a load of 2.5 on 2 cores)
def test_a_lamp_is_checked_against_its_own_rooms_interior():
    """The bedroom is shorter than the box (z to 3.6 m against 4.5) and wider (x to 2.3 m):
    a lamp is refused or taken by the loaded room's interior, not the box's."""
    from catalog.room.load import load_room

    bedroom = load_room("bedroom")
    FrameSettings(room=bedroom, lamps=[("A", (2.25, 0.3, 1.5))])          # outside the box, inside the bedroom
    FrameSettings(lamps=[("A", (0.5, 0.3, 4.0))])                         # a named room: the frame checks it
    with pytest.raises(SettingsError, match="^lamps: .* must lie inside the room x -1.8..2.3"):
        FrameSettings(room=bedroom, lamps=[("A", (0.5, 0.3, 4.0))])
    with pytest.raises(SettingsError, match="^lamps: .*give \\(x, y, z\\) in m, finite"):
        FrameSettings(lamps=[("A", (0.5, float("nan"), 1.0))])
