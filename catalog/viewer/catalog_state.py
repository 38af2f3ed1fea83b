"""The fabric list the viewer browses: presets load lazily and reload when their file changes.

A preset is read the first time it is shown (not at start-up), and again when its file's
modification time changes; files added to or removed from the fabric folder appear or
disappear at the next :meth:`FabricCatalog.refresh`. A preset that fails to load keeps its
one-line error (file, field, problem) for the panel, and the others stay usable.

No GL and nothing heavy here: numpy and the preset reader only.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from catalog.core.resources import fabric_dirs
from catalog.core.errors import CatalogError
from catalog.presets import Preset, list_presets, load_preset
from catalog.presets.facts import KINDS, FabricFacts, fabric_facts  # noqa: F401  (the panel's)


def _srgb_encode(linear: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1, piecewise) for the panel's swatches.

    catalog.optics.colorimetry.srgb_encode goes through colour-science, which imports scipy; the
    viewer must not, so the swatch uses this four-line numpy form of the same curve.
    """
    linear = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear,
                    1.055 * np.power(linear, 1.0 / 2.4) - 0.055)


def transmission_weights_rgb(preset: Preset) -> np.ndarray:
    """Per-channel share of light the fabric passes, direct + a_diff + a_spec (eq. 7).

    HG lobes integrate to 1 over the sphere (eq. 6), so a_diff and a_spec are the shares
    of the incident light in each lobe; ``direct`` is the see-through of the gaps. Dyed
    fabrics give per-channel lists in ``[btdf.rgb]``; the others are grey.
    """
    grey = preset.btdf.direct + preset.btdf.a_diff + preset.btdf.a_spec
    weights = np.full(3, grey, dtype=np.float64)
    rgb = preset.table("btdf").get("rgb")
    if isinstance(rgb, dict):
        try:
            direct = np.asarray(rgb.get("direct", [preset.btdf.direct] * 3), dtype=np.float64)
            a_diff = np.asarray(rgb.get("a_diff", [preset.btdf.a_diff] * 3), dtype=np.float64)
            a_spec = np.asarray(rgb.get("a_spec", [preset.btdf.a_spec] * 3), dtype=np.float64)
            per_channel = direct + a_diff + a_spec
            if per_channel.shape == (3,) and np.all(np.isfinite(per_channel)):
                weights = per_channel
        except (TypeError, ValueError):
            pass  # a malformed [btdf.rgb] is the renderer's to refuse; the swatch stays grey
    return weights


def swatch_srgb(preset: Preset) -> tuple[float, float, float]:
    """The swatch colour (sRGB-encoded, 0..1): the fabric's transmitted hue under white light.

    The hue is the per-channel transmission normalised to its largest channel, so a sheer
    white and a dense white both read white; a dyed fabric shows its dye.
    """
    weights = transmission_weights_rgb(preset)
    peak = float(np.max(weights))
    linear = weights / peak if peak > 0 else np.zeros(3)
    return tuple(float(v) for v in _srgb_encode(linear))  # type: ignore[return-value]


@dataclass
class FabricFilter:
    """The panel's filter by facts: the kinds shown and an openness range (per cent)."""

    kinds: set[str] | None = None               # None: every kind
    openness_pct: tuple[float, float] = (0.0, 100.0)

    def matches(self, facts: FabricFacts | None) -> bool:
        if facts is None:
            return True  # a broken preset stays listed (with its error)
        if self.kinds is not None and facts.kind not in self.kinds:
            return False
        low, high = self.openness_pct
        return low <= facts.openness_pct <= high

    @property
    def active(self) -> bool:
        return self.kinds is not None or self.openness_pct != (0.0, 100.0)


@dataclass
class FabricEntry:
    """One preset file as the panel sees it."""

    name: str
    path: Path
    preset: Preset | None = None
    error: str | None = None
    loaded_mtime_ns: int | None = None  # the file version that ``preset``/``error`` describe
    swatch: tuple[float, float, float] | None = None
    facts: FabricFacts | None = None

    @property
    def loaded(self) -> bool:
        return self.loaded_mtime_ns is not None

    @property
    def fluorescent(self) -> bool:
        return self.preset is not None and self.preset.has_fluorescence

    @property
    def label(self) -> str:
        if self.preset is not None:
            return f"{self.preset.display_name} ({self.name})"
        return self.name


def _mtime_ns(path: Path) -> int | None:
    try:
        return path.stat().st_mtime_ns
    except FileNotFoundError:
        return None


