"""The job: which fabrics, lights, frames and camera yaws to render, how, and where.

Everything the user can get wrong is refused here, before a context or a worker exists,
with one line naming the option (:class:`catalog.core.errors.InputError`, exit 2). Presets are
only *found* here (a missing file is the user's to fix); they are loaded and checked by the
worker, so one broken preset among thousands fails its fabric, not the job.

Every image has a key: the SHA-256 of its inputs (the preset file's bytes, the light, the
frame, the camera, the size, the format, the shading options and the catalog version). An
image whose key is in the manifest and whose file is there is done; a changed preset or
option gives new keys, so those images are rendered again.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from catalog.core.constants import FLUORESCENCE_MODES as FLUORESCENCE
from catalog.core.errors import CatalogError, InputError

FORMATS = ("png", "exr")
#: The most images one job may ask for (a guard against a typo such as 0:4800000).
MAX_IMAGES = 50_000_000
_SLICE = re.compile(r"\s*(-?\d+)\s*:\s*(-?\d+)\s*(?::\s*(-?\d+)\s*)?", re.ASCII)


def parse_frames(text: str) -> range:
    """``A:B[:STEP]`` -> range(A, B, STEP), as a Python slice (B excluded). Frame 0 is the
    settled drape, frame N > 0 the cloth simulated from it for N steps of 1/60 s (as
    ``catalog snapshot --frame N``)."""
    match = _SLICE.fullmatch(str(text))
    if match is None:
        raise InputError(f"{text!r} is not START:STOP[:STEP] (e.g. 0:48 or 0:48:4)",
                         field="--frames")
    start, stop = int(match.group(1)), int(match.group(2))
    step = int(match.group(3)) if match.group(3) is not None else 1
    if start < 0 or stop < 0:
        raise InputError(f"{text!r}: frames are counted from 0; negative ones have no meaning",
                         field="--frames")
    if step <= 0:
        raise InputError(f"{text!r}: STEP must be a positive whole number", field="--frames")
    from catalog.core.validate import MAX_FRAME  # noqa: PLC0415

    if stop > MAX_FRAME + 1:
        raise InputError(f"{text!r}: the last frame must be at most {MAX_FRAME} (one hour "
                         "of cloth at 60 frames a second)", field="--frames")
    frames = range(start, stop, step)
    if len(frames) == 0:
        raise InputError(f"{text!r} selects no frame (STOP is excluded, as in Python)",
                         field="--frames")
    return frames


def parse_yaws(text: str | None) -> tuple[float, ...]:
    """Camera yaw angles (deg): ``0,90,180`` or ``START:STOP:STEP`` (STOP excluded);
    None -> (0.0,) (the default view)."""
    if text is None:
        return (0.0,)
    text = str(text).strip()
    try:
        if ":" in text:
            parts = [float(v) for v in text.split(":")]
            if len(parts) != 3:
                raise ValueError
            start, stop, step = parts
            if not (all(math.isfinite(v) for v in parts) and step > 0 and stop > start):
                raise InputError(f"{text!r}: need START < STOP and STEP > 0", field="--yaw")
            count = math.ceil((stop - start) / step - 1e-9)
            yaws = tuple(round(start + i * step, 9) for i in range(count))
        else:
            yaws = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise InputError(f"{text!r} is not a list of angles in degrees (e.g. 0,90,180 or "
                         f"0:360:45)", field="--yaw") from None
    if not yaws:
        raise InputError("give at least one yaw angle", field="--yaw")
    if not all(math.isfinite(v) and -360.0 <= v <= 360.0 for v in yaws):
        raise InputError(f"{text!r}: each yaw must be a finite angle in -360..360 deg",
                         field="--yaw")
    if len(set(yaws)) != len(yaws):
        raise InputError(f"{text!r} names an angle twice", field="--yaw")
    return yaws


def split_list(text: str | None, option: str) -> tuple[str, ...]:
    """``A,B,C`` -> ("A", "B", "C"), refused when empty or with a repeated name."""
    names = tuple(part.strip() for part in str(text or "").split(",") if part.strip())
    if not names:
        raise InputError("give at least one name (comma-separated)", field=option)
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise InputError(f"{', '.join(repeated)} given twice", field=option)
    return names


def safe_name(text: str) -> str:
    """A light name as a file name part (``sun:22`` -> ``sun_22``)."""
    return "".join(c if c.isalnum() or c in "-._" else "_" for c in text)


def yaw_label(yaw_deg: float) -> str:
    return format(float(yaw_deg), "g")


@dataclass(frozen=True)
class ImageJob:
    """One image: where it goes (relative to the output folder) and what it shows."""
    path: str
    fabric: str
    light: str
    frame: int
    yaw_deg: float
    key: str


@dataclass(frozen=True)
class FabricTask:
    """The unit of work sent to a worker: one fabric and the images of it still to render.
    Plain data (picklable), so it travels to Dask workers as is."""
    fabric: str
    preset_path: str
    out_dir: str
    images: tuple[ImageJob, ...]
    size: tuple[int, int]
    image_format: str
    fluorescence: str
    bands: int
    pitch_deg: float
    distance_m: float
    exposure: float
    room: str = "box"


@dataclass(frozen=True)
class JobSpec:
    """A render-catalog job. Build it with :meth:`create` (which checks every field)."""
    fabrics: tuple[str, ...]
    lights: tuple[str, ...]
    frames: range
    yaws: tuple[float, ...]
    size: tuple[int, int]
    image_format: str
    out_dir: Path
    fluorescence: str = "physical"
    bands: int = 3
    pitch_deg: float = 0.0
    distance_m: float = 2.6
    exposure: float = 1.0
    room: str = "box"                 # a built-in name or a .glb path (lit by its transport)
    room_sha256: str = field(default="", compare=False)
    preset_paths: tuple[str, ...] = field(default=(), compare=False)
    preset_hashes: tuple[str, ...] = field(default=(), compare=False)

    @classmethod
    def create(cls, *, fabrics, lights, frames, size, image_format, out_dir, yaws=None,
               fluorescence: str = "physical", bands: int = 3, pitch_deg: float = 0.0,
               distance_m: float = 2.6, exposure: float = 1.0, room: str = "box") -> "JobSpec":
        """Check and normalise: ``fabrics``/``lights`` as lists or ``A,B`` strings,
        ``frames`` as ``A:B[:STEP]`` or a range, ``yaws`` as text or numbers, ``size`` as
        ``WxH`` or (w, h). Raises InputError naming the option."""
        from catalog.optics.lights import get_light  # noqa: PLC0415
        from catalog.presets import find_preset  # noqa: PLC0415
        from catalog.render import bands as band_lib  # noqa: PLC0415
        from catalog.render.snapshot import parse_size  # noqa: PLC0415

        fabrics = split_list(fabrics if isinstance(fabrics, str) else ",".join(fabrics),
                             "--fabric")
        from catalog.core.validate import parse_light_list  # noqa: PLC0415

        lights = tuple(parse_light_list(lights if isinstance(lights, str) else ",".join(lights),
                                        "--lights"))
        for light in lights:
            try:
                get_light(light)
            except InputError as exc:
                raise InputError(exc.problem, field="--lights") from None
        safe = [safe_name(light) for light in lights]
        if len(set(safe)) != len(safe):
            raise InputError(f"{', '.join(lights)}: two lights give the same file name",
                             field="--lights")
        if isinstance(frames, range):
            frames = parse_frames(f"{frames.start}:{frames.stop}:{frames.step}")
        else:
            frames = parse_frames(frames)
        if yaws is None or isinstance(yaws, str):
            yaws = parse_yaws(yaws)
        else:
            yaws = parse_yaws(",".join(repr(float(v)) for v in yaws))
        size = parse_size(size if isinstance(size, str) else f"{size[0]}x{size[1]}")
        image_format = str(image_format).lower().lstrip(".")
        if image_format not in FORMATS:
            raise InputError(f"{image_format!r} is not png or exr", field="--format")
        if fluorescence not in FLUORESCENCE:
            raise InputError(f"{fluorescence!r} is not one of {', '.join(FLUORESCENCE)}",
                             field="--mode")
        try:
            band_lib.check_band_count(bands)
        except CatalogError as exc:
            raise InputError(getattr(exc, "problem", str(exc)), field="--bands") from None
        from catalog.core.validate import check_camera  # noqa: PLC0415

        check_camera({"--distance": distance_m, "--exposure": exposure, "--pitch": pitch_deg})
        from catalog.room.load import room_path  # noqa: PLC0415

        room_file = room_path(room)
        room_sha256 = hashlib.sha256(room_file.read_bytes()).hexdigest()
        out_dir = Path(out_dir)
        if out_dir.exists() and not out_dir.is_dir():
            raise InputError(f"{str(out_dir)!r} exists and is not a folder", field="--out")
        total = len(fabrics) * len(lights) * len(frames) * len(yaws)
        if total > MAX_IMAGES:
            raise InputError(f"{total} images is more than {MAX_IMAGES} in one job",
                             field="--frames")
        paths, hashes, stems = [], [], {}
        for fabric in fabrics:
            try:
                path = find_preset(fabric)
            except InputError as exc:
                raise InputError(exc.problem, path=exc.path, field="--fabric") from None
            if path.stem in stems:
                raise InputError(f"{fabric!r} and {stems[path.stem]!r} are both called "
                                 f"{path.stem!r}", field="--fabric")
            stems[path.stem] = fabric
            paths.append(str(path.resolve()))
            hashes.append(hashlib.sha256(path.read_bytes()).hexdigest())
        return cls(fabrics=tuple(Path(p).stem for p in paths), lights=lights, frames=frames,
                   yaws=yaws, size=size, image_format=image_format, out_dir=out_dir,
                   fluorescence=fluorescence, bands=int(bands), pitch_deg=float(pitch_deg),
                   distance_m=float(distance_m), exposure=float(exposure),
                   room=str(room) if str(room) in ("box", "living") else str(room_file.resolve()),
                   room_sha256=room_sha256,
                   preset_paths=tuple(paths), preset_hashes=tuple(hashes))

    @property
    def image_count(self) -> int:
        return len(self.fabrics) * len(self.lights) * len(self.frames) * len(self.yaws)

    def describe(self) -> dict:
        """The job as JSON (the manifest's ``job``)."""
        return {"fabrics": list(self.fabrics), "lights": list(self.lights),
                "frames": {"start": self.frames.start, "stop": self.frames.stop,
                           "step": self.frames.step},
                "yaw_deg": list(self.yaws), "size": list(self.size), "format": self.image_format,
                "fluorescence": self.fluorescence, "bands": self.bands,
                "pitch_deg": self.pitch_deg, "distance_m": self.distance_m,
                "exposure": self.exposure, "room": self.room, "images": self.image_count}

    def image_key(self, index: int, light: str, frame: int, yaw_deg: float) -> str:
        """SHA-256 of everything the image depends on (fabric ``index`` in the job)."""
        from catalog import __version__  # noqa: PLC0415

        inputs = {"catalog": __version__, "fabric": self.fabrics[index],
                  "preset_sha256": self.preset_hashes[index], "light": light, "frame": frame,
                  "yaw_deg": float(yaw_deg), "pitch_deg": self.pitch_deg,
                  "distance_m": self.distance_m, "size": list(self.size),
                  "format": self.image_format, "fluorescence": self.fluorescence,
                  "bands": self.bands, "exposure": self.exposure}
        if self.room != "box" or self.room_sha256:
            inputs.update({"room": self.room, "room_sha256": self.room_sha256})
        text = json.dumps(inputs, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode("utf-8")).hexdigest()

    def images_of(self, index: int) -> list[ImageJob]:
        """Every image of fabric ``index``, in render order (frame, light, yaw)."""
        fabric = self.fabrics[index]
        return [ImageJob(path=f"{fabric}/{fabric}__{safe_name(light)}__f{frame:04d}"
                              f"__yaw{yaw_label(yaw)}.{self.image_format}",
                         fabric=fabric, light=light, frame=frame, yaw_deg=float(yaw),
                         key=self.image_key(index, light, frame, yaw))
                for frame in self.frames for light in self.lights for yaw in self.yaws]

    def task(self, index: int, images) -> FabricTask:
        return FabricTask(fabric=self.fabrics[index], preset_path=self.preset_paths[index],
                          out_dir=str(self.out_dir.resolve()), images=tuple(images),
                          size=tuple(self.size), image_format=self.image_format,
                          fluorescence=self.fluorescence, bands=self.bands,
                          pitch_deg=self.pitch_deg, distance_m=self.distance_m,
                          exposure=self.exposure, room=self.room)
