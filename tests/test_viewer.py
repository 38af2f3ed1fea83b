"""The viewer: a real glfw window under Xvfb (Mesa GLX), driven by simulated key presses.

Every window runs in a subprocess (`catalog view`): an EGL context (the renderer tests'
fixture lives in this pytest process) followed by a GLX window in one process ends it
with an X BadAccess. Xvfb is started here on a display it picks itself (-displayfd);
the tests skip only when the Xvfb binary is missing (tools/setup.sh installs it).

Pure logic (keys, orbit, settings cycles, the self-reloading preset list, timing) is
tested directly, without a window.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from catalog.core.resources import FABRIC_DIR, PROJECT_ROOT

#: Small and quick: a 16x24 cloth with the numpy backend (no JIT warm-up), a small window.
QUICK = ["--grid", "16x24", "--cloth-backend", "numpy", "--size", "480x320"]
LACE = "lace-fwa"  # the paper's brightened white lace
VOILE = "voile-white"  # plain white voile, no brightener
DYED = "sheer-teal"  # a teal-dyed sheer: absorbs the red
TIMEOUT_S = 240


# ----------------------------------------------------------------------------------
# Fixtures: an X server, and the catalog command in a subprocess

@pytest.fixture(scope="module")
def xdisplay():
    """A private Xvfb display (":N"), started on a free number Xvfb chooses itself."""
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        pytest.skip("Xvfb is not installed (tools/setup.sh installs xvfb)")
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen([xvfb, "-displayfd", str(write_fd), "-screen", "0", "1280x1024x24",
                             "-nolisten", "tcp", "-noreset"], pass_fds=(write_fd,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_fd)
    number = b""
    deadline = time.monotonic() + 30
    while not number.endswith(b"\n") and time.monotonic() < deadline:
        chunk = os.read(read_fd, 16)
        if not chunk:
            break
        number += chunk
    os.close(read_fd)
    if not number.strip().isdigit():
        proc.kill()
        pytest.fail(f"Xvfb did not report a display number (got {number!r})")
    yield f":{number.strip().decode()}"
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()


def _env(display: str | None) -> dict[str, str]:
    env = dict(os.environ)
    env.pop("WAYLAND_DISPLAY", None)
    env.pop("DISPLAY", None)
    if display is not None:
        env["DISPLAY"] = display
    return env


def _catalog(args: list[str], display: str | None, cwd: Path,
             timeout: float = TIMEOUT_S) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "catalog", *args], env=_env(display),
                          cwd=cwd, capture_output=True, text=True, timeout=timeout)


def _read_image(path: Path) -> np.ndarray:
    """(H, W, 3) float32: PNG scaled to 0..1, EXR as stored (linear)."""
    import OpenImageIO as oiio

    buf = oiio.ImageBuf(str(path))
    assert not buf.has_error, buf.geterror()
    pixels = buf.get_pixels(oiio.FLOAT)
    return np.asarray(pixels, dtype=np.float32)[:, :, :3]


def _stats_records(stdout: str) -> list[dict]:
    return [json.loads(line) for line in stdout.splitlines() if line.startswith("{")]


def _need_presets(*names: str) -> None:
    missing = [n for n in names if not (FABRIC_DIR / f"{n}.toml").exists()]
    if missing:
        pytest.fail(f"catalog presets missing from {FABRIC_DIR}: {', '.join(missing)}")


def _curtain_mask(a: np.ndarray, b: np.ndarray, threshold: float = 0.02) -> np.ndarray:
    """Pixels where two renders of the same (paused) mesh in two fabrics differ: the cloth."""
    return np.max(np.abs(a - b), axis=-1) > threshold


# ----------------------------------------------------------------------------------
# No display

def test_no_display_says_so_in_one_line(tmp_path):
    result = _catalog(["view"], display=None, cwd=tmp_path, timeout=60)
    assert result.returncode == 3  # an environment failure, not bad input
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "no display" in lines[0]
    assert "catalog snapshot" in lines[0] and "catalog sheet" in lines[0]
    assert result.stdout == ""


def test_unreachable_display_says_so_in_one_line(tmp_path):
    # a display number nobody serves: glfw.init fails -> the same one-line hint, exit 3
    free = next(n for n in range(4321, 4400) if not Path(f"/tmp/.X11-unix/X{n}").exists())
    result = _catalog(["view", *QUICK], display=f":{free}", cwd=tmp_path, timeout=60)
    assert result.returncode == 3, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "catalog snapshot" in lines[0] and "cannot open the display" in lines[0]


# ----------------------------------------------------------------------------------
# Screenshots of N frames

@pytest.mark.slow
def test_screenshot_is_the_curtain_in_the_fabrics_colour(xdisplay, tmp_path):
    """--frames N --screenshot: the window shows the curtain, coloured by its fabric.

    Two fabrics on the same paused mesh under D65 (fluorescence off): the pixels that
    differ are the cloth; there the teal sheer is clearly less red (relative to green)
    than the white lace, as its dye absorbs the red.
    """
    _need_presets(LACE, DYED)
    shots = {}
    for fabric in (LACE, DYED):
        out = tmp_path / f"{fabric}.png"
        result = _catalog(["view", *QUICK, "--fabric", fabric, "--light", "D65",
                           "--fluorescence", "off", "--paused", "--no-panel",
                           "--frames", "3", "--screenshot", str(out)], xdisplay, tmp_path)
        assert result.returncode == 0, result.stderr
        shots[fabric] = _read_image(out)
        assert shots[fabric].shape == (320, 480, 3)
    lace, teal = shots[LACE], shots[DYED]
    for image in (lace, teal):
        assert float(image.std()) > 0.02, "blank window"
    mask = _curtain_mask(lace, teal)
    assert mask.mean() > 0.10, f"the cloth covers only {mask.mean():.1%} of the window"
    lace_rgb = lace[mask].mean(axis=0)
    teal_rgb = teal[mask].mean(axis=0)
    assert teal_rgb[0] / teal_rgb[1] < 0.8 * lace_rgb[0] / lace_rgb[1], (lace_rgb, teal_rgb)
    # the white lace under D65 with no fluorescence is near neutral where the cloth is
    assert lace_rgb.max() / max(lace_rgb.min(), 1e-6) < 1.35, lace_rgb

    # full resolution (the runs above are at the software rasteriser's auto 0.5, upscaled
    # into the window): the same picture in the same place, only sharper
    out = tmp_path / "full.png"
    result = _catalog(["view", *QUICK, "--fabric", LACE, "--light", "D65", "--fluorescence",
                       "off", "--paused", "--no-panel", "--frames", "3", "--render-scale", "1",
                       "--screenshot", str(out)], xdisplay, tmp_path)
    assert result.returncode == 0, result.stderr
    full = _read_image(out)
    assert float(np.abs(full - lace).mean()) < 0.03
    np.testing.assert_allclose(full[mask].mean(axis=0), lace_rgb, atol=0.03)


@pytest.fixture(scope="module")
def stats_run(xdisplay, tmp_path_factory):
    """One `catalog view --frames 6 --stats` run with the defaults a user gets (first fabric,
    the sun at the hour slider's noon, the automatic cloth backend), in a small window."""
    _need_presets(LACE)
    cwd = tmp_path_factory.mktemp("stats")
    out = cwd / "shot.png"
    result = _catalog(["view", "--grid", "16x24", "--size", "480x320", "--frames", "6",
                       "--screenshot", str(out), "--stats"], xdisplay, cwd)
    assert result.returncode == 0, result.stderr
    return _stats_records(result.stdout)


@pytest.mark.slow
def test_stats_log_frame_time_and_its_parts(stats_run):
    """--stats: one JSON line per frame with its parts, then a summary."""
    frames = [r for r in stats_run if "frame" in r]
    assert [r["frame"] for r in frames] == list(range(1, 7))
    for record in frames:
        parts = record["simulation_ms"] + record["shading_ms"] + record["ui_ms"]
        assert 0 < parts <= record["total_ms"] + 1e-6
        assert record["other_ms"] >= 0
    first_fabric = sorted(p.stem for p in FABRIC_DIR.glob("*.toml"))[0]
    assert frames[0]["fabric"] == first_fabric and frames[0]["light"].startswith("sun at 12")
    summary = [r for r in stats_run if r.get("summary")]
    assert len(summary) == 1 and summary[0]["frames"] == 6
    assert summary[0]["size"] == [480, 320]
    assert summary[0]["median_total_ms"] >= summary[0]["median_shading_ms"] > 0


@pytest.mark.slow
def test_viewer_imports_no_scipy_by_its_first_frame(stats_run):
    """The viewer (window, renderer, cloth, panel) must not pull in scipy or matplotlib."""
    heavy = stats_run[0]["heavy_modules"]
    loaded = sorted(name for name, is_loaded in heavy.items() if is_loaded)
    assert heavy["matplotlib"] is False, f"the viewer imported matplotlib ({loaded})"
    assert heavy["scipy"] is False, f"the viewer imported scipy by its first frame ({loaded})"


@pytest.mark.slow
def test_split_screen_shows_two_fabrics(xdisplay, tmp_path):
    """--compare: left and right halves show the two fabrics under the same light."""
    _need_presets(LACE, DYED)
    common = [*QUICK, "--light", "D65", "--fluorescence", "off", "--paused", "--no-panel",
              "--frames", "3"]
    same = tmp_path / "same.png"
    split = tmp_path / "split.png"
    for args, out in (([*common, "--fabric", LACE, "--compare", LACE], same),
                      ([*common, "--fabric", LACE, "--compare", DYED], split)):
        result = _catalog(["view", *args, "--screenshot", str(out)], xdisplay, tmp_path)
        assert result.returncode == 0, result.stderr
    same_img, split_img = _read_image(same), _read_image(split)
    half = same_img.shape[1] // 2
    # left halves: the lace in both runs
    np.testing.assert_allclose(split_img[:, :half], same_img[:, :half], atol=2 / 255)
    mask = _curtain_mask(same_img[:, half:], split_img[:, half:])
    assert mask.mean() > 0.10
    right_lace = same_img[:, half:][mask].mean(axis=0)
    right_teal = split_img[:, half:][mask].mean(axis=0)
    assert right_teal[0] / right_teal[1] < 0.8 * right_lace[0] / right_lace[1]


@pytest.mark.slow
def test_gpu_cloth_draws_the_same_curtain_as_the_cpu_cloth(xdisplay, tmp_path):
    """--cloth-backend gpu: the compute shader writes the vertex buffer the renderer draws
    (moved onto the rod in the vertex shader). After 20 windy frames its picture matches
    the float64 numpy cloth's far closer than either matches the cloth at rest."""
    _need_presets(LACE)
    common = [*QUICK, "--fabric", LACE, "--light", "D65", "--no-panel", "--render-scale", "1",
              "--wind", "2", "--frames", "20"]
    images = {}
    for name, extra in (("numpy", ["--cloth-backend", "numpy"]),
                        ("gpu", ["--cloth-backend", "gpu"]),
                        ("rest", ["--cloth-backend", "numpy", "--paused"])):
        out = tmp_path / f"{name}.png"
        result = _catalog(["view", *common, *extra, "--screenshot", str(out)], xdisplay,
                          tmp_path)
        assert result.returncode == 0, result.stderr
        images[name] = _read_image(out)
    motion = float(np.abs(images["numpy"] - images["rest"]).mean())
    assert motion > 0.005, "the wind should move the curtain in 20 frames"
    assert float(np.abs(images["gpu"] - images["numpy"]).mean()) < 0.1 * motion


# ----------------------------------------------------------------------------------
# The real window driven by key presses (xdotool)

class Viewer:
    """A running `catalog view` and the X tools that drive it."""

    def __init__(self, display: str, cwd: Path, args: list[str]):
        if shutil.which("xdotool") is None:
            pytest.fail("xdotool is not installed (tools/setup.sh installs it)")
        self.display = display
        self.shots = cwd / "shots"
        # stdout into a file, not a pipe: --stats prints a line a frame, and a pipe nobody
        # reads until the end fills (64 KiB) and blocks the viewer before it sees Escape
        self._stdout_path = cwd / "viewer-stdout.jsonl"
        self._stdout = open(self._stdout_path, "w", encoding="utf-8")
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "catalog", "view", *QUICK, "--screenshot-dir",
             str(self.shots), "--frames", "100000", *args],
            env=_env(display), cwd=cwd, stdout=self._stdout, stderr=subprocess.PIPE,
            text=True)
        self.window = self._find_window()

    def _xdotool(self, *args: str, timeout: float = 30) -> str:
        return subprocess.run(["xdotool", *args], env=_env(self.display), capture_output=True,
                              text=True, timeout=timeout, check=True).stdout

    def _find_window(self) -> str:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise AssertionError(f"viewer exited early: {self.proc.stderr.read()}")
            found = subprocess.run(["xdotool", "search", "--name", "^catalog view"],
                                   env=_env(self.display), capture_output=True, text=True)
            if found.stdout.strip():
                return found.stdout.split()[0]
            time.sleep(0.3)
        raise AssertionError("no viewer window appeared")

    def title(self) -> str:
        return self._xdotool("getwindowname", self.window).strip()

    def keys(self, *names: str) -> None:
        for name in names:
            self._xdotool("key", "--window", self.window, name)
            time.sleep(0.15)

    def screenshot(self) -> tuple[np.ndarray, np.ndarray]:
        """Press S and wait for the new EXR + PNG pair: (linear scene, window as shown)."""
        before = set(self.shots.glob("view-*.png")) if self.shots.exists() else set()
        self.keys("s")
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline:
            new = (set(self.shots.glob("view-*.png")) - before) if self.shots.exists() else set()
            if new:
                png = new.pop()
                exr = png.with_suffix(".exr")
                if exr.exists():
                    return _read_image(exr), _read_image(png)
            if self.proc.poll() is not None:
                raise AssertionError(f"viewer exited: {self.proc.stderr.read()}")
            time.sleep(0.2)
        raise AssertionError("the S key saved no screenshot")

    def wait_title(self, text: str, timeout: float = 30) -> str:
        deadline = time.monotonic() + timeout
        title = ""
        while time.monotonic() < deadline:
            title = self.title()
            if text in title:
                return title
            time.sleep(0.2)
        raise AssertionError(f"title {title!r} never showed {text!r}")

    def drag(self, x: int, y: int, dx: int) -> None:
        """Press the left button at (x, y) in the window, move right by dx, release."""
        self._xdotool("mousemove", "--window", self.window, str(x), str(y))
        self._xdotool("mousedown", "1")
        time.sleep(0.2)
        for _ in range(5):
            self._xdotool("mousemove_relative", "--", str(dx // 5), "0")
            time.sleep(0.1)
        self._xdotool("mouseup", "1")
        time.sleep(0.2)

    def wheel(self, x: int, y: int, clicks: int) -> None:
        """Turn the wheel towards the scene (X button 4) ``clicks`` times at (x, y)."""
        self._xdotool("mousemove", "--window", self.window, str(x), str(y))
        self._xdotool("click", "--repeat", str(clicks), "--delay", "80", "4")
        time.sleep(0.3)

    def quit(self) -> int:
        self.keys("Escape")
        try:
            return self.proc.wait(timeout=60)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()

    def stdout_text(self) -> str:
        """What the viewer printed on stdout so far."""
        self._stdout.flush()
        return self._stdout_path.read_text(encoding="utf-8")

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self._stdout.close()


def _blue_share(image: np.ndarray, mask: np.ndarray) -> float:
    rgb = image[mask].mean(axis=0)
    return float(rgb[2] / rgb.sum())


@pytest.mark.slow
def test_keys_switch_fabric_light_and_fluorescence(xdisplay, tmp_path):
    """Drive the window with key presses and check each screenshot changes as it should.

    Space pauses the cloth, so every screenshot shows the same mesh. Right: another fabric,
    other colours. L (D65 -> A, tungsten): the cloth turns warmer. F (physical -> off): the
    brightened lace loses blue; the plain voile does not change at all. Then the mouse
    (orbit, zoom, not over the panel), H (help overlay) and Tab (panel hidden).
    """
    _need_presets(LACE, VOILE)
    names = sorted(p.stem for p in FABRIC_DIR.glob("*.toml"))
    viewer = Viewer(xdisplay, tmp_path, ["--fabric", LACE, "--light", "D65"])
    try:
        viewer.keys("space")
        viewer.wait_title("(paused)")
        assert LACE in viewer.title() and "D65" in viewer.title()
        lace_physical, window_png = viewer.screenshot()
        # the window PNG has the panel on the left; the EXR is the scene alone
        assert window_png.shape[1] == 480 and lace_physical.shape[1] < 480

        viewer.keys("Right")
        next_name = names[(names.index(LACE) + 1) % len(names)]
        viewer.wait_title(next_name)
        other, _ = viewer.screenshot()
        mask = _curtain_mask(lace_physical / lace_physical.max(), other / other.max(), 0.01)
        assert mask.mean() > 0.05, "another fabric should change the cloth's pixels"
        viewer.keys("Left")
        viewer.wait_title(LACE)

        viewer.keys("f")  # physical -> off
        viewer.wait_title("fluorescence off")
        lace_off, _ = viewer.screenshot()
        cloth = _curtain_mask(lace_physical, lace_off, 1e-4 * float(lace_physical.max()))
        assert cloth.mean() > 0.05, "fluorescence should change the brightened lace"
        assert _blue_share(lace_physical, cloth) > _blue_share(lace_off, cloth) + 0.005

        viewer.keys("l")  # D65 -> A: a warmer light
        viewer.wait_title("light A ")
        lace_a, _ = viewer.screenshot()
        rgb_d65, rgb_a = lace_off[cloth].mean(axis=0), lace_a[cloth].mean(axis=0)
        assert rgb_a[0] / rgb_a[2] > 1.5 * rgb_d65[0] / rgb_d65[2]

        # the plain voile: fluorescence on or off renders the same pixels
        steps = (names.index(VOILE) - names.index(LACE)) % len(names)
        viewer.keys(*(["Right"] * steps))
        viewer.wait_title(VOILE)
        voile_off, _ = viewer.screenshot()
        viewer.keys("f", "f")  # off -> paper -> physical
        viewer.wait_title("fluorescence physical")
        voile_physical, _ = viewer.screenshot()
        np.testing.assert_allclose(voile_physical, voile_off, rtol=1e-5,
                                   atol=1e-6 * float(voile_off.max()))

        # the mouse: a drag over the panel leaves the camera alone (the panel has the
        # mouse there); a drag over the scene orbits it; the wheel zooms
        viewer.drag(100, 8, dx=100)
        same, _ = viewer.screenshot()
        np.testing.assert_allclose(same, voile_physical, rtol=1e-5,
                                   atol=1e-6 * float(voile_off.max()))
        viewer.drag(300, 160, dx=100)
        orbited, _ = viewer.screenshot()
        assert np.abs(orbited - same).mean() > 0.05 * same.mean()
        viewer.wheel(300, 160, 3)
        zoomed, window_before = viewer.screenshot()
        assert np.abs(zoomed - orbited).mean() > 0.05 * orbited.mean()

        # H: the help overlay is drawn over the window, the scene (EXR) is untouched
        viewer.keys("h")
        scene, window_help = viewer.screenshot()
        np.testing.assert_allclose(scene, zoomed, rtol=1e-6)
        assert np.abs(window_help - window_before).mean() > 0.01
        # Tab: the panel goes, the scene takes the whole width
        viewer.keys("h", "Tab")
        wide, _ = viewer.screenshot()
        assert wide.shape[1] > zoomed.shape[1] and wide.shape[0] == zoomed.shape[0]
        assert viewer.quit() == 0
    finally:
        viewer.close()


# ----------------------------------------------------------------------------------
# Broken and changing presets

def _copy_fabrics(target: Path, names: list[str]) -> None:
    target.mkdir()
    for name in names:
        shutil.copy(FABRIC_DIR / f"{name}.toml", target / f"{name}.toml")
    # presets name their spectra relative to their folder: keep those reachable
    (target / "measurements").symlink_to(FABRIC_DIR / "measurements")
    (target / "patterns").symlink_to(FABRIC_DIR / "patterns")   # and their [pattern] images


@pytest.mark.slow
def test_broken_preset_shows_an_error_and_the_others_render(xdisplay, tmp_path):
    _need_presets(LACE, VOILE)
    fabrics = tmp_path / "fabrics"
    _copy_fabrics(fabrics, [LACE, VOILE])
    text = (FABRIC_DIR / f"{VOILE}.toml").read_text()
    broken = text.replace('name = "voile-white"', 'name = "aaa-broken"')
    broken = broken.replace("g_spec = ", "g_spec = 1.5 # was ", 1)
    (fabrics / "aaa-broken.toml").write_text(broken)  # sorts first: the viewer must skip it
    out = tmp_path / "shot.png"
    result = _catalog(["view", *QUICK, "--fabrics", str(fabrics), "--frames", "4",
                       "--screenshot", str(out), "--stats", "--paused"], xdisplay, tmp_path)
    assert result.returncode == 0, result.stderr
    first = _stats_records(result.stdout)[0]
    errors = first["panel_errors"]
    assert len(errors) == 1 and "aaa-broken.toml" in errors[0] and "btdf.g_spec" in errors[0]
    # the first usable preset of the search path (the folder's, then the built-in ones),
    # not the broken one
    usable = sorted({p.stem for p in fabrics.glob("*.toml")} - {"aaa-broken"}
                    | {p.stem for p in FABRIC_DIR.glob("*.toml")})
    assert first["fabric"] == usable[0]
    image = _read_image(out)
    panel = image[:, :200]
    # the error is written in the panel in its red (1.0, 0.42, 0.35)
    reddish = (panel[..., 0] > 0.8) & (panel[..., 1] < 0.6) & (panel[..., 2] < 0.55)
    assert reddish.sum() > 20
    assert float(image[:, 330:].std()) > 0.02  # the curtain still renders


@pytest.mark.slow
def test_broken_preset_on_the_command_line_is_refused(xdisplay, tmp_path):
    _need_presets(VOILE)
    fabrics = tmp_path / "fabrics"
    _copy_fabrics(fabrics, [VOILE])
    (fabrics / "bad.toml").write_text('schema = 1\nname = "bad"\n')
    result = _catalog(["view", *QUICK, "--fabrics", str(fabrics), "--fabric", "bad",
                       "--frames", "2", "--screenshot", str(tmp_path / "x.png")],
                      xdisplay, tmp_path, timeout=60)
    assert result.returncode == 2
    assert "bad.toml" in result.stderr and "display_name" in result.stderr
    assert not (tmp_path / "x.png").exists()


@pytest.mark.slow
def test_a_failed_frame_fails_a_frames_run(xdisplay, tmp_path):
    """--frames N --screenshot: a frame that could not be drawn as asked (here the shown
    fabric's dye file is missing) ends the run with its one-line error, exit 2, and no
    screenshot, instead of exit 0 with the error only in the panel."""
    _need_presets(VOILE)
    fabrics = tmp_path / "fabrics"
    _copy_fabrics(fabrics, [VOILE])
    preset = fabrics / f"{VOILE}.toml"
    preset.write_text(preset.read_text() + '\n[dye]\ntransmittance = "no-such-dye.csv"\n')
    result = _catalog(["view", *QUICK, "--fabrics", str(fabrics), "--fabric", VOILE,
                       "--frames", "2", "--screenshot", str(tmp_path / "x.png")],
                      xdisplay, tmp_path, timeout=120)
    assert result.returncode == 2, result.stderr
    assert "no-such-dye.csv" in result.stderr
    # one error line (the viewer's start-up note on llvmpipe's cheaper settings may precede it)
    errors = [ln for ln in result.stderr.strip().splitlines() if "error:" in ln]
    assert len(errors) == 1 and "Traceback" not in result.stderr, result.stderr
    assert not (tmp_path / "x.png").exists()


@pytest.mark.slow
def test_preset_reloads_when_its_file_changes(xdisplay, tmp_path):
    """Edit a preset while the viewer shows it: the new version appears; a broken edit
    shows its error and the viewer keeps running."""
    _need_presets(VOILE, LACE)
    fabrics = tmp_path / "fabrics"
    _copy_fabrics(fabrics, [VOILE, LACE])
    path = fabrics / f"{VOILE}.toml"
    original = path.read_text()
    viewer = Viewer(xdisplay, tmp_path, ["--fabrics", str(fabrics), "--fabric", VOILE,
                                         "--paused"])
    try:
        viewer.wait_title(VOILE)
        before, _ = viewer.screenshot()
        edited = original.replace("display_name = ", 'display_name = "Edited voile" # ', 1)
        # a lobe, not LD: the [pattern]'s open area must keep matching btdf.direct (issue 12)
        edited = edited.replace("\nk_d = ", "\nk_d = 1.5 # was ", 1)
        path.write_text(edited)
        viewer.wait_title("Edited voile")
        after, _ = viewer.screenshot()
        assert not np.allclose(after, before), "a changed preset should render differently"
        # a new file sorting first shifts the list: the viewer keeps showing the voile
        lace = (fabrics / f"{LACE}.toml").read_text()
        (fabrics / "aaa-new.toml").write_text(lace.replace(f'name = "{LACE}"',
                                                           'name = "aaa-new"'))
        time.sleep(1.5)  # > the 0.5 s rescan interval, several frames
        again, _ = viewer.screenshot()
        assert "Edited voile" in viewer.title()
        np.testing.assert_allclose(again, after, rtol=1e-6)
        path.write_text(original.replace("\nk_d = ", "\nk_d = -1 # was ", 1))
        title = viewer.wait_title(f"- {VOILE} -")  # the name alone: it no longer loads
        assert "Edited" not in title
        assert viewer.proc.poll() is None
        assert viewer.quit() == 0
    finally:
        viewer.close()


# ----------------------------------------------------------------------------------
# Logic without a window

def test_orbit_camera_clamps_and_wraps():
    from catalog.viewer.input import OrbitCamera

    camera = OrbitCamera()
    camera.drag(1e6, 0)
    assert -180.0 <= camera.yaw_deg < 180.0
    camera.drag(0, 1e6)
    assert camera.pitch_deg == camera.max_pitch_deg
    camera.drag(0, -1e6)
    assert camera.pitch_deg == camera.min_pitch_deg
    camera.zoom(1e3)
    assert camera.distance_m == camera.min_distance_m
    camera.zoom(-1e3)   # out as far as the room allows in this direction (issue 12)
    from catalog.viewer.input import room_limit_m

    assert camera.distance_m == min(camera.max_distance_m,
                                    room_limit_m(camera.yaw_deg, camera.pitch_deg, camera.target))
    camera.reset()   # the home view: the default view's composition (catalog.render.camera)
    view = camera.view
    assert (camera.yaw_deg, camera.pitch_deg, camera.distance_m) == (
        view.yaw_deg, view.pitch_deg, view.distance_m)
    camera.drag(float("nan"), 1.0)
    camera.zoom(float("inf"))
    assert np.isfinite([camera.yaw_deg, camera.pitch_deg, camera.distance_m]).all()
    # one wheel step in then out comes back
    camera = OrbitCamera()
    camera.zoom(1)
    camera.zoom(-1)
    assert camera.distance_m == pytest.approx(OrbitCamera().distance_m, rel=1e-12)


def test_keys_and_cycles():
    import glfw

    from catalog.viewer.input import Action, action_for_key
    from catalog.viewer.settings import (FLUORESCENCE_MODES, LIGHT_CYCLE, next_fluorescence,
                                         next_light)

    assert action_for_key(glfw.KEY_RIGHT, glfw.PRESS) is Action.NEXT_FABRIC
    assert action_for_key(glfw.KEY_RIGHT, glfw.REPEAT) is Action.NEXT_FABRIC
    assert action_for_key(glfw.KEY_S, glfw.REPEAT) is None  # no burst of screenshots
    assert action_for_key(glfw.KEY_L, glfw.RELEASE) is None
    assert action_for_key(glfw.KEY_Q, glfw.PRESS) is None
    mode = "off"
    seen = []
    for _ in range(len(FLUORESCENCE_MODES)):
        mode = next_fluorescence(mode)
        seen.append(mode)
    assert seen == ["paper", "physical", "off"]
    light = LIGHT_CYCLE[0]
    for _ in range(len(LIGHT_CYCLE)):
        light = next_light(light)
    assert light == LIGHT_CYCLE[0]
    assert next_light("FL7") == LIGHT_CYCLE[0]
    assert "UV-A" in LIGHT_CYCLE and "LED-B4" in LIGHT_CYCLE and "D65" in LIGHT_CYCLE


def _preset_text(name: str, direct: float = 0.1, g_spec: float = 0.9) -> str:
    return (f'schema = 1\nname = "{name}"\ndisplay_name = "{name.title()}"\n[btdf]\n'
            f"direct = {direct}\nk_d = 0.7\nk_s = 0.5\ntau = 0.25\nrho = 0.8\ng_diff = 0.2\n"
            f"g_spec = {g_spec}\n")


def test_catalog_loads_lazily_and_reloads_on_change(tmp_path):
    from catalog.viewer.catalog_state import FabricCatalog

    (tmp_path / "a.toml").write_text(_preset_text("a"))
    (tmp_path / "b.toml").write_text(_preset_text("b", g_spec=1.5))
    clock = [0.0]
    catalog = FabricCatalog(tmp_path, rescan_interval_s=0.5, clock=lambda: clock[0])
    assert catalog.names == ["a", "b"]
    assert not any(entry.loaded for entry in catalog.entries)  # nothing read at start
    assert catalog.load(0).preset.btdf.direct == pytest.approx(0.1)
    assert catalog.entries[1].loaded is False
    broken = catalog.load(1)
    assert broken.preset is None and "b.toml" in broken.error and "btdf.g_spec" in broken.error
    assert catalog.step(0, +1) == 0  # the broken one is skipped, wrapping back to a

    # edit a: picked up at the next refresh after the interval, not before
    path = tmp_path / "a.toml"
    path.write_text(_preset_text("a", direct=0.3))
    os.utime(path, ns=(time.time_ns() + 10**9, time.time_ns() + 10**9))
    clock[0] = 0.1
    assert catalog.refresh() == []
    clock[0] = 1.0
    assert catalog.refresh() == ["a"]
    assert catalog.load(0).preset.btdf.direct == pytest.approx(0.3)
    # repair b, add c, remove nothing: all seen
    (tmp_path / "b.toml").write_text(_preset_text("b"))
    (tmp_path / "c.toml").write_text(_preset_text("c"))
    clock[0] = 2.0
    assert sorted(catalog.refresh()) == ["b", "c"]
    assert catalog.load(1).preset is not None and catalog.errors() == []
    (tmp_path / "c.toml").unlink()
    clock[0] = 3.0
    assert catalog.refresh() == ["c"] and catalog.names == ["a", "b"]


def test_swatch_shows_the_dye(tmp_path):
    from catalog.presets import load_preset
    from catalog.viewer.catalog_state import swatch_srgb

    (tmp_path / "white.toml").write_text(_preset_text("white"))
    dyed = _preset_text("red") + "[btdf.rgb]\na_diff = [0.4, 0.1, 0.05]\n"
    (tmp_path / "red.toml").write_text(dyed)
    white = swatch_srgb(load_preset(tmp_path / "white.toml"))
    red = swatch_srgb(load_preset(tmp_path / "red.toml"))
    assert white == pytest.approx((1.0, 1.0, 1.0))
    assert red[0] == pytest.approx(1.0) and red[0] > red[1] > red[2] > 0


def test_frame_timer_parts_add_up():
    from catalog.viewer.timing import FrameTimer

    ticks = iter([0.0, 0.001, 0.004, 0.004, 0.006, 0.010])  # s
    timer = FrameTimer(clock=lambda: next(ticks))
    timer.begin_frame()  # 0.000
    with timer.part("simulation"):  # 0.001 .. 0.004
        pass
    with timer.part("shading"):  # 0.004 .. 0.006
        pass
    times = timer.end_frame()  # 0.010
    assert times.total_ms == pytest.approx(10.0)
    assert times.parts_ms["simulation"] == pytest.approx(3.0)
    assert times.parts_ms["shading"] == pytest.approx(2.0)
    assert times.parts_ms["ui"] == 0.0
    assert times.other_ms == pytest.approx(5.0)
    assert timer.median_ms()["total"] == pytest.approx(10.0)


def test_run_sh_without_display_renders_the_sheet_command(tmp_path):
    """tools/run.sh with no display chooses the headless sheet (dry run)."""
    env = _env(None)
    env["CATALOG_RUN_DRY"] = "1"
    result = subprocess.run(["bash", str(PROJECT_ROOT / "tools" / "run.sh")], env=env,
                            capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "catalog sheet --lights D65,sun:22,LED-B4,UV-A --out" in result.stdout
