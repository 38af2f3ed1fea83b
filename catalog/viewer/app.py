"""The viewer's window and main loop.

Per frame: poll events -> apply keys and panel changes -> step the cloth (simulation)
-> draw the curtain into the window's framebuffer, one renderer per half in split screen
(shading) -> draw the panel over it (UI) -> copy to the window and swap.

Everything is drawn into a framebuffer of our own and copied to the window: screenshots
read that framebuffer (``ctx.screen.read()`` on a glfw window raises a GL error, although
the pixels are right).
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from catalog.core.constants import FRAME_DT_S
from catalog.core.errors import CatalogError
from catalog.viewer.catalog_state import FabricCatalog
from catalog.viewer.input import Action, MouseOrbit, OrbitCamera, action_for_key
from catalog.viewer.settings import (SUN, ViewerSettings, next_fluorescence, next_light)
from catalog.viewer.timing import FrameTimer

#: Scene resolution on a software rasteriser (llvmpipe): a quarter of the pixels, upscaled.
SOFTWARE_RENDER_SCALE = 0.5
#: On a software rasteriser the room's light (issue 13) follows a moving cloth every this many
#: frames, and the glare (bloom) is off: docs/room.md has their cost.
SOFTWARE_ROOM_UPDATE_EVERY = 4
SOFTWARE_BLOOM = False
#: Bounds on the simulated time per frame in interactive use (slow machines run slow motion
#: rather than let the cloth take huge steps), s.
MIN_FRAME_DT_S, MAX_FRAME_DT_S = 1.0 / 240.0, 1.0 / 15.0
#: The panel alone is shown for at most this long before the scene's first frame, while the
#: thumbnails' drafts are drawn (ViewerApp._first_look), s.
FIRST_LOOK_MAX_S = 3.0


@dataclass
class ViewerOptions:
    """The command line's choices (see catalog/commands/view.py)."""

    fabric: str | None = None
    light: str | None = None
    compare: str | None = None
    size: tuple[int, int] = (1280, 720)
    frames: int | None = None  # run this many frames then exit (None: until closed)
    screenshot: Path | None = None  # PNG of the window after the last frame
    screenshot_dir: Path = Path("screenshots")  # where the S key saves
    stats: bool = False
    fluorescence: str = "physical"
    bands: int = 3
    hour: float | None = None
    wind_m_s: float | None = None
    grid: tuple[int, int] = (96, 56)
    distance_m: float | None = None  # the camera's home distance (R returns); None: the view's
    cloth_backend: str | None = None  # None: auto (see ViewerApp._choose_cloth_backend)
    panel: bool = True
    paused: bool = False
    render_scale: float | None = None  # scene resolution / window resolution; None: auto
    room_light: bool = True  # the room lit through the curtain, the clear sky, glare (issue 13)
    fabric_dir: Path | None = None  # None: --fabrics / $CATALOG_FABRICS, then the built-in catalog
    room: str | None = "living"  # the room (a built-in name or FILE.glb) lit by its transport
    ev100: float | None = None  # fixed exposure; None: automatic
    white_balance: str = "room"
    compare_fluorescence: str | None = None  # the right half's fluorescence (None: the left's)


def heavy_modules_loaded() -> dict[str, bool]:
    """Which of the modules the viewer must not need are in this process."""
    # a None entry is a module marked absent (catalog view marks scipy so), not a loaded one
    return {name: sys.modules.get(name) is not None
            for name in ("scipy", "colour", "matplotlib", "pvlib", "pandas")}


