"""Accuracy over the whole scene space: the frame against the path-traced reference (issue 33).

``catalog bench --sections accuracy --scenes N --seed S [--room NAME] --json``

N scenes are drawn at random (``numpy.random.default_rng(S)``, :func:`draw_scenes`) from what a
user can choose: every catalog fabric; a light family drawn uniformly from :data:`LIGHT_FAMILIES`
(the sun by hour 6-20 h, the sun by path, CIE illuminants, LEDs, the UV and violet lamps) and a
light within it; the camera's yaw, pitch and distance over the viewer's range on the room side
(:data:`YAW_RANGE_DEG`, :data:`PITCH_RANGE_DEG`, the distance log-uniform from 0.3 m to the
room's limit); the room (one of the built-in rooms, :data:`ROOMS`). The curtain is closed:
``catalog reference`` has no open curtain, so an open one cannot be judged yet.

For each scene the frame (:class:`catalog.render.frame.FrameRenderer`, the linear radiance
``catalog snapshot`` writes to EXR) and the reference (``catalog reference``'s Mitsuba scene, two
independent halves) are rendered at SIZE and compared at SIZE / MEASURE_REDUCTION (each compared
pixel the mean of MEASURE_REDUCTION^2 rendered ones, linear radiance: the view as seen from
twice as far, FLIP at the same pixels per degree), both shown through ONE neutral display
defined here, not the product's (:func:`neutral_display`):

- exposure from the reference alone: its luminance's 99th percentile maps to
  :data:`P99_TARGET` (1.0) before the tone curve; the frame gets the same scale;
- a fixed tone curve per channel, extended Reinhard with white :data:`TONE_WHITE`:
  t(x) = x (1 + x / w^2) / (1 + x), clipped to [0, 1] (the 99th percentile lands at 0.625);
- no white balance (the sRGB white, D65), no glare, the sRGB curve.

Measured per scene: the mean LDR-FLIP of the two display images; the curtain's Delta E 2000
(colour-science's CIEDE2000 on CIELAB of the display images, D65 white, on the compared pixels
wholly on the cloth, by centre rays through the reference's own geometry), its mean; the
reference's own noise, the mean FLIP of its two halves (two seeds) shown through the same
display (each half has sqrt(2) the noise of their mean, so this bounds the noise's share from
above); the same two figures at the rendered size (``*_full_size``); the frame's time (median of
repeats with glFinish) and the reference's (its halves at the spp it ended with, scene building
excluded), both at SIZE.

The noise rule (:func:`adaptive_reference`): the reference is rendered in rounds of new seeds,
START_SPP first and each round doubling the total, until its noise is below NOISE_SHARE (a fifth)
of the FLIP it judges, or the next round would pass the SPP cap or REFERENCE_BUDGET_CPU_S (a
round takes about as long as all before it). The budget counts the reference's CPU time (its
process's, every Mitsuba thread), not wall time, so where the rule stops does not depend on how
loaded the machine is. The reference is never judged by the frame's look, only
by its own noise against the error; each row says whether the rule holds
(``noise_below_fifth``), the spp it ended with and each round's figures (``spp_rounds``).

Seeds: :data:`TUNE_SEED` for choosing, :data:`REPORT_SEED` (fixed before the report run) for the
published figures (``python -m benchmarks.accuracy record`` regenerates them).
"""

from __future__ import annotations

import functools
import math
import time
from pathlib import Path

import numpy as np

from catalog.gl.context import own_context_unless_given

#: Seeds: choose on TUNE_SEED, report on REPORT_SEED (fixed before the report was run).
TUNE_SEED = 1
REPORT_SEED = 33033
#: Rooms this bench draws among (the built-in rooms, catalog.room.load.BUILTIN_ROOMS), each
#: drawn in the frame by its transport and in the reference from the same file.
ROOMS = ("box", "living", "bedroom")
SIZE = (160, 90)
QUICK_SIZE = (64, 36)
#: The noise rule: a scene's reference is rendered in rounds (the first of START_SPP, each
#: next one doubling the total) until its own noise, the mean FLIP of its two halves (two seeds),
#: is below NOISE_SHARE of the FLIP it judges, or SPP (the cap) is reached, or the next round
#: would take the scene's reference past REFERENCE_BUDGET_CPU_S of CPU time (its CPU time so far
#: doubles). CPU time, not wall: the rule must not depend on the machine's load (a wall budget
#: bought 64-1024 spp for like scenes as others' load came and went).
NOISE_SHARE = 0.2
START_SPP = 64
QUICK_START_SPP = 32
SPP = 1024
QUICK_SPP = 64
REFERENCE_BUDGET_CPU_S = 120.0
QUICK_REFERENCE_BUDGET_CPU_S = 40.0
#: Both images are compared at SIZE / MEASURE_REDUCTION: each compared pixel the mean of
#: MEASURE_REDUCTION^2 rendered ones (linear radiance, before the display), the view as it is
#: seen from MEASURE_REDUCTION times farther at the same FLIP pixels per degree. The rendered
#: size (and the speed comparison, at equal size) stays SIZE.
MEASURE_REDUCTION = 2
DEFAULT_SCENES = 48
QUICK_SCENES = 2
#: The neutral display: the reference's luminance 99th percentile -> P99_TARGET, then the tone
#: curve x (1 + x / TONE_WHITE^2) / (1 + x) (TONE_WHITE maps to 1), clipped, sRGB-encoded.
P99_TARGET = 1.0
TONE_WHITE = 2.0
#: The viewer's camera range drawn (degrees; the room side of the window: a view from outside
#: the window is not drawn).
YAW_RANGE_DEG = (-70.0, 70.0)
PITCH_RANGE_DEG = (-30.0, 45.0)
DISTANCE_MIN_M = 0.3
#: The light families, drawn uniformly, then a light within the family.
LIGHT_FAMILIES = {
    "sun by hour": None,  # an hour uniform in SUN_HOURS -> catalog.render.scene.sun_at_hour
    "sun by path": ("sun:22", "sun:100", "sun:200", "sun:300", "sun:400", "sun:500",
                    "sun-clear:22", "sun-clear:500"),
    "CIE illuminant": ("A", "D50", "D65", "D75", "FL2", "FL7", "FL11", "HP1"),
    "LED": ("LED-B1", "LED-B3", "LED-B5", "LED-BH1", "LED-RGB1", "LED-V1", "LED-warm"),
    "UV and violet lamp": ("UV-A", "UV-385", "LED-405", "LED-violet-white"),
}
SUN_HOURS = (6.0, 20.0)
#: The sun is drawn only where the product has it above the horizon (zenith below this).
SUN_ZENITH_LIMIT_DEG = 89.0


