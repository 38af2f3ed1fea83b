"""The scene of ``catalog snapshot`` exported for Mitsuba, from the same description.

:func:`describe_scene` (numpy only) reads everything from :mod:`catalog.render.scene`
(geometry, albedos, the key light's direction and disc, the sky and ground radiances of
:func:`catalog.render.scene.build_shading_inputs`) and :mod:`catalog.render.snapshot` (the
cloth simulation's curtain at a frame); :func:`build_mitsuba_scene` turns that into a
Mitsuba scene dict. When the real-time scene changes (patterns, fullness, room lighting),
the export follows because it holds no numbers of its own.

What the reference keeps and what it replaces (the real-time frame's stand-ins for light
it cannot trace are not light sources here; path tracing computes what they stand for):

- kept: the room (a catalog.room.model.Room, ``--room``: by default the built-in ``box``,
  today's grey box with its window opening), each surface a Lambertian of its albedo
  (factor x texture), the rod and rings (grey Lambertian, ROOM_ALBEDO),
  the curtain mesh, the camera (position, target, vertical field of view), the key light
  as a distant source with the disc of SUN_RADIUS_RAD and the key's normal irradiance, the
  sky above and the ground below the horizon with the real-time radiances (for a sun, the
  frame's clear sky by direction, catalog.optics.sun.sky), all in one environment map (the disc resolved by supersampling, normalised to the exact irradiance);
- replaced: the fill light (FILL_FRACTION of the key, a stand-in for the light bounced
  into the room), the walls' constant ROOM_FRACTION radiance and the cloth's ambient term
  (stand-ins for the inter-reflections): the path tracer follows the light's paths instead.
  ``stand_ins=True`` adds the fill light back (the direct-light validation uses it).

Colour: the RGB variant carries linear sRGB in the real-time frame's units (683 times the
sRGB matching functions: Y in cd m^-2 for a radiance in W m^-2 sr^-1 nm^-1); the dye is the
per-channel ratio RGB(key x dye) / RGB(key), exact for light of the key's spectrum, as the
3-band real-time frame does.

Fluorescence (physical mode), stated: a Lambertian emission on both sides of the cloth,
per vertex, from the photons the cloth absorbs there: the key light's at its incidence
|n . l| with its visibility from a shadow ray (folds shade each other), plus the outside
half-space's sky and ground (the room's light, with almost no UV, is left out), through
the same absorptance, quantum yield, saturation and emission spectrum as the real-time
frame (catalog.render.scene.with_physical_emission), M / (2 pi) per side. It enters the
scene as two emitting, null-scattering shells 0.5 mm either side of the cloth, whose
radiance (catalog.pathtrace.glow) is the per-vertex emission times c(uv) / mean(c) where
the fabric has a pattern: the threads glow, the holes do not, as the frame draws it. Issue 11
found that Mitsuba's built-in ``mesh_attribute`` radiance, used before, was seen about 10x
too faint by next-event estimation (the room's glow came almost only from BSDF-sampled hits);
the glow texture samples the shell in uv and tests/test_pathtrace.py checks that emitter
and BSDF sampling agree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from catalog.pathtrace import window_filter
from catalog.pathtrace.glow import ATTRIBUTE

#: Environment map size (lat-long, width = 2 height). 2048 x 1024: 0.18 deg texels.
ENV_WIDTH = 2048
#: Sub-samples per texel side where the key light's disc may fall.
DISC_SUPERSAMPLE = 8
#: The fluorescence shells' distance from the cloth (m).
SHELL_OFFSET_M = 5e-4


@dataclass
class SceneDescription:
    """Everything the reference needs, as numpy arrays (no Mitsuba here)."""

    size: tuple[int, int]
    camera_position: np.ndarray
    camera_target: np.ndarray
    fov_y_deg: float
    near_m: float
    far_m: float
    curtain: tuple                       # positions, normals, uvs, tangents, indices
    room_positions: np.ndarray           # (3T, 3) non-indexed triangles: the rod and the rings
    room_albedo: float                   # theirs
    fabric: dict                         # woven BSDF parameters + dye_rgb
    sky_rgb: np.ndarray
    ground_rgb: np.ndarray
    key_rgb: np.ndarray                  # normal irradiance, RGB
    key_to_light: np.ndarray
    key_radius_rad: float
    fill_rgb: np.ndarray                 # the real-time stand-in (used with stand_ins only)
    fill_to_light: np.ndarray
    fluorescence: dict | None            # per-vertex emission recipe (see module doc)
    inputs: object                       # catalog.optics.shading_reference.ShadingInputs of the frame
    info: dict = field(default_factory=dict)
    pattern: dict | None = None          # {"coverage": (H, W) array, "uv_scale": (su, sv)}
    fabric_size_m: tuple | None = None   # the rest fabric's (width, length) that uv 0..1 spans
    ring_xs_m: tuple = ()                # the curtain rings on the rod (x, m)
    sky: object = None                   # the frame's clear-sky model (a sun above the horizon)
    room_surfaces: tuple = ()            # the room's catalog.room.model.Surface values
    window_corners: np.ndarray | None = None   # (4, 3) the room's aperture
    window_normal: np.ndarray | None = None    # (3,) into the room


def rgb_weights(key_irradiance: np.ndarray) -> np.ndarray:
    """(3, L): spectrum -> linear sRGB in the frame's units (the 3-band weights)."""
    from catalog.render.bands import band_weights  # noqa: PLC0415

    weights, _ = band_weights(3, key_irradiance)
    return weights


