"""FrameSettings: everything a user can change about a real-time frame, as one frozen value.

The edge (a command, the viewer, the web export, the batch) builds one :class:`FrameSettings`
and hands it to :class:`catalog.render.frame.FrameRenderer` (its constructor or
:meth:`~catalog.render.frame.FrameRenderer.update`); a change is a new value
(``dataclasses.replace(settings, bands=6)``, or ``renderer.update(bands=6)``, which is the
same). The renderer compares the new value with the old one field by field and redraws what
:data:`STALE` says the changed fields make stale; nothing else is redrawn.

Names are resolved once, when the value is made: a fabric name to its
:class:`catalog.presets.Preset` and its files to a :class:`catalog.presets.fabric.Fabric`, a light name to its :class:`catalog.optics.lights.Light`,
``SunHour(h)`` to the sun at that hour. A bad value raises :class:`SettingsError` (a
``ValueError`` and an ``InputError``: the CLI prints its one line and exits 2) naming the field.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from catalog.core.constants import FLUORESCENCE_MODES
from catalog.core.errors import CatalogError, InputError
from catalog.render import scene as scene_lib
from catalog.render import curtain_frames
from catalog.render.camera import OrbitCamera
from catalog.render.passes.shadow import SHADOW_MAP_SIZES
from catalog.render.passes.targets import ANTIALIASING_MODES
from catalog.room.model import Room


class SettingsError(InputError, ValueError):
    """A frame setting out of its range: ``FIELD: problem``."""


@dataclass(frozen=True)
class SunHour:
    """The scene's sun at ``hour`` (local mean solar time, SUN_DATE, SUN_LATITUDE) behind the
    window (:func:`catalog.render.scene.sun_at_hour`): the light and where it stands."""

    hour: float


def orbit(yaw_deg: float, pitch_deg: float, distance_m: float, target=None,
          fov_y_deg: float | None = None, inside: bool = False, placement=None) -> OrbitCamera:
    """The orbit camera (:class:`catalog.render.camera.OrbitCamera`) in the room of
    ``placement`` (catalog.render.placement; None: the box): ``target`` None looks at its
    curtain's middle; ``inside``: kept inside its interior (what every command asks for; the
    library also draws the room from outside)."""
    extra = {} if fov_y_deg is None else {"fov_y_deg": float(fov_y_deg)}
    if target is not None:
        extra["target"] = tuple(float(v) for v in target)
    elif placement is not None:
        extra["target"] = tuple(float(v) for v in placement.curtain_middle)
    bounds = (placement.interior if placement is not None else scene_lib.ROOM_BOX) if inside else None
    return OrbitCamera(yaw_deg=float(yaw_deg), pitch_deg=float(pitch_deg),
                       distance_m=float(distance_m), bounds=bounds, **extra)


def _refuse(name: str, problem) -> SettingsError:
    return SettingsError(str(problem), field=name)


@dataclass(frozen=True)
class FrameSettings:
    """What a user chooses for a frame. Every field has a default but the fabric and the
    light, which a frame needs before it draws (None: not chosen yet)."""

    #: a :class:`catalog.presets.Preset`, or a preset name / .toml path (resolved here)
    fabric: object = None
    #: a light name of the library (``D65``, ``sun:22``, ``sun@...``), a Light, or SunHour(h)
    light: object = None
    #: the key light's (elevation, azimuth) in deg (azimuth 0: straight behind the window,
    #: 180: behind the viewer); None: from the light (the sun's elevation or the lamp's)
    key_direction_deg: tuple | None = None
    #: the fluorescence variant requested (FLUORESCENCE_MODES)
    fluorescence: str = "physical"
    #: spectral bands of the curtain's shading (catalog.render.bands.BAND_COUNTS)
    bands: int = 3
    camera: OrbitCamera = field(default_factory=OrbitCamera)
    #: a multiplier on top of the EV (compensation)
    exposure: float = 1.0
    #: a fixed exposure (EV100, as a camera's); None: metered per frame (auto exposure)
    ev: float | None = None
    #: "room" (adapt to the light's white) or "camera" (fixed D65), catalog.render.display
    white_balance: str = "room"
    #: ANTIALIASING_MODES; ``auto``: FXAA on a CPU rasteriser, MSAA on a GPU that has it
    antialiasing: str = "auto"
    #: the fabric's pattern, holes and layers (OIT); False: the flat, opaque cloth of eq. 8
    patterned: bool = True
    #: light the room through the curtain (shadow map, area light, bounce) or the constant room
    room_lighting: bool = True
    #: the key's shadow on the cloth through two layers of its folds (False: the nearest
    #: alone, what the web page shows: catalog.web.export.DESKTOP_MODES)
    key_second_layer: bool = True
    #: the side (texels) of the key light's maps, SHADOW_MAP_SIZES
    shadow_map_size: int = curtain_frames.SHADOW_TEXELS
    #: drawn aside: the curtain is not drawn, casts nothing, lights nothing
    curtain_open: bool = False
    #: lamps in the room: (light name or Light, (x, y, z) m) pairs, at most MAX_ROOM_LAMPS;
    #: each an isotropic point whose normal irradiance at 1 m is the light's spectrum
    lamps: tuple = ()
    #: the clear sky by direction (catalog/optics/sun/sky.py) or the flat sky and ground
    sky_model: bool = True
    #: an HDR latitude-longitude image (path) as the view behind the window; None: the sky
    environment: object = None
    #: glare before the tone map (energy-preserving, bloom.frag)
    bloom: bool = True
    #: while the cloth moves, the room's light is redrawn every this many frames
    room_update_every: int = 1
    #: the room drawn and lit by its precomputed transport: a built-in name (catalog.room),
    #: a .glb path, or the loaded catalog.room.model.Room (what the path tracer needs: the
    #: edge resolves it, catalog.pathtrace.render.reference_settings); None: the built-in
    #: box. Compared by :attr:`room_spec`.
    room: object = "box"

    # resolved from the fields above when the value is made (not compared, not replaced):
    # the fabric's tables (catalog.presets.fabric.Fabric: dye, fluorescence, residual, pattern),
    # the key light, its direction (unit, to the light) and the sun at the hour asked
    resolved_fabric: object = field(init=False, compare=False, repr=False, default=None)
    #: the environment image: (linear RGB float32 (H, W, 3), row 0 = zenith; its upper
    #: hemisphere's horizontal illuminance), or None
    resolved_environment: tuple | None = field(init=False, compare=False, repr=False, default=None)
    key_light: object = field(init=False, compare=False, repr=False, default=None)
    key_to_light: np.ndarray = field(init=False, compare=False, repr=False, default=None)
    sun: object = field(init=False, compare=False, repr=False, default=None)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "fabric", _resolve_fabric(self.fabric))
        if self.fabric is not None:
            from catalog.presets.fabric import resolve_fabric  # noqa: PLC0415

            set_(self, "resolved_fabric", resolve_fabric(self.fabric))   # every file read here
        key_light, sun, elevation_azimuth = _resolve_light(self.light)
        if isinstance(self.light, str):
            set_(self, "light", key_light)
        if self.key_direction_deg is not None:
            try:
                elevation_azimuth = tuple(float(v) for v in self.key_direction_deg)
            except (TypeError, ValueError):
                elevation_azimuth = ()
            if len(elevation_azimuth) != 2 or not all(map(math.isfinite, elevation_azimuth)):
                raise _refuse("key_direction_deg", f"{self.key_direction_deg!r}: give "
                              "(elevation, azimuth) in deg, finite")
            set_(self, "key_direction_deg", elevation_azimuth)
        set_(self, "key_light", key_light)
        set_(self, "sun", sun)
        set_(self, "key_to_light", scene_lib.key_direction(*elevation_azimuth))
        self._check_choices()
        set_(self, "lamps", _resolve_lamps(self.lamps, self.room))

    def _check_choices(self) -> None:
        from catalog.render import bands as band_lib, display as display_lib  # noqa: PLC0415

        choose = {"fluorescence": FLUORESCENCE_MODES, "white_balance": display_lib.WHITE_BALANCES,
                  "antialiasing": ANTIALIASING_MODES, "shadow_map_size": SHADOW_MAP_SIZES}
        for name, choices in choose.items():
            if getattr(self, name) not in choices:
                raise _refuse(name, f"{getattr(self, name)!r}: choose one of "
                              f"{', '.join(map(str, choices))}")
        object.__setattr__(self, "shadow_map_size", int(self.shadow_map_size))
        try:
            object.__setattr__(self, "bands", band_lib.check_band_count(self.bands))
            if self.ev is not None:
                object.__setattr__(self, "ev", display_lib.check_ev(self.ev))
        except CatalogError as exc:
            raise _refuse("bands" if "--bands" in str(exc) else "ev", exc) from None
        if not (isinstance(self.exposure, (int, float)) and math.isfinite(self.exposure)
                and self.exposure > 0):
            raise _refuse("exposure", f"{self.exposure!r} must be a positive number")
        object.__setattr__(self, "exposure", float(self.exposure))
        if not isinstance(self.camera, OrbitCamera):
            raise _refuse("camera", f"{self.camera!r} is not an OrbitCamera (see settings.orbit)")
        if not (isinstance(self.room_update_every, int) and self.room_update_every >= 1):
            raise _refuse("room_update_every", f"{self.room_update_every!r} must be an integer >= 1")
        for name in ("patterned", "room_lighting", "key_second_layer", "curtain_open",
                     "sky_model", "bloom"):
            value = getattr(self, name)
            if not isinstance(value, (bool, np.bool_)):
                raise _refuse(name, f"{value!r} must be True or False")
            object.__setattr__(self, name, bool(value))
        if self.room is None:
            object.__setattr__(self, "room", "box")
        if not isinstance(self.room, Room):
            if not isinstance(self.room, str) and not hasattr(self.room, "__fspath__"):
                raise _refuse("room", f"{self.room!r}: give a built-in room name, a .glb path "
                              "or a loaded Room")
            object.__setattr__(self, "room", str(self.room))
        if self.environment is not None:
            object.__setattr__(self, "environment", str(self.environment))
            object.__setattr__(self, "resolved_environment", _environment(self.environment))

    def replace(self, **changes) -> "FrameSettings":
        """``dataclasses.replace(self, **changes)``."""
        return dataclasses.replace(self, **changes)

    @property
    def room_spec(self) -> str | None:
        """The room as the frame's transport names it: a built-in name or a .glb path (a
        loaded Room by its name when built in, else by its file), or None."""
        if not isinstance(self.room, Room):
            return self.room
        from pathlib import Path  # noqa: PLC0415

        from catalog.room.load import BUILTIN_ROOMS, room_path  # noqa: PLC0415

        builtin = self.room.name in BUILTIN_ROOMS and Path(self.room.source) == room_path(self.room.name)
        return self.room.name if builtin else self.room.source

    @property
    def resolved_room(self):
        """The loaded :class:`catalog.room.model.Room` when the edge gave one, else None."""
        return self.room if isinstance(self.room, Room) else None

    def viewer_inside(self, placement=None) -> bool:
        """Whether the camera stands in the room: in front of the plane of the window of
        ``placement`` (catalog.render.placement, the drawn room's; None: the box's)."""
        window_z = scene_lib.WINDOW_Z if placement is None else placement.window_z
        return bool(self.camera.position[2] > window_z)

    def shading_inputs(self, placement=None):
        """(the scene's :class:`catalog.optics.shading_reference.ShadingInputs`, the
        fluorescence decision) for this value's fabric, key light and direction, mode and
        side of the window (of ``placement``, the drawn room's: :meth:`viewer_inside`): what
        the real-time frame (passes/scene_terms.py) and the path tracer
        (catalog.pathtrace.scene.describe_scene) both shade with. No file is read."""
        light = self.key_light
        if self.fabric is None or light is None:
            raise CatalogError("no fabric or no light: the scene is not complete")
        # a ``sun:PATH_KM`` light is the paper's beam, whose sky and ground are that beam
        # Rayleigh-scattered (paper_beam)
        return scene_lib.build_shading_inputs(
            self.fabric, light.irradiance_w_m2_nm, self.key_to_light, is_sun=light.is_sun,
            fluorescence=self.fluorescence, viewer_inside=self.viewer_inside(placement),
            paper_beam=light.sun is not None and light.sun.model == "paper")

    @property
    def sun_hour(self) -> dict | None:
        """With ``light=SunHour(h)``: the hour, the sun's zenith (deg), path (km) and light name."""
        if self.sun is None:
            return None
        return {"hour": self.sun.hour, "zenith_deg": self.sun.zenith_deg,
                "path_km": self.sun.path_km, "light": self.sun.light_name}


def _resolve_fabric(fabric):
    from catalog.presets import Preset, find_preset, load_preset  # noqa: PLC0415

    if fabric is None or isinstance(fabric, Preset):
        return fabric
    if not isinstance(fabric, (str, bytes)) and not hasattr(fabric, "__fspath__"):
        raise _refuse("fabric", f"{fabric!r}: give a Preset, a preset name or a .toml path")
    return load_preset(find_preset(fabric))


def _resolve_light(light):
    """(the key Light or None, the SunAtHour or None, the key's (elevation, azimuth) deg)."""
    from catalog.optics.lights import Light, get_light  # noqa: PLC0415

    if light is None:
        return None, None, (scene_lib.LAMP_ELEVATION_DEG, scene_lib.KEY_AZIMUTH_DEG)
    if isinstance(light, SunHour):
        try:
            hour = float(light.hour)
        except (TypeError, ValueError) as exc:
            raise _refuse("light", f"SunHour({light.hour!r}): {exc}") from None
        return _sun_at(hour)
    if isinstance(light, str):
        light = get_light(light)
    if not isinstance(light, Light):
        raise _refuse("light", f"{light!r}: give a light name, a Light or SunHour(hour)")
    return light, None, (scene_lib.key_elevation_for(light), scene_lib.KEY_AZIMUTH_DEG)


@functools.lru_cache(maxsize=64)
def _sun_at(hour: float) -> tuple:
    """SunHour(hour) resolved once (a value replaced keeps its sun: the web export draws
    each hour's scene with eight switches): (its Light, the SunAtHour, (elevation, azimuth))."""
    from catalog.optics.lights import get_light  # noqa: PLC0415

    try:
        sun = scene_lib.sun_at_hour(hour)
    except (TypeError, ValueError) as exc:
        raise _refuse("light", f"SunHour({hour!r}): {exc}") from None
    except InputError as exc:   # the hour's own field (--hour), as the CLI names it
        raise SettingsError(exc.problem, field=exc.field or "light") from None
    return get_light(sun.light_name), sun, (90.0 - sun.zenith_deg, sun.azimuth_deg)


def _environment(path: str) -> tuple:
    """The image at ``path`` read once while it is unchanged (its size and time as the key)."""
    import os  # noqa: PLC0415

    try:
        stat = os.stat(path)
        stamp = (stat.st_size, stat.st_mtime_ns)
    except OSError:
        stamp = None   # load_environment names the missing file
    return _environment_read(path, stamp)


@functools.lru_cache(maxsize=2)
def _environment_read(path: str, _stamp) -> tuple:
    from catalog.render import environment as env  # noqa: PLC0415

    pixels = env.load_environment(path)
    pixels.setflags(write=False)
    return pixels, env.upper_illuminance(pixels)


def _resolve_lamps(lamps, room) -> tuple:
    """(Light, (x, y, z) m) pairs, each inside the interior of ``room`` where it is a loaded
    Room (the path tracer's, catalog.render.placement); a named room's lamps are checked by
    the frame that draws it (FrameRenderer.update)."""
    from catalog.optics.lights import get_light  # noqa: PLC0415

    try:
        lamps = tuple(lamps)
    except TypeError:
        raise _refuse("lamps", f"{lamps!r}: give (light, (x, y, z) m) pairs") from None
    if len(lamps) > curtain_frames.MAX_ROOM_LAMPS:
        raise _refuse("lamps", f"at most {curtain_frames.MAX_ROOM_LAMPS} room lamps, got {len(lamps)}")
    interior = None
    if lamps and isinstance(room, Room):
        from catalog.render.placement import placement_of_room  # noqa: PLC0415

        interior = placement_of_room(room).interior
    resolved = []
    for lamp in lamps:
        try:
            light, position = lamp
            resolved.append((get_light(light) if isinstance(light, str) else light,
                             curtain_frames.check_lamp_position(position, interior)))
        except InputError:
            raise
        except (CatalogError, TypeError, ValueError) as exc:
            raise _refuse("lamps", exc) from None
    return tuple(resolved)


def _same(a, b) -> bool:
    if a is b:
        return True
    try:
        return bool(a == b)
    except (ValueError, TypeError):   # arrays inside
        return False


def changed(old: FrameSettings, new: FrameSettings) -> frozenset[str]:
    """The names of the fields whose values differ (objects such as a Preset or a Light by
    identity or equality, lamps by name and position)."""
    names = set()
    for f in dataclasses.fields(FrameSettings):
        if not f.init:
            continue
        a, b = getattr(old, f.name), getattr(new, f.name)
        if f.name == "lamps":
            a = tuple((id(light), position) for light, position in a)
            b = tuple((id(light), position) for light, position in b)
        elif f.name == "room":
            a, b = old.room_spec, new.room_spec
        elif f.name == "light":
            a, b = (old.key_light, tuple(old.key_to_light)), (new.key_light, tuple(new.key_to_light))
        if not _same(a, b):
            names.add(f.name)
    return frozenset(names)


#: What changed -> what is stale. The renderer (FrameRenderer.update) acts on each name:
#:   fabric_tables  the fabric's pattern uploaded (PatternTexture); its files were read when
#:                  the settings were made (resolved_fabric), none is read here
#:   scene_terms    the shading inputs (SceneTerms, keyed on fabric, light, key, mode, the
#:                  viewer's side of the window) and what follows them: the curtain's uniforms
#:                  or specialised program, the background's sky
#:   room_light     the room's light (the key's maps, the room transport's update) at the next frame
#:   room_transport the room's precomputed transport loaded (or dropped), then room_light
#:   room_targets   the key light's maps reallocated at the new size (then room_light)
#:   msaa_targets   the anti-aliasing mode resolved again; multisampled targets freed if unused
#:   environment    the environment image loaded (or freed), then room_light (the window's views see it)
#:   view           nothing cached: the next frame's view-projection
#:   display        the display pass's uniforms (exposure, white balance)
#:   glare          whether the glare pass runs
STALE: dict[str, tuple[str, ...]] = {
    "fabric": ("fabric_tables", "scene_terms", "room_light"),
    "light": ("scene_terms", "room_light"),
    "key_direction_deg": ("scene_terms", "room_light"),
    "fluorescence": ("scene_terms", "room_light"),
    "bands": ("scene_terms",),
    "camera": ("view",),   # scene_terms and room_light follow when the viewer crosses the window
    "exposure": ("display",),
    "ev": ("display",),
    "white_balance": ("display",),
    "antialiasing": ("msaa_targets",),
    "patterned": ("room_light",),
    "room_lighting": ("room_light",),
    "key_second_layer": ("room_light",),
    "shadow_map_size": ("room_targets", "room_light"),
    "curtain_open": ("room_light",),
    "lamps": ("room_light",),
    "sky_model": ("room_light",),
    "environment": ("environment", "room_light"),
    "bloom": ("glare",),
    "room_update_every": (),
    "room": ("room_transport", "room_light"),
}


def stale(old: FrameSettings, new: FrameSettings) -> frozenset[str]:
    """What :data:`STALE` says the fields changed from ``old`` to ``new`` make stale."""
    return frozenset(part for name in changed(old, new) for part in STALE[name])
