"""Before/after frames of the real-time renderer (issue 31: a refactor must not change a frame).

    PYTHONPATH=TREE python tools/frame_check.py render OUT.npz MESHES.npz
    PYTHONPATH=TREE python tools/frame_check.py accuracy OUT.npz [WIDTHxHEIGHT]
    python tools/frame_check.py compare BEFORE.npz AFTER.npz

``render`` draws CASES (the image bench's six scenes and options a user changes; an option
is a FrameSettings field) at 320x180 with the tree on PYTHONPATH (e.g. ``git archive
before-31 | tar -x -C /tmp/base``: a tree without FrameSettings is driven by its setters) and writes
each frame's linear radiance and its sRGB8 display image; the cloth's settled meshes are
written to MESHES.npz on the first run and read on the next, so both trees draw the same
vertices. ``compare`` prints per case the largest and mean relative difference of the linear
frames (|a - b| / max(|a|, 1e-3 max |a|)), the largest sRGB8 step and the mean FLIP of the
display images (catalog.pathtrace.metrics.flip_map), then the worst of each.

``accuracy`` draws the accuracy bench's report scenes instead (benchmarks/accuracy.py:
draw_scenes(DEFAULT_SCENES, REPORT_SEED), each as its ``measure_scene`` draws the frame:
describe_scene's settled drape in the scene's room, benchmarks.image.frame_images), at
ACCURACY_SIZE unless given; ``compare`` reads either file.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

SIZE = (320, 180)
ACCURACY_SIZE = (640, 360)
VIEWS = {"room": (20.0, 15.0, 2.6), "close-up": (0.0, 0.0, 0.8), "outside": (180.0, 5.0, 2.6)}


def cases() -> list:
    """(label, fabric, light name or None, view, options)."""
    from catalog.render.scene import sun_at_hour

    NOON = sun_at_hour(12.0).light_name
    BASE = [("lace-fwa", NOON, "room"), ("voile-white", "D65", "room"), ("safety-yellow", "UV-A", "room"),
            ("lace-fwa", "UV-A", "close-up"), ("voile-white", NOON, "close-up"), ("safety-yellow", "D65", "close-up")]
    CASES = [(f"{f}|{l}|{v}", f, l, v, {}) for f, l, v in BASE]
    CASES += [
        ("bands6", "lace-fwa", NOON, "room", {"bands": 6}),
        ("bands16", "voile-white", "D65", "close-up", {"bands": 16}),
        ("paper", "safety-yellow", "UV-A", "room", {"fluorescence": "paper"}),
        ("aa-off", "lace-fwa", NOON, "room", {"antialiasing": "off"}),
        ("room-off", "voile-white", "D65", "room", {"room_lighting": False}),
        ("shadow512", "lace-fwa", NOON, "room", {"shadow_map_size": 512}),
        ("flat", "voile-white", NOON, "room", {"patterned": False}),
        ("open", "lace-fwa", NOON, "room", {"curtain_open": True}),
        ("lamps", "voile-white", "D65", "room", {"lamps": [("A", (0.5, 0.3, 1.5))]}),
        ("hour9", "lace-fwa", None, "room", {"sun_hour": 9.0}),
        ("outside", "voile-white", NOON, "outside", {}),
        ("bloom-off", "lace-fwa", NOON, "close-up", {"bloom": False}),
        ("ev-camera", "safety-yellow", "D65", "room", {"ev": 9.0, "white_balance": "camera"}),
    ]
    return CASES


def render(out: Path, meshes_path: Path) -> None:
    from catalog.gl.context import create_headless_context
    from catalog.presets import find_preset, load_preset
    from catalog.render.frame import FrameRenderer
    from catalog.render.snapshot import ring_xs_m, simulated_curtain

    meshes = dict(np.load(meshes_path, allow_pickle=True)) if meshes_path.exists() else {}
    new_meshes = {}
    ctx = create_headless_context()
    frames, srgb = {}, {}
    for label, fabric, light, view, opts in cases():
        t = time.perf_counter()
        preset = load_preset(find_preset(fabric))
        if f"{fabric}/p" not in meshes:
            *mesh, fs = simulated_curtain(preset, 0)
            for k, a in zip("pnutif", mesh + [np.asarray(fs)]):
                meshes[f"{fabric}/{k}"] = new_meshes[f"{fabric}/{k}"] = np.asarray(a)
            meshes[f"{fabric}/rings"] = new_meshes[f"{fabric}/rings"] = np.asarray(ring_xs_m(preset))
        mesh = [meshes[f"{fabric}/{k}"] for k in "pnuti"]
        r = _renderer(FrameRenderer, ctx, preset, light, view, opts)
        r.set_mesh(*mesh, fabric_size_m=tuple(meshes[f"{fabric}/f"]))
        r.set_rings(list(meshes[f"{fabric}/rings"]))
        r.render(); r.render()
        frames[label] = r.read_linear()
        srgb[label] = r.read_srgb8()
        r.release()
        print(f"{label}: {time.perf_counter() - t:.1f} s", file=sys.stderr)
    np.savez_compressed(out, **{f"lin:{k}": v for k, v in frames.items()}, **{f"srgb:{k}": v for k, v in srgb.items()})
    if new_meshes and not meshes_path.exists():
        np.savez(meshes_path, **meshes)


def render_accuracy(out: Path, size=ACCURACY_SIZE) -> None:
    from benchmarks import accuracy
    from benchmarks.image import frame_images
    from catalog.gl.context import create_headless_context
    from catalog.optics.lights import get_light
    from catalog.pathtrace.render import reference_settings
    from catalog.pathtrace.scene import describe_scene
    from catalog.presets import find_preset, load_preset

    ctx = create_headless_context()
    frames, srgb = {}, {}
    for scene in accuracy.draw_scenes(accuracy.DEFAULT_SCENES, accuracy.REPORT_SEED):
        t = time.perf_counter()
        preset, light, cam = load_preset(find_preset(scene["fabric"])), get_light(scene["light"]), scene["camera"]
        desc = describe_scene(reference_settings(preset, light, yaw_deg=cam["yaw_deg"], pitch_deg=cam["pitch_deg"],
                                                 distance_m=cam["distance_m"], room=scene["room"]), size=tuple(size))
        frame = frame_images(ctx, desc, preset, light, 3, "physical", repeats=1, room=scene["room"])
        frames[scene["label"]] = frame["linear"]
        srgb[scene["label"]] = np.round(255.0 * frame["display"]).astype(np.uint8)
        print(f"{scene['label']}: {time.perf_counter() - t:.1f} s", file=sys.stderr)
    np.savez_compressed(out, **{f"lin:{k}": v for k, v in frames.items()}, **{f"srgb:{k}": v for k, v in srgb.items()})


def _renderer(FrameRenderer, ctx, preset, light, view, opts):
    """A FrameRenderer of the case: from its FrameSettings, or (a tree before the settings
    value, e.g. the tag before-31) through the setters the options name."""
    options = {"antialiasing": "fxaa", **opts}
    try:
        from catalog.render.settings import FrameSettings, SunHour, orbit
    except ImportError:
        r = FrameRenderer(ctx, SIZE)
        r.set_fabric(preset)
        if light is not None:
            r.set_light(light)
        setters = {"lamps": "room_lamps"}
        for name, value in options.items():
            getattr(r, f"set_{setters.get(name, name)}")(value)
        r.set_camera(*VIEWS[view])
        return r
    if "sun_hour" in options:
        options["light"] = SunHour(options.pop("sun_hour"))
    elif light is not None:
        options["light"] = light
    return FrameRenderer(ctx, SIZE, FrameSettings(fabric=preset, camera=orbit(*VIEWS[view]), **options))


def compare(before: Path, after: Path) -> float:
    from catalog.pathtrace.metrics import flip_map

    a, b = np.load(before), np.load(after)
    worst = worst_flip = 0.0
    for k in a.files:
        if not k.startswith("lin:"): continue
        x, y = a[k].astype(np.float64), b[k].astype(np.float64)
        scale = np.maximum(np.abs(x), 1e-3 * max(np.abs(x).max(), 1e-30))
        rel = np.abs(x - y) / scale
        d8 = np.abs(a["srgb:" + k[4:]].astype(int) - b["srgb:" + k[4:]].astype(int)).max()
        flip = float(flip_map(b["srgb:" + k[4:]] / 255.0, a["srgb:" + k[4:]] / 255.0).mean())
        worst, worst_flip = max(worst, rel.max()), max(worst_flip, flip)
        print(f"{k[4:]:34s} max rel {rel.max():.2e}  mean rel {rel.mean():.2e}  srgb8 max diff {d8}"
              f"  mean FLIP {flip:.5f}")
    print("worst", worst, "worst mean FLIP", worst_flip)
    return worst


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "render":
        render(Path(sys.argv[2]), Path(sys.argv[3]))
    elif len(sys.argv) in (3, 4) and sys.argv[1] == "accuracy":
        render_accuracy(Path(sys.argv[2]), *([tuple(int(v) for v in sys.argv[3].split("x"))] if len(sys.argv) == 4 else []))
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        compare(Path(sys.argv[2]), Path(sys.argv[3]))
    else:
        print("\n".join(__doc__.strip().splitlines()[2:4]), file=sys.stderr)
        sys.exit(2)
