"""Baked cloth animation for the web page (WebGL2 has no compute shaders for the simulation).

The project's cloth simulation (:mod:`catalog.cloth`, the numba backend) runs the desktop's
curtain -- the preset's *settled drape* (:mod:`catalog.cloth.drape`: fullness, pleats between
the rings, the drape ``catalog snapshot`` shows at frame 0), hung on the scene's rod -- in a
gentle gusty wind; after it settles, :data:`LOOP_S` seconds are sampled at :data:`BAKE_FPS`
and made to loop by cross-fading the last :data:`CROSSFADE_FRAMES` frames into the frames
just before the loop's start (so the last frame leads into the first). Normals and weft
tangents are recomputed from the blended grid by the project's mesh code.

Encoding (docs/web.md): per vertex, positions as uint16 steps of :data:`POSITION_STEP_M` above
the animation's bounding-box corner (error at most half a step, 0.05 mm). Each is stored as its
second difference in time (x[k] - 2 x[k-1] + x[k-2]: the residual of a constant-velocity
prediction; frame 0 as itself, frame 1 as its first difference), modulo 2^16 and zigzag-coded
(small negative residuals become small numbers); a frame's bytes are laid out in planes
(low bytes of every x, y, z, then the high bytes), then the whole is zlib-compressed, which
the page inflates with the browser's DecompressionStream. Normals and weft tangents are not
stored: decoder and page compute them from the decoded positions as the project's mesh code
does (:func:`catalog.cloth.mesh.grid_frames`: central differences, Gram-Schmidt;
:func:`frames_of_grid`), in float64, in the same order of operations. :func:`decode_frames` is the reference decoder; the page's
decoder (assets/app.js) must give the same float32 arrays.
"""

from __future__ import annotations

import base64
import hashlib
import zlib
from dataclasses import dataclass

import numpy as np

#: Sampling rate of the baked frames (the page interpolates between them), frames per second.
BAKE_FPS = 12
#: Length of the loop, s.
LOOP_S = 4.0
#: Frames at the loop's end blended into the frames before its start.
CROSSFADE_FRAMES = 12
#: Simulated time before the loop starts (the curtain settles into the wind), s.
SETTLE_S = 3.0
#: Mean wind from the window, m/s, and its gust strength (relative).
WIND_M_S = 0.6
GUST_STRENGTH = 0.6
#: uint16 positions: bytes per vertex and frame (normals and tangents are computed).
BYTES_PER_VERTEX = 6
#: Position quantum, m (0.1 mm: far below a pixel at any zoom the page allows).
POSITION_STEP_M = 1e-4


@dataclass(frozen=True)
class BakedAnimation:
    """An encoded looping animation and what is needed to decode it."""

    key: str                 # a hash of the cloth parameters (fabrics with equal ones share it)
    frames: int
    fps: float
    vertex_count: int
    indices: np.ndarray      # uint32 triangles (flat)
    uv: np.ndarray           # float32 (V, 2)
    offset_m: tuple[float, float, float]  # cloth frame -> scene
    lo_m: np.ndarray         # float64 (3,) bounding box low corner
    payload: bytes           # zlib of the shuffled, delta-coded frames
    fabric_size_m: tuple[float, float] = (0.0, 0.0)  # rest width, length (uv 0..1 spans them)
    rings_x_m: tuple[float, ...] = ()   # the rings on the rod, scene x (m)
    grid: tuple[int, int] = (0, 0)      # (columns, rows) of the particle grid (vertex order)

    def manifest(self) -> dict:
        return {"key": self.key, "frames": self.frames, "fps": self.fps,
                "vertex_count": self.vertex_count,
                "offset_m": list(self.offset_m),
                "fabric_size_m": [float(v) for v in self.fabric_size_m],
                "grid": [int(v) for v in self.grid],
                "rings_x_m": [float(v) for v in self.rings_x_m],
                "lo_m": [float(v) for v in self.lo_m], "step_m": POSITION_STEP_M,
                "index_count": int(self.indices.size),
                "encoded_bytes": len(self.payload),
                "raw_bytes": self.frames * self.vertex_count * BYTES_PER_VERTEX}

    def script(self) -> str:
        """The animation as a script the page loads with a <script> tag (file:// allows no
        fetch): registers base64 payload, indices and uvs under its key."""
        import json  # noqa: PLC0415

        def packed(raw: bytes) -> str:  # zlib, base64: the page inflates it
            return base64.b64encode(zlib.compress(raw, 9)).decode("ascii")

        data = {"manifest": self.manifest(),
                "payload": base64.b64encode(self.payload).decode("ascii"),
                "indices": packed(self.indices.astype("<u4").tobytes()),
                "uv": packed(self.uv.astype("<f4").tobytes())}
        return ("(window.CATALOG_ANIMATIONS = window.CATALOG_ANIMATIONS || {})"
                f"[{json.dumps(self.key)}] = {json.dumps(data)};\n")