@functools.lru_cache(maxsize=1)
def sun_hours() -> tuple[float, float]:
    """SUN_HOURS cut to where the product's sun is up (zenith < SUN_ZENITH_LIMIT_DEG), 0.01 h steps."""
    from catalog.render.scene import solar_zenith_deg  # noqa: PLC0415

    up = [h for h in np.arange(SUN_HOURS[0], SUN_HOURS[1] + 1e-9, 0.01)
          if solar_zenith_deg(float(h)) < SUN_ZENITH_LIMIT_DEG]
    return float(up[0]), float(up[-1])
#: The issue's goals (issue 33), on at least 48 report scenes.
GOAL = {"median_mean_flip_at_most": 0.06, "p90_mean_flip_at_most": 0.09, "max_mean_flip_at_most": 0.12,
        "median_curtain_delta_e_at_most": 1.5, "speedup_at_least": 1000.0}
#: The image bench's six scenes as named cases (``--seed`` none: ``named_cases()``).
RESULT_JSON = "benchmarks/bench_accuracy.json"
#: The CI sample (tests/test_bench_accuracy.py): ``catalog bench --quick --sections accuracy
#: --scenes CI_SCENES --seed CI_SEED`` (QUICK_SIZE, QUICK_SPP), its recorded rows in CI_JSON
#: (``python -m benchmarks.accuracy ci``). The tune seed's first scenes.
CI_SEED = TUNE_SEED
CI_SCENES = 3
CI_JSON = "benchmarks/bench_accuracy_ci.json"
WORST_SHOWN = 3


def catalog_fabrics() -> list[str]:
    from catalog.presets import list_presets  # noqa: PLC0415

    return sorted(p.stem for p in list_presets())


def check_room(room: str) -> str:
    from catalog.core.errors import InputError  # noqa: PLC0415

    if room not in ROOMS:
        raise InputError(f"{room!r} is not a built-in room of this bench; choose from {', '.join(ROOMS)}",
                         field="--room")
    return room


def draw_scenes(count: int, seed: int, room: str | None = None) -> list[dict]:
    """``count`` scenes drawn from the scene space with ``numpy.random.default_rng(seed)``;
    ``room`` None draws among ROOMS. Each: label, fabric, light, camera, room, curtain."""
    from catalog.render.camera import room_limit_m  # noqa: PLC0415
    from catalog.render.placement import placement_of_room  # noqa: PLC0415
    from catalog.render.scene import sun_at_hour  # noqa: PLC0415
    from catalog.room.load import load_room  # noqa: PLC0415

    placements = {}
    rng = np.random.default_rng(seed)
    fabrics = catalog_fabrics()
    families = list(LIGHT_FAMILIES)
    hours = sun_hours()
    scenes = []
    for index in range(count):
        fabric = fabrics[rng.integers(len(fabrics))]
        family = families[rng.integers(len(families))]
        if LIGHT_FAMILIES[family] is None:
            hour = float(rng.uniform(*hours))
            light, light_label = sun_at_hour(hour).light_name, f"sun at {hour:.1f} h"
        else:
            names = LIGHT_FAMILIES[family]
            light = names[rng.integers(len(names))]
            light_label = light
        yaw = float(rng.uniform(*YAW_RANGE_DEG))
        pitch = float(rng.uniform(*PITCH_RANGE_DEG))
        # the distance's variate is drawn before the room (the draws' order of old) and
        # scaled by that room's own limit: the camera stays inside the room it is drawn in
        share = rng.random()
        chosen_room = room or ROOMS[rng.integers(len(ROOMS))]
        if chosen_room not in placements:
            placements[chosen_room] = placement_of_room(load_room(chosen_room))
        placement = placements[chosen_room]
        far = max(DISTANCE_MIN_M * 1.5, room_limit_m(placement.curtain_middle, yaw, pitch,
                                                     placement.interior))
        lo, hi = math.log(DISTANCE_MIN_M), math.log(far)
        distance = float(math.exp(lo + (hi - lo) * share))
        scenes.append({"label": f"{index:02d} {fabric}, {light_label}, yaw {yaw:.0f} pitch {pitch:.0f} "
                                f"at {distance:.2f} m",
                       "fabric": fabric, "light": light, "light_family": family,
                       "camera": {"yaw_deg": round(yaw, 2), "pitch_deg": round(pitch, 2),
                                  "distance_m": round(distance, 3)},
                       "room": chosen_room, "curtain": "closed"})
    return scenes


def named_cases() -> list[dict]:
    """The image bench's six scenes (benchmarks.image.SCENES) in this bench's form."""
    from benchmarks import image  # noqa: PLC0415

    cases = []
    for label, fabric, light_key, view in image.SCENES:
        yaw, pitch, distance = image.VIEWS[view]
        cases.append({"label": label, "fabric": fabric, "light": image.light_name(light_key),
                      "light_family": "named case",
                      "camera": {"yaw_deg": yaw, "pitch_deg": pitch, "distance_m": distance},
                      "room": "box", "curtain": "closed"})
    return cases


