"""The output layer (atomic writes): every file a command writes goes through here.

What it guarantees (the README's "bad input" paragraph states it for users):

- **Checked before the work.** :func:`check_target` refuses, in one line naming the path,
  a target that is a folder, a parent that is a file, a folder that cannot be written, a
  target that is one of the command's inputs, and a disk without room for an estimate
  of the output. Commands call it (through :func:`atomic_path` or directly for outputs
  they write late) before they render or fit, so a refusal costs nothing.
- **Whole or not at all.** :func:`atomic_path` writes to a temporary file beside the
  target, checks its size (and, for images, a read-back through a caller's ``verify``),
  ``fsync``\\ s it, renames it onto the target and ``fsync``\\ s the folder. An existing
  good file is only ever replaced by a complete new one.
- **One line for every OS error.** ``OSError`` (no space, read-only file system, no
  permission, ...) becomes :class:`OutputError`: ``PATH: cannot write: CAUSE``; the CLI
  prints it and exits 2 (the user can fix it: free space, choose another folder).
- **Signals.** :func:`install_signal_handlers` (called once by the CLI) makes SIGTERM and
  SIGINT remove every temporary file and staging folder still open, then exit at once
  with the conventional status (128 + signal number: 143, 130), without unwinding; a
  watchdog thread does the same within :data:`SIGNAL_GRACE_S` when the main thread is
  inside native code that never returns to Python (a Mitsuba render). Renames onto
  targets are held off from signals (:func:`signals_deferred`). A SIGKILL cannot be caught: its
  litter is recognised by name (``.NAME.catalog-tmp-PID-...``) and removed by the next
  write into that folder once process PID is gone (:func:`remove_stale_temporaries`).
- **Several outputs.** :func:`staged_folder` stages a multi-output command's files in a
  temporary folder beside the destination and moves them in only when all are written;
  on failure the destination is left as it was.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import shutil
import signal
import sys
import threading
from pathlib import Path
from typing import Callable, Iterable, Iterator

from catalog.core.errors import CatalogError

#: Marks every temporary name this layer makes:
#: ``.{target name}{TEMP_MARK}-{pid}-{random}{token}{suffix}``, where ``token`` is a keyed
#: hash of the rest (:func:`_token`): the cleaner removes only names whose token checks, and
#: a staging folder only when it holds :data:`STAGE_MARKER` naming the same process (from
#: its making to its removal) or is empty (killed before its marker was written), so a
#: user's file or folder that merely looks like a temporary is never deleted.
TEMP_MARK = ".catalog-tmp"
_TEMP_NAME = re.compile(r"^\.(?P<target>.*)" + re.escape(TEMP_MARK)
                        + r"-(?P<pid>\d+)-(?P<rand>[0-9a-f]{8})(?P<token>[0-9a-f]{8})")
#: The file inside every staging folder that marks it as this layer's (holds the pid).
STAGE_MARKER = ".catalog-stage"
#: Room kept free beyond a command's own estimate (bytes): a file system filled to the
#: last block makes every other program on the machine fail too.
FREE_SPACE_MARGIN_BYTES = 1 << 20

#: Temporary files and staging folders this process has open (removed on SIGTERM/SIGINT).
_LIVE: set[Path] = set()
#: Every file this process has read as an input: (st_dev, st_ino) -> the path as given.
#: An output that is one of them (through a symlink, a hard link, another spelling) is
#: refused (:func:`input_clash`).
_INPUTS: dict[tuple[int, int], str] = {}
_INPUTS_ACTIVE: list[bool] = []


class OutputError(CatalogError):
    """An output that cannot be written: names the path and the cause (exit 2)."""

    def __init__(self, path: str | Path, cause: str):
        self.path = str(path)
        self.cause = cause
        super().__init__(f"{path}: cannot write: {cause}")


def os_cause(exc: OSError) -> str:
    """A short, human cause for an OS error ("no space left on device", ...)."""
    if exc.errno == errno.ENOSPC:
        return "no space left on device"
    if exc.errno == errno.EROFS:
        return "read-only file system"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "permission denied"
    if exc.errno == errno.EISDIR:
        return "is a folder"
    if exc.errno == errno.ENOTDIR:
        return "a parent in the path is a file, not a folder"
    if exc.errno == errno.EDQUOT:
        return "disk quota exceeded"
    return (exc.strerror or str(exc)).lower()


@contextlib.contextmanager
def os_errors_as_output_errors(path: str | Path) -> Iterator[None]:
    """Turn an ``OSError`` raised inside the block into :class:`OutputError` for ``path``."""
    try:
        yield
    except OutputError:
        raise
    except OSError as exc:
        raise OutputError(path, os_cause(exc)) from exc


# --------------------------------------------------------------------------- checks

def _existing_ancestor(path: Path) -> Path:
    """The nearest folder (or file) on ``path``'s way up that exists."""
    for candidate in (path, *path.parents):
        if candidate.exists():
            return candidate
    return Path(path.anchor or ".")


