"""The output layer (catalog.core.atomic): checked targets, whole-or-nothing writes, one
line for every OS error, signals, stale temporaries, several outputs staged.

Faults are real where the machine allows: a 64 KiB tmpfs for a full disk, a read-only
tmpfs, /dev/full and a closed descriptor for stdout. Where mounting is not permitted the
full disk is simulated by a writer that raises ENOSPC (the test says which it used).
"""

from __future__ import annotations

import contextlib
import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from catalog.core.atomic import (OutputError, STAGE_MARKER, TEMP_MARK, atomic_path,
                                 check_target, remove_stale_temporaries, staged_folder,
                                 temporary_owner, write_bytes_atomic, write_text_atomic)

ROOT = Path(__file__).resolve().parents[1]


def _catalog(*args, cwd=None, stdout=subprocess.PIPE, timeout=240, env_extra=None):
    env = dict(os.environ, PYTHONPATH=str(ROOT), **(env_extra or {}))
    return subprocess.run([sys.executable, "-m", "catalog", *args], cwd=cwd, stdout=stdout,
                          stderr=subprocess.PIPE, text=True, timeout=timeout, env=env)


def _litter(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*") if TEMP_MARK in p.name)


def _one_error_line(stderr: str) -> str:
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    assert "Traceback" not in stderr, stderr
    assert len(lines) == 1, stderr
    return lines[0]


@contextlib.contextmanager
def _tmpfs(path: Path, size: str = "64k", read_only: bool = False):
    """A small real file system at ``path``; yields False (nothing mounted) where the
    machine refuses to mount."""
    path.mkdir(parents=True, exist_ok=True)
    options = f"size={size}" + (",ro" if read_only else "")
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)],
                             capture_output=True).returncode == 0
    try:
        yield mounted
    finally:
        if mounted:
            subprocess.run(["umount", "-l", str(path)], capture_output=True)


# --------------------------------------------------------------------------- unit

def test_target_checks_name_the_path_and_the_cause(tmp_path):
    (tmp_path / "folder").mkdir()
    (tmp_path / "afile").write_text("x")
    with pytest.raises(OutputError, match="is a folder"):
        check_target(tmp_path / "folder")
    with pytest.raises(OutputError, match="is a file, not a folder"):
        check_target(tmp_path / "afile" / "out.png")
    with pytest.raises(OutputError, match="own input"):
        check_target(tmp_path / "afile", inputs=[tmp_path / "afile"])
    with pytest.raises(OutputError, match="no room"):
        check_target(tmp_path / "big.bin", estimate_bytes=1 << 62)
    assert check_target(tmp_path / "new" / "deeper" / "ok.png") == tmp_path / "new" / "deeper" / "ok.png"


def test_an_empty_or_unverified_file_never_replaces_a_good_one(tmp_path):
    target = tmp_path / "image.png"
    target.write_bytes(b"good image")
    with pytest.raises(OutputError, match="0 bytes"):
        with atomic_path(target):
            pass  # the writer "succeeded" and wrote nothing (a full disk does this)
    assert target.read_bytes() == b"good image"

    def refuse(_tmp):
        raise OutputError(target, "does not read back")

    with pytest.raises(OutputError, match="read back"):
        with atomic_path(target, verify=refuse) as tmp:
            tmp.write_bytes(b"garbage")
    assert target.read_bytes() == b"good image"
    assert _litter(tmp_path) == []


def test_os_errors_become_one_output_error(tmp_path, monkeypatch):
    target = tmp_path / "preset.toml"
    target.write_text("old = 1\n")
    real_open = open

    def full_disk_open(file, mode="r", *args, **kwargs):
        handle = real_open(file, mode, *args, **kwargs)
        if "w" in mode and TEMP_MARK in str(file):
            handle.close()
            raise OSError(errno.ENOSPC, "No space left on device", str(file))
        return handle

    monkeypatch.setattr("builtins.open", full_disk_open)
    with pytest.raises(OutputError) as caught:
        write_text_atomic(target, "new = 2\n")
    assert str(caught.value) == f"{target}: cannot write: no space left on device"
    monkeypatch.undo()
    assert target.read_text() == "old = 1\n"
    assert _litter(tmp_path) == []