def key_light_for(light) -> tuple[np.ndarray, bool]:
    """The key light's direction (unit, to the light) and whether it is the sun, as the
    real-time frame places it (:class:`catalog.render.settings.FrameSettings`' ``key_to_light``)."""
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    return scene_lib.key_direction(scene_lib.key_elevation_for(light)), light.is_sun


def describe_scene(settings, *, size=(256, 192), frame: int = 0, curtain=None) -> SceneDescription:
    """The scene the real-time frame draws with ``settings`` (a
    :class:`catalog.render.settings.FrameSettings`: its fabric and Fabric tables, key light
    and direction, fluorescence mode, camera and room), at ``size``, for the path tracer.
    The room must be resolved (``settings.room`` a loaded catalog.room.model.Room: the edge
    loads it, :func:`catalog.pathtrace.render.reference_settings`); nothing is read here.
    ``curtain``: the cloth's (positions, normals, uvs, tangents, indices[, fabric size]);
    None: the settled drape after ``frame`` frames, as catalog snapshot draws it."""
    from catalog.core.errors import CatalogError  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    from catalog.render.placement import placement_of_room  # noqa: PLC0415

    room = getattr(settings, "resolved_room", None)
    if room is None:
        raise CatalogError("describe_scene draws a resolved room: give FrameSettings whose room "
                           "is a loaded Room (catalog.pathtrace.render.reference_settings)")
    # the curtain and rod hung from this room's window, as the frame hangs them (its
    # placement: catalog.render.placement); the camera is the value's (reference_settings
    # aims it at this curtain and keeps it in this room's interior, as snapshot_settings does)
    placement = placement_of_room(room)
    preset, light, camera = settings.fabric, settings.key_light, settings.camera
    is_sun = light.is_sun
    # the frame's own shading inputs (FrameSettings.shading_inputs: passes/scene_terms.py),
    # the viewer's side taken from this room's window plane
    inputs, decision = settings.shading_inputs(placement)
    fabric_size = None
    rings: tuple = ()
    if curtain is None:  # as catalog snapshot: the settled drape, then `frame` frames of cloth
        from catalog.render.snapshot import ring_xs_m, simulated_curtain  # noqa: PLC0415

        *curtain, fabric_size = simulated_curtain(preset, frame, placement)
        rings = tuple(ring_xs_m(preset, placement))
    elif len(curtain) == 6:
        *curtain, fabric_size = curtain
    room_positions, _ = scene_lib.rod_mesh(placement)
    if rings:
        ring_positions, _ = scene_lib.ring_mesh(list(rings), placement)
        room_positions = np.concatenate([np.asarray(room_positions).reshape(-1, 3),
                                         np.asarray(ring_positions).reshape(-1, 3)])
    pattern = None
    loaded = settings.resolved_fabric.pattern
    if loaded is not None:
        cloth_m = fabric_size or (scene_lib.CURTAIN_WIDTH_M, scene_lib.CURTAIN_HEIGHT_M)
        pattern = {"coverage": np.asarray(loaded.coverage, dtype=np.float32),
                   "uv_scale": (float(cloth_m[0]) / loaded.repeat_m[0],
                                float(cloth_m[1]) / loaded.repeat_m[1])}
    from catalog.optics.dye_colour import dye_rgb_under  # noqa: PLC0415

    w = rgb_weights(inputs.key_irradiance)
    key_rgb = w @ inputs.key_irradiance
    # per channel RGB(key x dye) / RGB(key), whatever the channel's sign (the frame's beam
    # takes the same, dye_colour.key_dye_rgb): a UV lamp's faint visible leak is outside the
    # sRGB gamut (green < 0), and its green was once set to 0 here (issue 11), which took the
    # negative green out of every light the cloth scattered; a saturated dye under a white
    # light can be outside it too (safety-yellow's blue under D65 is about -0.04 of the key's).
    # A channel the key leaves empty takes the dye's own mean there.
    own_mean = w @ inputs.dye_transmittance / np.maximum(w @ np.ones_like(inputs.key_irradiance), 1e-30)
    dye_rgb = dye_rgb_under(inputs.key_irradiance, inputs.dye_transmittance, own_mean)
    fabric = {"direct": inputs.direct, "a_diff": inputs.a_diff, "g_diff": inputs.g_diff,
              "a_spec": inputs.a_spec, "g_spec": inputs.g_spec, "anisotropy": inputs.anisotropy,
              "dye_rgb": dye_rgb}
    fl = None
    if inputs.fluorescence_mode == "physical":
        from catalog.optics.fluorescence import absorbed_photon_irradiance  # noqa: PLC0415

        material = scene_lib.fluorescent_material(settings.resolved_fabric)
        outside = math.pi * 0.5 * (inputs.sky_radiance + inputs.ground_radiance)
        fl = {"mode": "physical", "key_photons": float(inputs.absorbed_photons[0]),
              "outside_photons": absorbed_photon_irradiance(material, outside),
              "saturation_photons": float(inputs.saturation_photons),
              "emission_rgb_per_photon": w @ inputs.emission_per_photon,
              "emission_spectrum": np.asarray(inputs.emission_per_photon, dtype=np.float64)}
    elif inputs.fluorescence_mode == "paper":
        fl = {"mode": "paper", "radiance_rgb": w @ inputs.paper_radiance,
              "emission_spectrum": np.asarray(inputs.paper_radiance, dtype=np.float64)}
    return SceneDescription(
        size=tuple(int(v) for v in size), camera_position=camera.position,
        camera_target=np.asarray(camera.target, dtype=np.float64), fov_y_deg=camera.fov_y_deg,
        near_m=camera.near_m, far_m=camera.far_m, curtain=tuple(np.asarray(a) for a in curtain),
        room_positions=np.asarray(room_positions, dtype=np.float64),
        room_albedo=scene_lib.ROOM_ALBEDO, fabric=fabric,
        sky_rgb=w @ inputs.sky_radiance, ground_rgb=w @ inputs.ground_radiance,
        key_rgb=key_rgb, key_to_light=np.asarray(inputs.key_to_light, dtype=np.float64),
        key_radius_rad=scene_lib.SUN_RADIUS_RAD, fill_rgb=w @ inputs.fill_irradiance,
        fill_to_light=np.asarray(inputs.fill_to_light, dtype=np.float64), fluorescence=fl,
        inputs=inputs, pattern=pattern, fabric_size_m=fabric_size, ring_xs_m=rings,
        sky=clear_sky_for(inputs, is_sun), room_surfaces=tuple(room.surfaces),
        window_corners=np.asarray(room.window.corners, dtype=np.float64),
        window_normal=np.asarray(room.window.normal, dtype=np.float64),
        info={"room": room.name, "fabric": preset.name, "light": light.name, "fluorescence_requested": decision.requested,
              "fluorescence_variant": inputs.fluorescence_mode, "frame": int(frame),
              "camera": {"yaw_deg": camera.yaw_deg, "pitch_deg": camera.pitch_deg,
                         "distance_m": camera.distance_m, "target": list(camera.target)}})