class FabricCatalog:
    """The presets in ``fabric_dir``, loaded on first use and reloaded on change.

    ``refresh()`` is cheap (one ``stat`` per file, at most every ``rescan_interval_s``) and
    is called once per frame by the viewer; it returns the names whose file changed, so the
    viewer can re-apply the preset it is showing.
    """

    def __init__(self, fabric_dir: Path | None = None, rescan_interval_s: float = 0.5,
                 clock: Callable[[], float] = time.monotonic):
        # None: the user's fabric folders, then the built-in catalog (catalog.core.resources)
        self.fabric_dir = None if fabric_dir is None else Path(fabric_dir)
        self.rescan_interval_s = float(rescan_interval_s)
        self._clock = clock
        self._last_scan: float | None = None
        self.entries: list[FabricEntry] = []
        self.refresh(force=True)

    @property
    def where(self) -> str:
        """The folder(s) searched, for messages."""
        folders = [self.fabric_dir] if self.fabric_dir is not None else fabric_dirs()
        return ", ".join(str(f) for f in folders)

    # -- the list ------------------------------------------------------------------
    @property
    def names(self) -> list[str]:
        return [entry.name for entry in self.entries]

    def __len__(self) -> int:
        return len(self.entries)

    def index_of(self, name: str) -> int:
        for i, entry in enumerate(self.entries):
            if entry.name == name:
                return i
        known = ", ".join(self.names) or "none"
        raise CatalogError(f"--fabric: unknown fabric {name!r} in {self.where} "
                           f"(known: {known})")

    def refresh(self, force: bool = False) -> list[str]:
        """Pick up added, removed and modified preset files; names of changed entries."""
        now = self._clock()
        if not force and self._last_scan is not None and \
                now - self._last_scan < self.rescan_interval_s:
            return []
        first_scan = self._last_scan is None
        self._last_scan = now
        changed: list[str] = []
        paths = {path.stem: path for path in list_presets(self.fabric_dir)}
        old = {entry.name: entry for entry in self.entries}
        entries = []
        for name, path in sorted(paths.items()):
            entry = old.get(name)
            if entry is None:
                entry = FabricEntry(name=name, path=path)
                if not first_scan:
                    changed.append(name)
            elif entry.loaded and _mtime_ns(path) != entry.loaded_mtime_ns:
                # the file changed since we read it: read it again when next needed
                entry.preset = None
                entry.error = None
                entry.loaded_mtime_ns = None
                entry.swatch = None
                entry.facts = None
                changed.append(name)
            entries.append(entry)
        changed.extend(name for name in old if name not in paths)
        self.entries = entries
        return changed

    # -- loading ------------------------------------------------------------------
    def load(self, index: int) -> FabricEntry:
        """The entry at ``index`` with its preset (or its error) loaded."""
        entry = self.entries[index]
        if not entry.loaded:
            mtime = _mtime_ns(entry.path)
            try:
                entry.preset = load_preset(entry.path)
                entry.error = None
                entry.swatch = swatch_srgb(entry.preset)
                entry.facts = fabric_facts(entry.preset)
            except CatalogError as exc:
                entry.preset = None
                entry.error = str(exc)
                entry.swatch = None
            except OSError as exc:
                entry.preset = None
                entry.error = f"{entry.path}: cannot read: {exc.strerror or exc}"
                entry.swatch = None
            entry.loaded_mtime_ns = mtime if mtime is not None else -1
        return entry

    def load_all(self) -> None:
        """Load every entry not loaded yet (the panel shows swatches for all)."""
        for index in range(len(self.entries)):
            self.load(index)

    def step(self, index: int, direction: int) -> int:
        """The next usable entry from ``index`` in ``direction`` (+1 / -1), wrapping round.

        Broken presets are skipped (their error stays in the panel); when nothing loads,
        ``index`` is returned unchanged.
        """
        count = len(self.entries)
        if count == 0:
            return index
        for offset in range(1, count + 1):
            candidate = (index + direction * offset) % count
            if self.load(candidate).preset is not None:
                return candidate
        return index

    def first_usable(self, start: int = 0) -> int | None:
        """The first entry at or after ``start`` (wrapping) that loads; None when none does."""
        count = len(self.entries)
        for offset in range(count):
            candidate = (start + offset) % count
            if self.load(candidate).preset is not None:
                return candidate
        return None

    def errors(self) -> list[str]:
        """The load errors of the entries read so far, one line each."""
        return [entry.error for entry in self.entries if entry.error]
