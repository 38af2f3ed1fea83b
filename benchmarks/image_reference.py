"""One scene's path-traced reference for the image section, in a process of its own.

``benchmarks.image`` renders a scene's reference in the Mitsuba variant the scene needs
(:func:`benchmarks.image.reference_variant_for`). Mitsuba's JIT crashed (a segfault) when
the variant was switched after renders in the same process, so a scene whose variant is not
the bench process's own is rendered here, in a child process, and handed back as an .npz:
the two half renders ``a`` and ``b``, the region masks ``mask_*``, the render time
``seconds`` (wall) and ``cpu_seconds`` (the process's CPU time, every thread: the two halves,
scene building excluded) and ``nan_pixel_passes``.

    python -m benchmarks.image_reference FABRIC LIGHT YAW PITCH DISTANCE WIDTH HEIGHT SPP VARIANT OUT.npz [FIRST_SEED [ROOM]]

(LIGHT a light's name; YAW, PITCH in degrees and DISTANCE in metres: the view's camera; ROOM a
built-in room or a .glb, the box when left out.)
"""

from __future__ import annotations

import sys
import time

import numpy as np


def render_halves(mi, desc, spp: int, first_seed: int = 0) -> dict:
    """The scene ``desc``'s two half renders (spp / 2 each, seeds ``first_seed`` and
    ``first_seed + 1``), its region masks, the halves' wall time (``seconds``) and CPU time
    (``cpu_seconds``: this process's, all of Mitsuba's threads; it does not grow with the
    machine's load as the wall time does) and the pixel-passes left out as NaN."""
    from catalog.pathtrace.render import MAX_DEPTH, region_masks, render_radiance  # noqa: PLC0415
    from catalog.pathtrace.scene import build_mitsuba_scene  # noqa: PLC0415

    scene = build_mitsuba_scene(mi, desc, max_depth=MAX_DEPTH)
    start, cpu_start = time.perf_counter(), time.process_time()
    report_a, report_b = {}, {}
    a = render_radiance(mi, scene, spp // 2, seed=first_seed, report=report_a)
    b = render_radiance(mi, scene, spp // 2, seed=first_seed + 1, report=report_b)
    seconds, cpu_seconds = time.perf_counter() - start, time.process_time() - cpu_start
    return {"a": a, "b": b, "masks": region_masks(mi, scene, desc), "seconds": seconds,
            "cpu_seconds": cpu_seconds,
            "nan_pixel_passes": report_a["nan_pixel_passes"] + report_b["nan_pixel_passes"]}


def main(argv=None) -> int:
    from catalog.core.atomic import atomic_path  # noqa: PLC0415
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.pathtrace.backend import load_mitsuba  # noqa: PLC0415
    from catalog.pathtrace.render import reference_settings  # noqa: PLC0415
    from catalog.pathtrace.scene import describe_scene  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415

    args = list(argv or sys.argv[1:])
    room = args.pop() if len(args) == 12 else "box"
    first_seed = int(args.pop()) if len(args) == 11 else 0
    fabric, light, yaw, pitch, distance, width, height, spp, variant, out = args
    desc = describe_scene(reference_settings(load_preset(find_preset(fabric)), get_light(light),
                                             yaw_deg=float(yaw), pitch_deg=float(pitch),
                                             distance_m=float(distance), room=room),
                          size=(int(width), int(height)))
    result = render_halves(load_mitsuba(variant), desc, int(spp), first_seed)
    with atomic_path(out) as tmp:
        with open(tmp, "wb") as handle:
            np.savez(handle, a=result["a"], b=result["b"], seconds=result["seconds"],
                     cpu_seconds=result["cpu_seconds"], nan_pixel_passes=result["nan_pixel_passes"],
                     **{f"mask_{name}": mask for name, mask in result["masks"].items()})
    return 0


if __name__ == "__main__":
    sys.exit(main())