# --------------------------------------------------------------------------- environment

def clear_sky_for(inputs, is_sun: bool):
    """The clear sky the frame draws behind the window for a sun above the horizon
    (:meth:`catalog.render.frame.FrameRenderer.sky_model_for`: Preetham's distribution with
    the irradiance of the scene's sky term and its ground), else None (the flat sky)."""
    if not (is_sun and inputs.key_to_light[1] > 1e-3):
        return None
    from catalog.optics.sun.sky import sky_model  # noqa: PLC0415

    return sky_model(inputs.key_to_light, diffuse_horizontal=math.pi * inputs.sky_radiance,
                     ground_radiance=inputs.ground_radiance)


def texel_directions(width: int, height: int, offsets=(0.5, 0.5)) -> np.ndarray:
    """Unit directions (H, W, 3) of a lat-long map as Mitsuba's envmap reads it:
    u = atan2(x, -z) / 2 pi, v = acos(y) / pi (y up, world = map frame)."""
    theta = math.pi * (np.arange(height)[:, None] + offsets[1]) / height
    phi = 2 * math.pi * (np.arange(width)[None, :] + offsets[0]) / width
    s = np.sin(theta)
    return np.stack(np.broadcast_arrays(s * np.sin(phi), np.cos(theta), -s * np.cos(phi)), -1)


