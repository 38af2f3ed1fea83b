"""The site's cloth bake child (catalog.web.bake._bake_child) when its parent is gone.

Ctrl-C reaches the whole process group; the child ignores SIGINT and the parent stops, so
the child's next result meets a closed pipe. It must end quietly (no traceback on stderr:
the kill trials count one as a crash), with a non-zero status, and write nothing after.
"""

import io
import pickle
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

#: The child with its bake replaced by a slow stand-in, so the parent's end of the pipe is
#: closed before the first result is written.
CHILD = ("import time, catalog.web.bake as b\n"
         "b.bake = lambda preset: (time.sleep(0.5), preset)[1]\n"
         "b._bake_child()\n")


@pytest.mark.slow   # a child Python
def test_bake_child_ends_quietly_when_its_parent_is_gone():
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    pickle.dump(["a", "b", "c"], child.stdin)
    child.stdin.close()
    child.stdout.close()   # the parent gone: nobody reads the results
    started = time.monotonic()
    status = child.wait(timeout=30)
    stderr = child.stderr.read().decode()
    assert stderr == "", stderr
    assert status == 1
    assert time.monotonic() - started < 1.5   # at the first result, not after all three


@pytest.mark.slow
def test_bake_child_writes_every_result_to_a_reading_parent():
    child = subprocess.run([sys.executable, "-c", CHILD], input=pickle.dumps(["a", "b"]),
                           capture_output=True, timeout=30)
    assert child.returncode == 0 and child.stderr == b""
    stream = io.BytesIO(child.stdout)
    assert [pickle.load(stream), pickle.load(stream)] == [("ok", "a"), ("ok", "b")]


@pytest.mark.slow
def test_bake_child_ends_at_once_on_ctrl_c_mid_bake():
    """Ctrl-C reaches the child with its parent (one process group): it ends by the default
    action at once, mid-bake, not when the bake returns (the kill trials' one slow web run:
    4.1 s, the parent's pipes held open by the child)."""
    child = subprocess.Popen([sys.executable, "-c", CHILD.replace("0.5", "20")],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    pickle.dump(["a"], child.stdin)
    child.stdin.close()
    time.sleep(1.0)   # inside the 20 s stand-in bake
    signalled = time.monotonic()
    child.send_signal(signal.SIGINT)
    status = child.wait(timeout=10)
    assert time.monotonic() - signalled < 1.0
    assert status == -signal.SIGINT
    assert child.stderr.read() == b"" and child.stdout.read() == b""


def _ended(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return True
    return "\nState:\tZ" in state   # a zombie: ended, not yet reaped


@pytest.mark.slow
def test_hard_exit_kills_the_registered_child_process():
    """os._exit leaves a subprocess running; hard_exit kills those in child_process."""
    script = ("import subprocess, sys\n"
              "from catalog.core import atomic\n"
              "p = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)'])\n"
              "print(p.pid, flush=True)\n"
              "with atomic.child_process(p):\n"
              "    atomic.hard_exit(130)\n")
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=30)
    assert run.returncode == 130, run.stderr
    pid = int(run.stdout.split()[0])
    deadline = time.monotonic() + 5.0
    while not _ended(pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _ended(pid)
