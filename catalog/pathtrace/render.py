"""``catalog reference``: the path-traced radiance of the snapshot scene, as a linear EXR.

Same arguments as ``catalog snapshot`` (fabric, light, cloth frame, size, camera distance)
plus the sample count; the EXR holds linear sRGB radiance in the frame's units (Y in
cd m^-2), exposure-free, written atomically (nothing is left behind on an error).

Integrator: Mitsuba's ``volpath`` (a unidirectional path tracer with next-event estimation
and MIS; unlike ``path`` it carries shadow rays through null surfaces, the cloth's gaps),
MAX_DEPTH bounces with Russian roulette after RR_DEPTH. With grey walls of albedo 0.6 the
light left after 16 bounces is 0.6^16 = 3e-4 of the first: the room's inter-reflections
are converged in depth; the remaining error is noise (docs/pathtrace.md: the spp for a
stated noise level, estimated from two independent renders).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.errors import CatalogError, InputError

MAX_DEPTH = 16
RR_DEPTH = 5
#: The largest sample count accepted (a guard against typing an extra zero).
MAX_SPP = 1 << 16
#: Host memory a reference pixel costs, bytes (an upper estimate: Mitsuba's film with its
#: weights, the float32 and float64 copies of the image, the region masks, the EXR buffer);
#: checked against a quarter of physical memory before Mitsuba is loaded, as snapshot's
#: frame is. Measured: the peak resident size did not change with spp (4 to 256).
REFERENCE_BYTES_PER_PIXEL = 128


@dataclass(frozen=True)
class ReferenceRequest:
    """A reference render: the scene the real-time frame draws (``scene``, a
    :class:`catalog.render.settings.FrameSettings` whose room is resolved; built by
    :func:`reference_settings`), at ``size``, with the path tracer's own choices."""

    scene: object
    size: tuple[int, int]
    out: Path | None
    spp: int = 64
    frame: int = 0
    variant: str = "llvm_ad_rgb"
    seed: int = 0
    max_depth: int = MAX_DEPTH


def reference_settings(fabric, light, *, yaw_deg: float = 0.0, pitch_deg: float = 0.0,
                       distance_m: float = 2.6, fluorescence: str = "physical", room="box",
                       inside: bool = False, **fields):
    """The scene value (:class:`catalog.render.settings.FrameSettings`) of ``fabric`` under
    ``light`` in ``room``, everything resolved here, at the edge: the preset and its Fabric
    tables, the light, the room loaded (a name, a .glb path or a Room) and the orbit camera
    (looking at the curtain of the room's window; ``inside``: kept inside the room's own
    interior, catalog.render.placement, as every command's is). ``fields``: any other
    FrameSettings field (e.g. ``key_direction_deg``). Bad input: one line naming the option."""
    from catalog.core import validate as checks  # noqa: PLC0415
    from catalog.render.placement import placement_of_room  # noqa: PLC0415
    from catalog.render.settings import FrameSettings, orbit  # noqa: PLC0415
    from catalog.room.model import Room  # noqa: PLC0415

    checks.check_camera({"--yaw": yaw_deg, "--pitch": pitch_deg})
    if not (math.isfinite(distance_m) and distance_m > 0.05):
        raise InputError(f"{distance_m!r} m: the camera distance must exceed 0.05 m",
                         field="--distance")
    settings = FrameSettings(fabric=fabric, light=light, fluorescence=fluorescence, **fields)
    if not isinstance(room, Room):
        from catalog.room.load import load_room  # noqa: PLC0415

        room = load_room(room)   # a bad room is refused before Mitsuba loads
    # the camera looks at the curtain of this room's window and (``inside``) stays in its own
    # interior, as catalog snapshot's does (catalog.render.snapshot.snapshot_settings)
    placement = placement_of_room(room)
    return settings.replace(camera=orbit(yaw_deg, pitch_deg, distance_m, inside=inside,
                                         placement=placement), room=room)


def check_out(path) -> Path:
    path = Path(path)
    if path.suffix.lower() != ".exr":
        raise InputError(f"{str(path)!r}: the reference is linear radiance: the name must end "
                         "in .exr", field="--out")
    if path.is_dir():
        raise InputError(f"{str(path)!r} is a folder", field="--out")
    parent = path.parent if str(path.parent) else Path(".")
    if parent.exists() and not parent.is_dir():
        raise InputError(f"{str(parent)!r} is not a folder", field="--out")
    import os  # noqa: PLC0415

    probe = parent
    while not probe.exists():
        probe = probe.parent
    if not os.access(probe, os.W_OK | os.X_OK):
        raise InputError(f"{str(path)!r} cannot be written (no write permission in "
                         f"{str(probe)!r})", field="--out")
    return path