def environment_map(sky_rgb, ground_rgb, key_rgb, key_to_light, radius_rad,
                    width: int = ENV_WIDTH, sky=None) -> np.ndarray:
    """Lat-long RGB radiance (H, W, 3) float32: sky above the horizon, ground below, the key
    light's disc of angular radius ``radius_rad`` whose integral over solid angle equals the
    key's normal irradiance ``key_rgb`` exactly (texel coverage by DISC_SUPERSAMPLE^2 samples)."""
    height = width // 2
    d = texel_directions(width, height)
    if sky is not None:  # the frame's clear sky (and hazy ground) by direction
        env = np.asarray(sky.radiance(d), dtype=np.float64)
    else:
        env = np.where(d[..., 1:2] >= 0, np.asarray(sky_rgb)[None, None, :],
                       np.asarray(ground_rgb)[None, None, :]).astype(np.float64)
    to_light = np.asarray(key_to_light, dtype=np.float64)
    to_light = to_light / np.linalg.norm(to_light)
    cos_r = math.cos(radius_rad)
    near = (d @ to_light) > math.cos(radius_rad + 4 * math.pi / height)
    rows, cols = np.nonzero(near)
    if rows.size == 0 or not np.any(np.asarray(key_rgb) > 0):
        return env.astype(np.float32)
    k = DISC_SUPERSAMPLE
    sub = (np.arange(k) + 0.5) / k
    cover = np.zeros(rows.size)
    for sy in sub:
        theta = math.pi * (rows + sy) / height
        for sx in sub:
            phi = 2 * math.pi * (cols + sx) / width
            s = np.sin(theta)
            dd = np.stack([s * np.sin(phi), np.cos(theta), -s * np.cos(phi)], -1)
            cover += (dd @ to_light) >= cos_r
    cover /= k * k
    texel_sr = (2 * math.pi / width) * (math.pi / height) * np.sin(math.pi * (rows + 0.5) / height)
    solid_angle = float(np.sum(cover * texel_sr))
    if solid_angle <= 0:
        return env.astype(np.float32)
    disc = np.asarray(key_rgb, dtype=np.float64) / solid_angle  # radiance of the disc
    env[rows, cols] = (1 - cover[:, None]) * env[rows, cols] + cover[:, None] * disc[None, :]
    return env.astype(np.float32)


# --------------------------------------------------------------------------- Mitsuba

def _mesh(mi, name, positions, indices, normals=None, uvs=None, props=None):
    import drjit as dr  # noqa: PLC0415

    positions = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1, 3)
    indices = np.ascontiguousarray(indices, dtype=np.uint32).reshape(-1, 3)
    mesh = mi.Mesh(name, positions.shape[0], indices.shape[0], props or mi.Properties(),
                   has_vertex_normals=normals is not None, has_vertex_texcoords=uvs is not None)
    params = mi.traverse(mesh)
    params["vertex_positions"] = dr.ravel(mi.Point3f(positions.T))
    params["faces"] = dr.ravel(mi.Vector3u(indices.T))
    if normals is not None:
        n = np.ascontiguousarray(normals, dtype=np.float32).reshape(-1, 3)
        params["vertex_normals"] = dr.ravel(mi.Normal3f(n.T))
    if uvs is not None:
        params["vertex_texcoords"] = dr.ravel(mi.Point2f(np.ascontiguousarray(uvs, dtype=np.float32).T))
    params.update()
    return mesh


def woven_bsdf_dict(fabric: dict, pattern: dict | None = None) -> dict:
    out = {"type": "woven", **{k: float(fabric[k]) for k in
                               ("direct", "a_diff", "g_diff", "a_spec", "g_spec", "anisotropy")},
           **{f"dye_{c}": float(v) for c, v in zip("rgb", fabric["dye_rgb"])}}
    if fabric.get("dye_spectrum") is not None:  # the spectral variant reads the dye per wavelength
        wavelengths, values = fabric["dye_spectrum"]
        out["dye"] = {"type": "regular", "wavelength_min": float(wavelengths[0]),
                      "wavelength_max": float(wavelengths[-1]),
                      "values": ", ".join(f"{v:.6g}" for v in values)}
    if pattern is not None:  # the coverage hook (model.md section 9)
        import mitsuba as mi  # noqa: PLC0415

        coverage = np.asarray(pattern["coverage"], dtype=np.float32)
        out["coverage"] = {"type": "bitmap", "raw": True,
                           "bitmap": mi.Bitmap(coverage[..., None])}
        out["coverage_mean"] = float(coverage.mean())
        scale = pattern.get("uv_scale", 1.0)
        su, sv = (scale, scale) if np.isscalar(scale) else scale
        out["uv_scale_u"], out["uv_scale_v"] = float(su), float(sv)
    return out


#: The glow shells' mesh: the curtain's triangles split in four this many times (midpoint
#: subdivision, the new vertices on the flat triangles, normals and uvs interpolated). The glow
#: is evaluated per vertex and interpolated, so a fold's shadow edge on the cloth was a ramp one
#: triangle (2 cm) wide, against the frame's per-pixel edge: issue 11's fourth round found the
#: lace's UV-A close-up lighter just inside each edge and darker just outside; 2 levels make the
#: ramp 5 mm, below a close-up pixel's 4 mm at 192 px (levels 2 and 3 differ by less than 0.5 %
#: in the curtain's mean there: docs/pathtrace.md).
GLOW_SUBDIVISIONS = 2