def check_path_text(path: str | Path) -> None:
    """A path the file system cannot store as given is refused: a NUL byte, or a name that
    is not valid text (an undecodable byte, kept by Python as a lone surrogate)."""
    text = os.fspath(path)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    if "\x00" in text:
        raise OutputError(repr(text)[1:-1], "the path holds a NUL byte")
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise OutputError(text.encode("utf-8", "backslashreplace").decode("ascii"),
                          "the path is not valid UTF-8 text") from None


def register_input(path: str | Path | None) -> None:
    """Record ``path`` as one of this process's inputs (every reader of a preset, spectrum,
    gonio file, dye, pattern, environment or matrix calls this): an output that resolves
    to it (symlinks followed, hard links by device and inode) is then refused."""
    if path is None or not _INPUTS_ACTIVE:
        return
    with contextlib.suppress(OSError, ValueError):
        info = os.stat(path)
        _INPUTS.setdefault((info.st_dev, info.st_ino), str(path))


def registered_inputs() -> list[str]:
    """The inputs this process has read so far (as given)."""
    return list(_INPUTS.values())


def track_inputs(active: bool) -> None:
    """Start (True) or end (False) a command's record of its inputs: the CLI does both
    around each command; library calls outside a command (a script regenerating a preset
    it has read) record nothing."""
    _INPUTS.clear()
    _INPUTS_ACTIVE[:] = [True] if active else []


def input_clash(target: str | Path, inputs: Iterable[str | Path] = ()) -> str | None:
    """The input ``target`` would overwrite (one of ``inputs`` or of the registered inputs,
    compared by device and inode after following symlinks), or None."""
    try:
        info = os.stat(target)
    except (OSError, ValueError):
        return None
    key = (info.st_dev, info.st_ino)
    for source in inputs:
        if source is None:
            continue
        with contextlib.suppress(OSError, ValueError):
            other = os.stat(source)
            if (other.st_dev, other.st_ino) == key:
                return str(source)
    return _INPUTS.get(key)


def refuse_special(target: Path) -> None:
    """An existing target that is not a regular file (a device such as /dev/null, a pipe, a
    socket) is refused: an output only ever replaces a regular file."""
    with contextlib.suppress(OSError, ValueError):
        mode = os.stat(target).st_mode
        import stat as stat_lib  # noqa: PLC0415

        if not (stat_lib.S_ISREG(mode) or stat_lib.S_ISDIR(mode)):
            raise OutputError(target, "is not a regular file (a device, pipe or socket); "
                                      "outputs only replace regular files")


def check_target(path: str | Path, *, inputs: Iterable[str | Path] = (),
                 estimate_bytes: int = 0, folder: bool = False) -> Path:
    """Refuse, before any work, an output that cannot be written; return it as a Path.

    ``inputs``: the command's input files (an output naming one of them is refused: an
    input is never overwritten by an output). ``estimate_bytes``: a rough size of what
    will be written (refused if the file system has less free room, plus a margin).
    ``folder``: the target is a folder of outputs (it may exist) rather than a file.
    """
    if str(path) == "":
        raise OutputError(path, "empty path")
    check_path_text(path)
    target = Path(path)
    if not folder and target.is_dir():
        raise OutputError(target, "is a folder (give a file name)")
    if folder and target.exists() and not target.is_dir():
        raise OutputError(target, "is a file, not a folder")
    refuse_special(target)
    clash = input_clash(target, inputs)
    if clash is not None:
        raise OutputError(target, f"is the command's own input ({clash}); choose another output")
    parent = target if folder else target.parent
    ancestor = _existing_ancestor(parent)
    if not ancestor.is_dir():
        raise OutputError(target, f"{ancestor} is a file, not a folder")
    try:
        stat = os.statvfs(ancestor)
    except OSError:
        stat = None
    if stat is not None and stat.f_flag & os.ST_RDONLY:
        raise OutputError(target, "read-only file system")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputError(target, f"folder {ancestor} is not writable")
    with contextlib.suppress(OSError):
        free = shutil.disk_usage(ancestor).free
        if free < estimate_bytes + FREE_SPACE_MARGIN_BYTES:
            raise OutputError(target, f"no room: {free} bytes free, about "
                                      f"{estimate_bytes + FREE_SPACE_MARGIN_BYTES} needed")
    return target