def read_script(path) -> BakedAnimation:
    """The animation written by :meth:`BakedAnimation.script` (for tests and benchmarks)."""
    import json  # noqa: PLC0415
    from pathlib import Path  # noqa: PLC0415

    text = Path(path).read_text(encoding="utf-8")
    data = json.loads(text[text.index("] = ") + len("] = "):].rstrip().rstrip(";"))
    m = data["manifest"]
    return BakedAnimation(
        key=m["key"], frames=m["frames"], fps=m["fps"], vertex_count=m["vertex_count"],
        indices=np.frombuffer(zlib.decompress(base64.b64decode(data["indices"])), dtype="<u4"),
        uv=np.frombuffer(zlib.decompress(base64.b64decode(data["uv"])), dtype="<f4").reshape(-1, 2),
        offset_m=tuple(m["offset_m"]), lo_m=np.array(m["lo_m"], dtype=np.float64),
        payload=base64.b64decode(data["payload"]),
        fabric_size_m=tuple(m["fabric_size_m"]), rings_x_m=tuple(m["rings_x_m"]),
        grid=tuple(m["grid"]))


def cloth_key(params) -> str:
    text = repr(sorted((k, v) for k, v in vars(params).items() if k != "extra"))
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def bake_params(preset):
    """The cloth parameters of a preset's baked loop: the desktop's drape
    (:func:`catalog.cloth.drape.drape_params`) in the page's wind."""
    from catalog.cloth.drape import drape_params  # noqa: PLC0415

    return drape_params(preset).with_changes(wind_speed_m_s=WIND_M_S, gust_strength=GUST_STRENGTH)


def simulate_loop(params, fps: float = BAKE_FPS, loop_s: float = LOOP_S,
                  crossfade: int = CROSSFADE_FRAMES, settle_s: float = SETTLE_S):
    """(frames, H, W, 3) float64 grid positions of a seamless loop, cloth frame, metres:
    ``params`` (:func:`bake_params`) started from their settled drape, as every desktop
    simulation starts (:func:`catalog.cloth.drape.settled_simulation`)."""
    from catalog.cloth.drape import settled_simulation  # noqa: PLC0415

    simulation = settled_simulation(params, backend="cpu")
    dt = 1.0 / fps
    settle = int(round(settle_s * fps))
    loop = int(round(loop_s * fps))
    if settle < crossfade:
        raise ValueError("the settling time must cover the cross-fade")
    history = []
    for _ in range(settle + loop):
        simulation.step(dt)
        history.append(np.array(simulation.positions(), dtype=np.float64))
    if not simulation.finite:
        from catalog.core.errors import CatalogError  # noqa: PLC0415
        raise CatalogError("the cloth simulation diverged while baking the web animation")
    frames = np.stack(history[settle:])
    before = np.stack(history[settle - crossfade:settle])
    for j in range(crossfade):
        w = (j + 1) / crossfade  # the last frame is the one before the start: the seam is a step
        frames[loop - crossfade + j] = (1 - w) * frames[loop - crossfade + j] + w * before[j]
    return frames, params


def _zigzag(d: np.ndarray, bits: int) -> np.ndarray:
    """Signed residuals (taken modulo 2^bits) -> 0, -1, 1, -2, .. as 0, 1, 2, 3, .."""
    half, full = 1 << (bits - 1), 1 << bits
    d = (d + half) % full - half
    return ((d << 1) ^ (d >> (bits - 1))) & (full - 1)


def _unzigzag(z: np.ndarray) -> np.ndarray:
    return (z >> 1) ^ -(z & 1)


def _planes(x: np.ndarray) -> np.ndarray:
    """(F, V, 3) -> (F, 3 V): a frame's x of every vertex, then y, then z."""
    return x.transpose(0, 2, 1).reshape(x.shape[0], -1)