def glow_shell_mesh(desc: SceneDescription, levels: int = GLOW_SUBDIVISIONS):
    """(positions, normals (unit), uvs, triangles) of the glow shells' mesh: the curtain's,
    subdivided ``levels`` times (trimesh's midpoint subdivision: every new vertex lies on the
    curtain's own triangles)."""
    from trimesh import remesh  # noqa: PLC0415

    positions, normals, uvs, _tangents, indices = desc.curtain
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    uv = np.asarray(uvs, dtype=np.float64).reshape(-1, 2)
    tri = np.asarray(indices).reshape(-1, 3)
    for _ in range(levels):
        p, tri, attributes = remesh.subdivide(p, tri, vertex_attributes={"normal": n, "uv": uv})
        n, uv = attributes["normal"], attributes["uv"]
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    return p, n, uv, tri


#: Mitsuba's normalisation of the CIE 1931 y-bar integral (its film divides by it: a constant
#: radiance of 1 has Y = 1).
MITSUBA_CIE_Y_INTEGRAL = 106.856895


def film_luminance(wavelengths: np.ndarray, values: np.ndarray) -> float:
    """The luminance Y Mitsuba's spectral film gives a spectrum (values on the evenly spaced
    ``wavelengths``, nm): the CIE 1931 ybar integral (the project's tables) over
    MITSUBA_CIE_Y_INTEGRAL."""
    from catalog.optics.colorimetry import cmfs  # noqa: PLC0415

    step_nm = float(wavelengths[1] - wavelengths[0])
    return float((cmfs(wavelengths)[:, 1] * values).sum() * step_nm / MITSUBA_CIE_Y_INTEGRAL)


def key_spectrum(desc: SceneDescription) -> tuple[np.ndarray, np.ndarray]:
    """For a spectral variant: the key light's normal irradiance over the visible range the
    variant samples (wavelengths nm, values), scaled so that the film's luminance is the RGB
    key's (``desc.key_rgb``, whose luminance is the spectrum's CIE Y by the project's
    tables). Given to Mitsuba as a spectrum, not as the environment's RGB: a UV lamp's faint
    visible leak lies outside sRGB (green -0.92 of red), and an RGB texel's upsampling clamps
    it into the gamut, which made the lamp-lit outside 12x its luminance."""
    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    visible = (GRID_NM >= 360.0) & (GRID_NM <= 830.0)
    wavelengths = GRID_NM[visible]
    values = np.clip(np.asarray(desc.inputs.key_irradiance, dtype=np.float64)[visible], 0.0, None)
    film = film_luminance(wavelengths, values)
    target = float(np.asarray(desc.key_rgb) @ np.array([0.2126, 0.7152, 0.0722]))
    return wavelengths, values * (max(target, 0.0) / film if film > 0 else 0.0)


def in_gamut_same_luminance(rgb: np.ndarray) -> np.ndarray:
    """Linear sRGB (..., 3) with its negative channels set to 0 and then scaled back to the
    luminance it had (0 where that was <= 0): what a spectral variant's RGB upsampling can
    carry of an out-of-gamut light (a UV lamp's violet leak) without changing its luminance."""
    luma = np.array([0.2126, 0.7152, 0.0722])
    rgb = np.asarray(rgb, dtype=np.float64)
    clipped = np.clip(rgb, 0.0, None)
    before, after = rgb @ luma, clipped @ luma
    scale = np.where(after > 0, np.clip(before, 0.0, None) / np.where(after > 0, after, 1.0), 0.0)
    return clipped * scale[..., None]


def glow_spectrum(mi, desc: SceneDescription) -> tuple[np.ndarray, np.ndarray, float]:
    """For a spectral variant: the glow's emission spectrum over the visible range the variant
    samples (wavelengths nm, values) and its luminance Y as Mitsuba's film takes it, the CIE
    1931 ybar integral over Mitsuba's CIE_Y_INTEGRAL (catalog.pathtrace.glow's
    ``set_spectrum``). Not mi.spectrum_list_to_srgb: it clamps the channels at 0, and a
    brightener's blue glow lies outside sRGB (its green is negative), while the film keeps
    the negative channel."""
    from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

    visible = GRID_NM >= 360.0
    wavelengths = GRID_NM[visible]
    values = np.clip(np.asarray(desc.fluorescence["emission_spectrum"], dtype=np.float64)[visible], 0.0, None)
    return wavelengths, values, film_luminance(wavelengths, values)