def test_stale_temporaries_of_dead_processes_are_removed_and_live_ones_kept(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    from catalog.core.atomic import STAGE_MARKER, temporary_name

    stale = tmp_path / temporary_name("x.png", int(dead), ".png")
    stale_stage = tmp_path / temporary_name("out", int(dead))
    live = tmp_path / temporary_name("y.png", os.getpid(), ".png")
    other = tmp_path / ".hidden"
    # a user's file and folder that merely look like temporaries (no valid token, no marker)
    look_alike = tmp_path / f".x.png{TEMP_MARK}-{dead}-abc.png"
    users_folder = tmp_path / f".out{TEMP_MARK}-{dead}-0123456789abcdef"
    unmarked_stage = tmp_path / temporary_name("old", int(dead))
    # a stage killed between its mkdir and its marker: empty, so removed
    empty_stage = tmp_path / temporary_name("killed", int(dead))
    empty_stage.mkdir()
    # a user's empty folder with a look-alike name (no valid token): never touched
    empty_look_alike = tmp_path / f".out{TEMP_MARK}-{dead}-fedcba9876543210"
    empty_look_alike.mkdir()
    for path in (stale, live, other, look_alike):
        path.write_text("x")
    for folder in (stale_stage, users_folder, unmarked_stage):
        folder.mkdir()
        (folder / "a.png").write_text("x")
    (stale_stage / STAGE_MARKER).write_text(f"{dead}\n")
    assert temporary_owner(stale.name) == int(dead)
    assert temporary_owner(other.name) is None and temporary_owner(look_alike.name) is None
    write_bytes_atomic(tmp_path / "x.png", b"new")
    assert not stale.exists() and not stale_stage.exists() and not empty_stage.exists()
    assert empty_look_alike.is_dir()
    assert live.exists() and other.exists() and look_alike.exists()
    assert (users_folder / "a.png").exists() and (unmarked_stage / "a.png").exists()
    assert remove_stale_temporaries(tmp_path) == []


def test_stage_keeps_its_marker_while_its_files_are_moved(tmp_path, monkeypatch):
    """A SIGKILL during the moves must leave a stage the cleaner claims (its marker in it),
    and the marker itself is never published."""
    from catalog.core import atomic

    out = tmp_path / "sheet"
    marked_at_move = []
    real_replace = os.replace

    def watching_replace(source, goal):
        source = Path(source)
        if atomic.TEMP_MARK in str(source.parent):
            marked_at_move.append((source.parent / STAGE_MARKER).is_file())
        return real_replace(source, goal)

    monkeypatch.setattr(atomic.os, "replace", watching_replace)
    with staged_folder(out) as stage:
        for name in ("a.png", "b.png"):
            (stage / name).write_text(name)
    assert marked_at_move == [True, True]
    assert sorted(p.name for p in out.iterdir()) == ["a.png", "b.png"]
    assert _litter(tmp_path) == []


def test_staged_folder_publishes_all_or_nothing(tmp_path):
    out = tmp_path / "sheet"
    out.mkdir()
    (out / "old.png").write_text("old")
    with pytest.raises(RuntimeError):
        with staged_folder(out) as stage:
            (stage / "a.png").write_text("a")
            raise RuntimeError("the third image failed")
    assert sorted(p.name for p in out.iterdir()) == ["old.png"]
    with staged_folder(out) as stage:
        (stage / "a.png").write_text("a")
        (stage / "sub").mkdir()
        (stage / "sub" / "b.png").write_text("b")
    assert sorted(str(p.relative_to(out)) for p in out.rglob("*")) == \
        ["a.png", "old.png", "sub", "sub/b.png"]
    assert _litter(tmp_path) == []


# --------------------------------------------------------------------------- real faults

#: Every command that writes a file or a folder, with its output on the faulty disk ({out}).
WRITERS = {
    "snapshot": ["snapshot", "--fabric", "voile-white", "--size", "32x24", "--out", "{out}/x.png"],
    "sheet": ["sheet", "--lights", "D65", "--size", "32x24", "--out", "{out}/sheet"],
    "fit": ["fit", "--gonio", "{measurements}/voile-white/gonio.csv", "--name", "p",
            "--out", "{out}/p.toml"],
    "fit --plot": ["fit", "--gonio", "{measurements}/voile-white/gonio.csv", "--name", "p",
                   "--out", "{tmp}/p.toml", "--plot", "{out}/p.png"],
    "fluorescence --plot": ["fluorescence", "--excitation", "{measurements}/lace-fwa/excitation.csv",
                            "--emission", "{measurements}/lace-fwa/emission.csv", "--light", "D65",
                            "--plot", "{out}/f.png"],
    "lights --plot": ["lights", "--plot", "{out}/l.png"],
    "sun --plot": ["sun", "--plot", "{out}/s.png"],
    "simulate --out": ["simulate", "--grid", "8x8", "--steps", "2", "--out", "{out}/c.obj"],
    "simulate --out {frame}": ["simulate", "--grid", "8x8", "--steps", "2",
                               "--out", "{out}/c_{frame}.obj"],
    "bench --out": ["bench", "--quick", "--sections", "fit", "--out", "{out}/bench"],
}


def _writer_args(name: str, out: Path, tmp: Path, project_root: Path) -> list[str]:
    measurements = project_root / "fabrics" / "measurements"
    return [a.replace("{out}", str(out)).replace("{tmp}", str(tmp))
            .replace("{measurements}", str(measurements)) for a in WRITERS[name]]


def _fill(disk: Path) -> None:
    """Fill a small file system to its last block."""
    fd = os.open(disk / "filler", os.O_WRONLY | os.O_CREAT)
    try:
        with contextlib.suppress(OSError):
            while True:
                os.write(fd, b"\0" * 4096)
    finally:
        os.close(fd)


@pytest.mark.parametrize("name", sorted(WRITERS))
@pytest.mark.slow
def test_full_disk_is_one_line_and_the_old_file_stays(tmp_path, name, project_root):
    disk = tmp_path / "disk"
    with _tmpfs(disk, size="64k") as mounted:
        if not mounted:
            pytest.skip("this machine does not allow a tmpfs mount; the ENOSPC path is "
                        "covered by test_os_errors_become_one_output_error")
        old = disk / "x.png"
        old.write_bytes(b"\x89PNG good old image")
        _fill(disk)
        result = _catalog(*_writer_args(name, disk, tmp_path, project_root))
        assert result.returncode == 2, result.stderr
        line = _one_error_line(result.stderr)
        assert str(disk) in line and ("no space" in line or "no room" in line), line
        assert old.read_bytes() == b"\x89PNG good old image"
        assert _litter(disk) == []
        assert sorted(p.name for p in disk.iterdir()) == ["filler", "x.png"]


@pytest.mark.parametrize("name", sorted(WRITERS))
def test_read_only_file_system_is_refused_before_the_work(tmp_path, name, project_root):
    ro = tmp_path / "ro"
    with _tmpfs(ro, read_only=True) as mounted:
        if not mounted:
            pytest.skip("this machine does not allow a read-only tmpfs mount")
        result = _catalog(*_writer_args(name, ro, tmp_path, project_root))
        assert result.returncode == 2, result.stderr
        line = _one_error_line(result.stderr)
        assert "read-only" in line and str(ro) in line, line


JSON_COMMANDS = {
    "lights": ["lights", "--json"],
    "fluorescence": ["fluorescence", "--excitation", "{measurements}/lace-fwa/excitation.csv",
                     "--emission", "{measurements}/lace-fwa/emission.csv", "--light", "D65",
                     "--json"],
    "simulate": ["simulate", "--grid", "8x8", "--steps", "2", "--json"],
    "snapshot": ["snapshot", "--fabric", "voile-white", "--size", "16x12", "--out", "{tmp}/s.png",
                 "--json"],
}


@pytest.mark.parametrize("how", ["closed", "full"])
@pytest.mark.parametrize("name", sorted(JSON_COMMANDS))
@pytest.mark.slow
def test_closed_or_full_stdout_is_one_line(tmp_path, project_root, how, name):
    if how == "full" and not Path("/dev/full").exists():
        pytest.skip("no /dev/full on this machine")
    measurements = project_root / "fabrics" / "measurements"
    cmd = [sys.executable, "-m", "catalog"] + [
        a.replace("{measurements}", str(measurements)).replace("{tmp}", str(tmp_path))
        for a in JSON_COMMANDS[name]]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    if how == "closed":
        # the child starts with file descriptor 1 closed, as `cmd >&-` does
        result = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                env=env, timeout=240, preexec_fn=lambda: os.close(1))
    else:
        with open("/dev/full", "w") as full:
            result = subprocess.run(cmd, stdout=full, stderr=subprocess.PIPE, text=True,
                                    env=env, timeout=240)
    assert result.returncode == 2, result.stderr
    line = _one_error_line(result.stderr)
    assert "stdout" in line and ("closed" in line or "no space" in line), line
    assert _litter(tmp_path) == []