def luminance(linear: np.ndarray) -> np.ndarray:
    """Y of linear sRGB (Rec. 709 weights)."""
    return linear[..., 0] * 0.2126 + linear[..., 1] * 0.7152 + linear[..., 2] * 0.0722


def exposure_from_reference(reference: np.ndarray) -> float:
    """The display's scale: the reference's luminance 99th percentile -> P99_TARGET."""
    p99 = float(np.percentile(luminance(reference), 99.0))
    return P99_TARGET / p99 if p99 > 0 else 1.0


def tone(x: np.ndarray) -> np.ndarray:
    """The fixed tone curve: extended Reinhard, x (1 + x / w^2) / (1 + x), w = TONE_WHITE."""
    x = np.maximum(x, 0.0)
    return x * (1.0 + x / TONE_WHITE ** 2) / (1.0 + x)


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    """IEC 61966-2-1's transfer function on [0, 1]."""
    c = np.clip(linear, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def neutral_display(linear: np.ndarray, scale: float) -> np.ndarray:
    """Linear sRGB radiance -> the bench's display sRGB in [0, 1] (float32): ``scale`` (from the
    reference alone), the fixed tone curve, clip, sRGB. No white balance, no glare."""
    return srgb_encode(tone(np.asarray(linear, dtype=np.float64) * scale)).astype(np.float32)


def curtain_delta_e(frame_display: np.ndarray, reference_display: np.ndarray, mask: np.ndarray):
    """colour-science's CIEDE2000 between the two display images on ``mask`` (CIELAB of the
    display sRGB, D65 white): the per-pixel values (1-D), or None if the mask is empty."""
    if not mask.any():
        return None
    import colour  # noqa: PLC0415

    def lab(display):
        return colour.XYZ_to_Lab(colour.sRGB_to_XYZ(display[mask].astype(np.float64)))

    return np.asarray(colour.delta_E(lab(frame_display), lab(reference_display), method="CIE 2000"))


def reference_halves(scene: dict, size, spp: int, own: dict, first_seed: int = 0) -> dict:
    """The scene's reference: two halves, region masks, time, variant. RGB references render in
    this process (``own["mi"]``, loaded once); a spectral one in a child process (Mitsuba's JIT
    crashed when the variant was switched in one process: benchmarks.image_reference)."""
    import subprocess  # noqa: PLC0415
    import sys  # noqa: PLC0415
    import tempfile  # noqa: PLC0415

    from benchmarks.image import REFERENCE_VARIANT, reference_variant_for  # noqa: PLC0415
    from benchmarks.image_reference import render_halves  # noqa: PLC0415
    from catalog.pathtrace.backend import load_mitsuba  # noqa: PLC0415

    desc = scene["_desc"]
    variant = reference_variant_for(desc.inputs)
    if variant == REFERENCE_VARIANT:
        if own.get("mi") is None:
            own["mi"] = load_mitsuba(REFERENCE_VARIANT)
        halves = render_halves(own["mi"], desc, spp, first_seed)
    else:
        cam = scene["camera"]
        with tempfile.TemporaryDirectory() as scratch:
            out = Path(scratch) / "reference.npz"
            subprocess.run([sys.executable, "-m", "benchmarks.image_reference", scene["fabric"],
                            scene["light"], repr(cam["yaw_deg"]), repr(cam["pitch_deg"]),
                            repr(cam["distance_m"]), str(size[0]), str(size[1]), str(spp),
                            variant, str(out), str(first_seed), scene["room"]], check=True)
            with np.load(out) as data:
                halves = {"a": data["a"], "b": data["b"], "seconds": float(data["seconds"]),
                          "cpu_seconds": float(data["cpu_seconds"]),
                          "nan_pixel_passes": int(data["nan_pixel_passes"]),
                          "masks": {k[5:]: data[k] for k in data.files if k.startswith("mask_")}}
    halves["variant"] = variant
    return halves


def reduce_box(image: np.ndarray, factor: int) -> np.ndarray:
    """The mean of each factor x factor block (the image cropped to whole blocks); (H, W) or
    (H, W, C)."""
    image = np.asarray(image, dtype=np.float64)
    if factor == 1:
        return image
    h, w = image.shape[0] // factor, image.shape[1] // factor
    blocks = image[:h * factor, :w * factor].reshape(h, factor, w, factor, *image.shape[2:])
    return blocks.mean(axis=(1, 3))


def judge(frame_linear, a, b, factor: int) -> dict:
    """At SIZE / factor: the display scale (from the reference alone), the displayed frame and
    reference, the FLIP map and the reference's noise (the mean FLIP of its two halves)."""
    from catalog.pathtrace import metrics  # noqa: PLC0415

    a, b = reduce_box(a, factor), reduce_box(b, factor)
    reference = 0.5 * (a + b)
    scale = exposure_from_reference(reference)
    shown_frame = neutral_display(reduce_box(frame_linear, factor), scale)
    shown_reference = neutral_display(reference, scale)
    flip = metrics.flip_map(shown_frame, shown_reference)
    noise = float(metrics.flip_map(neutral_display(a, scale), neutral_display(b, scale)).mean())
    return {"scale": scale, "frame": shown_frame, "reference": shown_reference, "flip": flip,
            "mean_flip": float(flip.mean()), "noise": noise}


def adaptive_reference(scene: dict, size, frame_linear, own: dict, start_spp: int, spp_cap: int,
                       budget_cpu_s: float) -> tuple[dict, list[dict]]:
    """The noise rule (NOISE_SHARE): the reference's halves accumulated over rounds of new seeds
    (START_SPP, then doubling the total) until the rule holds at the measure's size, the cap is
    reached or the next round would pass ``budget_cpu_s`` of the reference's CPU time. Returns
    the halves (as reference_halves,
    spp the total) and the rounds (spp, FLIP, noise at the measure's size)."""
    total, rounds, halves, seed = 0, [], None, 0
    step = int(start_spp)
    while True:
        new = reference_halves(scene, size, step, own, first_seed=seed)
        if halves is None:
            halves = new
        else:   # weighted by the samples each holds
            w_old, w_new = total / (total + step), step / (total + step)
            for half in ("a", "b"):
                halves[half] = (w_old * halves[half] + w_new * new[half]).astype(np.float32)
            halves["seconds"] += new["seconds"]
            halves["cpu_seconds"] += new["cpu_seconds"]
            halves["nan_pixel_passes"] += new["nan_pixel_passes"]
        total += step
        seed += 2
        measured = judge(frame_linear, halves["a"], halves["b"], MEASURE_REDUCTION)
        rounds.append({"spp": total, "mean_flip": measured["mean_flip"], "noise": measured["noise"],
                       "reference_s": float(halves["seconds"]),
                       "reference_cpu_s": float(halves["cpu_seconds"])})
        if measured["noise"] < NOISE_SHARE * measured["mean_flip"] or 2 * total > spp_cap \
                or 2 * halves["cpu_seconds"] > budget_cpu_s:
            break
        step = total
    halves["spp"] = total
    return halves, rounds


def measure_scene(ctx, scene: dict, size, spp: int, own: dict, repeats: int = 5,
                  start_spp: int = START_SPP, budget_cpu_s: float = REFERENCE_BUDGET_CPU_S) -> tuple[dict, dict]:
    """One scene: its row (JSON) and its images at the measure's size (frame, reference, FLIP
    map). ``spp``: the reference's cap (the noise rule: :func:`adaptive_reference`)."""
    from benchmarks.image import frame_images  # noqa: PLC0415
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.pathtrace.render import reference_settings  # noqa: PLC0415
    from catalog.pathtrace.scene import describe_scene  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415

    preset = load_preset(find_preset(scene["fabric"]))
    light = get_light(scene["light"])
    cam = scene["camera"]
    desc = describe_scene(reference_settings(preset, light, yaw_deg=cam["yaw_deg"],
                                             pitch_deg=cam["pitch_deg"],
                                             distance_m=cam["distance_m"], room=scene["room"]),
                          size=tuple(size))
    # the frame as ``catalog snapshot --room ROOM`` draws it: the room lit by its transport
    frame = frame_images(ctx, desc, preset, light, 3, "physical", repeats=repeats,
                         room=scene["room"])
    scene["_desc"] = desc
    halves, rounds = adaptive_reference(scene, size, frame["linear"], own, min(start_spp, spp), spp,
                                        budget_cpu_s)
    scene.pop("_desc")
    measured = judge(frame["linear"], halves["a"], halves["b"], MEASURE_REDUCTION)
    full = judge(frame["linear"], halves["a"], halves["b"], 1)
    curtain = reduce_box(halves["masks"]["curtain"].astype(np.float64), MEASURE_REDUCTION) > 0.999
    de = curtain_delta_e(measured["frame"], measured["reference"], curtain)
    mean_flip, noise = measured["mean_flip"], measured["noise"]
    frame_s = float(frame["seconds"])
    row = {k: v for k, v in scene.items() if not k.startswith("_")}
    row.update({
        "size": list(size), "measure_size": list(measured["flip"].shape[::-1]),
        "spp": int(halves["spp"]), "spp_rounds": rounds, "reference_variant": halves["variant"],
        "mean_flip": mean_flip,
        "curtain_delta_e_mean": None if de is None else float(np.nanmean(de)),
        "curtain_delta_e_p95": None if de is None else float(np.nanpercentile(de, 95)),
        "curtain_delta_e_nan_pixels": 0 if de is None else int(np.isnan(de).sum()),
        "curtain_pixels": int(curtain.sum()),
        "reference_flip_noise": noise,
        "noise_below_fifth": bool(noise < NOISE_SHARE * mean_flip),
        # the spp at which the noise would be a fifth of this FLIP (noise ~ 1 / sqrt(spp))
        "spp_for_noise_rule": float(halves["spp"] * (noise / (NOISE_SHARE * mean_flip)) ** 2) if mean_flip > 0 else None,
        # the same comparison at the rendered size (the previous report's measure)
        "mean_flip_full_size": full["mean_flip"], "reference_flip_noise_full_size": full["noise"],
        "frame_ms": 1e3 * frame_s, "reference_s": float(halves["seconds"]),
        "reference_cpu_s": float(halves["cpu_seconds"]),
        "speedup": float(halves["seconds"]) / frame_s if frame_s > 0 else math.inf,
        "display_scale": measured["scale"],
        "reference_nan_pixel_passes": int(halves["nan_pixel_passes"]),
        "fluorescence": desc.info["fluorescence_variant"],
    })
    return row, {"frame": measured["frame"], "reference": measured["reference"], "flip": measured["flip"]}


#: The regions the FLIP is split by (catalog.pathtrace.render.region_masks): the curtain, the
#: room (floor, walls, rod) and the outside seen through the window.
SPLIT_REGIONS = {"curtain": ("curtain",), "room": ("floor", "walls", "other"), "outside": ("outside",)}


def region_flip(flip: np.ndarray, masks: dict) -> dict:
    """Per region of SPLIT_REGIONS: its share of the image's summed FLIP and its pixels' share."""
    total = float(flip.sum()) or 1.0
    out = {}
    for name, parts in SPLIT_REGIONS.items():
        mask = np.zeros(next(iter(masks.values())).shape, dtype=bool)
        for part in parts:
            mask |= masks[part]
        # each compared pixel's share of the region (the masks are at the rendered size)
        weight = reduce_box(mask.astype(np.float64), mask.shape[0] // flip.shape[0])
        weight = weight[:flip.shape[0], :flip.shape[1]]
        out[name] = {"flip_share": float((flip * weight).sum()) / total, "pixel_share": float(weight.mean()),
                     "mean_flip": float((flip * weight).sum() / weight.sum()) if weight.sum() > 0 else None}
    return out


#: A fabric counts as dyed in the error split when its dye's CIELAB chroma (its transmittance
#: under D65, against D65's white) is above this; the whites, ivories and the neutral grey are
#: below (0-7.2), the cream batiste, dense linen and the three coloured cloths above (11.5-102).
DYED_CHROMA = 10.0


def dye_chroma(fabric: str) -> float:
    """CIELAB chroma of ``fabric``'s dye transmittance T(l) under D65 (colour-science)."""
    import colour  # noqa: PLC0415

    from catalog.presets import find_preset, load_preset  # noqa: PLC0415
    from catalog.render.scene import GRID_NM, dye_transmittance  # noqa: PLC0415

    t = np.asarray(dye_transmittance(load_preset(find_preset(fabric))), dtype=np.float64)
    sd = colour.SpectralDistribution(dict(zip(np.asarray(GRID_NM, dtype=np.float64), t)))
    lab = colour.XYZ_to_Lab(colour.sd_to_XYZ(sd, illuminant=colour.SDS_ILLUMINANTS["D65"]) / 100.0)
    return float(np.hypot(lab[1], lab[2]))


def add_region_split(rows: list[dict], rows_out: Path) -> None:
    """Each row's FLIP split by region (``flip_by_region``), from its streamed FLIP map and the
    region masks of its scene (a ray per pixel centre through the reference's geometry)."""
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.pathtrace.backend import load_mitsuba  # noqa: PLC0415
    from catalog.pathtrace.render import MAX_DEPTH, region_masks  # noqa: PLC0415
    from catalog.pathtrace.render import reference_settings  # noqa: PLC0415
    from catalog.pathtrace.scene import build_mitsuba_scene, describe_scene  # noqa: PLC0415
    from catalog.presets import find_preset, load_preset  # noqa: PLC0415

    import json  # noqa: PLC0415

    cache_path = Path(rows_out).with_suffix(".regions.json")   # labels -> their split, kept between publishes
    cache = json.loads(cache_path.read_text(encoding="utf-8")) if cache_path.is_file() else {}
    mi = load_mitsuba("llvm_ad_rgb")
    for number, row in enumerate(rows, 1):
        row.setdefault("dye_chroma", dye_chroma(row["fabric"]))
        if row["label"] in cache:
            row["flip_by_region"] = cache[row["label"]]
        if "flip_by_region" in row:
            continue
        cam = row["camera"]
        desc = describe_scene(reference_settings(load_preset(find_preset(row["fabric"])),
                                                 get_light(row["light"]), yaw_deg=cam["yaw_deg"],
                                                 pitch_deg=cam["pitch_deg"],
                                                 distance_m=cam["distance_m"],
                                                 room=row.get("room", "box")),
                              size=tuple(row["size"]))
        masks = region_masks(mi, build_mitsuba_scene(mi, desc, max_depth=MAX_DEPTH), desc)
        with np.load(Path(rows_out).with_suffix(f".{number:02d}.npz")) as data:
            row["flip_by_region"] = region_flip(data["flip"], masks)
        cache[row["label"]] = row["flip_by_region"]
        cache_path.write_text(json.dumps(cache), encoding="utf-8")


def stats(values: list[float]) -> dict:
    """Median, p90 and max of the finite values (a scene's NaN, e.g. a Delta E of a pixel
    colour-science could not convert, is left out and counted in the row's table)."""
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=np.float64)
    if not len(v):
        return {"median": None, "p90": None, "max": None}
    return {"median": float(np.median(v)), "p90": float(np.percentile(v, 90)), "max": float(v.max())}


def summarise(rows: list[dict]) -> dict:
    flip = stats([r["mean_flip"] for r in rows])
    de = stats([r["curtain_delta_e_mean"] for r in rows])
    speed = [r["speedup"] for r in rows]
    met = {
        "median_mean_flip": flip["median"] <= GOAL["median_mean_flip_at_most"],
        "p90_mean_flip": flip["p90"] <= GOAL["p90_mean_flip_at_most"],
        "max_mean_flip": flip["max"] <= GOAL["max_mean_flip_at_most"],
        "median_curtain_delta_e": de["median"] is not None and de["median"] <= GOAL["median_curtain_delta_e_at_most"],
        "speedup": min(speed) >= GOAL["speedup_at_least"],
        "scenes": len(rows) >= DEFAULT_SCENES,
    }
    worst = sorted(rows, key=lambda r: -r["mean_flip"])[:WORST_SHOWN]
    split = {}
    if all("flip_by_region" in r for r in rows):   # over the scenes with an error to split
        judged = [r for r in rows if sum(r["flip_by_region"][n]["flip_share"] for n in SPLIT_REGIONS) > 0] or rows
        split = {name: float(np.mean([r["flip_by_region"][name]["flip_share"] for r in judged]))
                 for name in SPLIT_REGIONS}
    by_family, by_fabric, by_room, by_dye = {}, {}, {}, {}
    for r in rows:
        by_family.setdefault(r["light_family"], []).append(r["mean_flip"])
        by_fabric.setdefault(r["fabric"], []).append(r["mean_flip"])
        by_room.setdefault(r.get("room", "box"), []).append(r["mean_flip"])
        if "dye_chroma" in r:
            by_dye.setdefault("dyed" if r["dye_chroma"] > DYED_CHROMA else "white", []).append(r)
    causes = {
        "by_room": {k: {"scenes": len(v), "median_mean_flip": float(np.median(v))} for k, v in sorted(by_room.items())},
        "by_dye": {k: {"scenes": len(v), "median_mean_flip": float(np.median([r["mean_flip"] for r in v])),
                       "median_curtain_delta_e": stats([r["curtain_delta_e_mean"] for r in v])["median"]}
                   for k, v in sorted(by_dye.items())},
    }
    if split:   # each region's own mean FLIP (its pixels only), median over the scenes showing it
        causes["region_mean_flip_median"] = {
            name: float(np.median([m for m in (r["flip_by_region"][name]["mean_flip"] for r in rows
                                                 if r["flip_by_region"][name]["pixel_share"] > 0.02)
                                   if m is not None] or [0.0]))
            for name in SPLIT_REGIONS}
    extra = {}
    if all("spp_rounds" in r for r in rows):
        extra = {"mean_flip_full_size": stats([r["mean_flip_full_size"] for r in rows]),
                 "spp_median": float(np.median([r["spp"] for r in rows])),
                 "measure_size": rows[0]["measure_size"]}
    return {**extra, "scenes": len(rows), "mean_flip": flip, "curtain_delta_e_mean": de,
            "flip_share_by_region": split, "causes": causes,
            "median_flip_by_light_family": {k: float(np.median(v)) for k, v in by_family.items()},
            "median_flip_by_fabric": {k: float(np.median(v)) for k, v in sorted(by_fabric.items())},
            "speedup": {"min": float(min(speed)), "median": float(np.median(speed))},
            "frame_ms_median": float(np.median([r["frame_ms"] for r in rows])),
            "reference_s_median": float(np.median([r["reference_s"] for r in rows])),
            "reference_flip_noise": stats([r["reference_flip_noise"] for r in rows]),
            "scenes_noise_not_below_fifth": sum(not r["noise_below_fifth"] for r in rows),
            # the spp the noise rule needs (noise ~ 1 / sqrt(spp)) and the reference time it projects
            "spp_for_noise_rule_median": float(np.median([r.get("spp_for_noise_rule") or 0.0 for r in rows])),
            "reference_s_for_noise_rule_total": float(sum(r["reference_s"] * max(1.0, (r.get("spp_for_noise_rule") or 0.0) / r["spp"])
                                                       for r in rows)),
            "goal": GOAL, "goal_met": met, "worst": [r["label"] for r in worst]}


@own_context_unless_given   # without ctx: its own, released after (the caller's current again)
def run(quick: bool = False, ctx=None, scenes: int | None = None, seed: int | None = None,
        room: str | None = None, size=None, spp: int | None = None, cases: list[dict] | None = None,
        progress=None, rows_out: Path | None = None) -> dict:
    """The section: ``scenes`` drawn with ``seed`` (REPORT_SEED by default), or ``cases``.
    ``rows_out``: each row appended there as one JSON line as soon as it is measured (a long
    run's finished scenes survive it)."""
    if room is not None:
        check_room(room)
    seed = REPORT_SEED if seed is None else int(seed)
    count = int(scenes or (QUICK_SCENES if quick else DEFAULT_SCENES))
    size = tuple(size or (QUICK_SIZE if quick else SIZE))
    spp = int(spp or (QUICK_SPP if quick else SPP))
    chosen = cases if cases is not None else draw_scenes(count, seed, room)
    own: dict = {}
    rows, images = [], {}
    start = time.perf_counter()
    for number, scene in enumerate(chosen, 1):
        row, pictures = measure_scene(ctx, dict(scene), size, spp, own, repeats=3 if quick else 5,
                                      start_spp=QUICK_START_SPP if quick else START_SPP,
                                      budget_cpu_s=QUICK_REFERENCE_BUDGET_CPU_S if quick else REFERENCE_BUDGET_CPU_S)
        rows.append(row)
        images[row["label"]] = pictures
        if rows_out is not None:
            import json  # noqa: PLC0415

            with open(rows_out, "a", encoding="utf-8") as handle:
                handle.write(json.dumps(row) + "\n")
            np.savez_compressed(Path(rows_out).with_suffix(f".{number:02d}.npz"), **pictures)
        if progress is not None:
            progress(f"accuracy {number}/{len(chosen)}: {row['label']}: FLIP {row['mean_flip']:.3f}, "
                     f"noise {row['reference_flip_noise']:.3f} at {row['spp']} spp, "
                     f"reference {row['reference_s']:.0f} s, "
                     f"{time.perf_counter() - start:.0f} s so far")
    summary = summarise(rows)
    result = {"rows": rows, "summary": summary,
              "settings": {"size": list(size), "spp": spp, "seed": None if cases is not None else seed,
                           "report_seed": REPORT_SEED, "tune_seed": TUNE_SEED, "room": room,
                           "display": {"exposure": f"reference luminance p99 -> {P99_TARGET}",
                                       "tone": f"x (1 + x / {TONE_WHITE:g}^2) / (1 + x)",
                                       "white_balance": "none (sRGB white)", "glare": "none"}}}
    result["_images"] = {label: images[label] for label in summary["worst"]}
    return result


def section_options(args) -> dict:
    """``catalog bench``'s options this section reads: --scenes, --seed, --room."""
    options = {}
    if getattr(args, "scenes", None) is not None:
        options["scenes"] = args.scenes
    if getattr(args, "seed", None) is not None:
        options["seed"] = args.seed
    if getattr(args, "room", None) is not None:
        options["room"] = check_room(args.room)
    return options


def plot(result: dict, folder) -> list[Path]:
    """The worst scenes' error maps: frame | reference | FLIP (PNG), one file each."""
    from benchmarks.image import slug, triptych  # noqa: PLC0415
    from benchmarks.plots import pyplot  # noqa: PLC0415
    from catalog.core.atomic import atomic_path  # noqa: PLC0415

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for rank, (label, pictures) in enumerate(result.pop("_images", {}).items(), 1):
        path = folder / f"accuracy-worst-{rank}-{slug(label)[:60]}.png"
        with atomic_path(path) as tmp:
            pyplot().imsave(tmp, triptych(pictures), format="png")
        written.append(path)
    return written


def _cell(value) -> str:
    from benchmarks.results import fmt  # noqa: PLC0415

    if isinstance(value, float):
        return f"{value:.4f}" if abs(value) < 1 else fmt(value)
    return "-" if value is None else str(value)


def markdown_tables(result: dict) -> dict[str, str]:
    """``accuracy`` (per scene) and ``accuracy-summary`` of one run."""
    columns = ("label", "light_family", "mean_flip", "reference_flip_noise", "noise_below_fifth", "spp",
               "mean_flip_full_size", "curtain_delta_e_mean", "frame_ms", "reference_s", "speedup",
               "reference_variant")
    headers = ("scene", "light family", "mean FLIP", "ref. noise (FLIP of halves)", "noise < FLIP / 5",
               "ref. spp", "mean FLIP at the rendered size", "curtain dE2000 mean", "frame ms",
               "reference s", "x faster", "reference variant")
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join("yes" if r.get(c) is True else "no" if r.get(c) is False else _cell(r.get(c))
                                for c in columns) + " |" for r in result["rows"]]
    s = result["summary"]
    f, d, n = s["mean_flip"], s["curtain_delta_e_mean"], s["reference_flip_noise"]
    g = s["goal_met"]
    cfg = result["settings"]

    def yes(key):
        return "met" if g[key] else "NOT met"

    summary = "\n".join([
        "| figure | median | p90 | max | goal |", "|---|---|---|---|---|",
        f"| mean FLIP | {_cell(f['median'])} | {_cell(f['p90'])} | {_cell(f['max'])} | "
        f"<= {GOAL['median_mean_flip_at_most']} / {GOAL['p90_mean_flip_at_most']} / "
        f"{GOAL['max_mean_flip_at_most']}: {yes('median_mean_flip')} / {yes('p90_mean_flip')} / {yes('max_mean_flip')} |",
        f"| curtain dE2000 mean | {_cell(d['median'])} | {_cell(d['p90'])} | {_cell(d['max'])} | "
        f"median <= {GOAL['median_curtain_delta_e_at_most']}: {yes('median_curtain_delta_e')} |",
        f"| reference noise (FLIP of its halves) | {_cell(n['median'])} | {_cell(n['p90'])} | {_cell(n['max'])} | "
        f"< 1/5 of the FLIP judged: {s['scenes'] - s['scenes_noise_not_below_fifth']} of {s['scenes']} scenes |",
        "",
        f"Where the noise rule (the reference's noise below a fifth of the FLIP it judges) does not "
        f"hold at the spp a reference ended with (its cap or its CPU-time budget), it would need "
        f"{s.get('spp_for_noise_rule_median', 0):,.0f} spp at the median scene (noise ~ 1 / sqrt(spp)); "
        f"all the references at the spp they need would take "
        f"{s.get('reference_s_for_noise_rule_total', 0) / 3600:.1f} h on this machine.",
        "",
        f"{s['scenes']} scenes (seed {cfg['seed']}; report seed {cfg['report_seed']}), rendered at "
        f"{cfg['size'][0]}x{cfg['size'][1]} px and compared at {s.get('measure_size', ['?', '?'])[0]}x"
        f"{s.get('measure_size', ['?', '?'])[1]} px (2x2 means); reference spp chosen per scene by the noise rule "
        f"(median {s.get('spp_median', 0):,.0f}, cap {cfg['spp']}); at the rendered size the mean FLIP is "
        f"median {_cell(s.get('mean_flip_full_size', {}).get('median'))}, p90 "
        f"{_cell(s.get('mean_flip_full_size', {}).get('p90'))}, max {_cell(s.get('mean_flip_full_size', {}).get('max'))}. "
        f"Frame {_cell(s['frame_ms_median'])} ms, reference {_cell(s['reference_s_median'])} s (medians); "
        f"the frame {s['speedup']['min']:,.0f}x (least) to {s['speedup']['median']:,.0f}x (median) faster "
        f"(goal >= {GOAL['speedup_at_least']:g}x: {yes('speedup')}). Worst: {'; '.join(s['worst'])}.",
    ])
    planned = result.get("planned_scenes")
    if planned and planned > s["scenes"]:
        per_scene = float(np.mean([r["reference_s"] for r in result["rows"]]))
        measured = sorted(int(r["label"].split()[0]) for r in result["rows"])
        missing = [i for i in range(planned) if i not in measured]
        summary += (f"\n\nThe run measured {s['scenes']} of the {planned} planned scenes in the time the "
                    f"shared machine allowed (the draw is seeded: the missing ones are scenes "
                    f"{', '.join(f'{i:02d}' for i in missing)} of the same list); the {planned} scenes project to "
                    f"{planned * per_scene / 3600:.1f} h of reference time at {cfg['spp']} spp "
                    f"(mean {per_scene:.0f} s a scene).")
    if s.get("flip_share_by_region"):
        share = s["flip_share_by_region"]
        summary += ("\n\nWhere the FLIP is (mean over the scenes of each region's share of the image's "
                    "summed FLIP): " + ", ".join(f"{k} {v:.0%}" for k, v in share.items()) + ".")
    causes = s.get("causes", {})
    if causes.get("region_mean_flip_median"):
        summary += ("\n\nEach region's own mean FLIP (its pixels only; median over the scenes where it "
                    "covers over 2 % of the image): " + ", ".join(
                        f"{k} {v:.3f}" for k, v in causes["region_mean_flip_median"].items()) + ".")
    if causes.get("by_room"):
        summary += ("\n\nMedian mean FLIP by room: " + ", ".join(
            f"{k} {v['median_mean_flip']:.3f} ({v['scenes']} scenes)" for k, v in causes["by_room"].items()) + ".")
    if causes.get("by_dye"):
        summary += (f"\n\nDyed cloths (dye chroma above {DYED_CHROMA:g}) against whites: " + "; ".join(
            f"{k}: FLIP {v['median_mean_flip']:.3f}, curtain dE2000 {_cell(v['median_curtain_delta_e'])} "
            f"({v['scenes']} scenes)" for k, v in causes["by_dye"].items()) + " (medians).")
    summary += ("\n\nMedian mean FLIP by light family: " + ", ".join(
        f"{k} {v:.3f}" for k, v in s["median_flip_by_light_family"].items())
        + "; by fabric: " + ", ".join(f"{k} {v:.3f}" for k, v in s.get("median_flip_by_fabric", {}).items()) + ".")
    compared = s.get("measure_size") or cfg["size"]
    readme = (f"Over {s['scenes']} scenes drawn at random from the whole scene space (report seed "
              f"{cfg['seed']}, rendered at {cfg['size'][0]}x{cfg['size'][1]} px, compared at "
              f"{compared[0]}x{compared[1]}; the reference's noise below a fifth of the error on "
              f"{s['scenes'] - s['scenes_noise_not_below_fifth']} of them; docs/accuracy.md; measured on "
              f"{result.get('commit', '?')}): mean FLIP median {_cell(f['median'])}, p90 {_cell(f['p90'])}, "
              f"max {_cell(f['max'])} (goals 0.06 / 0.09 / 0.12); curtain Delta E 2000 median "
              f"{_cell(d['median'])} (goal 1.5); the frame {s['speedup']['min']:,.0f}x to "
              f"{s['speedup']['median']:,.0f}x (median) faster than the reference.")
    return {"accuracy": "\n".join(lines), "accuracy-summary": summary, "accuracy-readme": readme}