def fluorescence_per_vertex(desc: SceneDescription, scene=None, mi=None,
                            mesh=None) -> np.ndarray | None:
    """Emitted radiance per side (V, 3) RGB at the vertices of ``mesh`` (positions, normals;
    default the curtain's), or None (module doc). ``scene``: a Mitsuba scene holding the
    curtain, for the key light's shadow rays."""
    fl = desc.fluorescence
    if fl is None:
        return None
    positions, normals = (desc.curtain[0], desc.curtain[1]) if mesh is None else (mesh[0], mesh[1])
    count = np.asarray(positions).reshape(-1, 3).shape[0]
    if fl["mode"] == "paper":
        return np.repeat(np.asarray(fl["radiance_rgb"])[None, :], count, axis=0)
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    cos_key = np.abs(n @ desc.key_to_light)
    visible = np.ones(count)
    if scene is not None:
        visible = key_visibility(desc, scene, mi, positions)
    absorbed = cos_key * visible * fl["key_photons"] + fl["outside_photons"]
    effective = absorbed / (1.0 + absorbed / fl["saturation_photons"])
    return effective[:, None] * np.asarray(fl["emission_rgb_per_photon"])[None, :]


#: Rays towards the key pass at most this many layers of cloth before the answer is kept.
MAX_KEY_LAYERS = 4


def key_visibility(desc: SceneDescription, scene, mi, positions) -> np.ndarray:
    """(V,) the key's excitation reaching ``positions`` (module doc): 1 in the open, LD per
    layer of cloth in the way (a fold in front dims the key through its gaps, it does not
    black it out; behind two layers LD^2, since issue 11's seventh round: LD for any number
    before, while the frame's two-layer shadow gives LD^2), 0 where the window wall (anything
    outside the wall's inner plane) stops the ray, whether or not cloth lies before it (issue
    11, fourth round: the wall had passed LD as the cloth does)."""
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    p = np.asarray(positions, dtype=np.float64).reshape(-1, 3) + 1e-3 * desc.key_to_light
    d = np.repeat(desc.key_to_light[None, :], p.shape[0], axis=0)
    window_point, window_normal = _window_plane(desc)
    blocked = np.zeros(p.shape[0], dtype=bool)
    layers = np.zeros(p.shape[0])
    active = np.ones(p.shape[0], dtype=bool)
    for _ in range(MAX_KEY_LAYERS):
        ray = mi.Ray3f(mi.Point3f(p.T.astype(np.float32)), mi.Vector3f(d.T.astype(np.float32)))
        si = scene.ray_intersect(ray)
        hit = np.asarray(si.is_valid(), dtype=bool) & active
        hit_p = np.asarray(si.p, dtype=np.float64).T
        wall = hit & ((hit_p - window_point) @ window_normal < 1e-3)
        blocked |= wall
        cloth = hit & ~wall
        layers += cloth
        active = cloth
        if not active.any():
            break
        p = np.where(cloth[:, None], hit_p + 1e-4 * d, p)
    visible = float(desc.fabric["direct"]) ** layers
    return np.where(blocked, 0.0, visible)


def _window_plane(desc: SceneDescription) -> tuple[np.ndarray, np.ndarray]:
    """A point of the room's aperture and its normal (into the room); the box's without a room."""
    if desc.window_corners is None:
        from catalog.render import scene as scene_lib  # noqa: PLC0415

        return np.array([0.0, 0.0, scene_lib.WINDOW_Z]), np.array([0.0, 0.0, 1.0])
    return np.asarray(desc.window_corners, dtype=np.float64)[0], np.asarray(desc.window_normal, dtype=np.float64)


def _window_area_m2(desc: SceneDescription) -> float:
    if desc.window_corners is None:
        from catalog.render import scene as scene_lib  # noqa: PLC0415

        x0, x1, y0, y1 = scene_lib.WINDOW_RECT
        return (x1 - x0) * (y1 - y0)
    c = np.asarray(desc.window_corners, dtype=np.float64)
    return 0.5 * float(np.linalg.norm(np.cross(c[2] - c[0], c[3] - c[1])))


def room_surface_bsdf(mi, surface) -> object:
    """A room surface's Lambertian BSDF: its factor, times its texture (linear) where it has one.
    A spectral variant upsamples the texture's linear RGB to spectra (``raw`` off: a float
    bitmap is linear, no transfer curve is applied); an RGB variant reads it as it is."""
    if surface.texture is None:
        return mi.load_dict({"type": "diffuse", "reflectance": {
            "type": "rgb", "value": [float(v) for v in surface.factor]}})
    albedo = np.ascontiguousarray(surface.texture * surface.factor[None, None, :], dtype=np.float32)
    return mi.load_dict({"type": "diffuse", "reflectance": {
        "type": "bitmap", "bitmap": mi.Bitmap(albedo), "raw": "spectral" not in mi.variant(),
        "filter_type": "bilinear",
        "wrap_mode": "repeat"}})


#: The least share of next-event samples an emitter gets (none is starved).
MIN_SAMPLING_SHARE = 0.15