def test_an_output_naming_the_input_is_refused_and_the_input_kept(tmp_path, project_root):
    source = project_root / "fabrics" / "measurements" / "lace-fwa"
    excitation = tmp_path / "excitation.csv"
    excitation.write_bytes((source / "excitation.csv").read_bytes())
    before = excitation.read_bytes()
    result = _catalog("fluorescence", "--excitation", str(excitation), "--emission",
                      str(source / "emission.csv"), "--light", "D65", "--plot", str(excitation))
    assert result.returncode == 2
    assert "--plot" in _one_error_line(result.stderr)
    assert excitation.read_bytes() == before


@pytest.mark.slow   # 0.6 s here
def test_a_preset_cannot_name_a_file_outside_its_folder(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("wavelength_nm,intensity\nTOP-SECRET-CONTENT\n")
    folder = tmp_path / "fabrics"
    folder.mkdir()
    preset = folder / "sneaky.toml"
    preset.write_text('schema = 1\nname = "sneaky"\ndisplay_name = "s"\n[btdf]\ndirect = 0.1\n'
                      'k_d = 0.7\nk_s = 0.5\ntau = 0.2\nrho = 0.8\ng_diff = 0.2\ng_spec = 0.9\n'
                      '[fluorescence]\nxyz = [1.0, 1.0, 1.0]\nrgb = [1.0, 1.0, 1.0]\n'
                      'excitation = "../secret.txt"\nemission = "../secret.txt"\n')
    result = _catalog("snapshot", "--fabric", str(preset), "--size", "16x16",
                      "--out", str(tmp_path / "o.png"))
    assert result.returncode == 2
    line = _one_error_line(result.stderr)
    assert "fluorescence.excitation" in line and "leaves the preset's folder" in line
    assert "TOP-SECRET" not in result.stderr + result.stdout
    assert not (tmp_path / "o.png").exists()


def test_fit_and_render_share_one_validator(tmp_path, make_preset):
    from catalog.core.errors import InputError
    from catalog.presets import load_preset, save_preset_dict

    path = make_preset("lace-bad")
    text = path.read_text().replace('[fluorescence]', '[fluorescence]\nquantum_yield = 5.0', 1)
    path.write_text(text)
    with pytest.raises(InputError, match="fluorescence.quantum_yield"):
        load_preset(path)
    good = load_preset(make_preset("lace-good"))
    doc = dict(good.raw)
    doc["fluorescence"] = dict(doc["fluorescence"], quantum_yield=5.0)
    target = tmp_path / "lace-good.toml"
    before = target.read_bytes()
    with pytest.raises(InputError, match="fluorescence.quantum_yield"):
        save_preset_dict(doc, target)
    assert target.read_bytes() == before  # the good file stays
    doc["fluorescence"] = dict(good.raw["fluorescence"])
    doc["fit"] = {"stderr": {"g_spec": float("nan")}}
    with pytest.raises(InputError, match="fit.stderr.g_spec"):
        save_preset_dict(doc, target)


# --------------------------------------------------------------------------- signals

def _sheet_args(out: Path) -> list[str]:
    return ["sheet", "--lights", "D65,A,FL2", "--size", "64x48", "--out", str(out)]


@pytest.mark.slow
@pytest.mark.parametrize("delay_s", [0.5, 2.0, 3.5, 5.0])
def test_sigterm_at_any_moment_leaves_no_temporary_and_no_partial_output(tmp_path, delay_s):
    out = tmp_path / "sheet"
    out.mkdir()
    (out / "keep.txt").write_text("the user's file")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen([sys.executable, "-m", "catalog", *_sheet_args(out)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay_s)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=120)
    assert "Traceback" not in stderr, stderr
    if proc.returncode == 0:  # finished before the signal: everything is there
        assert (out / "grid.png").exists()
    else:
        assert proc.returncode == 128 + signal.SIGTERM, stderr
        assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]  # as it was
    assert _litter(tmp_path) == []


