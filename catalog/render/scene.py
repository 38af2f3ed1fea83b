"""The scene: a curtain hanging in a window, the sun (or a lamp) behind it, a room around
the viewer; and the spectral description of its light (:class:`catalog.optics.shading_reference.ShadingInputs`).

Coordinates: metres, y up; the window is in the wall z = WINDOW_Z, the outside lies towards
-z, the room (and the viewer) towards +z. No GL here: meshes are numpy arrays and the
renderer uploads them. The room's boxes and rod are built in numpy (importing trimesh would
import scipy, which drawing a frame must not); prop files load through trimesh on demand.

Lighting model (the numbers are scene design, stated once here; the physics is eq. 5-8):

- key: the light the user picks, as a distant source behind the window (the sun's disc
  size, 0.2666 deg), normal irradiance = the light's spectrum;
- sky: for the sun, the clear sky of the same atmosphere (:func:`outside_radiances`,
  catalog/optics/sun/sky.py for its distribution over directions); for a lamp, outside above the
  horizon, radiance SKY_FRACTION E / pi (a lit backdrop); ground below: albedo
  GROUND_ALBEDO under the key light's horizontal irradiance;
- fill: the light bounced into the room, a directional light on the viewer's side with
  FILL_FRACTION of the key's spectrum (so a front-lit curtain is not black);
- room: grey walls of albedo ROOM_ALBEDO under ROOM_FRACTION of the key;
- ambient: the cloth's radiance under the sky/ground behind it and the room in front,
  through eq. 7's lobes integrated over each hemisphere (:func:`catalog.optics.shading_reference.hg_hemisphere_factors`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from catalog.core.errors import CatalogError, InputError
from catalog.optics.shading_reference import (ShadingInputs, ambient_view_ratios, hg_hemisphere_factors,
                                              outside_sky_share)
from catalog.optics.spectra import GRID_NM

WINDOW_Z = -0.2
#: Window opening in the wall (x from, x to, y from, y to), metres.
WINDOW_RECT = (-0.95, 0.95, -0.9, 1.35)
#: The room box (x, y, z extents), metres.
ROOM_BOX = ((-2.2, 2.2), (-1.3, 1.7), (WINDOW_Z, 4.5))
CURTAIN_TOP_Y = 1.25
#: The walls' thickness (m): the window's reveals are this deep.
WALL_THICKNESS_M = 0.1
CURTAIN_Z = -0.08
CURTAIN_WIDTH_M = 1.7
CURTAIN_HEIGHT_M = 2.2

SUN_RADIUS_RAD = math.radians(0.2666)
#: Paper mode: F (Y = 100) is read in 8-bit levels of a white at 255 (Table 2's units).
PAPER_F_PER_WHITE = 1.0 / 255.0
SKY_FRACTION = 0.12
GROUND_ALBEDO = 0.2
FILL_FRACTION = 0.04
FILL_TO_LIGHT = np.array([0.3, 0.5, 1.0]) / np.linalg.norm([0.3, 0.5, 1.0])
ROOM_ALBEDO = 0.6
ROOM_FRACTION = 0.03
#: A lamp (not the sun) stands this high above the horizon behind the window.
LAMP_ELEVATION_DEG = 25.0
#: The key light's azimuth from the window normal (deg, + to the right seen from the room).
KEY_AZIMUTH_DEG = 15.0
#: Where and when the hour of day is taken (the paper's setting: Japan, summer solstice).
SUN_DATE = "2026-06-21"
SUN_LATITUDE_DEG = 34.7


# --------------------------------------------------------------------------- meshes

@dataclass(frozen=True)
class Mesh:
    """Vertex arrays (float32) and triangle indices (int32, (T, 3))."""

    positions: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    tangents: np.ndarray
    indices: np.ndarray


def draped_curtain(columns: int = 120, rows: int = 80, folds: float = 5.5,
                   depth_m: float = 0.07, fold_shift_m: float = 0.0) -> Mesh:
    """A static draped curtain: sinusoidal folds hanging from a rod, deepest at the top.
    ``fold_shift_m`` slides the folds sideways (towards +x) inside a fixed outline.

    u runs along the weft (across, x), v along the warp (down from the rod, -y). The
    tangent is dP/du (weft); the normal dP/du x dP/dv' faces the room (+z) on average.
    """
    if columns < 2 or rows < 2:
        raise CatalogError("a curtain mesh needs at least 2 x 2 vertices")
    u = np.linspace(0.0, 1.0, columns)
    v = np.linspace(0.0, 1.0, rows)
    uu, vv = np.meshgrid(u, v)  # (rows, columns)
    amplitude = depth_m * (1.0 - 0.45 * vv)  # folds open up towards the hem
    phase = 2 * math.pi * folds * (uu - fold_shift_m / CURTAIN_WIDTH_M)
    x = (uu - 0.5) * CURTAIN_WIDTH_M
    y = CURTAIN_TOP_Y - vv * CURTAIN_HEIGHT_M
    z = CURTAIN_Z + amplitude * np.sin(phase)
    positions = np.stack([x, y, z], axis=-1)
    # analytic derivatives
    dp_du = np.stack([np.full_like(uu, CURTAIN_WIDTH_M), np.zeros_like(uu),
                      amplitude * 2 * math.pi * folds * np.cos(phase)], axis=-1)
    dp_dv = np.stack([np.zeros_like(uu), np.full_like(uu, -CURTAIN_HEIGHT_M),
                      -0.45 * depth_m * np.sin(phase)], axis=-1)
    normals = np.cross(dp_dv, dp_du)  # (0,-1,0) x (1,0,0) = (0,0,1): faces the room
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    tangents = dp_du / np.linalg.norm(dp_du, axis=-1, keepdims=True)
    index = np.arange(rows * columns).reshape(rows, columns)
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    c, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    triangles = np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)])
    return Mesh(positions.reshape(-1, 3).astype(np.float32),
                normals.reshape(-1, 3).astype(np.float32),
                np.stack([uu, vv], -1).reshape(-1, 2).astype(np.float32),
                tangents.reshape(-1, 3).astype(np.float32),
                triangles.astype(np.int32))


def box_triangles(x0, x1, y0, y1, z0, z1) -> np.ndarray:
    """An axis-aligned box as 12 triangles (12, 3, 3), counter-clockwise seen from outside."""
    c = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)], dtype=np.float64)
    # corner index = 4 ix + 2 iy + iz; each face as a quad (a, b, c, d) counter-clockwise from outside
    quads = [(0, 1, 3, 2), (4, 6, 7, 5),   # -x, +x
             (0, 4, 5, 1), (2, 3, 7, 6),   # -y, +y
             (0, 2, 6, 4), (1, 5, 7, 3)]   # -z, +z
    return np.array([tri for a, b, cc, d in quads for tri in ((c[a], c[b], c[cc]), (c[a], c[cc], c[d]))])


def rod_triangles(radius_m: float, length_m: float, centre, sections: int = 16) -> np.ndarray:
    """A closed cylinder along x (the curtain rod) as triangles, counter-clockwise from outside."""
    angle = np.linspace(0.0, 2 * math.pi, sections + 1)
    ring = np.stack([np.zeros_like(angle), radius_m * np.cos(angle), radius_m * np.sin(angle)], 1)
    left = ring + [-length_m / 2, 0, 0] + np.asarray(centre)
    right = ring + [length_m / 2, 0, 0] + np.asarray(centre)
    tris = []
    for i in range(sections):
        tris += [(left[i], left[i + 1], right[i + 1]), (left[i], right[i + 1], right[i])]
        tris += [(np.asarray(centre) + [-length_m / 2, 0, 0], left[i + 1], left[i]),
                 (np.asarray(centre) + [length_m / 2, 0, 0], right[i], right[i + 1])]
    return np.array(tris)


#: Curtain rings around the rod (m): the ring's radius (its bottom holds the heading at
#: CURTAIN_TOP_Y) and the wire's radius.
RING_RADIUS_M = 0.03
RING_WIRE_M = 0.004
ROD_Y = CURTAIN_TOP_Y + 0.03
ROD_RADIUS_M = 0.015


def ring_triangles(xs_m, sections: int = 16, wire_sections: int = 6, rod_y: float = ROD_Y,
                   curtain_z: float = CURTAIN_Z) -> np.ndarray:
    """Rings (tori in the y-z plane around the rod at height ``rod_y``, in the curtain's plane
    ``curtain_z``) at the given x positions, as triangles (T, 3, 3), counter-clockwise from outside."""
    xs_m = np.asarray(xs_m, dtype=np.float64).ravel()
    if xs_m.size == 0:
        return np.zeros((0, 3, 3))
    a = np.linspace(0.0, 2 * math.pi, sections + 1)            # around the ring
    b = np.linspace(0.0, 2 * math.pi, wire_sections + 1)       # around the wire
    aa, bb = np.meshgrid(a, b, indexing="ij")
    r = RING_RADIUS_M + RING_WIRE_M * np.cos(bb)
    ring = np.stack([RING_WIRE_M * np.sin(bb), rod_y + r * np.cos(aa), curtain_z + r * np.sin(aa)], -1)
    quads = []
    for i in range(sections):
        for j in range(wire_sections):
            p00, p10 = ring[i, j], ring[i + 1, j]
            p01, p11 = ring[i, j + 1], ring[i + 1, j + 1]
            quads += [(p00, p10, p11), (p00, p11, p01)]
    one = np.array(quads)
    return np.concatenate([one + [x, 0.0, 0.0] for x in xs_m])


def ring_mesh(xs_m, placement=None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`ring_triangles` on the rod of ``placement`` (catalog.render.placement; None: the
    box's), flat-shaded: (positions, normals) float32 (3T, 3)."""
    if placement is None:
        return _flat_shaded(ring_triangles(xs_m))
    return _flat_shaded(ring_triangles(xs_m, rod_y=placement.rod_y, curtain_z=placement.curtain_z))