def emitter_sampling_weights(desc: SceneDescription, emission: np.ndarray) -> dict[str, float]:
    """Next-event estimation's choice between the environment (sky, ground, the key's disc;
    ``key`` and ``backdrop`` its two parts, for a spectral variant's separate key) and each
    fluorescence shell, in proportion to the luminous power each sends into the
    room (the environment's through the window, a shell's pi L A), at least
    MIN_SAMPLING_SHARE each. Mitsuba's default, uniform over emitters, spends two thirds of
    the shadow rays on a faint glow under daylight and on a black sky under a UV lamp."""
    luma = np.array([0.2126, 0.7152, 0.0722])
    window_m2 = _window_area_m2(desc)
    key = max(float(desc.key_rgb @ luma), 0.0) * window_m2
    backdrop = math.pi * 0.5 * max(float((desc.sky_rgb + desc.ground_rgb) @ luma), 0.0) * window_m2
    env = key + backdrop
    positions = np.asarray(desc.curtain[0], dtype=np.float64).reshape(-1, 3)
    tri = np.asarray(desc.curtain[4]).reshape(-1, 3)
    area = 0.5 * np.linalg.norm(np.cross(positions[tri[:, 1]] - positions[tri[:, 0]],
                                         positions[tri[:, 2]] - positions[tri[:, 0]]), axis=1).sum()
    shell = math.pi * max(float(np.mean(np.abs(emission @ luma))), 0.0) * area
    total = env + 2 * shell
    if not total > 0:
        return {"environment": 1.0, "shell": 1.0, "key": 1.0, "backdrop": 1.0}
    share = {"environment": env, "shell": shell, "key": key, "backdrop": backdrop}
    return {name: max(value / total, MIN_SAMPLING_SHARE) for name, value in share.items()}