def git_commit() -> str:
    import subprocess  # noqa: PLC0415

    return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                          check=False).stdout.strip() or "unknown"


def record(scenes: int = DEFAULT_SCENES, rows_out: Path = Path("bench-out/accuracy-rows.jsonl")) -> dict:
    """The report run: ``scenes`` of REPORT_SEED at SIZE and SPP, its rows streamed to
    ``rows_out``; then :func:`publish` from them."""
    import sys  # noqa: PLC0415

    rows_out.parent.mkdir(parents=True, exist_ok=True)
    commit = git_commit()
    run(scenes=scenes, seed=REPORT_SEED, rows_out=rows_out,
        progress=lambda text: print(text, file=sys.stderr, flush=True))
    return publish(rows_out, commit, planned=scenes)


def publish(rows_out: Path, commit: str, planned: int, json_path: Path = Path(RESULT_JSON),
            image_folder: Path = Path("docs/img")) -> dict:
    """The committed figures from a run's streamed rows: RESULT_JSON and the worst scenes'
    error maps in ``image_folder`` (then tools/docs_figures.py fills the docs' blocks)."""
    import json  # noqa: PLC0415

    from benchmarks.image import triptych  # noqa: PLC0415
    from benchmarks.plots import pyplot  # noqa: PLC0415
    from catalog.core.atomic import atomic_path, write_text_atomic  # noqa: PLC0415

    lines = Path(rows_out).read_text(encoding="utf-8").splitlines()
    rows = [json.loads(line) for line in lines if line.strip()]
    add_region_split(rows, rows_out)
    for row in rows:   # a NaN (a scene's Delta E over a pixel colour-science could not convert) -> null
        for key, value in row.items():
            if isinstance(value, float) and not math.isfinite(value):
                row[key] = None
    summary = summarise(rows)
    first = rows[0]
    from benchmarks.results import machine_info  # noqa: PLC0415
    from catalog.gl.context import create_headless_context  # noqa: PLC0415

    machine = {**machine_info(create_headless_context()), "commit": commit}
    result = {"commit": commit, "machine": machine, "planned_scenes": planned, "rows": rows, "summary": summary,
              "settings": {"size": first["size"], "spp": max(r["spp"] for r in rows) if "spp_rounds" not in first else SPP,
                           "seed": REPORT_SEED,
                           "report_seed": REPORT_SEED, "tune_seed": TUNE_SEED, "room": None,
                           "display": {"exposure": f"reference luminance p99 -> {P99_TARGET}",
                                       "tone": f"x (1 + x / {TONE_WHITE:g}^2) / (1 + x)",
                                       "white_balance": "none (sRGB white)", "glare": "none"}}}
    for rank, label in enumerate(summary["worst"], 1):
        number = next(i for i, r in enumerate(rows, 1) if r["label"] == label)
        with np.load(Path(rows_out).with_suffix(f".{number:02d}.npz")) as data:
            pictures = {k: data[k] for k in data.files}
        with atomic_path(Path(image_folder) / f"accuracy_worst_{rank}.png") as tmp:
            pyplot().imsave(tmp, triptych(pictures), format="png")
    write_text_atomic(Path(json_path), json.dumps(result, indent=1) + "\n")
    # the docs' blocks (docs/accuracy.md, README.md) from the JSON: tools/docs_figures.py
    return result


def record_ci(json_path: Path = Path(CI_JSON)) -> dict:
    """Run the CI sample and keep its per-scene FLIP and the reference's noise in ``json_path``."""
    import json  # noqa: PLC0415

    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    result = run(quick=True, scenes=CI_SCENES, seed=CI_SEED)
    result.pop("_images")
    kept = {"commit": git_commit(), "seed": CI_SEED, "scenes": CI_SCENES,
            "size": list(QUICK_SIZE), "spp": QUICK_SPP,
            "rows": [{k: r[k] for k in ("label", "mean_flip", "reference_flip_noise",
                                        "curtain_delta_e_mean")} for r in result["rows"]]}
    write_text_atomic(json_path, json.dumps(kept, indent=1) + "\n")
    return kept


if __name__ == "__main__":
    import sys

    if sys.argv[1:2] == ["record"]:
        record(int(sys.argv[2]) if len(sys.argv) > 2 else DEFAULT_SCENES)
    elif sys.argv[1:2] == ["ci"]:
        record_ci()
    elif sys.argv[1:2] == ["publish"]:   # publish ROWS.jsonl COMMIT PLANNED
        publish(Path(sys.argv[2]), sys.argv[3], int(sys.argv[4]))