def validate(request: ReferenceRequest) -> None:
    """Refuse bad input before Mitsuba is loaded (the scene was resolved when its value was
    made: :func:`reference_settings`)."""
    check_options(request)
    if getattr(request.scene, "resolved_room", None) is None or request.scene.fabric is None \
            or request.scene.key_light is None:
        raise CatalogError("the reference draws a resolved scene: a FrameSettings with a "
                           "fabric, a light and a loaded Room (reference_settings)")


def check_options(request: ReferenceRequest) -> None:
    """The path tracer's own options (all but the scene), each refused in one line."""
    from catalog.pathtrace.backend import check_variant  # noqa: PLC0415
    from catalog.render.snapshot import parse_size  # noqa: PLC0415

    if request.out is not None:
        check_out(request.out)
    check_variant(request.variant)
    if not (isinstance(request.spp, int) and 1 <= request.spp <= MAX_SPP):
        raise InputError(f"{request.spp!r} samples per pixel: give a whole number in 1..{MAX_SPP}",
                         field="--spp")
    width, height = request.size
    parse_size(f"{width}x{height}")
    from catalog.core import validate as checks  # noqa: PLC0415

    checks.frame_memory_check(width, height, REFERENCE_BYTES_PER_PIXEL, "--size")
    checks.check_frame(request.frame, "--frame")
    checks.check_seed(request.seed, "--seed")
    if not 1 <= request.max_depth <= 256:
        raise InputError(f"{request.max_depth} must lie in 1..256", field="--max-depth")


def describe(request: ReferenceRequest):
    """The path tracer's :class:`catalog.pathtrace.scene.SceneDescription` of the request."""
    from catalog.pathtrace.scene import describe_scene  # noqa: PLC0415

    validate(request)
    return describe_scene(request.scene, size=request.size, frame=request.frame)


#: A spectral variant renders in this many passes (or one a sample when spp is smaller):
#: Mitsuba's volpath in a spectral variant returns NaN for a rare sample (issue 11, seventh
#: round: 2-5 pixels of 27 648 at 512 spp on the close-ups, none with the ``path``
#: integrator or in the RGB variant), which makes the whole pixel NaN. A pixel's pass that is
#: NaN is left out of its mean, a 1/8 of its samples; the passes' seeds are distinct.
SPECTRAL_PASSES = 8
#: `catalog reference` renders in this many passes in any variant (or one a sample when spp
#: is smaller): the progress counts them, and the image is the same with or without it.
REFERENCE_PASSES = 8


def render_radiance(mi, scene, spp: int, seed: int = 0, report: dict | None = None,
                    passes: int = 1, on_pass=None) -> np.ndarray:
    """(H, W, 3) float32 linear radiance of a loaded scene: the spp-weighted mean of
    ``passes`` renders with distinct seeds (at least SPECTRAL_PASSES in a spectral variant; at
    most one a sample), each pixel over its finite passes (``report``, when given, gets
    ``nan_pixel_passes``: how many pixel-passes were left out). ``on_pass(samples)``: called
    after each pass with its samples per pixel (the progress)."""
    spp, seed = int(spp), int(seed)
    passes = min(max(int(passes), SPECTRAL_PASSES if mi.is_spectral else 1), spp)
    if passes == 1:
        image = np.asarray(mi.render(scene, spp=spp, seed=seed), dtype=np.float32)[..., :3]
        if on_pass is not None:
            on_pass(spp)
        if report is not None:
            report["nan_pixel_passes"] = int(np.sum(~np.all(np.isfinite(image), axis=-1)))
        return image
    total, weight, dropped = None, None, 0
    for k in range(passes):
        count = spp // passes + (1 if k < spp % passes else 0)
        image = np.asarray(mi.render(scene, spp=count, seed=seed * passes + k), dtype=np.float64)[..., :3]
        finite = np.all(np.isfinite(image), axis=-1, keepdims=True)
        dropped += int(np.sum(~finite))
        contribution = np.where(finite, image * count, 0.0)
        total = contribution if total is None else total + contribution
        weight = finite * count if weight is None else weight + finite * count
        if on_pass is not None:
            on_pass(count)
    if report is not None:
        report["nan_pixel_passes"] = dropped
    with np.errstate(invalid="ignore", divide="ignore"):
        return (total / weight).astype(np.float32)   # NaN only where every pass was