def _room_parts() -> list[np.ndarray]:
    (x0, x1), (y0, y1), (z0, z1) = ROOM_BOX
    wx0, wx1, wy0, wy1 = WINDOW_RECT
    t = WALL_THICKNESS_M
    return [
        box_triangles(x0 - t, x1 + t, y0 - t, y0, z0 - t, z1 + t),       # floor
        box_triangles(x0 - t, x1 + t, y1, y1 + t, z0 - t, z1 + t),       # ceiling
        box_triangles(x0 - t, x0, y0, y1, z0 - t, z1 + t),               # left wall
        box_triangles(x1, x1 + t, y0, y1, z0 - t, z1 + t),               # right wall
        box_triangles(x0, x1, y0, y1, z1, z1 + t),                       # wall behind the viewer
        # the window wall, around the opening
        box_triangles(x0, wx0, y0, y1, z0 - t, z0),
        box_triangles(wx1, x1, y0, y1, z0 - t, z0),
        box_triangles(wx0, wx1, y0, wy0, z0 - t, z0),
        box_triangles(wx0, wx1, wy1, y1, z0 - t, z0),
        rod_triangles(ROD_RADIUS_M, CURTAIN_WIDTH_M + 0.4, (0.0, ROD_Y, CURTAIN_Z)),
    ]