class ViewerApp:
    """A window, its GL context, the renderers, the cloth, the panel and the loop."""

    def __init__(self, options: ViewerOptions):
        self.options = options
        self.catalog = FabricCatalog(options.fabric_dir)
        if len(self.catalog) == 0:
            raise CatalogError(f"no presets (*.toml) in {self.catalog.where}")
        self.settings = ViewerSettings(fluorescence=options.fluorescence, bands=options.bands,
                                       show_panel=options.panel, paused=options.paused,
                                       ev100=options.ev100, white_balance=options.white_balance,
                                       compare_fluorescence=options.compare_fluorescence)
        if options.hour is not None:
            self.settings.sun_hour = options.hour
        if options.wind_m_s is not None:
            self.settings.wind_m_s = options.wind_m_s
        self._choose_start(options)
        from catalog.viewer.room_start import start_room  # noqa: PLC0415

        #: the room's window and inside (catalog.render.placement): the curtain's rod and the
        #: camera's views; its bundle built first (with progress) when not cached
        self.placement = start_room(options.room if options.room_light else None)
        self.camera = OrbitCamera(home_distance_m=options.distance_m, placement=self.placement)
        self.camera.reset()
        self.timer = FrameTimer()
        self._actions: list[Action] = []
        self._quit = False
        self._screenshot_requested = False
        self.messages: dict[str, str] = {}  # topic -> one-line error shown in the panel
        #: The first error that spoiled a frame (a fabric or light that could not be applied, a
        #: render that failed). Interactive use shows it in the panel and goes on; a --frames
        #: run ends with it (no screenshot, non-zero exit).
        self.frame_error: CatalogError | None = None
        self.last_screenshot: str | None = None

    def _loadable_index(self, name: str) -> int:
        """The catalog index of fabric ``name``, refused in one line if it does not load."""
        index = self.catalog.index_of(name)
        entry = self.catalog.load(index)
        if entry.preset is None:
            raise CatalogError(entry.error or f"cannot load fabric {name!r}")
        return index

    def _choose_start(self, options: ViewerOptions) -> None:
        if options.fabric is not None:
            self.settings.fabric_index = self._loadable_index(options.fabric)
        else:
            first = self.catalog.first_usable(0)
            self.settings.fabric_index = 0 if first is None else first
        if options.compare is not None:
            self.settings.compare_index = self._loadable_index(options.compare)
        if options.light is not None:
            from catalog.optics.lights import get_light  # noqa: PLC0415

            if options.light != SUN:
                get_light(options.light)  # an unknown name is refused before a window opens
            self.settings.light = options.light

    # ------------------------------------------------------------------------------
    def run(self) -> int:
        from catalog.viewer.window import open_window  # noqa: PLC0415

        glfw, window = open_window(self.options.size, "catalog view")
        try:
            return self._run_in(glfw, window)
        finally:
            glfw.destroy_window(window)
            glfw.terminate()

    def _run_in(self, glfw, window) -> int:
        import moderngl  # noqa: PLC0415
        from imgui_bundle import imgui  # noqa: PLC0415
        from imgui_bundle.python_backends.glfw_backend import GlfwRenderer  # noqa: PLC0415

        from catalog.gl.context import wrap_window_context  # noqa: PLC0415
        from catalog.render.settings import orbit  # noqa: PLC0415
        from catalog.viewer.panel import Panel, PanelInfo  # noqa: PLC0415
        from catalog.viewer.scene import CurtainScene  # noqa: PLC0415

        self.glfw = glfw
        self.window = window
        self.ctx: moderngl.Context = wrap_window_context()
        self.render_scale = self._choose_render_scale()
        self.cloth_backend = self._choose_cloth_backend()
        self.room_settings = self._choose_room_settings()
        if self._software_gl() and self.options.room_light:
            import sys  # noqa: PLC0415

            print(f"catalog view: software rasteriser ({self.ctx.info.get('GL_RENDERER', '?')}): "
                  f"render scale {self.render_scale:g}, {self.cloth_backend} cloth, the room's "
                  f"light every {self.room_settings['room_update_every']} frames while the cloth "
                  f"moves, bloom {'on' if self.room_settings['bloom'] else 'off'}",
                  file=sys.stderr, flush=True)
        glfw.swap_interval(0 if self.options.frames is not None else 1)

        imgui.create_context()
        imgui.get_io().set_ini_filename("")  # no imgui.ini left in the user's folder
        self.gui = GlfwRenderer(window, attach_callbacks=True)
        self.panel = Panel()
        self._install_callbacks(imgui)
        self.panel_info = PanelInfo(cie_lights=self._cie_light_names())
        from catalog.viewer.thumbnails import ThumbnailCache  # noqa: PLC0415

        self.thumbnails = ThumbnailCache(self.ctx)
        self.panel_info.thumbnails = self.thumbnails

        self.scene = CurtainScene(self.options.grid, backend=self.cloth_backend,
                                  wind_m_s=self.settings.wind_m_s, ctx=self.ctx,
                                  placement=self.placement)
        self._fbo = None
        self._renderers: list = []
        self._scaled_fbos: list = []  # one per renderer when render_scale < 1
        self._layout_key = None
        #: per renderer slot, the fabric and light it refused (not tried again until they change)
        self._refused: dict[int, dict] = {}

        if self.settings.show_panel:
            self._first_look(imgui)
        frame = 0
        last_time = time.perf_counter()
        while not glfw.window_should_close(window) and not self._quit:
            self.timer.begin_frame()
            glfw.poll_events()
            self._apply_actions()
            self._refresh_catalog()
            self._ensure_targets()

            now = time.perf_counter()
            if self.options.frames is not None:
                frame_dt = FRAME_DT_S  # a frame count: reproducible simulated time
            else:
                frame_dt = min(MAX_FRAME_DT_S, max(MIN_FRAME_DT_S, now - last_time))
            last_time = now

            with self.timer.part("shading"):  # fabric/light/mode changes: band integrals
                self._sync_renderers()

            with self.timer.part("simulation"):
                self.scene.set_wind(self.settings.wind_m_s)
                self.scene.set_open(self.settings.curtain_open)
                if not self.settings.paused:
                    self.scene.step(frame_dt)
                for renderer in self._renderers:
                    self.scene.feed(renderer)
                self.ctx.finish()  # the gpu cloth's compute passes are simulation time

            with self.timer.part("shading"):
                self._fbo.use()
                self._fbo.clear(0.0, 0.0, 0.0, 1.0)
                for slot, (renderer, viewport) in enumerate(zip(self._renderers,
                                                                self._viewports())):
                    renderer.update(camera=orbit(
                        self.camera.yaw_deg, self.camera.pitch_deg, self.camera.distance_m,
                        target=self.camera.target, fov_y_deg=self.camera.fov_y_deg, inside=True,
                        placement=self.placement))
                    try:
                        self._set_exposure(slot, renderer)
                        if self._scaled_fbos:
                            small = self._scaled_fbos[slot]
                            renderer.render(fbo=small, viewport=(0, 0, *small.size),
                                            dt_s=frame_dt)
                            self._blit(small, viewport)
                        else:
                            renderer.render(fbo=self._fbo, viewport=viewport, dt_s=frame_dt)
                        self.messages.pop(f"render{slot}", None)
                    except CatalogError as exc:  # e.g. no fabric loads: say so, keep running
                        self.messages[f"render{slot}"] = str(exc)
                        self.frame_error = self.frame_error or exc
                self.ctx.finish()

            with self.timer.part("ui"):
                if self.settings.show_panel:
                    self._update_thumbnails()
                self._update_panel_info()
                self.gui.process_inputs()
                imgui.new_frame()
                self.panel.draw(self.settings, self.catalog, self.timer, self.panel_info,
                                tuple(self.glfw.get_window_size(self.window)),
                                camera=self.camera)
                imgui.render()
                self._fbo.use()
                self.gui.render(imgui.get_draw_data())
                self.ctx.finish()

            frame += 1
            last_frame = self.options.frames is not None and frame >= self.options.frames
            if self._screenshot_requested:
                self._screenshot_requested = False
                self._save_screenshot_pair()
            if last_frame and self.options.screenshot is not None and self.frame_error is None:
                self._save_window_png(self.options.screenshot)

            self.ctx.copy_framebuffer(self.ctx.screen, self._fbo)
            glfw.swap_buffers(window)
            self._update_title()
            times = self.timer.end_frame()
            if self.options.stats:
                self._log_stats(times, frame)
            if last_frame:
                break

        if self.options.stats:
            summary = {"summary": True, "frames": frame, "size": list(self._fbo.size),
                       "grid": list(self.options.grid), "renderer": self.ctx.info["GL_RENDERER"],
                       "render_scale": self.render_scale, "cloth_backend": self.cloth_backend,
                       **self.room_settings,
                       **{f"median_{k}_ms": round(v, 3)
                          for k, v in self.timer.median_ms().items()},
                       **self._panel_summary()}
            print(json.dumps(summary), flush=True)
        self.gui.shutdown()
        self.thumbnails.release()
        if self.options.frames is not None and self.frame_error is not None:
            raise self.frame_error  # one line on stderr, exit 2 (or 3 for the environment)
        return 0

    def _first_look(self, imgui) -> None:
        """Before the scene's first frame (its shaders and the fabric's tables take seconds on
        a software rasteriser): the panel alone, redrawn while the thumbnails' drafts come in,
        until every fabric has one or FIRST_LOOK_MAX_S passed. Not a frame of --frames."""
        deadline = time.perf_counter() + FIRST_LOOK_MAX_S
        self.catalog.load_all()
        while not self.glfw.window_should_close(self.window) and time.perf_counter() < deadline:
            self.glfw.poll_events()
            self._ensure_targets()
            self._update_thumbnails()
            self._update_panel_info()
            self._fbo.use()
            self._fbo.clear(0.0, 0.0, 0.0, 1.0)
            self.gui.process_inputs()
            imgui.new_frame()
            self.panel.draw(self.settings, self.catalog, self.timer, self.panel_info,
                            tuple(self.glfw.get_window_size(self.window)), camera=self.camera)
            imgui.render()
            self._fbo.use()
            self.gui.render(imgui.get_draw_data())
            self.ctx.copy_framebuffer(self.ctx.screen, self._fbo)
            self.glfw.swap_buffers(self.window)
            if "all_drafts_s" in self.thumbnails.times_s:
                break

    def _refresh_catalog(self) -> None:
        """Pick up changed, added and removed preset files; keep showing the same fabrics
        (by name: an added file shifts the indices)."""
        names = self.catalog.names
        shown = names[self.settings.fabric_index] if self.settings.fabric_index < len(names) \
            else None
        compared = names[self.settings.compare_index] \
            if self.settings.compare_index is not None \
            and self.settings.compare_index < len(names) else None
        if not self.catalog.refresh():
            return
        self._refused.clear()  # a preset file changed: try the presets again
        names = self.catalog.names
        if shown in names:
            self.settings.fabric_index = names.index(shown)
        else:
            first = self.catalog.first_usable(0)
            self.settings.fabric_index = 0 if first is None else first
        self.settings.compare_index = names.index(compared) if compared in names else None

    # -- input ---------------------------------------------------------------------
    def _install_callbacks(self, imgui) -> None:
        glfw, gui = self.glfw, self.gui
        io = imgui.get_io()
        def ui_wants_mouse(x: float, y: float) -> bool:
            # the panel's strip is the panel's; elsewhere only the help window (imgui's
            # flag, which lags a frame) takes the mouse
            over_panel = self.settings.show_panel and 0 <= x < self.panel.width_px
            return over_panel or (self.settings.show_help and io.want_capture_mouse)

        self.orbit = MouseOrbit(self.camera, ui_wants_mouse=ui_wants_mouse)

        def on_key(window, key, scancode, action, mods):
            gui.keyboard_callback(window, key, scancode, action, mods)
            if io.want_text_input:
                return
            viewer_action = action_for_key(key, action)
            if viewer_action is not None:
                self._actions.append(viewer_action)

        def on_button(window, button, action, mods):
            gui.mouse_button_callback(window, button, action, mods)
            self.orbit.button(button, action)

        def on_cursor(window, x, y):
            gui.mouse_callback(window, x, y)
            self.orbit.moved(x, y)

        def on_scroll(window, x_offset, y_offset):
            gui.scroll_callback(window, x_offset, y_offset)
            self.orbit.scrolled(y_offset)

        glfw.set_key_callback(self.window, on_key)
        glfw.set_mouse_button_callback(self.window, on_button)
        glfw.set_cursor_pos_callback(self.window, on_cursor)
        glfw.set_scroll_callback(self.window, on_scroll)

    def _apply_actions(self) -> None:
        settings = self.settings
        actions, self._actions = self._actions, []
        for action in actions:
            if action is Action.NEXT_FABRIC:
                settings.fabric_index = self.catalog.step(settings.fabric_index, +1)
            elif action is Action.PREVIOUS_FABRIC:
                settings.fabric_index = self.catalog.step(settings.fabric_index, -1)
            elif action is Action.NEXT_LIGHT:
                settings.light = next_light(settings.light)
            elif action is Action.CYCLE_FLUORESCENCE:
                settings.fluorescence = next_fluorescence(settings.fluorescence)
            elif action is Action.TOGGLE_PAUSE:
                settings.paused = not settings.paused
            elif action is Action.SCREENSHOT:
                self._screenshot_requested = True
            elif action is Action.TOGGLE_HELP:
                settings.show_help = not settings.show_help
            elif action is Action.TOGGLE_PANEL:
                settings.show_panel = not settings.show_panel
            elif action is Action.TOGGLE_CURTAIN:
                settings.curtain_open = not settings.curtain_open
            elif action is Action.RESET_VIEW:
                self.camera.reset()
            elif action is Action.NEXT_VIEW:
                self.camera.next_view()
            elif action is Action.QUIT:
                self._quit = True

    # -- renderers -----------------------------------------------------------------
    def _halves(self) -> int:
        return 2 if self.settings.compare_index is not None else 1

    def _viewports(self) -> list[tuple[int, int, int, int]]:
        """The scene's rectangles (x, y, w, h) in the window: right of the panel when it is
        shown, halved for a comparison."""
        width, height = self._fbo.size
        left = self.panel.width_for(width) if self.settings.show_panel else 0
        scene_width = width - left
        if self._halves() == 1:
            return [(left, 0, scene_width, height)]
        half = scene_width // 2
        return [(left, 0, half, height), (left + half, 0, scene_width - half, height)]

    def _ensure_targets(self) -> None:
        """(Re)make the window framebuffer and the renderers when the size or split changes."""
        from catalog.render.frame import FrameRenderer  # noqa: PLC0415

        size = tuple(self.glfw.get_framebuffer_size(self.window))
        if size[0] < 2 or size[1] < 2:  # minimised
            size = self._fbo.size if self._fbo is not None else (2, 2)
        key = (size, self._halves(), self.settings.show_panel)
        if key == self._layout_key:
            return
        if self._fbo is None or self._fbo.size != size:
            if self._fbo is not None:
                self._fbo.release()
            self._fbo = self.ctx.simple_framebuffer(size, components=4)
        for renderer in self._renderers:
            self.scene.forget(renderer)
            renderer.release()
        for small in self._scaled_fbos:
            small.release()
        self._renderers, self._scaled_fbos = [], []
        self._refused = {}
        self._layout_key = key
        for viewport in self._viewports():
            size = (viewport[2], viewport[3])
            if self.render_scale < 1.0:
                size = (max(1, round(size[0] * self.render_scale)),
                        max(1, round(size[1] * self.render_scale)))
                self._scaled_fbos.append(self.ctx.simple_framebuffer(size, components=4))
            renderer = FrameRenderer(self.ctx, size)
            renderer.update(bloom=self.room_settings["bloom"],
                            room_lighting=self.room_settings["room_light"],
                            sky_model=self.room_settings["room_light"],
                            room_update_every=self.room_settings["room_update_every"],
                            **({"room": self.options.room}
                               if self.room_settings["room_light"] and self.options.room is not None
                               else {}))
            self._renderers.append(renderer)

    def _choose_render_scale(self) -> float:
        """The option's scale, or on a software rasteriser SOFTWARE_RENDER_SCALE, else 1."""
        if self.options.render_scale is not None:
            return float(self.options.render_scale)
        return SOFTWARE_RENDER_SCALE if self._software_gl() else 1.0

    def _choose_room_settings(self) -> dict:
        """The room lighting's cheaper settings on a software rasteriser (the frame budget:
        docs/room.md), the full ones on a GPU."""
        if not self.options.room_light:
            return {"room_light": False, "bloom": False, "room_update_every": 1}
        if self._software_gl():
            return {"room_light": True, "bloom": SOFTWARE_BLOOM,
                    "room_update_every": SOFTWARE_ROOM_UPDATE_EVERY}
        return {"room_light": True, "bloom": True, "room_update_every": 1}

    def _software_gl(self) -> bool:
        from catalog.render.passes.targets import software_rasteriser  # noqa: PLC0415

        return software_rasteriser(self.ctx.info)

    def _choose_cloth_backend(self) -> str:
        """The option's backend, or: the GLSL compute cloth on a GPU (it writes the vertex
        buffer the renderer draws), the numba CPU cloth on a software rasteriser (where compute
        shaders run on the same CPU, slower than numba: 75 vs 496 ms a frame at 128x128).
        `catalog view` marks scipy absent before numba is imported, so numba does not pull
        scipy in (catalog/commands/view.py)."""
        if self.options.cloth_backend is not None:
            return self.options.cloth_backend
        return "cpu" if self._software_gl() else "gpu"

    def _blit(self, small, viewport: tuple[int, int, int, int]) -> None:
        """Scale a reduced-resolution scene up into its viewport of the window framebuffer
        (glBlitFramebuffer, linear filter; moderngl's copy_framebuffer does not scale)."""
        from OpenGL import GL as gl  # noqa: PLC0415  (PyOpenGL: imgui's backend needs it anyway)

        x, y, width, height = viewport
        gl.glBindFramebuffer(gl.GL_READ_FRAMEBUFFER, small.glo)
        gl.glBindFramebuffer(gl.GL_DRAW_FRAMEBUFFER, self._fbo.glo)
        gl.glBlitFramebuffer(0, 0, small.size[0], small.size[1], x, y, x + width, y + height,
                             gl.GL_COLOR_BUFFER_BIT, gl.GL_LINEAR)
        self._fbo.use()

    def _sync_renderers(self) -> None:
        """Hand each renderer what the user chose: :meth:`FrameRenderer.update` compares it
        with what the renderer draws and returns what it made stale (empty when nothing
        changed), so the viewer keeps no copy of its own. A fabric or light the renderer
        refused is remembered (``_refused``) and not tried again every frame."""
        from catalog.render.settings import SunHour  # noqa: PLC0415

        settings = self.settings
        if len(self.catalog) == 0:
            self.messages["catalog"] = f"no presets (*.toml) in {self.catalog.where}"
            return
        self.messages.pop("catalog", None)
        fabrics = [settings.fabric_index]
        if settings.compare_index is not None:
            fabrics.append(settings.compare_index)
        for slot, (renderer, fabric_index) in enumerate(zip(self._renderers, fabrics)):
            refused = self._refused.setdefault(slot, {})
            entry = self.catalog.load(fabric_index)
            fabric_key = (entry.name, id(entry.preset))
            if entry.preset is not None and refused.get("fabric") != fabric_key:
                try:
                    if "fabric_tables" in renderer.update(fabric=entry.preset) and slot == 0:
                        self.scene.set_fabric(entry.preset)
                    refused.pop("fabric", None)
                    self.messages.pop(f"fabric{slot}", None)
                except CatalogError as exc:
                    refused["fabric"] = fabric_key
                    self.messages[f"fabric{slot}"] = str(exc)
                    self.frame_error = self.frame_error or exc
            light_key = (settings.light, settings.sun_hour if settings.light == SUN else None)
            if refused.get("light") != light_key:
                try:
                    renderer.update(light=SunHour(settings.sun_hour) if settings.light == SUN
                                    else settings.light)
                    self._sun = renderer.settings.sun_hour   # None: not the sun by hour
                    refused.pop("light", None)
                    self.messages.pop("light", None)
                except CatalogError as exc:
                    refused["light"] = light_key
                    self.messages["light"] = str(exc)
                    self.frame_error = self.frame_error or exc
            renderer.update(fluorescence=settings.fluorescence if slot == 0
                            else settings.right_fluorescence,
                            white_balance=settings.white_balance, bands=settings.bands)
        if self.scene.preset_name is None:
            entry = self.catalog.load(settings.fabric_index)
            if entry.preset is not None:
                self.scene.set_fabric(entry.preset)

    def _set_exposure(self, slot: int, renderer) -> None:
        """A fixed EV for every half; auto: the left half meters and adapts, the right half
        shows at the left's exposure (a comparison at one exposure, e.g. fluorescence on |
        off, shows the difference instead of metering it away)."""
        if self.settings.ev100 is not None:
            renderer.update(ev=self.settings.ev100)
        elif slot == 0:
            renderer.update(ev=None)
        else:
            left = self._renderers[0]
            renderer.update(ev=left.metered_ev100 if left.ev100 is None and
                            left.metered_ev100 is not None else None)

    def _thumbnail_scene(self) -> tuple:
        settings = self.settings
        return (settings.light, settings.sun_hour if settings.light == SUN else None,
                settings.fluorescence, settings.white_balance, settings.ev100)

    def _update_thumbnails(self) -> None:
        """Draw the thumbnails that are missing or stale (a few per frame)."""
        from catalog.render.settings import SunHour  # noqa: PLC0415

        settings = self.settings

        def apply_scene(renderer) -> None:
            if settings.light == SUN:
                renderer.update(light=SunHour(settings.sun_hour))
            else:
                renderer.update(light=settings.light)
            renderer.update(fluorescence=settings.fluorescence,
                            white_balance=settings.white_balance,
                            ev=settings.ev100)

        entries = [entry for entry in self.catalog.entries
                   if settings.fabric_filter.matches(entry.facts)]
        self.thumbnails.update(entries, self._thumbnail_scene(), apply_scene)

    def _panel_summary(self) -> dict:
        """What the panel showed at the end (the --stats summary; tests read it)."""
        scene = self._thumbnail_scene()
        thumbnails = {entry.name: [round(float(v), 3) for v in
                                   self.thumbnails.get(entry.name).pixels.reshape(-1, 3).mean(axis=0)]
                      for entry in self.catalog.entries
                      if self.thumbnails.get(entry.name) is not None
                      and self.thumbnails.has_draft(entry, scene)}   # draft or final
        final = sorted(entry.name for entry in self.catalog.entries
                       if self.thumbnails.is_current(entry, scene))
        return {"thumbnails": thumbnails, "thumbnail_renders": self.thumbnails.renders,
                "thumbnail_drafts": self.thumbnails.draft_renders, "thumbnails_final": final,
                "thumbnail_times_s": {k: round(v, 3) for k, v in self.thumbnails.times_s.items()},
                "facts": {entry.name: entry.facts.lines() for entry in self.catalog.entries
                          if entry.facts is not None},
                "labels": {entry.name: entry.label for entry in self.catalog.entries},
                "panel": self.panel.layout,
                "ev100": [r.info().get("ev100") for r in self._renderers],
                "fluorescence": [r.mode for r in self._renderers]}

    def _cie_light_names(self) -> list[str]:
        try:
            from catalog.optics.lights import cie_names  # noqa: PLC0415

            return list(cie_names())
        except CatalogError:
            return []

    def _update_panel_info(self) -> None:
        info = self.panel_info
        try:
            renderer_info = self._renderers[0].info() if self._renderers else {}
        except CatalogError:
            renderer_info = {}
        sun = getattr(self, "_sun", None)
        info.sun_path_km = None if sun is None else sun["path_km"]
        info.sun_elevation_deg = None if sun is None else 90.0 - sun["zenith_deg"]
        if sun is None and self.settings.light.startswith("sun:"):
            try:
                info.sun_path_km = float(self.settings.light[4:])
            except ValueError:
                pass
        info.fluorescence_compiled = renderer_info.get("fluorescence_needed")
        info.ev100 = renderer_info.get("ev100")
        info.white_balance_adapted = renderer_info.get("white_balance_adapted")
        info.messages = list(self.messages.values())
        info.last_screenshot = self.last_screenshot

    def _update_title(self) -> None:
        entry = self.catalog.entries[self.settings.fabric_index] \
            if self.settings.fabric_index < len(self.catalog) else None
        fabric = entry.label if entry is not None else "?"
        title = f"catalog view - {fabric}"
        if self.settings.compare_index is not None \
                and self.settings.compare_index < len(self.catalog):
            title += f" | {self.catalog.entries[self.settings.compare_index].label}"
        title += (f" - light {self.settings.light_label} - fluorescence "
                  f"{self.settings.fluorescence}")
        if self.settings.compare_index is not None and self.settings.compare_fluorescence:
            title += f" | {self.settings.compare_fluorescence}"
        if self.settings.paused:
            title += " (paused)"
        if title != getattr(self, "_title", None):
            self.glfw.set_window_title(self.window, title)
            self._title = title

    # -- screenshots and stats -------------------------------------------------------
    def window_pixels(self) -> np.ndarray:
        """The window as shown: (H, W, 3) uint8, row 0 at the top, read from our framebuffer."""
        width, height = self._fbo.size
        data = self._fbo.read(components=3, alignment=1)
        return np.frombuffer(data, dtype=np.uint8).reshape(height, width, 3)[::-1]

    def scene_linear(self) -> np.ndarray:
        """The curtain's linear radiance without the panel, halves side by side."""
        halves = [np.asarray(renderer.read_linear(), dtype=np.float32)
                  for renderer in self._renderers]
        return np.concatenate(halves, axis=1) if len(halves) > 1 else halves[0]

    def _shown_name(self) -> str:
        index = self.settings.fabric_index
        return self.catalog.entries[index].name if index < len(self.catalog) else "none"

    def _metadata(self) -> dict[str, str]:
        meta = {"catalog:fabric": self._shown_name(), "catalog:light": self.settings.light_label,
                "catalog:fluorescence": self.settings.fluorescence,
                "catalog:bands": str(self.settings.bands), "Software": "catalog view",
                "catalog:white_balance": self.settings.white_balance,
                "catalog:ev100": "auto" if self.settings.ev100 is None else str(self.settings.ev100)}
        compare = self.settings.compare_index
        if compare is not None and compare < len(self.catalog):
            meta["catalog:compare"] = self.catalog.entries[compare].name
        return meta

    def _save_window_png(self, path: Path) -> None:
        from catalog.viewer.screenshot import write_image  # noqa: PLC0415

        write_image(path, self.window_pixels(), self._metadata())

    def _save_screenshot_pair(self) -> None:
        from catalog.viewer.screenshot import next_screenshot_stem, write_image  # noqa: PLC0415

        stem = next_screenshot_stem(self.options.screenshot_dir, self._shown_name(),
                                    self.settings.light_label)
        try:
            write_image(stem.with_suffix(".exr"), self.scene_linear(), self._metadata())
            write_image(stem.with_suffix(".png"), self.window_pixels(), self._metadata())
            self.last_screenshot = str(stem) + ".{exr,png}"
            self.messages.pop("screenshot", None)
        except (CatalogError, OSError) as exc:
            self.messages["screenshot"] = f"screenshot not saved: {exc}"

    def _log_stats(self, times, frame: int) -> None:
        record = {"frame": frame, "total_ms": round(times.total_ms, 3),
                  **{f"{part}_ms": round(ms, 3) for part, ms in times.parts_ms.items()},
                  "other_ms": round(times.other_ms, 3)}
        if frame == 1:
            record["heavy_modules"] = heavy_modules_loaded()
            record["fabric"] = self._shown_name()
            record["light"] = self.settings.light_label
            record["panel_errors"] = self.catalog.errors() + list(self.messages.values())
        print(json.dumps(record), flush=True)
