"""The site's cloth bake child (catalog.web.bake._bake_child) when its parent is gone.

Ctrl-C reaches the whole process group; the child ignores SIGINT and the parent stops, so
the child's next result meets a closed pipe. It must end quietly (no traceback on stderr:
the kill trials count one as a crash), with a non-zero status, and write nothing after.
"""

import io
import pickle
import subprocess
import sys
import time

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