@functools.lru_cache(maxsize=1)
def room_props() -> tuple[np.ndarray, np.ndarray]:
    """The room (walls, floor, ceiling, the window wall with its opening) and the curtain rod;
    returns non-indexed (positions, face normals), float32 (3T, 3).

    Built with numpy, not trimesh: importing trimesh imports scipy, which a frame must not
    (the viewer's rule); tests/test_render_scene.py checks these solids against trimesh's.
    """
    triangles = np.concatenate(_room_parts())
    return _flat_shaded(triangles)


def rod_mesh(placement=None) -> tuple[np.ndarray, np.ndarray]:
    """The curtain rod alone, on the window of ``placement`` (catalog.render.placement; None:
    the box's, the last of the room's parts), flat-shaded like :func:`room_props`."""
    if placement is None:
        return _flat_shaded(_room_parts()[-1])
    return _flat_shaded(rod_triangles(ROD_RADIUS_M, placement.rod_length_m, placement.rod_centre))


def _flat_shaded(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.repeat(normals[:, None, :], 3, axis=1)
    return (triangles.reshape(-1, 3).astype(np.float32), normals.reshape(-1, 3).astype(np.float32))


# --------------------------------------------------------------------------- the sun

def key_direction(elevation_deg: float, azimuth_deg: float = KEY_AZIMUTH_DEG) -> np.ndarray:
    """Unit vector towards a distant light behind the window (outside is -z)."""
    el, az = math.radians(elevation_deg), math.radians(azimuth_deg)
    return np.array([math.sin(az) * math.cos(el), math.sin(el), -math.cos(az) * math.cos(el)])


@dataclass(frozen=True)
class SunAtHour:
    hour: float
    zenith_deg: float
    azimuth_deg: float  # from the window normal (the window faces south)
    path_km: float
    light_name: str


#: Day of the year of SUN_DATE (the June solstice).
SUN_DAY_OF_YEAR = 172


def solar_zenith_deg(hour: float, day_of_year: int = SUN_DAY_OF_YEAR,
                     latitude_deg: float = SUN_LATITUDE_DEG) -> float:
    """The scene's sun: :func:`catalog.optics.sun.model.solar_zenith_deg_at_solar_time` on SUN_DATE at
    SUN_LATITUDE (closed form, no pvlib: drawing a frame must not import scipy)."""
    from catalog.optics.sun.model import solar_zenith_deg_at_solar_time  # noqa: PLC0415

    return solar_zenith_deg_at_solar_time(hour, day_of_year, latitude_deg)


def sun_at_hour(hour: float) -> SunAtHour:
    """Hour of local mean solar time on SUN_DATE at SUN_LATITUDE -> the sun through a
    south-facing window: zenith (:func:`solar_zenith_deg`), path length through the paper's
    22 km shell (catalog.optics.sun.model), and the light name ``sun:PATH_KM`` of the light library."""
    from catalog.optics.sun.model import path_km_from_zenith  # noqa: PLC0415

    if not (math.isfinite(hour) and 0.0 <= hour < 24.0):
        raise InputError(f"{hour!r} is not an hour of the day (0 <= hour < 24)", field="--hour")
    zenith = solar_zenith_deg(hour)
    if zenith >= 90.0:
        raise InputError(f"the sun is below the horizon at {hour:g} h (zenith {zenith:.1f} deg)",
                         field="--hour")
    path = path_km_from_zenith(zenith)
    azimuth = max(-75.0, min(75.0, 15.0 * (hour - 12.0)))  # hour angle, kept inside the window
    return SunAtHour(hour, zenith, azimuth, path, f"sun:{path:.1f}")


def key_elevation_for(light) -> float:
    """Elevation (deg) of the key light (a catalog.optics.lights.Light): the sun's, from its
    path length or its date, time and place (``light.sun``, resolved when the library made
    it), so that the sky behind the window (catalog/optics/sun/sky.py) is the one of that sun;
    a lamp's, or a sun whose path has no zenith, LAMP_ELEVATION_DEG."""
    if light.sun is not None and light.sun.elevation_deg is not None:
        return light.sun.elevation_deg
    return LAMP_ELEVATION_DEG


# --------------------------------------------------------------------------- fabric spectra

def dye_transmittance(preset) -> np.ndarray:
    """T(l) of a preset's ``[dye] transmittance`` CSV on GRID_NM (edge values held), or 1
    (:func:`catalog.presets.fabric.resolve_fabric`: read once per preset)."""
    from catalog.presets.fabric import resolve_fabric  # noqa: PLC0415

    return resolve_fabric(preset).dye_transmittance


def relative_dye(transmittance: np.ndarray) -> np.ndarray:
    """The dye's spectral shape around the grey fit: T(l) / T_mean, T_mean weighted by ybar.

    The preset's grey [btdf] lobes are fitted to the luminance-like gonio column, so they
    already hold the dye's mean absorption; the spectral factor only redistributes it
    (a cloth with no dye, T = 1, gets exactly 1).
    """
    from catalog.optics.colorimetry import cmfs  # noqa: PLC0415

    ybar = cmfs(GRID_NM)[:, 1]
    mean = float(transmittance @ ybar) / float(np.sum(ybar))
    if not mean > 0:
        raise InputError("dye transmittance is zero over the visible range", field="dye.transmittance")
    return transmittance / mean


def fluorescent_material(preset, irradiance: np.ndarray | None = None):
    """The physical-mode material of a preset with a ``[fluorescence]`` table (else None).

    A preset whose ``[fluorescence]`` has ``bands`` (extra excitation bands, each with its
    own excitation, emission, quantum_yield and peak_absorptance; docs/bispectral.md) is
    collapsed under ``irradiance`` into one fluorophore
    (:func:`catalog.optics.fluorescence.combine_under_light`): pre-integrated per (material,
    light), so the shader's work is the same. Without ``irradiance`` the main band is
    returned (and every band's files are checked)."""
    from catalog.optics import fluorescence as fl  # noqa: PLC0415
    from catalog.presets.fabric import resolve_fabric  # noqa: PLC0415

    materials = resolve_fabric(preset).fluorescent_materials
    if not materials:
        return None
    if irradiance is None or len(materials) == 1:
        return materials[0]
    return fl.combine_under_light(list(materials), np.asarray(irradiance, dtype=np.float64))


def fluorescence_residual(preset):
    """The preset's measured residual (``[fluorescence] residual``, a file beside the preset;
    catalog.optics.measured_residual), or None. Bad fields: one-line InputError."""
    from catalog.presets.fabric import resolve_fabric  # noqa: PLC0415

    return resolve_fabric(preset).residual


def paper_emission_shape(preset) -> np.ndarray:
    """The emission Le on GRID_NM, 380-780 nm only (eq. 1), scaled so that sum ybar s dl = 1
    (eq. 3's K / 100): F = 100 sum cmf s is the paper's fluorescence colour."""
    from catalog.optics.colorimetry import cmfs  # noqa: PLC0415
    from catalog.optics.spectra import VISIBLE_NM  # noqa: PLC0415
    from catalog.presets.fabric import resolve_fabric  # noqa: PLC0415

    emission = resolve_fabric(preset).emission_on_grid
    emission = np.where((GRID_NM >= VISIBLE_NM[0]) & (GRID_NM <= VISIBLE_NM[1]), emission, 0.0)
    y = float(emission @ cmfs(GRID_NM)[:, 1])
    if not y > 0:
        raise InputError("emission has no luminance in 380-780 nm",
                         path=preset.fluorescence.emission)
    return emission / y


# --------------------------------------------------------------------------- the light

@dataclass(frozen=True)
class FluorescenceDecision:
    requested: str        # "off" | "paper" | "physical"
    used: str             # the variant compiled
    needed: bool | None   # fluorescence_needed's verdict (None: no brightener / not asked)
    delta_e: float | None


def decide_fluorescence(preset, irradiance: np.ndarray, requested: str) -> FluorescenceDecision:
    """Which fluorescence variant a scene needs: none for a fabric without brightener, none
    when the emission changes the lit cloth by less than Delta E 2000 0.1 under this light
    (:func:`catalog.optics.fluorescence.fluorescence_needed`; the same judgement for both modes)."""
    from catalog.optics.fluorescence import fluorescence_delta_e  # noqa: PLC0415

    from catalog.core.constants import FLUORESCENCE_MODES  # noqa: PLC0415

    if requested not in FLUORESCENCE_MODES:
        raise CatalogError(f"fluorescence mode {requested!r}: choose off, paper or physical")
    material = fluorescent_material(preset, irradiance)
    if requested == "off" or material is None:
        return FluorescenceDecision(requested, "off", None, None)
    delta_e = fluorescence_delta_e(material, irradiance)
    # a measured residual is carried with the physical emission whenever a band is excited
    needed = delta_e > 0.1 or (requested == "physical" and fluorescence_residual(preset) is not None)
    return FluorescenceDecision(requested, requested if needed else "off", needed, delta_e)


def outside_radiances(key_irradiance: np.ndarray, to_light: np.ndarray, is_sun: bool,
                      paper_beam: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Mean radiance spectra of the sky and the ground outside the window.

    The sun above the horizon: the clear sky of the same atmosphere (catalog.optics.sun.model
    clear_sky at the sun's zenith): sky = diffuse horizontal / pi (a uniform sky with the same
    irradiance; catalog/optics/sun/sky.py spreads it over the sky by Preetham's distribution),
    ground = albedo x global horizontal / pi. ``paper_beam`` (the ``sun:PATH`` lights, the
    paper's beam after Rayleigh scattering alone): that atmosphere's sky has the colour of
    the same beam Rayleigh-scattered, key x (550 / l)^4, at the clear sky's luminance, and the
    ground is lit by that beam and sky. A lamp (or the sun at or below the horizon): the scene
    design of the module docstring (a lit backdrop, SKY_FRACTION of the key)."""
    tint = (550.0 / GRID_NM) ** 4
    if is_sun and to_light[1] > 1e-3:
        from catalog.optics.colorimetry import cmfs  # noqa: PLC0415
        from catalog.optics.sun.model import Atmosphere, clear_sky  # noqa: PLC0415

        zenith = min(math.degrees(math.acos(min(float(to_light[1]), 1.0))), 89.5)
        clear = clear_sky(zenith)
        albedo = Atmosphere().ground_albedo
        if not paper_beam:
            return clear.diffuse_horizontal / math.pi, albedo * clear.global_horizontal / math.pi
        ybar = cmfs(GRID_NM)[:, 1]
        shape = key_irradiance * tint
        scale = float(clear.diffuse_horizontal @ ybar) / max(float(shape @ ybar), 1e-300)
        diffuse = shape * scale
        cos_z = math.cos(math.radians(zenith))
        return diffuse / math.pi, albedo * (key_irradiance * cos_z + diffuse) / math.pi
    return (SKY_FRACTION * key_irradiance * (tint if is_sun else 1.0) / math.pi,
            GROUND_ALBEDO * key_irradiance * max(to_light[1], 0.0) / math.pi)


def build_shading_inputs(preset, key_irradiance: np.ndarray, key_to_light: np.ndarray, *,
                         is_sun: bool, fluorescence: str = "physical", paper_beam: bool = False,
                         viewer_inside: bool = True, neutral: bool = False) -> tuple[ShadingInputs, FluorescenceDecision]:
    """The spectral description of the scene's light on the curtain for a preset; ``neutral``:
    its dye left out (T = 1), the light a white cloth of the same weave passes and reflects."""
    from catalog.optics.colorimetry import cmfs  # noqa: PLC0415
    from catalog.optics.fluorescence import paper_intensity  # noqa: PLC0415

    key = np.asarray(key_irradiance, dtype=np.float64)
    to_light = np.asarray(key_to_light, dtype=np.float64)
    to_light = to_light / np.linalg.norm(to_light)
    sky, ground = outside_radiances(key, to_light, is_sun, paper_beam)
    fill = FILL_FRACTION * key
    room = ROOM_ALBEDO * ROOM_FRACTION * key / math.pi
    disc = key / (math.pi * SUN_RADIUS_RAD ** 2)
    chord2 = tuple((2 * math.sin(r / 2)) ** 2 for r in (0.9 * SUN_RADIUS_RAD, 1.1 * SUN_RADIUS_RAD))

    btdf = preset.btdf
    anisotropy = float(preset.raw.get("btdf", {}).get("anisotropy", 0.0))
    if not -1.0 < anisotropy < 1.0:
        raise InputError(f"{anisotropy:g} is out of range (-1, 1)", path=preset.path,
                         field="btdf.anisotropy")
    dye = np.ones_like(GRID_NM, dtype=np.float64) if neutral else relative_dye(dye_transmittance(preset))
    behind = 0.5 * (sky + ground)  # mean radiance of the outside half-space
    front = room
    if not viewer_inside:
        behind, front = front, behind
    fwd_d, back_d = hg_hemisphere_factors(btdf.g_diff)
    fwd_s, back_s = hg_hemisphere_factors(btdf.g_spec)
    ambient = dye * (btdf.a_diff * (fwd_d * behind + back_d * front)
                     + btdf.a_spec * (fwd_s * behind + back_s * front))
    # the outside's share of it (the cloth's own folds hide part of the outside: issue 11)
    outside = 0.5 * (sky + ground)
    tilt = share = None
    if viewer_inside:
        ambient_outside = dye * (btdf.a_diff * fwd_d + btdf.a_spec * fwd_s) * outside
        # the lobes bring the sky from above the view's line and the ground from below it
        # (issue 11; the ambient's share of each, outside_sky_share, by the view's height)
        tilt = dye * (btdf.a_diff * fwd_d + btdf.a_spec * fwd_s) * (sky - ground)
        share = outside_sky_share(btdf.a_diff, btdf.g_diff, btdf.a_spec, btdf.g_spec)
    else:
        ambient_outside = dye * (btdf.a_diff * back_d + btdf.a_spec * back_s) * outside

    decision = decide_fluorescence(preset, key, fluorescence)
    paper = None
    absorbed = (0.0, 0.0, 0.0)
    saturation = math.inf
    emission_per_photon = None
    if decision.used == "paper":
        excitation = _excitation_on_grid(preset)
        intensity = paper_intensity(key, excitation)  # eq. 4
        white_y = float(key @ cmfs(GRID_NM)[:, 1]) / math.pi  # a white diffuser's Y (W-weighted)
        # eq. 8: I_fluor F_c. Its scale is arbitrary (model.md section 6); Table 2 reads as
        # 8-bit levels, so F (Y = 100) is taken in units of a white at 255: F / 255 x white
        paper = intensity * PAPER_F_PER_WHITE * 100.0 * paper_emission_shape(preset) * white_y
    inputs = ShadingInputs(
        key_irradiance=key, key_to_light=to_light, fill_irradiance=fill,
        fill_to_light=FILL_TO_LIGHT.copy(), sky_radiance=sky, ground_radiance=ground,
        sun_disc_radiance=disc, room_radiance=room, sun_chord2=chord2,
        direct=btdf.direct, a_diff=btdf.a_diff, g_diff=btdf.g_diff, a_spec=btdf.a_spec,
        g_spec=btdf.g_spec, anisotropy=anisotropy, dye_transmittance=dye,
        ambient_radiance=ambient, fluorescence_mode=decision.used, paper_radiance=paper,
        absorbed_photons=absorbed, saturation_photons=saturation,
        emission_per_photon=emission_per_photon, ambient_outside_radiance=ambient_outside,
        # the ambient by view (issue 11): the outside lies behind the cloth for a viewer inside
        ambient_view_outside=ambient_view_ratios(btdf.a_diff, btdf.g_diff, btdf.a_spec,
                                                 btdf.g_spec, backward=not viewer_inside),
        ambient_view_room=ambient_view_ratios(btdf.a_diff, btdf.g_diff, btdf.a_spec,
                                              btdf.g_spec, backward=viewer_inside),
        outside_sky_share=share, ambient_tilt_radiance=tilt)
    if decision.used == "physical":
        residual = fluorescence_residual(preset)
        inputs = with_physical_emission(
            inputs, fluorescent_material(preset, key),
            None if residual is None else residual.exitance_w_m2_nm(key))
    return inputs, decision


def with_physical_emission(inputs: ShadingInputs, material,
                           residual_exitance: np.ndarray | None = None) -> ShadingInputs:
    """``inputs`` with physical-mode fluorescence of ``material`` switched on (the one place
    these terms are made): absorbed photons at normal incidence for the key and fill lights
    and, from both sides of the cloth, the outside half-space and the room; the emission
    ``quantum_yield p(l) h c / l`` per effective photon as a radiance, M / pi shared by the
    two sides of a thin cloth (M / (2 pi) on each).

    ``residual_exitance`` (W m^-2 nm^-1 on GRID_NM, signed: a measured residual under the
    key light at normal incidence, catalog.optics.measured_residual) is folded into the
    emission per photon, M_res / (2 pi N_key): under the key (any incidence) and the fill
    (the key's spectrum) the shader then adds exactly M_res's share, at no extra cost; under
    the ambient light, whose spectrum differs, and above saturation, approximately. Dropped
    when the key excites no band (N_key = 0)."""
    from dataclasses import replace  # noqa: PLC0415

    from catalog.optics.fluorescence import absorbed_photon_irradiance, photon_energy_j  # noqa: PLC0415

    ambient_irradiance = math.pi * (0.5 * (inputs.sky_radiance + inputs.ground_radiance)
                                    + inputs.room_radiance)
    absorbed = (absorbed_photon_irradiance(material, inputs.key_irradiance),
                absorbed_photon_irradiance(material, inputs.fill_irradiance),
                absorbed_photon_irradiance(material, ambient_irradiance))
    absorbed_room = absorbed_photon_irradiance(material, math.pi * inputs.room_radiance)
    emission = (material.quantum_yield * material.emission_pdf_per_nm
                * photon_energy_j(GRID_NM) / (2 * math.pi))
    if residual_exitance is not None and absorbed[0] > 0:
        effective_key = absorbed[0] / (1.0 + absorbed[0] / material.saturation_photon_irradiance)
        emission = emission + np.asarray(residual_exitance, dtype=np.float64) / (2 * math.pi * effective_key)
    return replace(inputs, fluorescence_mode="physical", absorbed_photons=absorbed,
                   absorbed_room_photons=absorbed_room,
                   saturation_photons=material.saturation_photon_irradiance,
                   emission_per_photon=emission)


def with_room_solved(inputs: ShadingInputs) -> ShadingInputs:
    """``inputs`` without the stand-ins for the room's light on the curtain's room side (issue
    11, fourth round), for a viewer in the room whose frame lights that side by the room's
    solved light instead (curtain.frag ROOM_SIDE, an RGB term the float64 twin adds with
    :func:`catalog.optics.shading_reference.room_side_linear_srgb`): no fill light, the
    ambient term's outside share alone, and neither exciting the fluorescence (the room's
    light excites next to nothing: under daylight it is the daylight's, weaker, under UV-A
    the visible glow). The path-traced reference has no stand-ins either."""
    from dataclasses import replace  # noqa: PLC0415

    outside = (inputs.ambient_outside_radiance if inputs.ambient_outside_radiance is not None
               else np.zeros_like(inputs.ambient_radiance))
    key, _fill, ambient = inputs.absorbed_photons
    return replace(inputs, fill_irradiance=np.zeros_like(inputs.fill_irradiance),
                   ambient_radiance=np.array(outside, dtype=np.float64),
                   absorbed_photons=(key, 0.0, max(ambient - inputs.absorbed_room_photons, 0.0)),
                   absorbed_room_photons=0.0)


def _excitation_on_grid(preset) -> np.ndarray:
    from catalog.presets.fabric import resolve_fabric  # noqa: PLC0415

    return resolve_fabric(preset).excitation_on_grid
