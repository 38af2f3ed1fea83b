"""`catalog render-catalog` and catalog.batch: the job's options, resume after a kill,
determinism across engines and worker counts, a failing fabric, and the renderer kept per
process giving exactly what `catalog snapshot` gives.

Small on purpose: 48x32 images, a few frames, at most two Dask workers on loopback.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from catalog.batch import JobSpec, parse_frames, parse_yaws
from catalog.batch.worker import RendererPool, render_fabric
from catalog.commands.cli import main
from catalog.core.errors import InputError

CATALOG = [sys.executable, "-m", "catalog"]
SMALL = ["--size", "48x32", "--no-progress"]


def _dask() -> bool:
    try:
        import distributed  # noqa: F401
    except ImportError:
        return False
    return True


needs_dask = pytest.mark.skipif(not _dask(), reason="Dask distributed not installed "
                                                    "(pip install '.[batch]')")


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _images(folder: Path) -> dict[str, Path]:
    """The images under their final names (a killed run's temporary files, hidden names that
    end in the image's suffix too, are not images yet: the next run removes them)."""
    return {str(p.relative_to(folder)): p for p in sorted(folder.glob("*/*"))
            if p.suffix in (".png", ".exr") and not p.name.startswith(".")}


def _run(args, **kw):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    return subprocess.run(CATALOG + args, capture_output=True, text=True, env=env,
                          timeout=kw.pop("timeout", 300), **kw)


# ---------------------------------------------------------------------- options (no GL)

def test_frames_are_a_python_slice():
    assert parse_frames("0:48") == range(0, 48)
    assert parse_frames("3:10:3") == range(3, 10, 3)
    assert list(parse_frames("3:10:3")) == list(range(48))[3:10:3]  # B excluded, as Python
    for bad in ("5:2", "4:4", "0:10:0", "0:10:-1", "-1:3", "a:b", "3", "1:2:3:4"):
        with pytest.raises(InputError, match="--frames"):
            parse_frames(bad)


def test_yaw_list_and_range():
    assert parse_yaws(None) == (0.0,)
    assert parse_yaws("0,90,-45") == (0.0, 90.0, -45.0)
    assert parse_yaws("0:360:90") == (0.0, 90.0, 180.0, 270.0)
    assert parse_yaws("0:1:0.3") == (0.0, 0.3, 0.6, 0.9)
    for bad in ("a", "0,0", "0:360", "10:0:5", "0:10:0", "720", "nan"):
        with pytest.raises(InputError, match="--yaw"):
            parse_yaws(bad)


@pytest.mark.parametrize("change, option", [
    (["--frames", "5:2"], "--frames"),
    (["--frames", "x"], "--frames"),
    (["--size", "0x32"], "--size"),
    (["--format", "jpg"], "--format"),
    (["--fabric", "no-such-fabric"], "--fabric"),
    (["--fabric", "lace-fwa,lace-fwa"], "--fabric"),
    (["--lights", "NOT-A-LIGHT"], "--lights"),
    (["--yaw", "0,a"], "--yaw"),
    (["--workers", "0"], "--workers"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"], "--workers"),
    (["--scheduler", "nowhere"], "--scheduler"),
    (["--bands", "5"], "--bands"),
    (["--distance", "-1"], "--distance"),
    (["--retries", "-1"], "--retries"),
])
def test_bad_options_refused_in_one_line_nothing_written(tmp_path, capsys, change, option):
    out = tmp_path / "out"
    args = ["render-catalog", "--fabric", "lace-fwa", "--lights", "D65", "--frames", "0:1",
            "--out", str(out), *SMALL]
    # a later option replaces an earlier one of the same name in argparse
    assert main(args + change) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert option.lower() in err[0].lower(), err[0]
    assert not out.exists()


def test_out_must_be_a_folder(tmp_path, capsys):
    out = tmp_path / "file.txt"
    out.write_text("keep me")
    assert main(["render-catalog", "--fabric", "lace-fwa", "--lights", "D65",
                 "--out", str(out), *SMALL]) == 2
    assert "--out" in capsys.readouterr().err
    assert out.read_text() == "keep me"


def test_image_names_and_keys():
    spec = JobSpec.create(fabrics="lace-fwa,linen-dense", lights="D65,sun:22", frames="0:4:2",
                          yaws="0,22.5", size="48x32", image_format="exr", out_dir="unused")
    images = spec.images_of(0) + spec.images_of(1)
    assert spec.image_count == len(images) == 2 * 2 * 2 * 2
    assert "lace-fwa/lace-fwa__sun_22__f0002__yaw22.5.exr" in {i.path for i in images}
    assert len({i.key for i in images}) == len(images)  # every image its own inputs
    again = JobSpec.create(fabrics="lace-fwa,linen-dense", lights="D65,sun:22",
                           frames="0:4:2", yaws="0,22.5", size="48x32", image_format="exr",
                           out_dir="elsewhere")
    assert [i.key for i in again.images_of(0)] == [i.key for i in spec.images_of(0)]
    other = JobSpec.create(fabrics="lace-fwa", lights="D65,sun:22", frames="0:4:2",
                           yaws="0,22.5", size="64x32", image_format="exr", out_dir="unused")
    assert not {i.key for i in other.images_of(0)} & {i.key for i in spec.images_of(0)}


def test_retry_then_report_in_process(monkeypatch, tmp_path):
    """A task that raises is retried; one that keeps raising is reported, the rest done."""
    import catalog.batch.worker as worker
    from catalog.batch.engine import _run_process

    calls: dict[str, int] = {}

    def flaky(task, pool=None, on_image=None):
        calls[task.fabric] = calls.get(task.fabric, 0) + 1
        if task.fabric == "always" or (task.fabric == "once" and calls[task.fabric] == 1):
            raise RuntimeError("worker lost")
        return {"fabric": task.fabric, "ok": True, "records": [], "error": None}

    monkeypatch.setattr(worker, "render_fabric", flaky)
    monkeypatch.setattr(worker, "process_pool", lambda *a, **k: None)

    class Task:
        def __init__(self, fabric):
            self.fabric = fabric
    results = {}
    _run_process([Task("once"), Task("always"), Task("fine")], 2, None,
                 lambda task, result: results.__setitem__(task.fabric, result))
    assert calls == {"once": 2, "always": 3, "fine": 1}
    assert results["once"]["ok"] and results["fine"]["ok"]
    assert not results["always"]["ok"]
    assert "worker lost" in results["always"]["error"] and "2 retries" in results["always"]["error"]


# ---------------------------------------------------------------------- rendering (GL)

@pytest.mark.gl
@pytest.mark.slow
def test_batch_images_equal_snapshot_images(gl, tmp_path):
    """The kept renderer, reused across lights, frames and yaws, gives exactly the pixels of
    a fresh `catalog snapshot` of the same fabric, light, frame and yaw (0 px differ)."""
    import OpenImageIO as oiio

    from catalog.render.snapshot import SnapshotRequest, render_snapshot

    spec = JobSpec.create(fabrics="lace-fwa", lights="D65,A", frames="0:5:4", yaws="0,35",
                          size="48x32", image_format="png", out_dir=tmp_path / "batch")
    result = render_fabric(spec.task(0, spec.images_of(0)), RendererPool(ctx=gl))
    assert result["ok"], result
    assert len(result["records"]) == 8
    for light, frame, yaw in (("A", 0, 35.0), ("D65", 4, 0.0), ("A", 4, 35.0)):
        single = tmp_path / f"single-{light}-{frame}-{yaw}.png"
        render_snapshot(SnapshotRequest(fabric="lace-fwa", light=light, size=(48, 32),
                                        out=single, frame=frame, yaw_deg=yaw), ctx=gl)
        batch = tmp_path / "batch" / "lace-fwa" / f"lace-fwa__{light}__f{frame:04d}__yaw{yaw:g}.png"
        a = oiio.ImageBuf(str(single)).get_pixels(oiio.UINT8)
        b = oiio.ImageBuf(str(batch)).get_pixels(oiio.UINT8)
        assert a.shape == b.shape == (32, 48, 3)
        assert np.array_equal(a, b), f"{light} frame {frame} yaw {yaw}: {np.sum(a != b)} values differ"
    # frames and yaws change the picture (the test above is not comparing blanks)
    first = oiio.ImageBuf(str(tmp_path / "batch/lace-fwa/lace-fwa__D65__f0000__yaw0.png")).get_pixels()
    moved = oiio.ImageBuf(str(tmp_path / "batch/lace-fwa/lace-fwa__D65__f0004__yaw35.png")).get_pixels()
    assert np.abs(first - moved).mean() > 0.01


@pytest.mark.gl
@pytest.mark.slow
def test_failing_fabric_reported_rest_finish(tmp_path, make_preset):
    broken = make_preset("broken", rho=1.5)  # out of range: refused when the worker loads it
    out = tmp_path / "out"
    run = _run(["render-catalog", "--fabric", f"lace-fwa,{broken},linen-dense",
                "--lights", "D65", "--frames", "0:3", "--out", str(out), "--json", *SMALL])
    assert run.returncode == 3, run.stderr
    summary = json.loads(run.stdout)
    assert list(summary["failed"]) == ["broken"]
    assert "rho" in summary["failed"]["broken"]
    assert "fabric broken failed" in run.stderr and "rho" in run.stderr
    assert summary["rendered"] == 6
    names = set(_images(out))
    assert names == {f"{f}/{f}__D65__f{n:04d}__yaw0.png" for f in ("lace-fwa", "linen-dense")
                     for n in range(3)}
    manifest = json.loads((out / "manifest.json").read_text())
    assert list(manifest["failed"]) == ["broken"]
    assert {rec["path"] for rec in manifest["images"]} == names


@pytest.mark.gl
@needs_dask
@pytest.mark.slow
def test_failing_fabric_on_dask_workers(tmp_path, make_preset):
    broken = make_preset("broken", g_spec=3.0)
    out = tmp_path / "out"
    run = _run(["render-catalog", "--fabric", f"{broken},lace-fwa", "--lights", "D65,A",
                "--frames", "0:2", "--out", str(out), "--workers", "2", "--json", *SMALL])
    assert run.returncode == 3, run.stderr
    summary = json.loads(run.stdout)
    assert list(summary["failed"]) == ["broken"] and summary["rendered"] == 4
    assert len(_images(out)) == 4


@pytest.mark.gl
@pytest.mark.slow
def test_same_images_whatever_the_engine_and_workers(tmp_path):
    """One process, one and two Dask workers (LocalCluster) and an existing cluster reached
    with --scheduler write byte-identical files (PNG; EXR for one process against two
    workers), and the manifest's hashes are the files' hashes."""
    job = ["render-catalog", "--fabric", "lace-fwa,fluoro-pink", "--lights", "D65,LED-B4",
           "--frames", "0:3:2", "--yaw", "0,40", "--json", *SMALL]
    hashes = {}
    runs = [("process", "png", []), ("process", "exr", [])]
    if _dask():
        runs += [("dask-1", "png", ["--workers", "1"]), ("dask-2", "png", ["--workers", "2"]),
                 ("dask-2", "exr", ["--workers", "2"])]
    cluster = None
    if _dask():  # an existing cluster, reached by address (--scheduler), on loopback
        import logging

        from distributed import LocalCluster
        cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None,
                               silence_logs=logging.ERROR)
        runs.append(("scheduler", "png", ["--scheduler", cluster.scheduler_address]))
    try:
        for name, fmt, extra in runs:
            _render_and_hash(job, tmp_path, name, fmt, extra, hashes)
    finally:
        if cluster is not None:
            cluster.close()
    for name, fmt, _ in runs:
        assert hashes[(name, fmt)] == hashes[("process", fmt)], f"{name} {fmt} differs"
    if not _dask():
        pytest.skip("Dask not installed: only the one-process engine was compared")


def _render_and_hash(job, tmp_path, name, fmt, extra, hashes):
    """Render the job with one engine; record the files' hashes; check the manifest."""
    out = tmp_path / f"{name}-{fmt}"
    run = _run(job + ["--format", fmt, "--out", str(out)] + extra)
    assert run.returncode == 0, run.stderr
    summary = json.loads(run.stdout)
    assert summary["rendered"] == 2 * 2 * 2 * 2
    if name == "dask-2":  # two processes, one context each, llvmpipe threads shared
        assert len(summary["processes"]) == 2
        assert all(p["contexts_created"] == 1 for p in summary["processes"])
        assert {p["lp_num_threads"] for p in summary["processes"]} <= {
            os.environ.get("LP_NUM_THREADS"), str(max(1, len(os.sched_getaffinity(0)) // 2))}
    files = _images(out)
    hashes[(name, fmt)] = {k: _sha(p) for k, p in files.items()}
    assert len(files) == 16
    manifest = json.loads((out / "manifest.json").read_text())
    assert {r["path"]: r["sha256"] for r in manifest["images"]} == hashes[(name, fmt)]


@pytest.mark.gl
@pytest.mark.slow
def test_resume_after_kill(tmp_path):
    """SIGKILL mid-run; the re-run keeps every finished image untouched (same inode and
    mtime), renders only the rest, leaves no partial or temporary file, and the manifest
    lists every image with its file's hash."""
    out = tmp_path / "out"
    job = ["render-catalog", "--fabric", "lace-fwa,linen-dense", "--lights", "D65,A",
           "--frames", "0:3:2", "--yaw", "0:360:20", "--out", str(out), *SMALL]
    total = 2 * 2 * 2 * 18
    proc = subprocess.Popen(CATALOG + job, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if len(_images(out)) >= 12:
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the run finished before it could be killed: make the job bigger"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = {name: (p.stat().st_ino, p.stat().st_mtime_ns, _sha(p))
              for name, p in _images(out).items()}
    assert 12 <= len(before) < total
    import OpenImageIO as oiio
    for name in before:  # every file under a final name is a whole image
        buf = oiio.ImageBuf(str(out / name))
        assert buf.get_pixels(oiio.UINT8).shape == (32, 48, 3), name
    from catalog.core.atomic import TEMP_MARK, temporary_name
    torn = temporary_name("lace-fwa__A__f0002__yaw0.png", proc.pid, ".png")  # the killed run's
    (out / "lace-fwa" / torn).write_bytes(b"\x89PNG torn")
    with open(out / "manifest.journal.jsonl", "a") as journal:
        journal.write('{"path": "lace-fwa/torn')  # a line cut by the kill

    rerun = _run(job + ["--json"])
    assert rerun.returncode == 0, rerun.stderr
    summary = json.loads(rerun.stdout)
    after = _images(out)
    assert len(after) == total
    for name, (inode, mtime, digest) in before.items():  # untouched: not rendered twice
        stat = after[name].stat()
        assert (stat.st_ino, stat.st_mtime_ns, _sha(after[name])) == (inode, mtime, digest), name
    assert summary["rendered"] == total - len(before)
    assert summary["rendered"] + summary["kept"] + summary["skipped"] == total
    assert not [p for p in out.rglob("*") if TEMP_MARK in p.name], "temporary files left behind"
    manifest = json.loads((out / "manifest.json").read_text())
    assert {r["path"]: r["sha256"] for r in manifest["images"]} == {
        name: _sha(p) for name, p in after.items()}
    assert not (out / "manifest.journal.jsonl").exists()

    third = _run(job + ["--json"])  # and a run with nothing left does nothing
    assert third.returncode == 0 and json.loads(third.stdout)["skipped"] == total
    assert all(after[n].stat().st_mtime_ns == p.stat().st_mtime_ns for n, p in _images(out).items())


def test_cost_model_by_hand():
    """The paper model against a hand count: 16 fabrics, 1 light, frames 0..2, 8 workers per
    node; a fabric costs 2 simulated frames (0.1 s each) + 3 images (0.01 s each) = 0.23 s,
    a process per image pays 1 s start + 0.01 s + 0.1 s per frame simulated: 3.33 s a fabric."""
    from benchmarks.batch_scaling import cost_model, markdown_tables

    model = cost_model(0.01, 0.1, 1.0, 5.0, fabrics=16, lights=1, frames=3, nodes=(1, 2),
                       workers_per_node=8)
    one, two = model["rows"]
    assert model["images"] == 48
    assert one["batch_s"] == pytest.approx(5.0 + 2 * 0.23, abs=2e-3)
    assert two["batch_s"] == pytest.approx(5.0 + 0.23, abs=2e-3)
    assert one["process_per_image_s"] == pytest.approx(16 * 3.33 / 8, abs=2e-3)
    assert two["process_per_image_s"] == pytest.approx(16 * 3.33 / 16, abs=2e-3)
    settled = cost_model(0.01, 0.1, 1.0, 5.0, settle_s=2.0, fabrics=16, lights=1, frames=3,
                         nodes=(1,), workers_per_node=8)["rows"][0]
    assert settled["batch_s"] == pytest.approx(5.0 + 2 * (2.0 + 0.23), abs=2e-3)  # per fabric
    row = {"engine": "process", "wall_s": 1.0, "images_per_s": 200.0, "speedup_vs_dask_1": 1.0,
           "cpu_s_per_image": 0.01, "simulate_s": 0.1, "render_s": 0.2, "write_s": 0.1,
           "startup_s": 0.0}
    tables = markdown_tables({"job": {"images": 200, "fabrics": ["a"] * 5, "lights": ["D65", "A"],
                                      "frames": "0:5", "yaw_deg": "0,30", "size": "96x64"},
                              "machine": {"cpus": 2, "load_average_1min": 1.0},
                              "rows": [row], "model": model})
    assert set(tables) == {"batch_engines", "batch_model"}
    assert "| process | 1.0 | 200.00 |" in tables["batch_engines"]


@needs_dask
def test_task_thread_split_into_cpu_run_wait_and_sleep():
    """A task's thread time, from the kernel's schedstat: a busy loop is on a CPU or waiting
    for one, a sleep is asleep; the three add up to the wall time."""
    import catalog.batch.worker as worker

    if worker.thread_sched() is None:
        pytest.skip("no /proc/thread-self/schedstat here")
    before, start = worker.thread_sched(), time.perf_counter()
    while time.perf_counter() - start < 0.2:
        pass
    busy = worker._sched_split(before, time.perf_counter() - start)
    assert busy["thread_cpu_s"] + busy["run_wait_s"] == pytest.approx(0.2, abs=0.03)
    assert busy["sleep_s"] < 0.03
    before, start = worker.thread_sched(), time.perf_counter()
    time.sleep(0.2)
    asleep = worker._sched_split(before, time.perf_counter() - start)
    assert asleep["sleep_s"] == pytest.approx(0.2, abs=0.03)
    assert asleep["thread_cpu_s"] < 0.03


def test_two_worker_bound_by_hand():
    """The best whole-task deal, tried by hand: tasks 6, 3, 3, 3 s on two workers: 6 | 3+3+3
    is 9, 6+3 | 3+3 is 9, so 9; with 1 s outside the tasks (wall 16) the bound is 16/10."""
    from benchmarks.batch_workers import best_makespan, two_worker_bound

    assert best_makespan([6, 3, 3, 3]) == 9
    assert best_makespan([5, 4, 3, 3, 3]) == 9    # 5+4 | 3+3+3
    assert best_makespan([1.0] * 20) == 10        # the greedy path (more than 12 tasks)
    run = {"wall_s": 16.0, "tasks": [{"wall_s": w} for w in (6, 3, 3, 3)]}
    assert two_worker_bound(run) == pytest.approx(1.6)
    assert two_worker_bound({"wall_s": 1.0}) is None


def test_worker_plugin_threads_and_device(monkeypatch):
    """Per worker: LP_NUM_THREADS = cores / workers on the host (unless set or forced), and
    the EGL device = the worker's rank on its host modulo the devices there."""
    import catalog.batch.worker as worker
    import catalog.gl.context as context
    from catalog.batch.dask_engine import RendererPlugin

    class FakeWorker:
        def __init__(self, address):
            self.address = address

    ranks = {"tcp://10.0.0.1:4001": (0, 4), "tcp://10.0.0.1:4002": (1, 4),
             "tcp://10.0.0.1:4003": (2, 4), "tcp://10.0.0.1:4004": (3, 4)}
    cpus = len(os.sched_getaffinity(0))
    try:
        monkeypatch.setattr(context, "egl_device_count", lambda: 2)
        monkeypatch.delenv("CATALOG_EGL_DEVICE", raising=False)
        for address, (rank, _) in ranks.items():
            monkeypatch.delenv("LP_NUM_THREADS", raising=False)
            RendererPlugin(ranks).setup(FakeWorker(address))
            assert worker.process_pool().device_index == rank % 2
            assert os.environ["LP_NUM_THREADS"] == str(max(1, cpus // 4))
        monkeypatch.setattr(context, "egl_device_count", lambda: 1)  # one device: the default
        RendererPlugin(ranks).setup(FakeWorker("tcp://10.0.0.1:4002"))
        assert worker.process_pool().device_index is None
        monkeypatch.setenv("CATALOG_EGL_DEVICE", "3")
        monkeypatch.setenv("LP_NUM_THREADS", "5")
        RendererPlugin(ranks).setup(FakeWorker("tcp://10.0.0.9:1"))
        assert worker.process_pool().device_index == 3
        assert os.environ["LP_NUM_THREADS"] == "5"  # set by the cluster's owner: kept
        RendererPlugin(ranks, lp_threads=7).setup(FakeWorker("tcp://10.0.0.9:1"))
        assert os.environ["LP_NUM_THREADS"] == "7"  # --lp-threads forces it
    finally:
        worker.close_process_pool()