# --------------------------------------------------------------------------- temporaries

def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _token(target_name: str, pid: int, rand: str) -> str:
    import hashlib  # noqa: PLC0415

    return hashlib.blake2s(f"{target_name}|{pid}|{rand}".encode("utf-8", "surrogateescape"),
                           key=b"catalog-temporary", digest_size=4).hexdigest()


def temporary_name(target_name: str, pid: int | None = None, suffix: str = "") -> str:
    """A fresh temporary name for a target called ``target_name`` of process ``pid``."""
    import secrets  # noqa: PLC0415

    pid = os.getpid() if pid is None else pid
    rand = secrets.token_hex(4)
    return f".{target_name}{TEMP_MARK}-{pid}-{rand}{_token(target_name, pid, rand)}{suffix}"


def temporary_owner(name: str) -> int | None:
    """The process id a temporary name of this layer records, or None for other names
    (including names that look like one but whose token does not check)."""
    match = _TEMP_NAME.match(name)
    if match is None:
        return None
    pid = int(match.group("pid"))
    if _token(match.group("target"), pid, match.group("rand")) != match.group("token"):
        return None
    return pid


def _is_our_stage(folder: Path, pid: int) -> bool:
    with contextlib.suppress(OSError, ValueError):
        return (folder / STAGE_MARKER).read_text().strip() == str(pid)
    return False


def remove_stale_temporaries(folder: str | Path) -> list[Path]:
    """Remove this layer's temporaries in ``folder`` whose process is gone (a SIGKILL's
    litter); return what was removed. Files of live processes are left alone."""
    removed = []
    folder = Path(folder)
    with contextlib.suppress(OSError):
        for entry in folder.iterdir():
            pid = temporary_owner(entry.name)
            if pid is None or _pid_alive(pid):
                continue
            with contextlib.suppress(OSError):
                if entry.is_dir() and not entry.is_symlink():
                    if not _is_our_stage(entry, pid):
                        # a stage killed between its mkdir and its marker is empty; rmdir
                        # removes only an empty folder, so a user's look-alike is never lost
                        entry.rmdir()
                    else:
                        shutil.rmtree(entry)
                else:
                    entry.unlink()
                removed.append(entry)
    return removed


def _make_temporary_file(target: Path, suffix: str) -> Path:
    for _ in range(100):
        tmp = target.parent / temporary_name(target.name, suffix=suffix)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # umask applies
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise OSError(errno.EEXIST, "no free temporary name")


def _make_stage(destination: Path, beside: Path) -> Path:
    for _ in range(100):
        stage = beside / temporary_name(destination.name)
        try:
            stage.mkdir(mode=0o700)
        except FileExistsError:
            continue
        (stage / STAGE_MARKER).write_text(f"{os.getpid()}\n")
        return stage
    raise OSError(errno.EEXIST, "no free temporary name")


def _fsync_folder(folder: Path) -> None:
    with contextlib.suppress(OSError):  # not every file system lets a folder be fsync'ed
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _remove(path: Path) -> None:
    with contextlib.suppress(OSError):
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()
    _LIVE.discard(path)


