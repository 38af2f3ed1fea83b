"""The web catalog in a real browser: Debian's chromium headless, WebGL2 through SwiftShader,
driven by selenium (catalog/web/browser.py). One browser for the module; the site is the
session's `web_site` (tests/conftest.py). The page's frame time is measured by the benchmark
(`catalog bench web`), not here."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from catalog.web import browser as web_browser

pytestmark = [pytest.mark.browser, pytest.mark.gl, pytest.mark.slow]

_missing = web_browser.missing_reason()
if _missing:
    pytestmark.append(pytest.mark.skip(reason=_missing))

SIZE = (160, 120)


@pytest.fixture(scope="module")
def page(web_site):
    b = web_browser.Browser(1000, 900)
    yield b
    b.close()


@pytest.fixture(scope="module")
def animations(web_site):
    """The site's baked animations, read from its own anim/*.js and decoded by the reference
    decoder (so the EGL frame gets exactly the page's curtain)."""
    from catalog.web.bake import read_script

    out, _ = web_site
    return {a.key: a for a in (read_script(p) for p in (out / "anim").iterdir())}


def _animation_of(out: Path, fabric: str, animations) -> object:
    data = web_browser.site_data(out)
    return animations[next(f["animation"] for f in data["fabrics"] if f["name"] == fabric)]


def _viewer(page, out, **state):
    state = {"view": "viewer", "size": f"{SIZE[0]}x{SIZE[1]}", **state}
    page.open(out, **state)
    return page.canvas()


def test_page_loads_without_errors_and_renders(page, web_site):
    out, _ = web_site
    page.open(out)
    assert page.console_errors() == []
    assert page.page_errors() == []
    cards = page.driver.find_elements("css selector", "#grid .card")
    assert [c.get_attribute("data-fabric") for c in cards] == ["fluoro-pink", "linen-dense"]
    # a card opens the viewer, which draws a curtain (not black, not one colour)
    cards[0].click()
    page.settle()
    image = page.canvas()
    assert page.state()["view"] == "viewer"
    assert image.mean() > 20 and image.reshape(-1, 3).std(axis=0).max() > 5
    assert page.console_errors() == []


#: Since the display adapts to the light of the surfaces in view (measured from the frame's
#: drawn HDR target and G-buffer): the export records its scenes dry (no pixels drawn), so the
#: recorded white is measured from an undrawn target (it falls back to the light's own white:
#: the identity under D65) and the page's white balance differs from the desktop's: under the
#: sun 12 449 of 19 200 pixels over 3/255, mean 4.0/255; fluoro-pink under D65 (the room lit
#: through the pink cloth) a frame-wide shift, page minus desktop R +1.32, G -0.73, B +0.21
#: (mean 0.87/255, the edge clause met: 166 of 19 200). With a drawn frame's white put into the
#: page's data the D65 cases pass: mean 0.25 (glare off, the desktop's own 160x120 white), 0.35
#: and 0.34 (glare off, on: the white of a drawn frame at the recorder's 67x43); with issue 33's
#: real frame before the dry one and the lamps in the white's key (test_white_lamps.py) the
#: export gives mean 0.34, 147 edge pixels (glare off). Drop the marks once both are merged.
#: linen-dense sun@18 with lamp A stays off (mean 4.9, page minus desktop B +9.7): the visible
#: white depends on the frame's aspect (its field of view), and the recorder's 67x43 (1.56) is
#: not the test's 4:3 (sun@18, lamp A: blue gain 1.40 at 67x43, 1.44 at 16:9, 1.22 at 4:3).
_WHITE_MISMATCH = pytest.mark.xfail(reason="page vs desktop: the export's dry recording "
                                           "measures the visible white from an undrawn target",
                                    strict=False)


@pytest.mark.parametrize("fabric, light, fluorescence, frame, camera, glare, lamp", [
    pytest.param("fluoro-pink", "D65", "on", 0, None, "off", "none", marks=_WHITE_MISMATCH),
    pytest.param("linen-dense", "sun@8", "on", 17, None, "off", "none", marks=_WHITE_MISMATCH),
    ("fluoro-pink", "UV-A", "off", 30, None, "off", "none"),
    pytest.param("fluoro-pink", "sun@15", "on", 5, (35.0, 20.0, 1.8), "off", "none",  # its camera
                 marks=_WHITE_MISMATCH),
    pytest.param("fluoro-pink", "D65", "on", 0, None, "on", "none",      # the glare's targets
                 marks=_WHITE_MISMATCH),
    pytest.param("linen-dense", "sun@18", "on", 3, None, "on", "A",      # a room lamp
                 marks=_WHITE_MISMATCH),  # measured: mean 3.1/255, 11 136 pixels unmatched
])
def test_page_frame_matches_the_egl_frame(page, web_site, animations, gl, fabric, light,
                                          fluorescence, frame, camera, glare, lamp):
    """The page's canvas and the desktop frame (EGL, same baked cloth frame, same camera, same
    glare and room lamp): off edges every channel within 3/255, mean within 0.5/255, at most
    1 % of the pixels over 3/255 on edges (browser.py states the rule)."""
    out, _ = web_site
    orbit = {} if camera is None else dict(zip(("yaw_deg", "pitch_deg", "distance_m"), camera))
    shown = _viewer(page, out, fabric=fabric, light=light, fluorescence=fluorescence, frame=frame,
                    glare=glare, lamp=lamp, **orbit)
    scene = web_browser.site_data(out)["scenes"][f"{fabric}|{light}|{fluorescence}|{glare}|{lamp}"]
    desktop = web_browser.egl_frame(fabric, light, fluorescence, frame, SIZE,
                                    _animation_of(out, fabric, animations), ctx=gl, camera=camera,
                                    ev100=scene["ev100"], glare=glare, lamp=lamp)
    figures = web_browser.compare_frames(shown, desktop)
    assert web_browser.frames_match(figures), json.dumps(figures)
    assert page.console_errors() == []


def test_page_decodes_the_packed_data_as_the_reference(page, web_site, animations):
    """data.js and anim/*.js hold deflated, quantised bytes (site.pack_data, bake.encode,
    export.encode_texels); what the page decodes from them is bit for bit what the reference
    decoders give, whose distance to the desktop's values the codec tests bound (texels within
    half a step of their channel's range, positions within 0.05 mm, normals within 1/254)."""
    import base64

    from catalog.web.bake import decode_frames
    from catalog.web.export import decode_texels

    out, _ = web_site
    page.open(out)
    data = web_browser.site_data(out)
    run = "const done = arguments[arguments.length - 1];" \
          "window.catalogApp.decoded(arguments[0], arguments[1], arguments[2]).then(done);"
    as_f32 = lambda text: np.frombuffer(base64.b64decode(text), dtype="<f4")  # noqa: E731
    quantised = [rid for rid, t in data["textures"].items() if t.get("quantised")]
    assert len(quantised) >= 2  # the two fabrics' patterns
    for rid in quantised:
        page_texels = as_f32(page.driver.execute_async_script(run, "texels", rid, 0))
        assert np.array_equal(page_texels, decode_texels(data["textures"][rid])), rid
    for key, animation in animations.items():
        reference = decode_frames(animation)
        for frame in (0, 1, 2, animation.frames - 1):
            arrays = page.driver.execute_async_script(run, "animation", key, frame)
            for got, want in zip(arrays, reference):
                assert np.array_equal(as_f32(got), want[frame].ravel()), (key, frame)
    assert page.console_errors() == []


def test_fluorescence_switch_changes_the_uv_picture(page, web_site):
    """Under UV-A, switching the brightener's fluorescence off (key F) changes the curtain (at
    least a tenth of the picture) and only darkens: fluorescence adds light to every pixel
    it touches; switching it on again (the checkbox) restores the frame exactly."""
    out, _ = web_site
    on = _viewer(page, out, fabric="fluoro-pink", light="UV-A", frame=0)
    page.driver.find_element("id", "canvas-a").send_keys("f")
    page.settle()
    assert page.state()["fluorescence"] == "off"
    off = page.canvas()
    page.driver.find_element("id", "fluorescence").click()  # the checkbox
    page.settle()
    again = page.canvas()
    changed = np.any(on != off, axis=-1)
    assert changed.mean() > 0.1
    brightness_on = on.astype(int).sum(axis=-1)[changed]
    brightness_off = off.astype(int).sum(axis=-1)[changed]
    assert np.all(brightness_off <= brightness_on)
    assert np.array_equal(again, on)


def test_glare_switch_spreads_light_from_bright_to_dark(page, web_site):
    """The glare (key G, then the checkbox) is the desktop's energy-preserving bloom: it
    brightens the darkest tenth of the picture (mean +1/255 at least; measured +2..3/255 at the
    bounds' setting) and does not brighten the brightest tenth (mean change <= +0.1/255;
    measured -0.2..-0.4/255); off again gives the frame back exactly."""
    out, _ = web_site
    on = _viewer(page, out, fabric="linen-dense", light="D65", frame=0)
    assert page.state()["glare"] == "on"  # the snapshot's default
    page.driver.find_element("id", "canvas-a").send_keys("g")
    page.settle()
    assert page.state()["glare"] == "off"
    off = page.canvas()
    page.driver.find_element("id", "glare").click()
    page.settle()
    assert page.state()["glare"] == "on" and np.array_equal(page.canvas(), on)
    lum = off.astype(float).mean(axis=-1)
    change = (on.astype(float) - off).mean(axis=-1)
    dark, bright = lum <= np.percentile(lum, 10), lum >= np.percentile(lum, 90)
    assert change[dark].mean() >= 1.0
    assert change[bright].mean() <= 0.1


@pytest.mark.xfail(strict=True, reason="issue 32: the page draws the room under the constant light "
                                      "until it loads the room's transport pack, so a lamp no longer "
                                      "lights the walls beside it (mean 0.157 against 2 x 0.146 asked)")
def test_room_lamp_switch_lights_the_room_beside_it(page, web_site):
    """A room lamp (the select, then key M) stands right of the window: it only adds light
    (at most 0.5 % of the pixels darker by over 2/255: edge pixels; the exposure is the
    scene's), more on the right third of the picture than on the left (measured 32 vs 9/255),
    and the incandescent lamp's light is redder than the white LED's (red over blue)."""
    from selenium.webdriver.support.ui import Select

    out, _ = web_site
    none = _viewer(page, out, fabric="linen-dense", light="D65", frame=0, glare="off").astype(int)
    Select(page.driver.find_element("id", "lamp")).select_by_value("A")
    page.settle()
    assert page.state()["lamp"] == "A"
    lamp_a = page.canvas().astype(int)
    page.driver.find_element("id", "canvas-a").send_keys("m")
    page.settle()
    assert page.state()["lamp"] == "LED-B4"
    lamp_led = page.canvas().astype(int)
    w = none.shape[1]
    ratios = []
    for lit in (lamp_a, lamp_led):
        change = lit - none
        assert (change.min(axis=-1) < -2).mean() <= 0.005
        assert change[:, 2 * w // 3:].mean() > 2.0 * change[:, :w // 3].mean() > 0
        ratios.append(change[..., 0].mean() / change[..., 2].mean())
    assert ratios[0] > 1.5 * ratios[1]


def test_light_switch_and_sun_hour(page, web_site):
    from selenium.webdriver.support.ui import Select

    out, _ = web_site
    d65 = _viewer(page, out, fabric="linen-dense", light="D65", frame=0)
    Select(page.driver.find_element("id", "light")).select_by_value("sun")
    page.settle()
    state = page.state()
    assert state["light"] == "sun@12"
    assert page.driver.find_element("id", "hour-label").is_displayed()
    noon = page.canvas()
    page.driver.find_element("id", "canvas-a").send_keys("[")  # an hour earlier
    page.settle()
    assert page.state()["light"] == "sun@11"
    assert np.abs(noon.astype(int) - d65.astype(int)).mean() > 2


def test_orbit_zoom_keys_and_drag(page, web_site):
    from selenium.webdriver.common.action_chains import ActionChains

    out, _ = web_site
    first = _viewer(page, out, fabric="fluoro-pink", light="D65", frame=0)
    canvas = page.driver.find_element("id", "canvas-a")
    ActionChains(page.driver).click_and_hold(canvas).move_by_offset(40, 10).release().perform()
    page.settle()
    state = page.state()
    assert state["yaw_deg"] == pytest.approx(-12.0) and state["pitch_deg"] == pytest.approx(3.0)
    orbited = page.canvas()
    canvas.send_keys("+")
    page.settle()
    assert page.state()["distance_m"] == pytest.approx(2.6 / 1.1)
    assert np.abs(orbited.astype(int) - first.astype(int)).mean() > 1
    canvas.send_keys("r")
    page.settle()
    assert np.array_equal(page.canvas(), first)


def test_the_cloth_plays_and_pauses(page, web_site):
    """Playing advances the loop (the picture moves); Space pauses it (the picture holds)."""
    import time

    out, _ = web_site
    page.open(out, view="viewer", fabric="fluoro-pink", light="D65", size="160x120")
    assert page.state()["playing"]
    first, t0 = page.canvas(), page.state()["t"]
    time.sleep(1.0)
    page.settle()
    assert page.state()["t"] > t0
    assert not np.array_equal(page.canvas(), first)
    page.driver.find_element("id", "canvas-a").send_keys(" ")
    page.settle()
    paused = page.canvas()
    time.sleep(0.5)
    assert not page.state()["playing"]
    assert np.array_equal(page.canvas(), paused)


def test_compare_shows_the_second_fabric(page, web_site):
    from selenium.webdriver.support.ui import Select

    out, _ = web_site
    a = _viewer(page, out, fabric="fluoro-pink", light="D65", frame=0)
    Select(page.driver.find_element("id", "compare")).select_by_value("linen-dense")
    page.settle()
    assert page.driver.find_element("id", "pane-b").is_displayed()
    b = page.canvas("canvas-b")
    assert b.shape == a.shape
    assert np.abs(a.astype(int) - b.astype(int)).mean() > 2   # another fabric, another picture
    assert page.console_errors() == []


def test_facts_and_phone_size(page, web_site):
    out, _ = web_site
    page.driver.set_window_size(390, 844)
    try:
        page.open(out, view="viewer", fabric="fluoro-pink", light="D65", frame=0)
        facts = page.driver.find_element("id", "facts").text
        assert "26 % see-through" in facts and "quantum yield" in facts and "fluorescent dye" in facts
        width = page.driver.execute_script("return [document.documentElement.scrollWidth, window.innerWidth]")
        assert width[0] <= width[1], "the page scrolls sideways at phone width"
        canvas = page.driver.find_element("id", "canvas-a")
        assert canvas.size["width"] <= 390
        shot = os.environ.get("CATALOG_WEB_SCREENSHOT_PHONE")
        if shot:
            page.screenshot(Path(shot))
    finally:
        page.driver.set_window_size(1000, 900)


def test_touch_orbit_and_pinch(page, web_site):
    """Touch through Chrome's input layer (DevTools touch events): one finger orbits, two
    fingers spreading apart zoom in."""
    out, _ = web_site
    _viewer(page, out, fabric="fluoro-pink", light="D65", frame=0)
    rect = page.driver.execute_script(
        "const r = document.getElementById('canvas-a').getBoundingClientRect();"
        "return [r.left + r.width / 2, r.top + r.height / 2];")
    x, y = rect

    def touch(kind, points):
        page.driver.execute_cdp_cmd("Input.dispatchTouchEvent", {
            "type": kind, "touchPoints": [{"x": px, "y": py, "id": i} for i, (px, py) in
                                          enumerate(points)]})

    touch("touchStart", [(x, y)])
    touch("touchMove", [(x + 20, y)])
    touch("touchEnd", [])
    page.settle()
    assert page.state()["yaw_deg"] == pytest.approx(-6.0)
    before = page.state()["distance_m"]
    touch("touchStart", [(x - 20, y), (x + 20, y)])
    touch("touchMove", [(x - 30, y), (x + 30, y)])
    touch("touchMove", [(x - 40, y), (x + 40, y)])
    touch("touchEnd", [])
    page.settle()
    assert page.state()["distance_m"] < before


def test_static_host_and_no_network(page, web_site):
    """The same site served over HTTP (any static host) renders too; and the page asks for
    nothing but its own files (file:// or that host)."""
    import functools
    import http.server
    import threading

    out, _ = web_site
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(out))
    handler.log_message = lambda *a: None
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        port = server.server_address[1]
        page.driver.get("about:blank")
        page.driver.get(f"http://127.0.0.1:{port}/index.html#view=viewer&fabric=linen-dense"
                        f"&light=D65&frame=0&size=160x120")
        page.settle()
        image = page.canvas()
        names = page.driver.execute_script(
            "return performance.getEntriesByType('resource').map(e => e.name)")
        assert image.mean() > 20
        assert names and all(n.startswith(f"http://127.0.0.1:{port}/") for n in names)
        assert page.console_errors() == []
    finally:
        server.shutdown()
        server.server_close()
    # from file://: every reference in the document (scripts added by the page included) is a
    # relative path, an in-page anchor or a data: URL
    page.open(out, view="viewer", fabric="linen-dense", light="D65", frame=0)
    refs = page.driver.execute_script(
        "return [...document.querySelectorAll('[src],[href]')]"
        ".map(e => e.getAttribute('src') || e.getAttribute('href'))")
    assert any(r.startswith("anim/") for r in refs)
    for ref in refs:
        assert ref.startswith(("data:", "#")) or "://" not in ref and not ref.startswith("//"), ref


def test_plain_json_data_renders_the_same(page, web_site, tmp_path):
    """The page also reads data.js as plain JSON (site.plain_data_js, the form before packing,
    which the benchmark loads for its before/after): the same canvas, pixel for pixel."""
    import shutil

    from catalog.web.site import plain_data_js

    out, _ = web_site
    plain = tmp_path / "plain"
    shutil.copytree(out, plain)
    (plain / "data.js").write_text(plain_data_js(web_browser.site_data(out)), encoding="utf-8")
    state = {"fabric": "fluoro-pink", "light": "sun@15", "frame": 5, "lamp": "A"}
    packed_image = _viewer(page, out, **state)
    plain_image = _viewer(page, plain, **state)
    assert np.array_equal(packed_image, plain_image)
    assert page.console_errors() == [] and page.page_errors() == []


def test_a_frame_that_fails_is_reported_not_waited_for(page, web_site, tmp_path):
    """A frame that throws is tried again at each animation frame and never counts as drawn
    (issue 32's lit room: a sampler2DShadow uniform the page refused, which looked like a hang
    of the first frame until the selenium script timeout): settle gives up at once with the
    page's error (CatalogError), well within the 60 s script timeout; the page's own copy of
    the site, its replayer made to throw."""
    import shutil
    import time

    from catalog.core.errors import CatalogError

    out, _ = web_site
    broken = tmp_path / "broken"
    shutil.copytree(out, broken)
    app = (broken / "app.js").read_text(encoding="utf-8")
    marker = "    render(scene, camera) {\n"
    assert app.count(marker) == 1
    (broken / "app.js").write_text(app.replace(
        marker, marker + "      throw new Error('a recorded command the page cannot replay');\n"),
        encoding="utf-8")
    start = time.monotonic()
    with pytest.raises(CatalogError, match="did not draw: .*a recorded command the page cannot"):
        page.open(broken, view="viewer", fabric="fluoro-pink", light="D65", frame=0)
    assert time.monotonic() - start < 20.0
    # the broken page throws at every animation frame until it is left: leave it, then read
    # its messages, so that the next test on this browser starts clean
    page.driver.get("about:blank")
    page.console_errors()


def test_frame_time_under_swiftshader_is_reported(page, web_site, record_property):
    """Reported, not asserted as a speed (BENCHMARKS.md has the benchmark's figures): the hook
    gives finite frame times, the CPU part no larger than the whole frame."""
    out, _ = web_site
    _viewer(page, out, fabric="fluoro-pink", light="D65", frame=0)
    result = page.benchmark(5)
    assert 0 < result["cpu_ms"] <= result["frame_ms"] < 60_000
    record_property("swiftshader_frame_ms_160x120", result["frame_ms"])
    print(f"page frame under SwiftShader at 160x120: {result['frame_ms']:.1f} ms "
          f"(CPU part {result['cpu_ms']:.1f} ms)")


def test_screenshot_for_the_readme(page, web_site):
    """The page as a visitor sees it (compare on, UV-A); written where
    CATALOG_WEB_SCREENSHOT says (the README's picture comes from this test)."""
    out, _ = web_site
    page.open(out, view="viewer", fabric="fluoro-pink", compare="linen-dense", light="sun@17",
              frame=0)
    assert page.console_errors() == []
    shot = os.environ.get("CATALOG_WEB_SCREENSHOT")
    if shot:
        page.screenshot(Path(shot))
