"""The panel's layout in a 1280x720 window, from imgui's own numbers (no GL, no window: the
draw lists are built and not rendered): with the default sections the light picker and every
open control end inside the window and the fabric list gets at least FABRIC_ROWS_MIN rows;
collapsing sections gives their height to the fabric list. Bounds: bottoms <= 720 px; a
collapsed section frees more than 20 px."""

from __future__ import annotations

import pytest

imgui = pytest.importorskip("imgui_bundle").imgui

from catalog.viewer.catalog_state import FabricCatalog  # noqa: E402
from catalog.viewer.input import OrbitCamera  # noqa: E402
from catalog.viewer.panel import FABRIC_ROWS_MIN, THUMBNAIL_PX, Panel, PanelInfo  # noqa: E402
from catalog.viewer.settings import ViewerSettings  # noqa: E402
from catalog.viewer.timing import FrameTimer  # noqa: E402

WINDOW = (1280, 720)


@pytest.fixture
def gui():
    context = imgui.create_context()
    io = imgui.get_io()
    io.display_size = imgui.ImVec2(*WINDOW)
    io.backend_flags |= imgui.BackendFlags_.renderer_has_textures  # no font texture needed
    io.set_ini_filename("")
    yield io
    imgui.destroy_context(context)


def _draw(panel, frames: int = 3) -> dict:
    catalog, settings, timer = FabricCatalog(), ViewerSettings(), FrameTimer()
    for _ in range(frames):
        timer.begin_frame()
        imgui.new_frame()
        panel.draw(settings, catalog, timer, PanelInfo(cie_lights=["D65", "A"]), WINDOW,
                   camera=OrbitCamera())
        imgui.render()
        timer.end_frame()
    return dict(panel.layout)


def test_the_panel_fits_a_1280x720_window_with_the_light_picker(gui):
    layout = _draw(Panel())
    assert len(FabricCatalog()) >= 8   # a list longer than the window could hold in full
    assert layout["light_bottom_px"] <= WINDOW[1]
    assert layout["content_bottom_px"] <= WINDOW[1]
    top, bottom = layout["fabric_list_px"]
    assert bottom - top >= FABRIC_ROWS_MIN * THUMBNAIL_PX[1]
    assert layout["sections"]["light"] and layout["sections"]["view"]


def test_collapsed_sections_give_their_height_to_the_fabric_list(gui):
    panel = Panel()
    before = _draw(panel)
    panel.sections.update(fluorescence=False, display=False, view=False)
    after = _draw(panel)
    assert not any(after["sections"][k] for k in ("fluorescence", "display", "view"))
    grown = (after["fabric_list_px"][1] - after["fabric_list_px"][0]) \
        - (before["fabric_list_px"][1] - before["fabric_list_px"][0])
    assert grown > 3 * 20
    assert after["content_bottom_px"] <= WINDOW[1]
    panel.sections.update(curtain=True, timing=True, compare=True)  # all open: the list keeps
    opened = _draw(panel)                                            # its rows, the panel scrolls
    top, bottom = opened["fabric_list_px"]
    assert bottom - top >= FABRIC_ROWS_MIN * THUMBNAIL_PX[1]
    assert opened["light_bottom_px"] <= WINDOW[1]
