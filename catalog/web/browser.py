"""Drive the web catalog in a real browser: Debian's ``chromium`` headless, WebGL2 through
SwiftShader (a CPU implementation), controlled by selenium through ``chromedriver``.

Used by the browser tests and the web benchmark; nothing here runs at page time.
"""

from __future__ import annotations

import base64
import io
import shutil
import time
from pathlib import Path
from urllib.parse import urlencode

import numpy as np

from catalog.core.errors import CatalogError

CHROMIUM_ARGS = ("--headless=new", "--no-sandbox", "--use-angle=swiftshader",
                 "--enable-unsafe-swiftshader", "--disable-dev-shm-usage",
                 "--force-device-scale-factor=1")


def find_browser() -> tuple[str, str] | None:
    """(chromium, chromedriver) paths, or None when either is missing."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    return (chromium, driver) if chromium and driver else None


def missing_reason() -> str | None:
    """Why the browser cannot run here (None when it can)."""
    try:
        import selenium  # noqa: F401, PLC0415
    except ImportError:
        return "selenium is not installed (tools/setup.sh installs .[test])"
    if find_browser() is None:
        return "Debian's chromium and chromium-driver are not installed (tools/setup.sh)"
    return None


class Browser:
    """One headless chromium with a page of the site."""

    def __init__(self, width: int = 1000, height: int = 900):
        from selenium import webdriver  # noqa: PLC0415
        from selenium.webdriver.chrome.service import Service  # noqa: PLC0415

        found = find_browser()
        if found is None:
            raise CatalogError(missing_reason() or "no browser")
        options = webdriver.ChromeOptions()
        for arg in CHROMIUM_ARGS:
            options.add_argument(arg)
        options.add_argument(f"--window-size={width},{height}")
        options.binary_location = found[0]
        options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        self.driver = webdriver.Chrome(options=options, service=Service(found[1]))
        self.driver.set_script_timeout(60)

    def open(self, site: Path, **state) -> float:
        """Load DIR/index.html with the state in its hash; wait until drawn. Returns the
        seconds from navigation to the first drawn frame (the page's own clock)."""
        url = (Path(site).resolve() / "index.html").as_uri()
        if state:
            url += "#" + urlencode({k: v for k, v in state.items() if v is not None})
        self.driver.get("about:blank")  # a new load even when only the hash differs
        self.driver.get(url)
        self.settle()
        first = self.driver.execute_script("return window.catalogApp.stats.firstFrameMs")
        return None if first is None else first / 1000.0

    def settle(self) -> None:
        """Wait until the page has drawn its state; a page that failed to start or whose frame
        failed (it would try again each animation frame, never drawn) is refused at once
        with its errors (CatalogError), rather than waited for until the script timeout."""
        # the page starts once its data is inflated: wait for its hooks first
        drawn = self.driver.execute_async_script(
            "const done = arguments[arguments.length - 1];"
            "const poll = () => window.catalogApp ? window.catalogApp.settle().then(done)"
            " : window.catalogStartError ? done(false) : setTimeout(poll, 20); poll();")
        if drawn is not True:
            errors = self.driver.execute_script(
                "return window.catalogApp ? window.catalogApp.stats.errors"
                " : [window.catalogStartError]")
            raise CatalogError("the page did not draw: " + "; ".join(map(str, errors)))

    def set(self, **state) -> None:
        self.driver.execute_script("window.catalogApp.set(arguments[0])", state)
        self.settle()

    def state(self) -> dict:
        return self.driver.execute_script("return Object.assign({}, window.catalogApp.state)")

    def canvas(self, element_id: str = "canvas-a") -> np.ndarray:
        """The canvas's pixels, uint8 (H, W, 3), row 0 = top."""
        from PIL import Image  # noqa: PLC0415

        url = self.driver.execute_script(
            "return document.getElementById(arguments[0]).toDataURL('image/png')", element_id)
        data = base64.b64decode(url.split(",", 1)[1])
        return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))

    def console_errors(self) -> list[str]:
        """Console messages at level SEVERE since the last call (page errors included)."""
        return [entry["message"] for entry in self.driver.get_log("browser")
                if entry.get("level") == "SEVERE"]

    def page_errors(self) -> list[str]:
        return self.driver.execute_script("return window.catalogApp.stats.errors")

    def benchmark(self, frames: int) -> dict:
        return self.driver.execute_script("return window.catalogApp.benchmark(arguments[0])", frames)

    def screenshot(self, path: Path) -> None:
        self.driver.save_screenshot(str(path))

    def close(self) -> None:
        self.driver.quit()


def _mesh(animation, frame: int) -> tuple:
    """The baked cloth's ``frame`` as set_mesh takes it."""
    from catalog.web import bake as bake_lib  # noqa: PLC0415

    positions, normals, tangents = bake_lib.decode_frame(animation, frame)
    return positions, normals, animation.uv, tangents, animation.indices.astype(np.int32)


def egl_frame(fabric: str, light: str, fluorescence: str, frame: int, size: tuple[int, int],
              animation, ctx=None, camera: tuple[float, float, float] | None = None,
              ev100: float | None = None, glare: str = "off", lamp: str = "none") -> np.ndarray:
    """The desktop frame (EGL) of the same fabric, light, fluorescence, glare and room-lamp
    switches, baked cloth frame and camera (yaw deg, pitch deg, distance m; default the renderer's): uint8 (H, W, 3), row
    0 = top. ``ev100``: the page's fixed exposure of the scene (None: the desktop meters).
    Without ``ctx``, in a context of its own, released after (the caller's current again)."""
    from catalog.gl.context import headless_context  # noqa: PLC0415

    with headless_context(ctx) as own:
        return _egl_frame_in(own, fabric, light, fluorescence, frame, size, animation, camera,
                             ev100, glare, lamp)


