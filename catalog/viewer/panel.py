"""The on-screen panel (imgui-bundle): the fabrics as a catalog (a thumbnail rendered under
the current light, the full name, the preset's facts, a filter by facts), compare, light,
fluorescence (per half when comparing), bands, exposure and white balance, the view (a zoom
slider for the camera's distance and a reset button, beside the wheel and the R key), wind,
curtain, frame time (the graphs behind a toggle); and the help overlay.

Layout: the controls come first, each section under a header that collapses it (SECTIONS_OPEN
says which start open), the light picker at the top; the fabric list comes last and scrolls
in the height the sections leave, so a 1280x720 window shows every open control.

Immediate mode: :meth:`Panel.draw` is called once per frame between ``imgui.new_frame()``
and ``imgui.render()``; it reads and writes a :class:`ViewerSettings` and reads the
catalog and the frame timer. It never touches GL itself.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from imgui_bundle import imgui

from catalog.viewer.catalog_state import KINDS, FabricCatalog
from catalog.viewer.input import KEY_HELP
from catalog.viewer.settings import (BAND_COUNTS, EV_SLIDER_RANGE, FLUORESCENCE_MODES,
                                     LED_LIGHTS, SUN, SUN_HOUR_RANGE, UV_LIGHTS, UVA_LIGHT,
                                     WHITE_BALANCES, WIND_RANGE_M_S, ViewerSettings)
from catalog.viewer.timing import FrameTimer

PANEL_WIDTH_PX = 360
#: The thumbnails' size on the panel (px).
THUMBNAIL_PX = (72, 54)
#: The panel's sections and whether each starts open: in a 1280x720 window the open ones,
#: the fabric list's header and FABRIC_ROWS_MIN rows of it fit (tests/test_viewer_panel.py).
SECTIONS_OPEN = {"light": True, "fluorescence": True, "display": True, "view": True,
                 "curtain": False, "timing": False, "compare": False}
#: The fabric list's least height, in thumbnail rows (below it the panel scrolls).
FABRIC_ROWS_MIN = 3
ERROR_COLOUR = imgui.ImVec4(1.0, 0.42, 0.35, 1.0)
DIM_COLOUR = imgui.ImVec4(0.7, 0.7, 0.7, 1.0)


@dataclass
class PanelInfo:
    """What the panel shows but does not set: the renderer's view of the scene."""

    sun_path_km: float | None = None
    sun_elevation_deg: float | None = None
    fluorescence_compiled: bool | None = None
    cie_lights: list[str] = field(default_factory=list)  # CIE illuminant names for the combo
    messages: list[str] = field(default_factory=list)  # errors to show (light, fabric, save)
    last_screenshot: str | None = None
    ev100: float | None = None       # the exposure the left half shows now (auto: adapted)
    white_balance_adapted: bool | None = None
    thumbnails: object = None        # catalog.viewer.thumbnails.ThumbnailCache, or None