def encode(frames_p):
    """(lo_m, zlib payload) of (F, V, 3) float positions (m)."""
    lo = frames_p.reshape(-1, 3).min(axis=0)
    q = np.rint((frames_p - lo) / POSITION_STEP_M).astype(np.int64)
    if q.max() > 65535:
        from catalog.core.errors import CatalogError  # noqa: PLC0415
        raise CatalogError("the baked curtain spans more than 6.5 m: uint16 positions overflow")
    dp = q.copy()  # second differences: the residual of x[k-1] + (x[k-1] - x[k-2])
    dp[1:] = q[1:] - q[:-1]
    dp[2:] = q[2:] - 2 * q[1:-1] + q[:-2]
    zp = _planes(_zigzag(dp, 16))
    planes = np.concatenate([zp & 0xFF, zp >> 8], axis=1).astype("u1")
    return lo, zlib.compress(planes.tobytes(), 9)


def bake(preset, fps: float = BAKE_FPS, loop_s: float = LOOP_S) -> BakedAnimation:
    """Simulate and encode the looping curtain of a preset (its ``[cloth]`` table)."""
    from catalog.cloth.drape import rod_centre_x_m  # noqa: PLC0415
    from catalog.cloth.mesh import CurtainMesh  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415
    from catalog.render.snapshot import ring_xs_m  # noqa: PLC0415

    grids, params = simulate_loop(bake_params(preset), fps, loop_s)
    meshes = [CurtainMesh.from_grid(g, params) for g in grids]
    frames_p = np.stack([m.positions.astype(np.float64) for m in meshes])
    lo, payload = encode(frames_p)
    # the desktop's rod offset (catalog.render.snapshot.curtain_on_rod): rings centred on the window
    offset = (-rod_centre_x_m(params), scene_lib.CURTAIN_TOP_Y - params.rod_y_m,
              scene_lib.CURTAIN_Z)
    return BakedAnimation(key=cloth_key(params), frames=len(meshes), fps=float(fps),
                          vertex_count=meshes[0].positions.shape[0],
                          indices=meshes[0].indices.astype(np.uint32).ravel(),
                          uv=meshes[0].uv, offset_m=offset, lo_m=lo,
                          payload=payload, fabric_size_m=(params.width_m, params.height_m),
                          rings_x_m=tuple(ring_xs_m(preset)),
                          grid=(params.grid_w, params.grid_h))


