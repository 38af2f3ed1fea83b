"""The panel's zoom (issue 12): a slider for the camera's distance and a reset button, driven
by imgui without a window (no GL: imgui's draw lists are built and not rendered), with the
mouse events a user's click sends. Bounds: a click at the slider's near end brings the camera
within 5 % of its nearest distance (0.2 m) on a logarithmic scale, one at the far end within
5 % of the room's limit in that direction; reset returns to the home distance exactly."""

from __future__ import annotations

import math

import pytest

imgui = pytest.importorskip("imgui_bundle").imgui

from catalog.viewer.input import OrbitCamera, room_limit_m  # noqa: E402
from catalog.viewer.panel import Panel  # noqa: E402


@pytest.fixture
def gui():
    context = imgui.create_context()
    io = imgui.get_io()
    io.display_size = imgui.ImVec2(400, 600)
    io.backend_flags |= imgui.BackendFlags_.renderer_has_textures  # no font texture needed
    io.mouse_double_click_time = 0.0  # two clicks in a row are two clicks, not a text edit
    io.set_ini_filename("")           # no imgui.ini written into the working folder
    yield io
    imgui.destroy_context(context)


def _frame(panel, camera):
    imgui.new_frame()
    imgui.set_next_window_pos(imgui.ImVec2(0, 0))
    imgui.set_next_window_size(imgui.ImVec2(360, 300))
    imgui.begin("panel")
    panel._view(camera)
    imgui.end()
    imgui.render()


def _click(io, panel, camera, x, y):
    io.add_mouse_pos_event(x, y)
    _frame(panel, camera)
    io.add_mouse_button_event(0, True)
    _frame(panel, camera)
    io.add_mouse_button_event(0, False)
    _frame(panel, camera)
    _frame(panel, camera)


def test_the_zoom_slider_moves_the_camera_and_reset_brings_it_home(gui):
    panel = Panel()
    camera = OrbitCamera(distance_m=2.6, home_distance_m=2.6)
    _frame(panel, camera)
    (x0, y0), (x1, y1) = panel.zoom_rect_px
    y = 0.5 * (y0 + y1)
    _click(gui, panel, camera, x0 + 3.0, y)   # the slider's near end
    assert abs(math.log(camera.distance_m / camera.min_distance_m)) < 0.05
    far = min(camera.max_distance_m, room_limit_m(camera.yaw_deg, camera.pitch_deg,
                                                   camera.target))
    _click(gui, panel, camera, x1 - 3.0, y)   # the far end: kept inside the room
    assert camera.distance_m <= far + 1e-9
    assert abs(math.log(camera.distance_m / far)) < 0.05
    (x0, y0), (x1, y1) = panel.reset_rect_px
    _click(gui, panel, camera, 0.5 * (x0 + x1), 0.5 * (y0 + y1))
    assert camera.distance_m == 2.6 and camera.yaw_deg == camera.view.yaw_deg \
        and camera.pitch_deg == camera.view.pitch_deg


def test_set_distance_is_clamped_like_the_wheel():
    camera = OrbitCamera()
    camera.set_distance(0.01)
    assert camera.distance_m == camera.min_distance_m
    camera.set_distance(100.0)
    assert camera.distance_m == camera.distance_limits_m()[1]
    before = camera.distance_m
    camera.set_distance(float("nan"))
    assert camera.distance_m == before