class Panel:
    """Draws the panel; ``width_px`` is the strip of the window it covers on the left."""

    def __init__(self, width_px: int = PANEL_WIDTH_PX):
        self.preferred_width_px = width_px
        self.width_px = width_px
        self.zoom_rect_px = None    # ((x0, y0), (x1, y1)) of the zoom slider, last frame
        self.reset_rect_px = None   # ... of the reset button
        #: which sections are open (their headers collapse them); the fabric list below them
        #: takes the height they leave
        self.sections = dict(SECTIONS_OPEN)
        #: the last frame's layout, screen px from the window's top: where the light section
        #: ends, the fabric list's top and bottom, the content's bottom (tests, --stats)
        self.layout: dict = {}

    def width_for(self, window_width_px: int) -> int:
        """The strip the panel takes in a window this wide: at most half of it."""
        return min(self.preferred_width_px, window_width_px // 2)

    # ------------------------------------------------------------------------------
    def draw(self, settings: ViewerSettings, catalog: FabricCatalog, timer: FrameTimer,
             info: PanelInfo, window_size_px: tuple[int, int], camera=None) -> None:
        """``camera``: the viewer's :class:`catalog.viewer.input.OrbitCamera` (the View
        section's zoom moves it; None: no View section)."""
        self.width_px = self.width_for(window_size_px[0])
        window_height_px = window_size_px[1]
        if settings.show_panel:
            imgui.set_next_window_pos(imgui.ImVec2(0, 0))
            imgui.set_next_window_size(imgui.ImVec2(self.width_px, window_height_px))
            flags = (imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize
                     | imgui.WindowFlags_.no_collapse)
            imgui.begin("Fabric catalog", None, flags)
            top = imgui.get_cursor_screen_pos().y
            # errors first: in view in any window (a broken preset, a light, a save)
            catalog.load_all()  # facts for every preset; a file is read once per version
            for error in catalog.errors():
                imgui.push_text_wrap_pos(self.width_px - 10)
                imgui.text_colored(ERROR_COLOUR, error)
                imgui.pop_text_wrap_pos()
            self._messages(info)
            if self._section("light", "Light  (L)"):
                self._light(settings, info)
            self.layout = {"window_px": [int(window_size_px[0]), int(window_height_px)],
                           "light_bottom_px": imgui.get_cursor_screen_pos().y}
            if self._section("fluorescence", "Fluorescence  (F)"):
                self._fluorescence(settings, info)
            if self._section("display", "Display"):
                self._display(settings, info)
            if camera is not None and self._section("view", "View"):
                self._view(camera)
            if self._section("curtain", "Curtain"):
                self._simulation(settings)
            if self._section("timing", "Frame time"):
                self._timing(settings, timer)
            if self._section("compare", "Compare (split screen)"):
                self._compare(settings, catalog)
            self._fabrics(settings, catalog, info)
            self.layout["top_px"] = top
            self.layout["sections"] = dict(self.sections)
            imgui.end()
        if settings.show_help:
            self._help()

    # ------------------------------------------------------------------------------
    def _fabrics(self, settings: ViewerSettings, catalog: FabricCatalog, info: PanelInfo) -> None:
        imgui.separator_text("Fabric  (Left / Right)")
        self._filter(settings)
        # the list scrolls in the height the sections above leave (at least FABRIC_ROWS_MIN
        # rows): the light picker and the other controls stay in the window
        row_px = THUMBNAIL_PX[1] + imgui.get_style().item_spacing.y
        left_px = imgui.get_content_region_avail().y
        list_px = max(left_px, FABRIC_ROWS_MIN * row_px)
        self.layout["fabric_list_px"] = [imgui.get_cursor_screen_pos().y, 0.0]
        imgui.begin_child("fabric-list", imgui.ImVec2(0, list_px))
        shown = 0
        for index, entry in enumerate(catalog.entries):
            if not settings.fabric_filter.matches(entry.facts):
                continue
            shown += 1
            imgui.push_id(f"fabric-{entry.name}")
            thumbnail = info.thumbnails.get(entry.name) if info.thumbnails is not None else None
            size = imgui.ImVec2(*THUMBNAIL_PX)
            if thumbnail is not None:
                clicked = imgui.image_button("thumb", imgui.ImTextureRef(thumbnail.texture.glo), size)
            elif entry.swatch is not None:  # until the renderer has drawn it
                clicked = imgui.color_button("swatch", imgui.ImVec4(*entry.swatch, 1.0),
                                             imgui.ColorEditFlags_.no_tooltip, size)
            else:
                clicked = imgui.button(" ! ", size)
            if clicked and entry.preset is not None:
                settings.fabric_index = index
            imgui.same_line()
            imgui.begin_group()
            imgui.push_text_wrap_pos(0.0)   # the list's right edge (its scrollbar left of it)
            if entry.error is not None:
                imgui.text_colored(ERROR_COLOUR, f"{entry.name}: broken preset")
            else:
                selected = index == settings.fabric_index
                name = entry.label
                if selected:
                    imgui.text_colored(imgui.ImVec4(1.0, 0.85, 0.4, 1.0), "> " + name)
                else:
                    imgui.text_wrapped(name)
                if entry.facts is not None:
                    for line in entry.facts.lines():
                        imgui.text_colored(DIM_COLOUR, line)
                    if imgui.is_item_hovered():   # the rows the web page lists, the same words
                        imgui.set_tooltip("\n".join(f"{label}: {value}"
                                                     for label, value in entry.facts.rows()))
            imgui.pop_text_wrap_pos()
            imgui.end_group()
            imgui.pop_id()
        if shown == 0:
            imgui.text_colored(DIM_COLOUR, "no fabric has these facts")
        imgui.end_child()
        self.layout["fabric_list_px"][1] = imgui.get_item_rect_max().y
        self.layout["content_bottom_px"] = imgui.get_item_rect_max().y

    def _section(self, name: str, label: str) -> bool:
        """A collapsing header whose open state lives in :attr:`sections` (a click toggles
        it; setting the dict opens or closes it at the next frame)."""
        imgui.set_next_item_open(bool(self.sections[name]), imgui.Cond_.always)
        opened = imgui.collapsing_header(f"{label}###{name}")
        self.sections[name] = bool(opened)
        return opened

    def _compare(self, settings: ViewerSettings, catalog: FabricCatalog) -> None:
        names = ["(none)"] + [entry.name for entry in catalog.entries]
        current = 0 if settings.compare_index is None else settings.compare_index + 1
        changed, current = imgui.combo("right half", current, names)
        if changed:
            settings.compare_index = None if current == 0 else current - 1
        if imgui.button("this fabric: fluorescence on | off"):
            settings.compare_index = settings.fabric_index
            if settings.fluorescence == "off":
                settings.fluorescence = "physical"
            settings.compare_fluorescence = "off"
        if settings.compare_index is not None:
            modes = ["(as the left)", *FLUORESCENCE_MODES]
            current = 0 if settings.compare_fluorescence is None \
                else modes.index(settings.compare_fluorescence)
            changed, current = imgui.combo("right fluorescence", current, modes)
            if changed:
                settings.compare_fluorescence = None if current == 0 else modes[current]

    def _filter(self, settings: ViewerSettings) -> None:
        fabric_filter = settings.fabric_filter
        label = "Filter by facts" + ("  (on)" if fabric_filter.active else "")
        if not imgui.collapsing_header(label):
            return
        kinds = set(KINDS) if fabric_filter.kinds is None else set(fabric_filter.kinds)
        for kind in KINDS:
            changed, on = imgui.checkbox(kind, kind in kinds)
            if changed:
                kinds = kinds | {kind} if on else kinds - {kind}
                fabric_filter.kinds = None if kinds == set(KINDS) else kinds
        low, high = fabric_filter.openness_pct
        changed, low, high = imgui.drag_float_range2("openness", low, high, 0.5, 0.0, 100.0,
                                                     "%.0f %%", "%.0f %%")
        if changed:
            fabric_filter.openness_pct = (max(0.0, low), min(100.0, max(low, high)))

    def _light(self, settings: ViewerSettings, info: PanelInfo) -> None:
        kind = self._light_kind(settings.light, info)
        if imgui.radio_button("Sun", kind == "sun"):
            settings.light = SUN
        imgui.same_line()
        if imgui.radio_button("CIE", kind == "cie"):
            settings.light = "D65" if "D65" in info.cie_lights or not info.cie_lights \
                else info.cie_lights[0]
        imgui.same_line()
        if imgui.radio_button("LED", kind == "led"):
            settings.light = LED_LIGHTS[0]
        imgui.same_line()
        if imgui.radio_button("UV lamp", kind == "uva"):
            settings.light = UVA_LIGHT

        kind = self._light_kind(settings.light, info)
        if kind == "sun":
            changed, hour = imgui.slider_float("hour", settings.sun_hour, *SUN_HOUR_RANGE,
                                               "%.1f h")
            if changed:  # the slider drives the sun (also after --light sun:PATH_KM)
                settings.sun_hour = hour
                settings.light = SUN
            if info.sun_path_km is not None:
                elevation = ("" if info.sun_elevation_deg is None
                             else f", elevation {info.sun_elevation_deg:.0f} deg")
                imgui.text(f"path through the air {info.sun_path_km:.0f} km{elevation}")
        elif kind == "cie" and info.cie_lights:
            names = info.cie_lights
            current = names.index(settings.light) if settings.light in names else 0
            changed, current = imgui.combo("illuminant", current, names)
            if changed:
                settings.light = names[current]
        elif kind == "led":
            current = LED_LIGHTS.index(settings.light) if settings.light in LED_LIGHTS else 0
            changed, current = imgui.combo("LED", current, list(LED_LIGHTS))
            if changed:
                settings.light = LED_LIGHTS[current]
        elif kind == "uva":
            current = UV_LIGHTS.index(settings.light) if settings.light in UV_LIGHTS else 0
            changed, current = imgui.combo("UV", current, list(UV_LIGHTS))
            if changed:
                settings.light = UV_LIGHTS[current]
        elif kind == "other":
            imgui.text(f"light {settings.light}")

    @staticmethod
    def _light_kind(light: str, info: PanelInfo) -> str:
        if light == SUN or light.startswith("sun"):
            return "sun"
        if light in UV_LIGHTS:
            return "uva"
        if light in LED_LIGHTS:
            return "led"
        if light in info.cie_lights:
            return "cie"
        return "other"

    def _fluorescence(self, settings: ViewerSettings, info: PanelInfo) -> None:
        for mode in FLUORESCENCE_MODES:
            if imgui.radio_button(mode, settings.fluorescence == mode):
                settings.fluorescence = mode
            imgui.same_line()
        imgui.new_line()
        if info.fluorescence_compiled is False and settings.fluorescence != "off":
            imgui.text_colored(DIM_COLOUR, "below the colour threshold: not compiled")
        imgui.text("bands")
        for bands in BAND_COUNTS:
            imgui.same_line()
            if imgui.radio_button(f"{bands}##bands", settings.bands == bands):
                settings.bands = bands

    def _display(self, settings: ViewerSettings, info: PanelInfo) -> None:
        auto = settings.ev100 is None
        changed, auto = imgui.checkbox("auto exposure", auto)
        if changed:
            settings.ev100 = None if auto else (info.ev100 if info.ev100 is not None else 10.0)
        shown = settings.ev100 if settings.ev100 is not None else (info.ev100 or 0.0)
        changed, value = imgui.slider_float("exposure", shown, *EV_SLIDER_RANGE, "EV %.1f")
        if changed:  # dragging the slider fixes the exposure
            settings.ev100 = value
        imgui.text("white balance")
        for choice in WHITE_BALANCES:
            imgui.same_line()
            if imgui.radio_button(f"{choice}##wb", settings.white_balance == choice):
                settings.white_balance = choice
        if settings.white_balance == "room" and info.white_balance_adapted is False:
            imgui.text_colored(DIM_COLOUR, "this light is no white: shown as D65")

    def _view(self, camera) -> None:
        """Zoom: the camera's distance to the curtain on a logarithmic slider (0.2 m shows
        the threads), clamped as the wheel is (inside the room); reset = the R key."""
        near, far = camera.distance_limits_m()
        slider_width_px = imgui.calc_item_width()   # the slider's frame, left of its label
        changed, value = imgui.slider_float("distance", float(camera.distance_m), near, far,
                                            "%.2f m", imgui.SliderFlags_.logarithmic)
        top_left, bottom_right = imgui.get_item_rect_min(), imgui.get_item_rect_max()
        self.zoom_rect_px = ((top_left.x, top_left.y), (top_left.x + slider_width_px, bottom_right.y))
        if changed:
            camera.set_distance(value)
        if imgui.button("reset view (R)"):
            camera.reset()
        top_left, bottom_right = imgui.get_item_rect_min(), imgui.get_item_rect_max()
        self.reset_rect_px = ((top_left.x, top_left.y), (bottom_right.x, bottom_right.y))
        imgui.same_line()
        imgui.text_colored(DIM_COLOUR, "wheel: zoom, drag: orbit")

    def _simulation(self, settings: ViewerSettings) -> None:
        changed, wind = imgui.slider_float("wind", settings.wind_m_s, *WIND_RANGE_M_S,
                                           "%.1f m/s")
        if changed:
            settings.wind_m_s = wind
        if imgui.button("Open curtain" if not settings.curtain_open else "Close curtain"):
            settings.curtain_open = not settings.curtain_open
        imgui.same_line()
        _, settings.paused = imgui.checkbox("pause (Space)", settings.paused)

    def _timing(self, settings: ViewerSettings, timer: FrameTimer) -> None:
        medians = timer.median_ms()
        if not medians:
            imgui.text("(measuring)")
            return
        total = medians["total"]
        fps = 1e3 / total if total > 0 else float("inf")
        imgui.text(f"{total:6.1f} ms  ({fps:5.1f} fps), median of {len(timer.history)}")
        _, settings.show_timing = imgui.checkbox("frame-time graphs", settings.show_timing)
        if not settings.show_timing:
            return
        imgui.text(f"simulation {medians['simulation']:5.1f} ms")
        imgui.text(f"shading    {medians['shading']:5.1f} ms")
        imgui.text(f"UI         {medians['ui']:5.1f} ms")
        imgui.text(f"other      {medians['other']:5.1f} ms  (swap, events)")
        totals = np.asarray(timer.totals_ms(), dtype=np.float32)
        imgui.plot_lines("##frametimes", totals, graph_size=imgui.ImVec2(self.width_px - 20, 40))

    def _messages(self, info: PanelInfo) -> None:
        if info.last_screenshot:
            imgui.text_colored(DIM_COLOUR, f"saved {info.last_screenshot}")
        for message in info.messages:
            imgui.push_text_wrap_pos(self.width_px - 10)
            imgui.text_colored(ERROR_COLOUR, message)
            imgui.pop_text_wrap_pos()

    def _help(self) -> None:
        io = imgui.get_io()
        imgui.set_next_window_pos(imgui.ImVec2(io.display_size.x * 0.5, io.display_size.y * 0.5),
                                  imgui.Cond_.always, imgui.ImVec2(0.5, 0.5))
        # sized from its text, not auto-resized: an auto-resized window is hidden in the frame
        # it first appears (imgui measures it then), so a screenshot of that frame missed it
        lines = [f"{key:>6}  {what}" for key, what in KEY_HELP]
        style = imgui.get_style()
        width = max(imgui.calc_text_size(line).x for line in lines) + 2 * style.window_padding.x
        height = (len(lines) * imgui.get_text_line_height_with_spacing() + imgui.get_frame_height()
                  + 2 * style.window_padding.y)
        imgui.set_next_window_size(imgui.ImVec2(width, height), imgui.Cond_.always)
        imgui.begin("Keys", None, imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.no_resize)
        for line in lines:
            imgui.text(line)
        imgui.end()