def bake_apart(presets, on_baked=None) -> list[BakedAnimation]:
    """:func:`bake` of each preset, in order, in one child Python (this interpreter, this
    import path): the cloth simulation's compiled kernels (numba, about 190 MB) stay out of
    the caller, which renders the site's frames after. ``on_baked()``: called as each
    animation arrives (the progress). An error in the child is raised here (CatalogError);
    the child is ended if the caller stops."""
    import os  # noqa: PLC0415
    import pickle  # noqa: PLC0415
    import subprocess  # noqa: PLC0415
    import sys  # noqa: PLC0415

    from catalog.core.atomic import child_process  # noqa: PLC0415
    from catalog.core.errors import CatalogError  # noqa: PLC0415

    if not presets:
        return []
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    child = subprocess.Popen([sys.executable, "-c", "from catalog.web.bake import _bake_child; "
                              "_bake_child()"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             env=env)
    with child_process(child):
        try:
            pickle.dump(list(presets), child.stdin)
            child.stdin.close()
            animations = []
            for _ in presets:
                try:
                    kind, value = pickle.load(child.stdout)
                except EOFError:
                    raise CatalogError(f"the cloth bake's child process ended (exit "
                                       f"{child.wait()})") from None
                if kind == "error":
                    raise CatalogError(value)
                animations.append(value)
                if on_baked is not None:
                    on_baked()
            child.stdout.close()
            if child.wait() != 0:
                raise CatalogError(f"the cloth bake's child process failed (exit {child.returncode})")
            return animations
        finally:
            if child.poll() is None:
                child.kill()
                child.wait()


def _bake_child() -> None:
    """The child of :func:`bake_apart`: presets (pickled) on stdin; ("ok", animation) or
    ("error", message) on stdout, one per preset as it is baked."""
    import os  # noqa: PLC0415
    import pickle  # noqa: PLC0415
    import signal  # noqa: PLC0415
    import sys  # noqa: PLC0415

    from catalog.core.errors import CatalogError  # noqa: PLC0415

    # Ctrl-C reaches the whole terminal's process group: this child ends at once by the
    # default action (no traceback, nothing of its own to clean up; a Python handler would
    # wait for the bake's compiled loop to return), as it does on SIGTERM
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    presets = pickle.load(sys.stdin.buffer)
    out = sys.stdout.buffer
    for preset in presets:
        try:
            result = ("ok", bake(preset))
        except CatalogError as error:
            result = ("error", str(error))
        try:
            pickle.dump(result, out)
            out.flush()
        except BrokenPipeError:
            # the parent is gone (stopped by a signal): nobody reads the rest; end quietly,
            # stdout pointed at devnull so the interpreter's own flush at exit cannot fail
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            sys.exit(1)
        if result[0] == "error":
            return


def decode_frames(animation: BakedAnimation):
    """Every frame as the page builds it: float32 (F, V, 3) positions in the scene
    ((lo + q step) + offset, in float64, then rounded to float32), and the unit normals and
    weft tangents of :func:`catalog.cloth.mesh.grid_frames` of the float64 grid (lo + q step),
    rounded to float32."""
    f, v = animation.frames, animation.vertex_count
    cols, rows = animation.grid
    if cols * rows != v:
        from catalog.core.errors import CatalogError  # noqa: PLC0415
        raise CatalogError(f"baked loop {animation.key}: grid {cols}x{rows} is not {v} vertices")
    planes = np.frombuffer(zlib.decompress(animation.payload), dtype="u1").reshape(f, 6 * v)
    n = 3 * v
    dp = _unzigzag(planes[:, :n].astype(np.int64) | (planes[:, n:].astype(np.int64) << 8))
    dp = dp.reshape(f, 3, v).transpose(0, 2, 1)
    q = np.empty_like(dp)
    q[0] = dp[0] % 65536
    if f > 1:
        q[1] = (q[0] + dp[1]) % 65536
    for k in range(2, f):
        q[k] = (2 * q[k - 1] - q[k - 2] + dp[k]) % 65536
    cloth = np.asarray(animation.lo_m, dtype=np.float64) + q * POSITION_STEP_M
    offset = np.asarray(animation.offset_m, dtype=np.float64)
    positions = (cloth + offset).astype(np.float32)
    normals = np.empty((f, v, 3), dtype=np.float32)
    tangents = np.empty((f, v, 3), dtype=np.float32)
    for k in range(f):
        nk, tk = frames_of_grid(cloth[k].reshape(rows, cols, 3))
        normals[k] = nk.reshape(v, 3)
        tangents[k] = tk.reshape(v, 3)
    return positions, normals, tangents


def frames_of_grid(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`catalog.cloth.mesh.grid_frames` (unit normals and weft tangents of an (H, W, 3)
    float64 grid: central differences, one-sided at the edges; n = down x across; the tangent
    is across made orthogonal to n), with every sum written out left to right, the order in
    which the page's JavaScript evaluates them (numpy's reductions may associate otherwise), so
    that both give the same float64 values."""
    from catalog.cloth.backend_numpy import grid_differences  # noqa: PLC0415

    down, across = grid_differences(x)   # element-wise: no reduction whose order could differ
    d0, d1, d2 = down[..., 0], down[..., 1], down[..., 2]
    a0, a1, a2 = across[..., 0], across[..., 1], across[..., 2]
    n0, n1, n2 = d1 * a2 - d2 * a1, d2 * a0 - d0 * a2, d0 * a1 - d1 * a0
    length = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    length = np.where(length > 0.0, length, 1.0)
    n0, n1, n2 = n0 / length, n1 / length, n2 / length
    dot = a0 * n0 + a1 * n1 + a2 * n2
    t0, t1, t2 = a0 - dot * n0, a1 - dot * n1, a2 - dot * n2
    length = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    length = np.where(length > 0.0, length, 1.0)
    return np.stack([n0, n1, n2], axis=-1), np.stack([t0 / length, t1 / length, t2 / length], axis=-1)


def decode_frame(animation: BakedAnimation, frame: int):
    """Frame ``frame`` (wrapping) of :func:`decode_frames`: positions, normals, tangents."""
    positions, normals, tangents = decode_frames(animation)
    k = frame % animation.frames
    return positions[k], normals[k], tangents[k]