@contextlib.contextmanager
def atomic_path(target: str | Path, suffix: str | None = None, *,
                inputs: Iterable[str | Path] = (), estimate_bytes: int = 0,
                verify: Callable[[Path], None] | None = None,
                min_bytes: int = 1) -> Iterator[Path]:
    """Yield a temporary path beside ``target``; when the block ends, publish it.

    Before: :func:`check_target` and removal of stale temporaries in the folder. After the
    block: the file must exist with at least ``min_bytes`` bytes, pass ``verify(tmp)``
    (which raises to refuse it), is ``fsync``\\ ed and renamed onto ``target``. On any
    exception, or a signal, the temporary is removed and ``target`` is left as it was.
    The temporary keeps the target's suffix (image writers pick the format from it).
    """
    target = check_target(target, inputs=inputs, estimate_bytes=estimate_bytes)
    with os_errors_as_output_errors(target):
        target.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(target.parent)
        with signals_deferred():
            tmp = _make_temporary_file(target, suffix if suffix is not None else target.suffix)
            _LIVE.add(tmp)
    try:
        try:
            yield tmp
        except OSError as exc:
            # the writer failed on the temporary (no space, I/O error): say so for the target;
            # an OS error about another file (an input) is not this layer's to rename
            if exc.filename is not None and Path(exc.filename) != tmp:
                raise
            raise OutputError(target, os_cause(exc)) from exc
        with os_errors_as_output_errors(target):
            size = tmp.stat().st_size
            if size < min_bytes:
                raise OutputError(target, f"the written file has {size} bytes "
                                          "(the disk may be full); the old file is kept")
            if verify is not None:
                verify(tmp)
            with open(tmp, "rb+") as handle:
                os.fsync(handle.fileno())
            # commit_together: published with the group's others; a file written into a live
            # staging folder is not (the stage itself publishes all of it, or none)
            group = _GROUPS[-1] if _GROUPS and not _in_live_stage(target) else None
            if group is not None:
                group.append((tmp, target, tuple(inputs)))
                return
            _publish([(tmp, target, tuple(inputs))])
    finally:
        if tmp in _LIVE and not any(tmp == t for g in _GROUPS for t, _, _ in g):
            _remove(tmp)


def _in_live_stage(target: Path) -> bool:
    """Whether ``target`` lies inside a staging folder of :func:`staged_folder` still open."""
    return any(stage.is_dir() and target.is_relative_to(stage) for stage in _LIVE)


#: Open :func:`commit_together` groups (innermost last): (temporary, target, inputs).
_GROUPS: list[list[tuple[Path, Path, tuple]]] = []


def _publish(items: list[tuple[Path, Path, tuple]]) -> None:
    """Rename temporaries onto their targets, every check first, no signal in between."""
    for _tmp, target, inputs in items:
        refuse_special(target)
        clash = input_clash(target, inputs)
        if clash is not None:
            raise OutputError(target, f"is the command's own input ({clash}); choose "
                                      "another output")
    with signals_deferred():
        for tmp, target, _ in items:
            with os_errors_as_output_errors(target):
                os.replace(tmp, target)
            _LIVE.discard(tmp)
    for folder in {target.parent for _, target, _ in items}:
        _fsync_folder(folder)


@contextlib.contextmanager
def commit_together() -> Iterator[None]:
    """Outputs written by :func:`atomic_path` inside the block are published together when
    it ends without error (every check first, then the renames with signals held off); on
    an error or a signal none is (``catalog fit --plot P.png --out P.toml``)."""
    group: list[tuple[Path, Path, tuple]] = []
    _GROUPS.append(group)
    try:
        yield
        _GROUPS.remove(group)
        _publish(group)
    finally:
        if group in _GROUPS:
            _GROUPS.remove(group)
        for tmp, _, _ in group:
            if tmp in _LIVE:
                _remove(tmp)


def write_text_atomic(target: str | Path, text: str, *, inputs: Iterable[str | Path] = ()) -> None:
    """Write ``text`` (UTF-8) to ``target`` atomically."""
    data = text.encode("utf-8")
    write_bytes_atomic(target, data, inputs=inputs)


