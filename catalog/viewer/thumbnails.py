"""The panel's fabric thumbnails: each fabric rendered by the renderer itself, small, under
the light the viewer shows, cached, and rendered again when the light (or the display
choices) change. Each carries an inset close-up of the fabric (the weave or the lace's
motif, catalog.render.sheet's inset: the whole curtain alone shows the white fabrics nearly
alike at this size).

Two passes. The draft: half the thumbnail's resolution, the room's light off (the cloth's own
shadow maps only), the pattern's hardware box mip chain (no Fourier prefilter), no inset:
about a third of the final's cost, drawn before the first frame of the scene (the viewer's
first look) and then until DRAFT_BUDGET_S of a frame is spent, so every fabric has a
picture within seconds of the window opening. Then the final one: full resolution, the room
lit through the curtain, the prefiltered pattern, the close-up inset; at most
``per_frame`` a frame, so a light change costs a few small renders spread over the next
frames, not a stall. Both passes use the uniform (not specialised) curtain program, so
switching fabrics compiles nothing. A thumbnail is an RGB8 texture the panel shows with
imgui.image.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from catalog.core.errors import CatalogError

THUMBNAIL_SIZE_PX = (72, 54)
#: Final thumbnails drawn per frame at most.
PER_FRAME = 2
#: The draft's resolution divisor (each draft pixel is shown as DRAFT_SCALE^2 pixels).
DRAFT_SCALE = 2
#: Drafts are drawn until this much of a frame is spent (at least one a frame), s.
DRAFT_BUDGET_S = 0.25
#: The close-up inset's share of the thumbnail's side (catalog.render.sheet.put_inset).
INSET_FRACTION = 0.5


@dataclass
class Thumbnail:
    key: tuple            # (fabric name, preset id, scene key) it was drawn for
    pixels: np.ndarray    # (H, W, 3) uint8, row 0 at the top
    texture: object       # moderngl.Texture holding ``pixels``
    final: bool = False   # False: the draft (low resolution, no room light)


def with_inset(cell: np.ndarray, close: np.ndarray) -> np.ndarray:
    """``cell`` with the close-up ``close`` (same size) reduced into its lower right corner."""
    from catalog.render.sheet import put_inset  # noqa: PLC0415

    out = np.array(cell, dtype=np.uint8, copy=True)
    put_inset(out, close, INSET_FRACTION)
    return out


class ThumbnailCache:
    """Thumbnails by fabric name for one scene key (light, fluorescence, display)."""

    def __init__(self, ctx, size=THUMBNAIL_SIZE_PX, per_frame: int = PER_FRAME,
                 draft_budget_s: float = DRAFT_BUDGET_S, clock=time.perf_counter):
        self.ctx = ctx
        self.size = tuple(size)
        self.per_frame = int(per_frame)
        self.draft_budget_s = float(draft_budget_s)
        self._clock = clock
        self._renderers: dict[str, object] = {}   # "draft" / "final" -> FrameRenderer
        self._items: dict[str, Thumbnail] = {}
        self.renders = 0         # final thumbnails drawn so far (tests, stats)
        self.draft_renders = 0   # drafts drawn so far
        #: seconds from this cache's creation (the window's first frame) to the first draft,
        #: every entry's draft and every entry's final thumbnail (the viewer's --stats)
        self.started_s = clock()
        self.times_s: dict[str, float] = {}

    def get(self, name: str) -> Thumbnail | None:
        return self._items.get(name)

    def pixels(self) -> dict[str, np.ndarray]:
        return {name: item.pixels for name, item in self._items.items()}

    def _key(self, entry, scene_key: tuple) -> tuple:
        return (entry.name, id(entry.preset), scene_key)

    def is_current(self, entry, scene_key: tuple) -> bool:
        """The final thumbnail for this scene is there."""
        item = self._items.get(entry.name)
        return item is not None and item.final and item.key == self._key(entry, scene_key)

    def has_draft(self, entry, scene_key: tuple) -> bool:
        """A picture (draft or final) for this scene is there."""
        item = self._items.get(entry.name)
        return item is not None and item.key == self._key(entry, scene_key)

    def update(self, entries, scene_key: tuple, apply_scene) -> int:
        """Draw the drafts that are missing for ``scene_key`` (within the frame's budget),
        or when every entry has one, up to ``per_frame`` final thumbnails.

        ``entries``: the catalog's loaded entries (those with a preset); ``apply_scene(r)``
        sets the light, fluorescence and display choices on a thumbnail renderer.
        Returns how many were drawn (drafts and finals)."""
        entries = [entry for entry in entries if entry.preset is not None]
        start = self._clock()
        drawn = 0
        for entry in entries:
            if self.has_draft(entry, scene_key):
                continue
            if drawn and self._clock() - start >= self.draft_budget_s:
                return drawn
            if self._draw(entry, scene_key, apply_scene, final=False):
                drawn += 1
                self.draft_renders += 1
                self.times_s.setdefault("first_draft_s", self._clock() - self.started_s)
        if entries and all(self.has_draft(e, scene_key) for e in entries):
            self.times_s.setdefault("all_drafts_s", self._clock() - self.started_s)
        if drawn:
            return drawn
        for entry in entries:
            if drawn >= self.per_frame:
                break
            if self.is_current(entry, scene_key):
                continue
            if self._draw(entry, scene_key, apply_scene, final=True):
                drawn += 1
                self.renders += 1
        if entries and all(self.is_current(e, scene_key) for e in entries):
            self.times_s.setdefault("all_final_s", self._clock() - self.started_s)
        return drawn

    def _draw(self, entry, scene_key: tuple, apply_scene, final: bool) -> bool:
        from catalog.render.sheet import close_up  # noqa: PLC0415

        renderer = self._ensure_renderer("final" if final else "draft")
        try:
            renderer.update(fabric=entry.preset)
            apply_scene(renderer)
            renderer.render()
            pixels = renderer.read_srgb8()
            if final:   # the close-up costs a second render: the final thumbnail's only
                pixels = with_inset(pixels, close_up(renderer))
        except CatalogError:
            self._drop(entry.name)
            return False
        if not final:   # each draft pixel shown as a DRAFT_SCALE x DRAFT_SCALE block
            pixels = np.repeat(np.repeat(pixels, DRAFT_SCALE, axis=0), DRAFT_SCALE, axis=1)
            pixels = pixels[:self.size[1], :self.size[0]]
        self._store(entry.name, self._key(entry, scene_key), pixels, final)
        return True

    def _ensure_renderer(self, kind: str):
        renderer = self._renderers.get(kind)
        if renderer is None:
            from catalog.render.frame import FrameRenderer  # noqa: PLC0415
            from catalog.render.settings import FrameSettings, orbit  # noqa: PLC0415

            if kind == "final":
                renderer = FrameRenderer(self.ctx, self.size, FrameSettings(camera=orbit(0.0, 0.0, 2.9)),
                                         specialise=False)
            else:
                size = tuple(-(-side // DRAFT_SCALE) for side in self.size)
                renderer = FrameRenderer(self.ctx, size,
                                         FrameSettings(camera=orbit(0.0, 0.0, 2.9),
                                                       room_lighting=False, bloom=False),
                                         specialise=False)
                renderer.fabric_pattern.set_prefilter(False)
            self._renderers[kind] = renderer
        return renderer

    def _store(self, name: str, key: tuple, pixels: np.ndarray, final: bool) -> None:
        item = self._items.get(name)
        # row 0 first: imgui's uv (0, 0), the image's top-left, is the texture's first row
        pixels = np.ascontiguousarray(pixels, dtype=np.uint8)
        if pixels.shape[:2] != (self.size[1], self.size[0]):
            raise CatalogError(f"thumbnail of {name}: {pixels.shape[1]}x{pixels.shape[0]} px, "
                               f"not {self.size[0]}x{self.size[1]}")
        data = pixels.tobytes()
        if item is None:
            texture = self.ctx.texture(self.size, 3, data)
            self._items[name] = Thumbnail(key, pixels, texture, final)
        else:
            item.texture.write(data)
            item.key, item.pixels, item.final = key, pixels, final

    def _drop(self, name: str) -> None:
        item = self._items.pop(name, None)
        if item is not None:
            item.texture.release()

    def release(self) -> None:
        for name in list(self._items):
            self._drop(name)
        for renderer in self._renderers.values():
            renderer.release()
        self._renderers = {}
