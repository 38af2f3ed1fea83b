"""Headless snapshots: render a fabric under a light through EGL and write EXR or PNG.

EXR holds the linear scene-referred radiance (float32, linear sRGB primaries, Y in
cd m^-2); PNG the tone-mapped, sRGB-encoded display image (8 bit). Both carry the
fabric, light and mode in their metadata, and are written atomically (a temporary file
beside the target, renamed when complete), so an error leaves no partial image.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.constants import FRAME_DT_S  # noqa: F401  (the frame step behind --frame N)
from catalog.core.errors import CatalogError, InputError
from catalog.render.imagefile import (OCIO_LINEAR_SPACE, exr_colour_metadata,  # noqa: F401
                                     read_metadata, write_image)

IMAGE_SUFFIXES = (".exr", ".png")


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` -> (width, height), refused unless both are whole numbers in 1..MAX_SIDE_PX."""
    from catalog.core.cliargs import parse_wxh  # noqa: PLC0415
    from catalog.render.passes.targets import MAX_SIDE_PX  # noqa: PLC0415

    return parse_wxh(text, "--size", 1, MAX_SIDE_PX)


#: The largest single GL resource a software rasteriser allocates, bytes (Mesa llvmpipe's
#: LP_MAX_TEXTURE_SIZE, 1 GiB; its GL_MAX_TEXTURE_SIZE of 16384 px a side does not say it).
SOFTWARE_MAX_RESOURCE_BYTES = 1 << 30
#: Bytes a pixel of the frame's largest target takes (RGBA32F: the HDR target).
HDR_TARGET_BYTES_PER_PIXEL = 16


def check_gl_size(ctx, size) -> None:
    """Refuse, before a target is allocated, a size the context cannot hold: a side beyond
    its queried limits (catalog.render.passes.targets.gl_size_limit) or, on a software rasteriser, an
    HDR target above its per-resource cap."""
    from catalog.render.passes.targets import gl_size_limit, software_rasteriser  # noqa: PLC0415

    width, height = size
    limit = gl_size_limit(ctx)
    if width > limit or height > limit:
        raise InputError(f"{width}x{height}: each side must be at most {limit} px (this GL "
                         "context's limit)", field="--size")
    need = width * height * HDR_TARGET_BYTES_PER_PIXEL
    if software_rasteriser(ctx.info) and need > SOFTWARE_MAX_RESOURCE_BYTES:
        side = int((SOFTWARE_MAX_RESOURCE_BYTES / HDR_TARGET_BYTES_PER_PIXEL) ** 0.5)
        raise InputError(f"{width}x{height}: the HDR target would take {need >> 20} MiB, more "
                         f"than the {SOFTWARE_MAX_RESOURCE_BYTES >> 20} MiB a software "
                         f"rasteriser allocates at once (about {side}x{side} px at most)",
                         field="--size")


def new_renderer(ctx, size, **options):
    """A FrameRenderer of ``size`` on ``ctx``, the size checked first (:func:`check_gl_size`);
    a framebuffer the driver still refuses is the same one line naming --size."""
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415

    check_gl_size(ctx, size)
    try:
        return FrameRenderer(ctx, size, **options)
    except Exception as exc:  # noqa: BLE001 - moderngl.Error is the GL driver's refusal
        if "framebuffer" not in str(exc).lower():
            raise
        width, height = size
        raise InputError(f"{width}x{height}: this GL context cannot make a framebuffer that "
                         f"large ({' '.join(str(exc).split())[:80]})", field="--size") from None