def write_bytes_atomic(target: str | Path, data: bytes, *, inputs: Iterable[str | Path] = ()) -> None:
    """Write ``data`` to ``target`` atomically (refused before writing if there is no room)."""
    with atomic_path(target, inputs=inputs, estimate_bytes=len(data),
                     min_bytes=min(1, len(data))) as tmp:
        with open(tmp, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        if tmp.stat().st_size != len(data):
            raise OutputError(target, f"wrote {tmp.stat().st_size} of {len(data)} bytes")


# --------------------------------------------------------------------------- several outputs

@contextlib.contextmanager
def staged_folder(destination: str | Path, *, inputs: Iterable[str | Path] = (),
                  estimate_bytes: int = 0,
                  replace_listed: Callable[[Path], None] | None = None) -> Iterator[Path]:
    """Yield an empty staging folder beside ``destination``; on success move its files in.

    A multi-output command (sheet, export, bench, web) writes everything into the staging
    folder; only when the block ends without error are the files moved into
    ``destination`` (created if needed), each by an atomic rename, sub-folders included.
    On failure or a signal the staging folder is removed and ``destination`` is left as
    it was. It returns nothing: the caller knows the names it wrote into the stage.
    ``replace_listed(destination)``, called just before the moves (signals held off),
    removes what an earlier run wrote and this one no longer does (the web site's manifest).
    """
    destination = check_target(destination, inputs=inputs, estimate_bytes=estimate_bytes,
                               folder=True)
    with os_errors_as_output_errors(destination):
        # the stage sits on the destination's own file system: inside it when it exists (a
        # mount point's parent is another file system), else beside it
        beside = destination if destination.is_dir() else destination.parent
        made = [folder for folder in (beside, *beside.parents) if not folder.exists()]
        beside.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(beside)
        with signals_deferred():
            stage = _make_stage(destination, beside)
            _LIVE.add(stage)
    marker = stage / STAGE_MARKER
    try:
        yield stage
        # the marker stays until the stage is removed (it is not published): a SIGKILL
        # during the moves leaves a stage the next run's cleaner still claims
        staged = [source for source in sorted(stage.rglob("*")) if source != marker]
        with os_errors_as_output_errors(destination):
            destination.mkdir(parents=True, exist_ok=True)
            remove_stale_temporaries(destination)
            for source in staged:
                if source.is_dir():
                    continue
                with open(source, "rb") as handle:
                    os.fsync(handle.fileno())
            for source in staged:
                relative = source.relative_to(stage)
                goal = destination / relative
                if source.is_dir():
                    if goal.exists() and not goal.is_dir():
                        raise OutputError(goal, "is a file, not a folder")
                    goal.mkdir(exist_ok=True)
                    continue
                if goal.is_dir():
                    raise OutputError(goal, "is a folder (an output file has that name)")
                refuse_special(goal)
                clash = input_clash(goal, inputs)
                if clash is not None:
                    raise OutputError(goal, f"is the command's own input ({clash})")
            # every check passed: the renames below are within one file system
            with signals_deferred():
                if replace_listed is not None:
                    replace_listed(destination)
                for source in staged:
                    if source.is_file():
                        os.replace(source, destination / source.relative_to(stage))
            _fsync_folder(destination)
        made = []
    finally:
        _remove(stage)
        for folder in made:  # the folders made above the destination, on a failure
            with contextlib.suppress(OSError):
                folder.rmdir()


# --------------------------------------------------------------------------- signals

class Terminated(SystemExit):
    """Raised by the SIGTERM handler so that ``finally`` blocks and context managers run."""


#: Seconds a signalled process has to unwind by itself (its ``finally`` blocks, a Dask
#: cluster's close) before the watchdog ends it; the promise is an exit within one second.
SIGNAL_GRACE_S = 0.4
#: Held while temporaries are renamed onto their targets: the watchdog waits for it.
_COMMIT_LOCK = threading.RLock()
_DEFERRED = {"depth": 0, "pending": None}
_WATCHDOG = {"installed": False, "signalled": None}
#: Child processes started with subprocess (:func:`child_process`) that :func:`hard_exit`
#: ends with this one: os._exit leaves them running, holding the caller's pipes open.
_CHILDREN: set = set()


@contextlib.contextmanager
def child_process(process) -> Iterator:
    """``process`` (a subprocess.Popen) ended by :func:`hard_exit` if this process is
    signalled while the block runs; the caller still waits for or kills it itself."""
    _CHILDREN.add(process)
    try:
        yield process
    finally:
        _CHILDREN.discard(process)


def _cleanup_live() -> None:
    for path in list(_LIVE):
        _remove(path)


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold SIGTERM/SIGINT off for a short critical step (a rename sequence): a signal that
    arrives meanwhile is acted on when the block ends."""
    with _COMMIT_LOCK:
        _DEFERRED["depth"] += 1
        try:
            yield
        finally:
            _DEFERRED["depth"] -= 1
    pending = _DEFERRED["pending"]
    if _DEFERRED["depth"] == 0 and pending is not None:
        _DEFERRED["pending"] = None
        _on_signal(pending, None)


def _on_signal(signum, _frame) -> None:
    """SIGTERM/SIGINT: remove the temporaries and end the process at once (143 / 130).

    No unwinding: a ``finally`` that tears an EGL context down, or a library's cleanup,
    run from inside a signal has crashed (a segfault in 1 of 35 snapshot trials). Every
    target is whole (renames are atomic and held off from signals), so there is nothing to
    finish; Dask workers, child processes, are terminated by :func:`hard_exit`."""
    if _DEFERRED["depth"] > 0:
        _DEFERRED["pending"] = signum
        return
    hard_exit(128 + signum)


def hard_exit(status: int) -> None:
    """End the process now with ``status``: this process's temporaries removed, its child
    processes (Dask workers) terminated, no interpreter teardown (an EGL context torn down
    inside a signal has crashed; os._exit skips it), the subprocesses of
    :func:`child_process` killed."""
    acquired = _COMMIT_LOCK.acquire(timeout=2.0)
    try:
        _cleanup_live()
        with contextlib.suppress(Exception):
            import multiprocessing  # noqa: PLC0415

            for child in multiprocessing.active_children():
                child.terminate()
        for process in list(_CHILDREN):
            with contextlib.suppress(Exception):
                process.kill()
        with contextlib.suppress(Exception):
            sys.stderr.flush()
    finally:
        os._exit(status)
        if acquired:  # pragma: no cover - os._exit does not return
            _COMMIT_LOCK.release()


def _watch(read_fd: int) -> None:
    """The watchdog thread: woken by the C-level signal handler (set_wakeup_fd) even while
    the main thread is inside native code (Mitsuba, llvmpipe), it gives the main thread
    SIGNAL_GRACE_S to unwind and then ends the process itself."""
    import time  # noqa: PLC0415

    while True:
        try:
            data = os.read(read_fd, 64)
        except OSError:
            return
        numbers = [b for b in data if b in (signal.SIGTERM, signal.SIGINT)]
        if not numbers:
            continue
        _WATCHDOG["signalled"] = numbers[0]
        time.sleep(SIGNAL_GRACE_S)
        hard_exit(128 + numbers[0])


def install_signal_handlers() -> None:
    """SIGTERM and SIGINT remove this process's temporaries and end it (143 / 130), within
    a second even inside native code (the watchdog thread)."""
    try:
        for signum in (signal.SIGTERM, signal.SIGINT):
            signal.signal(signum, _on_signal)
    except ValueError:  # not the main thread: leave the handlers
        return
    if _WATCHDOG["installed"]:
        return
    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)
    try:
        signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
    except ValueError:
        os.close(read_fd)
        os.close(write_fd)
        return
    _WATCHDOG["installed"] = True
    threading.Thread(target=_watch, args=(read_fd,), name="catalog-signal-watchdog",
                     daemon=True).start()


# --------------------------------------------------------------------------- stdout

def write_stdout(text: str) -> None:
    """Write ``text`` to stdout; a closed or full stdout becomes one :class:`OutputError`."""
    if sys.stdout is None:  # started with file descriptor 1 closed
        raise OutputError("stdout", "closed")
    try:
        sys.stdout.write(text)
        sys.stdout.flush()
    except (BrokenPipeError, OSError, ValueError) as exc:
        silence_stdout()
        cause = os_cause(exc) if isinstance(exc, OSError) and not isinstance(exc, BrokenPipeError) \
            else "closed"
        raise OutputError("stdout", cause) from exc


def silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush cannot fail again."""
    if sys.stdout is None:
        return
    with contextlib.suppress(OSError, ValueError, AttributeError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