def _staged_image(folder: Path, pid: int) -> bool:
    """Whether ``pid``'s staging folder under ``folder`` holds its marker, written whole, and
    a finished image: the stage the next run must recognise and remove, and the kill lands
    between two images, seconds before the renames into the destination."""
    for stage in folder.rglob(f"*{TEMP_MARK}*"):
        with contextlib.suppress(OSError):
            if ((stage / STAGE_MARKER).read_text() == f"{pid}\n"
                    and any(stage.glob("*.png"))):
                return True
    return False


@pytest.mark.slow
def test_sigkill_leaves_no_partial_target_and_the_next_run_clears_the_litter(tmp_path):
    """Killed once a staged image is there (polled, not a guessed delay: under load a guessed
    delay landed before the stage or after the run). The kill waits for the stage's marker
    written whole: a kill between the stage's mkdir and its marker leaves a folder the cleaner
    rightly does not claim (it might be a user's), which no test of the cleaner should hit."""
    out = tmp_path / "sheet"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    log = tmp_path / "stderr.txt"   # a file, not a pipe: a full pipe would stall the child
    with open(log, "w") as stderr:
        proc = subprocess.Popen([sys.executable, "-m", "catalog", *_sheet_args(out)], env=env,
                                stdout=subprocess.DEVNULL, stderr=stderr)
    try:
        deadline = time.monotonic() + 240
        while not _staged_image(tmp_path, proc.pid):
            assert proc.poll() is None, (f"the sheet ended ({proc.returncode}) before an image "
                                         f"was staged: {log.read_text()}")
            assert time.monotonic() < deadline, "no image staged in 240 s"
            time.sleep(0.02)
    finally:
        proc.kill()
        proc.wait(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    assert _litter(tmp_path), "the kill left no stage behind"
    # nothing reached the destination: its files only arrive, after the stage, all at once
    assert not out.exists() or sorted(p.name for p in out.iterdir()) == []
    # the next write there clears the litter; one fabric under one light is enough for it
    result = _catalog("sheet", "--fabric", "fluoro-pink", "--lights", "D65", "--size", "64x48",
                      "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert _litter(tmp_path) == []
    assert sorted(p.name for p in out.iterdir()) == ["fluoro-pink__D65.png", "grid.png"]
