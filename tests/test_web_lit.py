"""The page with the room lit by its transport (issue 32, export.DESKTOP_MODES
``room_lighting`` on for this module's site): the page replays the host step's recorded
outputs (the light map, the room-side, wall and cloth textures) and draws the room as the
desktop does, in headless Chromium (SwiftShader) against the desktop frame (EGL, llvmpipe).

Measured (160x120, D65; frames 0 and 5): the room's pixels within 1/255 (the walls'
gradients differ by a quantisation step in places), their mean 0.01-0.11/255; the whole
frame's mean 0.21-0.37/255, 138-245 pixels over 3/255 that a one-pixel edge shift explains
(the rod's line, the folds' edges: over browser.py's 1 % for fluoro-pink), 0-1 pixel
unmatched (a glint on a fold). The site's scenes are recorded with the room lit; the page's
own export keeps the constant room (export.DESKTOP_MODES says why)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from catalog.web import browser as web_browser

pytestmark = [pytest.mark.browser, pytest.mark.gl, pytest.mark.slow]

_missing = web_browser.missing_reason()
if _missing:
    pytestmark.append(pytest.mark.skip(reason=_missing))

SIZE = (160, 120)
#: Every channel of every room pixel (outside the curtain and its rod, ROOM_MARGIN_PX from
#: them) within this of the desktop's, and their mean within ROOM_MEAN_8BIT.
ROOM_TOLERANCE_8BIT = 2
ROOM_MEAN_8BIT = 0.5
#: The curtain's and the rod's pixels: the box of the cloth's projected vertices grown by this
#: (the rod and its rings overhang the cloth by some 7 px at this size).
ROOM_MARGIN_PX = 9


@pytest.fixture(scope="module")
def lit(tmp_path_factory, gl_context):
    """(site folder, animations by key) of a lit-room site of two fabrics of different cloth
    under D65; DESKTOP_MODES room_lighting on while the module runs (the desktop frames
    compared are lit too)."""
    from catalog.web import export
    from catalog.web.bake import read_script
    from catalog.web.site import build_site

    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(export.DESKTOP_MODES, "room_lighting", True)
        out = tmp_path_factory.mktemp("web_lit") / "site"
        build_site(out, fabrics="fluoro-pink,linen-dense", lights="D65", ctx=gl_context)
        yield out, {a.key: a for a in (read_script(p) for p in (out / "anim").iterdir())}


@pytest.fixture(scope="module")
def page(lit):
    b = web_browser.Browser(1000, 900)
    yield b
    b.close()


def _room_mask(data: dict, animation, frame: int) -> np.ndarray:
    """(H, W) True on the room's pixels: outside the box of the baked frame's vertices as the
    page's default camera projects them, grown by ROOM_MARGIN_PX."""
    from catalog.render.settings import orbit
    from catalog.web.bake import decode_frame

    c = data["camera"]
    camera = orbit(c["yaw_deg"], c["pitch_deg"], c["distance_m"], target=c["target"],
                   fov_y_deg=c["fov_y_deg"])
    p = decode_frame(animation, frame)[0].astype(np.float64)
    clip = np.c_[p, np.ones(len(p))] @ camera.view_projection(SIZE[0] / SIZE[1]).T
    ndc = clip[:, :2] / clip[:, 3:]
    x = (ndc[:, 0] + 1) / 2 * SIZE[0]
    y = (1 - ndc[:, 1]) / 2 * SIZE[1]
    m = ROOM_MARGIN_PX
    rows, cols = np.mgrid[0:SIZE[1], 0:SIZE[0]]
    inside = ((cols >= x.min() - m) & (cols <= x.max() + m)
              & (rows >= y.min() - m) & (rows <= y.max() + m))
    return ~inside


@pytest.mark.parametrize("fabric, frame, glare, lamp", [
    ("linen-dense", 0, "off", "none"),   # the site's second fabric: its own cloth recorded
    ("linen-dense", 0, "on", "A"),       # the glare's targets and a room lamp in the transport
    # measured: the room's pixels within 2/255 but their mean 0.65/255, a frame-wide shift
    # (page minus desktop R -1.33, G +0.28, B +0.85): the display's white, as in
    # test_web_browser's _WHITE_MISMATCH cases, not the room's light
    pytest.param("fluoro-pink", 0, "on", "A", marks=pytest.mark.xfail(
        reason="page vs desktop: the recorded frame's visible white (its 67x43 aspect)",
        strict=False)),
    # the cloth moved: the desktop updates the room's light from its frame 5, the page
    # replays the recorded one (frame 0's); measured: the room's pixels within 1/255 still
    ("fluoro-pink", 5, "off", "none"),
])
def test_the_lit_room_on_the_page_is_the_desktops(page, lit, gl_context, fabric, frame, glare,
                                                  lamp):
    """The page's frame and the desktop's (the same baked cloth frame, the scene's exposure),
    both with the room lit: every room pixel within ROOM_TOLERANCE_8BIT per channel, their
    mean within ROOM_MEAN_8BIT; the whole frame's mean within browser.py's
    MEAN_TOLERANCE_8BIT. The lit room is not the constant one: on the same pixels the desktop's
    constant room differs from its lit room by more than the page does."""
    from catalog.web import export

    out, animations = lit
    data = web_browser.site_data(out)
    key = export.scene_key(fabric, "D65", "on", glare, lamp)
    scene = data["scenes"][key]
    assert any(c["op"] == "host" for c in data["structures"][scene["structure"]])
    animation = animations[next(f["animation"] for f in data["fabrics"] if f["name"] == fabric)]
    page.open(out, view="viewer", size=f"{SIZE[0]}x{SIZE[1]}", fabric=fabric, light="D65",
              fluorescence="on", frame=frame, glare=glare, lamp=lamp)
    shown = page.canvas()
    assert page.console_errors() == [] and page.page_errors() == []
    same = dict(fabric=fabric, light="D65", fluorescence="on", frame=frame, size=SIZE,
                animation=animation, ctx=gl_context, ev100=scene["ev100"], glare=glare, lamp=lamp)
    desktop = web_browser.egl_frame(**same)
    room = _room_mask(data, animation, frame)
    assert room.mean() > 0.2   # the walls, floor and ceiling beside and below the curtain
    diff = np.abs(shown.astype(np.int16) - desktop.astype(np.int16))
    figures = web_browser.compare_frames(shown, desktop)
    room_figures = {"room_pixels": int(room.sum()), "room_max_8bit": int(diff[room].max()),
                    "room_mean_8bit": float(diff[room].mean())}
    message = json.dumps({**figures, **room_figures})
    assert room_figures["room_max_8bit"] <= ROOM_TOLERANCE_8BIT, message
    assert room_figures["room_mean_8bit"] <= ROOM_MEAN_8BIT, message
    assert figures["mean_abs_8bit"] <= web_browser.MEAN_TOLERANCE_8BIT, message
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(export.DESKTOP_MODES, "room_lighting", False)
        constant = web_browser.egl_frame(**same)
    lit_vs_constant = np.abs(constant.astype(np.int16) - desktop.astype(np.int16))[room].mean()
    assert lit_vs_constant > 4 * room_figures["room_mean_8bit"] + 1.0, \
        f"{message}; the constant room's mean difference {lit_vs_constant:.3f}/255"