def build_mitsuba_scene(mi, desc: SceneDescription, *, max_depth: int = 16,
                        integrator: dict | None = None, room: bool = True,
                        environment: bool = True, stand_ins: bool = False,
                        key_as_directional: bool = False):
    """The Mitsuba scene of ``desc`` (loaded). ``room``/``environment``/``stand_ins`` and
    ``key_as_directional`` switch parts for the validation scenes (the direct-light check
    uses the curtain alone under the two directional lights of the real-time frame)."""
    width, height = desc.size
    sensor = {
        "type": "perspective", "fov": float(desc.fov_y_deg), "fov_axis": "y",
        "near_clip": float(desc.near_m), "far_clip": float(desc.far_m),
        "to_world": mi.ScalarTransform4f().look_at(origin=[float(v) for v in desc.camera_position],
                                                   target=[float(v) for v in desc.camera_target],
                                                   up=[0.0, 1.0, 0.0]),
        "film": {"type": "hdrfilm", "width": width, "height": height, "pixel_format": "rgb",
                 "rfilter": {"type": "box"}},
        "sampler": {"type": "independent"},
    }
    scene = {"type": "scene", "sensor": sensor,
             "integrator": integrator or {"type": "volpath", "max_depth": int(max_depth),
                                          "rr_depth": 5}}
    positions, normals, uvs, _tangents, indices = desc.curtain
    props = mi.Properties()
    fabric = dict(desc.fabric)
    if mi.is_spectral:  # the dye per wavelength (visible range of the grid), not per channel
        from catalog.optics.spectra import GRID_NM  # noqa: PLC0415

        visible = (GRID_NM >= 360) & (GRID_NM <= 830)
        fabric["dye_spectrum"] = (GRID_NM[visible], desc.inputs.dye_transmittance[visible])
    props["bsdf"] = mi.load_dict(woven_bsdf_dict(fabric, desc.pattern))
    scene["curtain"] = _mesh(mi, "curtain", positions, indices, normals, uvs, props)
    if room:
        tris = desc.room_positions.reshape(-1, 3)
        room_props = mi.Properties()
        room_props["bsdf"] = mi.load_dict({"type": "diffuse", "reflectance": {
            "type": "rgb", "value": [desc.room_albedo] * 3}})
        scene["room"] = _mesh(mi, "room", tris, np.arange(tris.shape[0]).reshape(-1, 3),
                              props=room_props)
        for index, surface in enumerate(desc.room_surfaces):
            corners = np.asarray(surface.triangles, dtype=np.float64).reshape(-1, 3)
            surface_props = mi.Properties()
            surface_props["bsdf"] = room_surface_bsdf(mi, surface)
            uvs = None if surface.uvs is None else np.asarray(surface.uvs).reshape(-1, 2)
            name = f"room_{index}"
            scene[name] = _mesh(mi, name, corners, np.arange(corners.shape[0]).reshape(-1, 3),
                                uvs=uvs, props=surface_props)
    # a spectral variant takes the key as its own spectrum (key_spectrum), a directional light
    # (the disc's 0.27 degree radius gives penumbrae under 1 mm at the folds' distances)
    spectral_key = bool(mi.is_spectral) and environment and not key_as_directional
    # the outside in the key's own spectrum through a filter across the window, where it is the
    # key's spectrum times a scalar (catalog.pathtrace.window_filter, issue 11's eighth round)
    filtered = spectral_key and window_filter.sheet_applies(desc)
    if environment:
        env = environment_map(desc.sky_rgb, desc.ground_rgb,
                              np.zeros(3) if key_as_directional or spectral_key else desc.key_rgb,
                              desc.key_to_light, desc.key_radius_rad, sky=desc.sky)
        if filtered:
            env = window_filter.grey_environment(env)
        elif mi.is_spectral:
            env = in_gamut_same_luminance(env).astype(np.float32)
        scene["environment"] = {"type": "envmap", "bitmap": mi.Bitmap(env)}
    sheet_transmission = None
    if spectral_key:
        wavelengths, values = key_spectrum(desc)
        if filtered:   # the key crosses the sheet too: given as its luminance times D65
            luminance = film_luminance(wavelengths, values)
            d65 = window_filter.mitsuba_d65(mi, wavelengths)
            sheet_transmission = (wavelengths, window_filter.transmission(values, luminance, d65))
            values = luminance * d65
        scene["key"] = {"type": "directional", "direction": [float(-v) for v in desc.key_to_light],
                        "irradiance": {"type": "regular", "wavelength_min": float(wavelengths[0]),
                                       "wavelength_max": float(wavelengths[-1]),
                                       "values": ", ".join(f"{v:.6g}" for v in values)}}
    if key_as_directional:
        scene["key"] = {"type": "directional", "direction": [float(-v) for v in desc.key_to_light],
                        "irradiance": {"type": "rgb", "value": [float(v) for v in desc.key_rgb]}}
    if stand_ins:
        scene["fill"] = {"type": "directional",
                         "direction": [float(-v) for v in desc.fill_to_light],
                         "irradiance": {"type": "rgb", "value": [float(v) for v in desc.fill_rgb]}}
    if sheet_transmission is not None:
        sheet_props = mi.Properties()
        sheet_bsdf = mi.load_dict({"type": "window_filter"})
        sheet_bsdf.set_transmission(*sheet_transmission)
        sheet_props["bsdf"] = sheet_bsdf
        positions_s, faces_s, normals_s = window_filter.sheet_geometry()
        scene[window_filter.SHEET_ID] = _mesh(mi, window_filter.SHEET_ID, positions_s, faces_s,
                                              normals_s, props=sheet_props)
    if desc.fluorescence is None:
        return mi.load_dict(scene)
    # the glow's visibility rays (key_visibility) take the scene without the sheet
    loaded = mi.load_dict({k: v for k, v in scene.items() if k != window_filter.SHEET_ID})
    p, n, shell_uvs, tri = glow_shell_mesh(desc)
    emission = fluorescence_per_vertex(desc, loaded, mi, mesh=(p, n))
    weights = emitter_sampling_weights(desc, emission)
    if environment:   # with a key of its own (spectral) the environment is the backdrop alone
        scene["environment"]["sampling_weight"] = weights["backdrop" if spectral_key else "environment"]
    if spectral_key:
        scene["key"]["sampling_weight"] = weights["key"]
    glow = {"type": "patterned_glow",
            "mean_radiance": float(np.mean(np.abs(emission))),
            "max_radiance": float(np.max(np.abs(emission))) if emission.size else 0.0}
    if desc.pattern is not None:  # the threads glow, the holes do not (module doc)
        coverage = np.asarray(desc.pattern["coverage"], dtype=np.float32)
        su, sv = desc.pattern.get("uv_scale", (1.0, 1.0))
        glow.update({"coverage": {"type": "bitmap", "raw": True, "bitmap": mi.Bitmap(coverage[..., None])},
                     "coverage_mean": float(coverage.mean()), "uv_scale_u": float(su),
                     "uv_scale_v": float(sv)})
    for side, sign in (("front", 1.0), ("back", -1.0)):
        shell_props = mi.Properties()
        shell_props["bsdf"] = mi.load_dict({"type": "null"})
        radiance = mi.load_dict(glow)
        if mi.is_spectral:   # the glow's own spectrum, not the RGB it converts to
            radiance.set_spectrum(*glow_spectrum(mi, desc))
        shell_props["emitter"] = mi.load_dict({"type": "area", "sampling_weight": weights["shell"],
                                               "radiance": radiance})
        faces = tri if sign > 0 else tri[:, ::-1]
        # the curtain's uv: the glow texture samples its emitter in uv (catalog.pathtrace.glow)
        shell = _mesh(mi, f"fluorescence_{side}", p + sign * SHELL_OFFSET_M * n, faces,
                      sign * n, shell_uvs, shell_props)
        shell.add_attribute(ATTRIBUTE, 3, np.ascontiguousarray(emission, dtype=np.float32).ravel())
        radiance.attach(shell)
        scene[f"fluorescence_{side}"] = shell
    return mi.load_dict(scene)