def _egl_frame_in(ctx, fabric, light, fluorescence, frame, size, animation, camera, ev100,
                  glare, lamp) -> np.ndarray:
    from catalog.render.frame import FrameRenderer  # noqa: PLC0415
    from catalog.render.settings import SunHour, orbit  # noqa: PLC0415
    from catalog.web.export import (FLUORESCENCE, GLARE, configure_desktop_frame,  # noqa: PLC0415
                                    room_lamps)

    renderer = FrameRenderer(ctx, size)
    try:
        renderer.update(fabric=fabric)
        if light.startswith("sun@"):
            renderer.update(light=SunHour(float(light[4:])))
        else:
            renderer.update(light=light)
        renderer.update(fluorescence=FLUORESCENCE[fluorescence])
        configure_desktop_frame(renderer)
        renderer.update(bloom=GLARE[glare], lamps=room_lamps(lamp))
        if ev100 is not None:
            renderer.update(ev=ev100)
        # the display's white measured as the export measures it (catalog.web.export.record:
        # the default camera, the baked cloth's first frame), then kept while the camera and
        # the cloth move, as the page keeps it
        renderer.set_mesh(*_mesh(animation, 0), fabric_size_m=animation.fabric_size_m)
        renderer.set_mesh_offset((0.0, 0.0, 0.0))
        renderer.set_rings(animation.rings_x_m)
        renderer.render()
        if camera is not None:
            renderer.update(camera=orbit(*camera))
        renderer.set_mesh(*_mesh(animation, frame), fabric_size_m=animation.fabric_size_m)
        renderer.render()
        return renderer.read_srgb8()
    finally:
        renderer.release()


#: The per-pixel comparison of a page frame with the EGL frame (docs/web.md). A pixel
#: matches when every channel is within PIXEL_TOLERANCE_8BIT of the EGL pixel, or, at an
#: edge, when the difference is what a one-pixel shift of that edge gives: one frame's pixel
#: lies (within the tolerance, per channel) between the least and the largest value of the
#: other frame's 3x3 neighbourhood (two rasterisers may cover a silhouette or crease pixel
#: differently; where one leaves a one-pixel crack between two faces, a face behind shows in
#: its frame only, so either direction counts). Every pixel must
#: match; at most EDGE_SHARE_MAX of them by the edge clause; the mean absolute difference
#: over all pixels and channels within MEAN_TOLERANCE_8BIT.
PIXEL_TOLERANCE_8BIT = 3
MEAN_TOLERANCE_8BIT = 0.5
EDGE_SHARE_MAX = 0.01


def site_data(site: Path) -> dict:
    """The page's data of a built site (data.js unpacked; bytes as base64)."""
    from catalog.web.site import unpack_data  # noqa: PLC0415

    return unpack_data((Path(site) / "data.js").read_text(encoding="utf-8"))


def _neighbourhood(image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-channel least and largest value of each pixel's 3x3 neighbourhood (int16)."""
    x = np.pad(image.astype(np.int16), ((1, 1), (1, 1), (0, 0)), mode="edge")
    h, w = image.shape[:2]
    stack = np.stack([x[i:i + h, j:j + w] for i in range(3) for j in range(3)])
    return stack.min(axis=0), stack.max(axis=0)


def compare_frames(page: np.ndarray, desktop: np.ndarray) -> dict:
    """The figures of the comparison rule above (no verdict: :func:`frames_match`)."""
    if page.shape != desktop.shape:
        raise CatalogError(f"frame sizes differ: page {page.shape}, desktop {desktop.shape}")
    p, d = page.astype(np.int16), desktop.astype(np.int16)
    diff = np.abs(p - d)
    worst = diff.max(axis=-1)
    tol = PIXEL_TOLERANCE_8BIT
    close = worst <= tol
    lo_d, hi_d = _neighbourhood(desktop)
    lo_p, hi_p = _neighbourhood(page)
    shift = (np.all((p >= lo_d - tol) & (p <= hi_d + tol), axis=-1)
             | np.all((d >= lo_p - tol) & (d <= hi_p + tol), axis=-1))
    edge = ~close & shift
    unmatched = ~close & ~shift
    return {"mean_abs_8bit": float(diff.mean()), "max_abs_8bit": int(diff.max()),
            # page minus desktop, per channel (R, G, B): a frame-wide shift (e.g. another
            # white balance or exposure) shows here, where edges average out
            "signed_mean_8bit": [round(float(v), 3) for v in (p - d).reshape(-1, 3).mean(axis=0)],
            "pixels": int(worst.size), "within_tolerance": int(close.sum()),
            "edge_shift": int(edge.sum()), "unmatched": int(unmatched.sum()),
            "max_abs_unmatched_8bit": int(worst[unmatched].max()) if unmatched.any() else 0}


def frames_match(figures: dict) -> bool:
    return (figures["unmatched"] == 0
            and figures["mean_abs_8bit"] <= MEAN_TOLERANCE_8BIT
            and figures["edge_shift"] <= EDGE_SHARE_MAX * figures["pixels"])


def wait_until(predicate, timeout_s: float = 10.0) -> bool:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False
