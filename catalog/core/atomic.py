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
  SIGINT remove every temporary file and staging folder still open, then exit with the
  conventional status (128 + signal number: 143, 130). A SIGKILL cannot be caught: its
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
import tempfile
from pathlib import Path
from typing import Callable, Iterable, Iterator

from catalog.core.errors import CatalogError

#: Marks every temporary name this layer makes: ``.{target name}{TEMP_MARK}-{pid}-{random}``.
TEMP_MARK = ".catalog-tmp"
_TEMP_NAME = re.compile(r"^\..*" + re.escape(TEMP_MARK) + r"-(\d+)-")
#: Room kept free beyond a command's own estimate (bytes): a file system filled to the
#: last block makes every other program on the machine fail too.
FREE_SPACE_MARGIN_BYTES = 1 << 20

#: Temporary files and staging folders this process has open (removed on SIGTERM/SIGINT).
_LIVE: set[Path] = set()


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


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_target(path: str | Path, *, inputs: Iterable[str | Path] = (),
                 estimate_bytes: int = 0, folder: bool = False) -> Path:
    """Refuse, before any work, an output that cannot be written; return it as a Path.

    ``inputs``: the command's input files (an output naming one of them is refused: an
    input is never overwritten by an output). ``estimate_bytes``: a rough size of what
    will be written (refused if the file system has less free room, plus a margin).
    ``folder``: the target is a folder of outputs (it may exist) rather than a file.
    """
    target = Path(path)
    if str(path) == "":
        raise OutputError(path, "empty path")
    if not folder and target.is_dir():
        raise OutputError(target, "is a folder (give a file name)")
    if folder and target.exists() and not target.is_dir():
        raise OutputError(target, "is a file, not a folder")
    for source in inputs:
        if source is not None and _same_file(target, Path(source)):
            raise OutputError(target, f"is the command's own input ({source}); choose another output")
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


def temporary_owner(name: str) -> int | None:
    """The process id a temporary name of this layer records, or None for other names."""
    match = _TEMP_NAME.match(name)
    return int(match.group(1)) if match else None


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
                    shutil.rmtree(entry)
                else:
                    entry.unlink()
                removed.append(entry)
    return removed


def _temp_prefix(target: Path) -> str:
    return f".{target.name}{TEMP_MARK}-{os.getpid()}-"


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
        fd, tmp_name = tempfile.mkstemp(prefix=_temp_prefix(target),
                                        suffix=suffix if suffix is not None else target.suffix,
                                        dir=target.parent)
        os.close(fd)
    tmp = Path(tmp_name)
    _LIVE.add(tmp)
    try:
        # mkstemp makes the file private (0600); a preset or an image is an ordinary file.
        umask = os.umask(0)
        os.umask(umask)
        with os_errors_as_output_errors(target):
            os.chmod(tmp, 0o666 & ~umask)
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
            os.replace(tmp, target)
            _LIVE.discard(tmp)
            _fsync_folder(target.parent)
    finally:
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
                  estimate_bytes: int = 0) -> Iterator[Path]:
    """Yield an empty staging folder beside ``destination``; on success move its files in.

    A multi-output command (sheet, export, bench, web) writes everything into the staging
    folder; only when the block ends without error are the files moved into
    ``destination`` (created if needed), each by an atomic rename, sub-folders included.
    On failure or a signal the staging folder is removed and ``destination`` is left as
    it was. It returns nothing: the caller knows the names it wrote into the stage.
    """
    destination = check_target(destination, inputs=inputs, estimate_bytes=estimate_bytes,
                               folder=True)
    with os_errors_as_output_errors(destination):
        destination.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(destination.parent)
        stage = Path(tempfile.mkdtemp(prefix=_temp_prefix(destination), dir=destination.parent))
    _LIVE.add(stage)
    try:
        yield stage
        with os_errors_as_output_errors(destination):
            destination.mkdir(parents=True, exist_ok=True)
            remove_stale_temporaries(destination)
            for source in sorted(stage.rglob("*")):
                if source.is_dir():
                    continue
                with open(source, "rb") as handle:
                    os.fsync(handle.fileno())
            for source in sorted(stage.rglob("*")):
                relative = source.relative_to(stage)
                goal = destination / relative
                if source.is_dir():
                    if goal.exists() and not goal.is_dir():
                        raise OutputError(goal, "is a file, not a folder")
                    goal.mkdir(exist_ok=True)
                    continue
                if goal.is_dir():
                    raise OutputError(goal, "is a folder (an output file has that name)")
            # every check passed: the renames below are within one file system
            for source in sorted(stage.rglob("*")):
                if source.is_file():
                    os.replace(source, destination / source.relative_to(stage))
            _fsync_folder(destination)
    finally:
        _remove(stage)


# --------------------------------------------------------------------------- signals

class Terminated(SystemExit):
    """Raised by the SIGTERM handler so that ``finally`` blocks and context managers run."""


def _cleanup_live() -> None:
    for path in list(_LIVE):
        _remove(path)


def _on_signal(signum, _frame) -> None:
    _cleanup_live()
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(128 + signum)


def install_signal_handlers() -> None:
    """SIGTERM and SIGINT remove this process's temporaries and end it (143 / 130)."""
    for signum in (signal.SIGTERM, signal.SIGINT):
        with contextlib.suppress(ValueError):  # not the main thread: leave the handlers
            signal.signal(signum, _on_signal)


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