def check_output(path: str | Path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in IMAGE_SUFFIXES:
        raise InputError(f"{str(path)!r}: the image must end in .exr (linear) or .png (sRGB)",
                         field="--out")
    if path.exists() and path.is_dir():
        raise InputError(f"{str(path)!r} is a folder", field="--out")
    return path


@dataclass(frozen=True)
class SnapshotRequest:
    fabric: str
    light: str
    size: tuple[int, int]
    out: Path
    frame: int = 0
    fluorescence: str = "physical"    # "off" | "paper" | "physical"
    bands: int = 3
    hour: float | None = None
    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    distance_m: float = 2.6
    target: tuple | None = None       # the orbit's target (m); None: the curtain's middle
    fov_y_deg: float | None = None    # vertical field of view; None: the camera's default
    exposure: float = 1.0
    ev: float | None = None           # EV100; None: automatic exposure
    white_balance: str = "room"
    environment: str | None = None    # FILE.exr behind the window (issue 13)
    curtain_open: bool = False
    room_light: bool = True
    bloom: bool = True
    lamps: tuple = ()                 # (light name, (x, y, z) m) placed in the room
    room: str = "box"                 # a built-in room or FILE.glb (lit by its transport)


def simulated_curtain(preset, frames: int, placement=None):
    """The curtain after ``frames`` frames of the cloth simulation started from the settled
    drape (frame 0: the settled drape itself; catalog.cloth.drape), hung on the rod of
    ``placement`` (catalog.render.placement; None: the box's). Returns (positions, normals,
    uv, tangents, indices, fabric size (w, h) m)."""
    simulation = curtain_simulation(preset, placement)
    simulation.run(frames, FRAME_DT_S)
    return curtain_on_rod(simulation, placement)


def curtain_simulation(preset, placement=None):
    """The preset's cloth simulation at the settled drape (frame 0) for the rod of
    ``placement``; step it by ``FRAME_DT_S`` for the next frames (catalog render-catalog
    steps one through them all)."""
    from catalog.cloth.drape import settled_simulation  # noqa: PLC0415
    from catalog.render.placement import placed_drape_params  # noqa: PLC0415

    return settled_simulation(placed_drape_params(preset, placement), backend="numpy")


def curtain_on_rod(simulation, placement=None):
    """A running simulation's curtain moved onto the rod of ``placement`` (None: the box's):
    (positions, normals, uv, tangents, indices, fabric size (w, h) m)."""
    from catalog.cloth.mesh import CurtainMesh  # noqa: PLC0415
    from catalog.render.placement import BOX  # noqa: PLC0415

    params = simulation.params
    mesh = CurtainMesh.from_grid(simulation.positions(), params)
    offset = (placement or BOX).curtain_offset(params)
    return (mesh.positions + offset, mesh.normals, mesh.uv, mesh.tangents[:, :3], mesh.indices,
            (params.width_m, params.height_m))


def ring_xs_m(preset, placement=None) -> list[float]:
    """x of the curtain's rings on the rod of ``placement`` (m, world; None: the box's): the
    settled drape's ring columns."""
    from catalog.cloth.drape import rod_centre_x_m  # noqa: PLC0415
    from catalog.cloth.state import ring_positions  # noqa: PLC0415
    from catalog.render.placement import BOX, placed_drape_params  # noqa: PLC0415

    params = placed_drape_params(preset, placement)
    centre = (placement or BOX).window_centre_x
    return [float(x) - rod_centre_x_m(params) + centre for x in ring_positions(params)[:, 0]]


def check_display_choices(ev, white_balance, exposure=1.0) -> None:
    """--ev, --white-balance and --exposure, refused in one line naming the option."""
    import math  # noqa: PLC0415

    from catalog.render import display  # noqa: PLC0415

    if ev is not None:
        try:
            display.check_ev(ev)
        except CatalogError as exc:
            raise InputError(str(exc).split(": ", 1)[-1], field="--ev") from None
    if white_balance not in display.WHITE_BALANCES:
        raise InputError(f"{white_balance!r}: choose one of {', '.join(display.WHITE_BALANCES)}",
                         field="--white-balance")
    if not (math.isfinite(exposure) and exposure > 0):
        raise InputError(f"{exposure!r} must be a positive number", field="--exposure")


def validate(request: SnapshotRequest):
    """Everything that can be refused before a context exists: the preset, the light, the
    size, the output name. Returns (preset, light)."""
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render import bands as band_lib  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    check_output(request.out)
    width, height = request.size
    parse_size(f"{width}x{height}")
    from catalog.core import validate as checks  # noqa: PLC0415

    checks.check_frame(request.frame, "--frame")
    checks.check_camera({"--distance": request.distance_m, "--exposure": request.exposure,
                         "--yaw": request.yaw_deg, "--pitch": request.pitch_deg})
    band_lib.check_band_count(request.bands)
    check_display_choices(request.ev, request.white_balance, request.exposure)
    preset = load_preset(find_preset(request.fabric))
    scene_lib.dye_transmittance(preset)
    scene_lib.fluorescent_material(preset)
    light = get_light(request.light) if request.hour is None else None
    if request.environment is not None:
        from catalog.render.environment import load_environment  # noqa: PLC0415

        load_environment(request.environment)  # refused now, before a context exists
    from catalog.room.load import room_path  # noqa: PLC0415

    room_path(request.room)   # a name or a file; its rules are checked as it loads (set_room)
    from catalog.render import curtain_frames  # noqa: PLC0415

    if len(request.lamps) > curtain_frames.MAX_ROOM_LAMPS:
        raise InputError(f"at most {curtain_frames.MAX_ROOM_LAMPS} lamps, got {len(request.lamps)}",
                         field="--lamp")
    for name, position in request.lamps:
        get_light(name)
        try:
            curtain_frames.check_lamp_position(position)
        except CatalogError as exc:
            raise InputError(str(exc), field="--lamp") from None
    return preset, light


def render_snapshot(request: SnapshotRequest, ctx=None) -> dict:
    """Render one image as asked and write it; returns a JSON-able report. Without ``ctx``, in
    a context of its own, released after (the caller's current context current again)."""
    from catalog.gl.context import headless_context  # noqa: PLC0415

    preset, light = validate(request)
    with headless_context(ctx) as ctx:
        return _snapshot_in(ctx, request, preset, light)


def _snapshot_in(ctx, request: SnapshotRequest, preset, light) -> dict:
    import time  # noqa: PLC0415

    from catalog.gl.context import describe  # noqa: PLC0415

    renderer = new_renderer(ctx, request.size)
    try:
        sun = configure_renderer(renderer, request, preset, light)
        placement = renderer.placement     # the room's window (catalog.render.placement)
        *mesh, fabric_size = simulated_curtain(preset, request.frame, placement)
        renderer.set_mesh(*mesh, fabric_size_m=fabric_size)
        renderer.set_rings(ring_xs_m(preset, placement))
        mesh_source = ("settled drape" if request.frame == 0
                       else f"cloth simulation from the settled drape, frame {request.frame}")
        start = time.perf_counter()
        renderer.render()
        pixels = (renderer.read_linear() if request.out.suffix.lower() == ".exr"
                  else renderer.read_srgb8())
        render_s = time.perf_counter() - start
        info = renderer.info()
    finally:
        renderer.release()
    if not np.all(np.isfinite(pixels)):
        raise CatalogError("the render has NaN or infinite pixels; nothing written")
    metadata = image_metadata(info, request.frame, request.out.suffix.lower() == ".exr")
    write_image(request.out, pixels, metadata)
    report = dict(info)
    report.update({"out": str(request.out), "frame": request.frame, "mesh": mesh_source,
                   "render_s": round(render_s, 4), "gl": describe(ctx),
                   "mean_linear_rgb" if pixels.dtype == np.float32 else "mean_srgb8":
                   [round(float(v), 4) for v in pixels.reshape(-1, 3).mean(axis=0)]})
    if sun is not None:
        report["sun"] = sun
    return report


def configure_renderer(renderer, request: SnapshotRequest, preset, light):
    """Every renderer setting a snapshot depends on but the mesh, from ``request`` (the
    preset and light already loaded). Returns the sun's report with ``request.hour``."""
    renderer.update(snapshot_settings(request, preset, light, renderer.settings))
    return renderer.settings.sun_hour


def snapshot_settings(request: SnapshotRequest, preset, light, base=None):
    """The scene value (:class:`catalog.render.settings.FrameSettings`) a snapshot draws:
    ``base`` (None: the defaults) with every field ``request`` sets, the preset and light (or
    ``request.hour``'s sun) as loaded; the camera looks at and stays inside the room's own
    placement (catalog.render.placement: its window's curtain, its interior)."""
    from catalog.render.placement import room_placement  # noqa: PLC0415
    from catalog.render.settings import FrameSettings, SunHour, orbit  # noqa: PLC0415

    placement = room_placement(request.room)   # where the camera may go: the room's inside
    return (base or FrameSettings()).replace(
        fabric=preset, light=light if request.hour is None else SunHour(request.hour),
        fluorescence=request.fluorescence, bands=request.bands,
        camera=orbit(request.yaw_deg, request.pitch_deg, request.distance_m,
                     target=request.target, fov_y_deg=request.fov_y_deg, inside=True,
                     placement=placement),
        exposure=request.exposure, ev=request.ev, white_balance=request.white_balance,
        curtain_open=request.curtain_open, room_lighting=request.room_light,
        bloom=request.bloom, environment=request.environment, lamps=request.lamps,
        room=request.room)


def image_metadata(info: dict, frame: int, linear: bool) -> dict:
    """The metadata a snapshot writes, from the renderer's ``info()``."""
    metadata = {
        "ImageDescription": f"catalog snapshot: {info['fabric']} under {info['light']}, "
                            f"fluorescence {info['fluorescence_variant']}",
        "catalog:fabric": info["fabric"],
        "catalog:light": info["light"],
        "catalog:mode": info["mode"],
        "catalog:fluorescence_variant": info["fluorescence_variant"],
        "catalog:bands": str(info["bands"]),
        "catalog:frame": str(frame),
        "catalog:encoding": ("linear sRGB primaries, Y in cd/m2 (scene-referred)"
                             if linear
                             else "sRGB; CAT16 white balance, Michaelis-Menten tone curve, "
                                  "OKLab gamut compression (docs/display.md)"),
        "catalog:ev100": f"{info['ev100']:.4f}",
        "catalog:exposure_scale": repr(info["exposure"]),
        "catalog:auto_exposure": str(info["auto_exposure"]).lower(),
        "catalog:white_balance": info["white_balance"],
    }
    if linear:
        metadata.update(exr_colour_metadata())
    return metadata
