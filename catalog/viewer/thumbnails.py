"""The panel's fabric thumbnails: each fabric rendered by the renderer itself, small, under
the light the viewer shows, cached, and rendered again when the light (or the display
choices) change.

One :class:`catalog.render.frame.FrameRenderer` of THUMBNAIL_SIZE_PX draws them, with the
uniform (not specialised) curtain program, so switching fabrics compiles nothing. At most
``per_frame`` thumbnails are drawn in a frame, so a light change costs a few small renders
spread over the next frames, not a stall. A thumbnail is an RGB8 texture the panel shows
with imgui.image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from catalog.core.errors import CatalogError

THUMBNAIL_SIZE_PX = (72, 54)
#: Thumbnails drawn per frame at most.
PER_FRAME = 2


@dataclass
class Thumbnail:
    key: tuple            # (fabric name, preset id, scene key) it was drawn for
    pixels: np.ndarray    # (H, W, 3) uint8, row 0 at the top
    texture: object       # moderngl.Texture holding ``pixels``


class ThumbnailCache:
    """Thumbnails by fabric name for one scene key (light, fluorescence, display)."""

    def __init__(self, ctx, size=THUMBNAIL_SIZE_PX, per_frame: int = PER_FRAME):
        self.ctx = ctx
        self.size = tuple(size)
        self.per_frame = int(per_frame)
        self._renderer = None
        self._items: dict[str, Thumbnail] = {}
        self.renders = 0  # how many thumbnails were drawn so far (tests, stats)

    def get(self, name: str) -> Thumbnail | None:
        return self._items.get(name)

    def pixels(self) -> dict[str, np.ndarray]:
        return {name: item.pixels for name, item in self._items.items()}

    def is_current(self, entry, scene_key: tuple) -> bool:
        item = self._items.get(entry.name)
        return item is not None and item.key == (entry.name, id(entry.preset), scene_key)

    def update(self, entries, scene_key: tuple, apply_scene) -> int:
        """Draw up to ``per_frame`` thumbnails that are missing or stale for ``scene_key``.

        ``entries``: the catalog's loaded entries (those with a preset); ``apply_scene(r)``
        sets the light, fluorescence and display choices on the thumbnail renderer.
        Returns how many were drawn."""
        drawn = 0
        for entry in entries:
            if drawn >= self.per_frame:
                break
            if entry.preset is None or self.is_current(entry, scene_key):
                continue
            renderer = self._ensure_renderer()
            try:
                renderer.update(fabric=entry.preset)
                apply_scene(renderer)
                renderer.render()
                pixels = renderer.read_srgb8()
            except CatalogError:
                self._drop(entry.name)
                continue
            self._store(entry.name, (entry.name, id(entry.preset), scene_key), pixels)
            drawn += 1
        self.renders += drawn
        return drawn

    def _ensure_renderer(self):
        if self._renderer is None:
            from catalog.render.frame import FrameRenderer  # noqa: PLC0415
            from catalog.render.settings import FrameSettings, orbit  # noqa: PLC0415

            self._renderer = FrameRenderer(self.ctx, self.size,
                                           FrameSettings(camera=orbit(0.0, 0.0, 2.9)),
                                           specialise=False)
        return self._renderer

    def _store(self, name: str, key: tuple, pixels: np.ndarray) -> None:
        item = self._items.get(name)
        # row 0 first: imgui's uv (0, 0), the image's top-left, is the texture's first row
        data = np.ascontiguousarray(pixels).tobytes()
        if item is None:
            texture = self.ctx.texture(self.size, 3, data)
            self._items[name] = Thumbnail(key, pixels, texture)
        else:
            item.texture.write(data)
            item.key, item.pixels = key, pixels

    def _drop(self, name: str) -> None:
        item = self._items.pop(name, None)
        if item is not None:
            item.texture.release()

    def release(self) -> None:
        for name in list(self._items):
            self._drop(name)
        if self._renderer is not None:
            self._renderer.release()
            self._renderer = None