def render_reference(request: ReferenceRequest, desc=None,
                     progress: bool = False) -> tuple[np.ndarray, dict]:
    """Render the reference (REFERENCE_PASSES passes); write it when ``request.out`` is set.
    ``progress``: the samples rendered, their rate and the time left on stderr
    (catalog.core.progress). Returns (pixels, report)."""
    from catalog.core.progress import progress as progress_bar  # noqa: PLC0415
    from catalog.pathtrace.backend import load_mitsuba  # noqa: PLC0415
    from catalog.pathtrace.scene import build_mitsuba_scene  # noqa: PLC0415

    # bad input first, then the library (one line each), then the scene
    if desc is None:
        desc = describe(request)
    else:
        validate(request)
    mi = load_mitsuba(request.variant)
    start = time.perf_counter()
    scene = build_mitsuba_scene(mi, desc, max_depth=request.max_depth)
    build_s = time.perf_counter() - start
    start = time.perf_counter()
    with progress_bar("catalog reference", total=request.spp, unit="spp",
                      enabled=progress) as bar:
        pixels = render_radiance(mi, scene, request.spp, request.seed,
                                 passes=REFERENCE_PASSES, on_pass=bar.advance)
    render_s = time.perf_counter() - start
    if not np.all(np.isfinite(pixels)):
        raise CatalogError("the reference has NaN or infinite pixels; nothing written")
    report = dict(desc.info)
    report.update({"size": list(desc.size), "spp": request.spp, "variant": request.variant,
                   "integrator": f"volpath, max_depth {request.max_depth}, rr_depth {RR_DEPTH}",
                   "seed": request.seed, "build_s": round(build_s, 4),
                   "render_s": round(render_s, 4),
                   "mean_linear_rgb": [round(float(v), 4) for v in pixels.reshape(-1, 3).mean(0)]})
    if request.out is not None:
        from catalog.render.snapshot import write_image  # noqa: PLC0415

        write_image(request.out, pixels, {
            "ImageDescription": f"catalog reference: {report['fabric']} under {report['light']}, "
                                f"path traced ({request.spp} spp)",
            "catalog:fabric": report["fabric"], "catalog:light": report["light"],
            "catalog:frame": str(request.frame), "catalog:spp": str(request.spp),
            "catalog:variant": request.variant,
            "catalog:fluorescence_variant": report["fluorescence_variant"],
            "catalog:encoding": "linear sRGB primaries, Y in cd/m2 (scene-referred)"})
        report["out"] = str(request.out)
    return pixels, report


def region_masks(mi, scene, desc) -> dict[str, np.ndarray]:
    """Boolean (H, W) masks of what each pixel centre sees: curtain, floor, walls (the four
    walls, the window wall and the ceiling), outside (through the window), other (the rod),
    from a ray per pixel centre through the reference's own camera and geometry."""
    import drjit as dr  # noqa: PLC0415

    from catalog.pathtrace.window_filter import SHEET_ID  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415

    width, height = desc.size
    sensor = scene.sensors()[0]
    index = dr.arange(mi.UInt32, width * height)
    film = mi.Point2f((mi.Float(index % width) + 0.5) / width,
                      (mi.Float(index // width) + 0.5) / height)
    ray, _ = sensor.sample_ray(0.0, 0.5, film, mi.Point2f(0.5, 0.5))
    si = scene.ray_intersect(ray)
    shapes = {s.id(): s for s in scene.shapes()}
    valid = np.asarray(si.is_valid(), dtype=bool)
    on_curtain = np.zeros(valid.shape, dtype=bool)
    for name, shape in shapes.items():  # the cloth and its fluorescence shells
        if name == "curtain" or name.startswith("fluorescence_"):
            on_curtain |= np.asarray(si.shape == mi.ShapePtr(shape), dtype=bool)
    on_curtain &= valid
    if SHEET_ID in shapes:   # the spectral outside's filter sheet (window_filter) is the outside
        valid &= ~np.asarray(si.shape == mi.ShapePtr(shapes[SHEET_ID]), dtype=bool)
    on_room = valid & ~on_curtain
    p = np.asarray(si.p, dtype=np.float64)
    p = p.T if p.shape[0] == 3 else p
    (x0, x1), (y0, y1), (z0, z1) = scene_lib.ROOM_BOX
    tol = 2e-3
    floor = on_room & (np.abs(p[:, 1] - y0) < tol)
    walls = on_room & ~floor & ((np.abs(p[:, 1] - y1) < tol) | (np.abs(p[:, 0] - x0) < tol)
                                | (np.abs(p[:, 0] - x1) < tol) | (np.abs(p[:, 2] - z1) < tol)
                                | (np.abs(p[:, 2] - z0) < tol))
    masks = {"curtain": on_curtain, "floor": floor, "walls": walls, "outside": ~valid,
             "other": on_room & ~floor & ~walls}
    return {k: v.reshape(height, width) for k, v in masks.items()}
