"""Room transport convergence: the precomputed operator (catalog.room.transport) against
brute-force path tracing (catalog.room.brute_force) at probe points of the built-in rooms,
as each resolution rises (receivers uniform or refined where the light changes fast, window
patches, basis order, form-factor rays); the precompute's time and the cache's.

    python -m benchmarks.room_transport [--quick] [--rooms box,living,bedroom]
        [--sweeps element_m,adaptive,...] [--json-out FILE]

``--sweeps`` measures only those sweeps (``--sweeps none``: only the timing and the web
pack); the others are kept from the existing JSON, each sweep naming the commit it was
measured on.

The window sends a smooth, direction- and position-dependent radiance into the room (a
sky-like light, brighter travelling down, graded across the window: :func:`window_radiance`),
projected onto each configuration's patches and SH by quadrature (the captured views of the
aperture). The error is the relative RMS over the probes of the light map's irradiance
(luminance; catalog.room.lightmap, as the GL pass draws it, and ``flat``: the receiver's own
value) against the path tracer's; the reference's own noise is given beside it.
Writes benchmarks/bench_room_transport.json and docs/img/room_transport_convergence.png.
"""

from __future__ import annotations

import subprocess
import time
from dataclasses import replace

import numpy as np

from benchmarks.results import fmt
from catalog.room import sh

RESULT_JSON = "benchmarks/bench_room_transport.json"
FIGURE = "docs/img/room_transport_convergence.png"
LUMA = np.array([0.2126, 0.7152, 0.0722])
#: The sky-like window radiance (linear RGB, arbitrary units).
SKY_RGB = np.array([0.8, 0.9, 1.1])


def window_radiance(window):
    """L(x, w) (M, 3): exp(-1.2 w_y) (light from above is brighter) times 1 + 0.5 (s - 1/2)
    across the window's u edge (s in 0..1)."""
    u = window.u_edge / np.linalg.norm(window.u_edge) ** 2

    def radiance(x, w):
        s = (x - window.origin) @ u
        return (np.exp(-1.2 * w[:, 1]) * (1.0 + 0.5 * (s - 0.5)))[:, None] * SKY_RGB[None, :]

    return radiance


def project_window(transport, radiance, points_per_side: int = 4, n_theta: int = 10, n_phi: int = 20):
    """(P, K, 3) the window radiance's coefficients: per patch, the mean over a grid of
    points of the SH projection over a Gauss hemisphere quadrature (in the window's frame)."""
    from catalog.room.transport import patch_points  # noqa: PLC0415

    params = transport.params
    nu, nv = params.patches
    dirs_local, weights = sh.hemisphere_quadrature(n_theta, n_phi)
    dirs = dirs_local @ transport.frame                      # local -> world (rows of frame)
    g = (np.arange(points_per_side) + 0.5) / points_per_side
    ss, tt = [a.ravel() for a in np.meshgrid(g, g)]
    out = np.zeros((nu * nv, sh.basis_count(params.order), 3))
    for p in range(nu * nv):
        x, _ = patch_points(transport.window, params.patches, ss, tt, np.full(ss.size, p))
        xx = np.repeat(x, dirs.shape[0], axis=0)
        ww = np.tile(dirs, (x.shape[0], 1))
        values = radiance(xx, ww).reshape(x.shape[0], dirs.shape[0], 3).mean(axis=0)
        out[p] = sh.project(dirs_local, weights, values, params.order)
    return out


def _commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def sweeps(quick: bool) -> dict:
    from catalog.room.transport import TransportParams  # noqa: PLC0415

    base = TransportParams(element_m=0.3, patches=(4, 4), order=3, gather_rays=256, window_samples=4,
                           refine_levels=0)
    adaptive = replace(base, element_m=TransportParams().element_m, refine_levels=TransportParams().refine_levels,
                       refine_tolerance=TransportParams().refine_tolerance)
    if quick:
        return {"element_m": [replace(base, element_m=v) for v in (0.6, 0.3)],
                "adaptive": [replace(adaptive, max_receivers=v) for v in (2500, 4000)],
                "order": [replace(base, order=v) for v in (1, 3)]}
    return {
        "element_m": [replace(base, element_m=v) for v in (0.8, 0.5, 0.35, 0.25)],
        "adaptive": [replace(adaptive, max_receivers=v) for v in (2000, 3500, 5000, 6500)],
        "patches": [replace(base, patches=(v, v)) for v in (1, 2, 4, 8)],
        "order": [replace(base, order=v) for v in (1, 2, 3, 4)],
        "gather_rays": [replace(base, gather_rays=v) for v in (16, 64, 256, 1024)],
    }


def run_room(name: str, quick: bool, probes: int, paths: int, only=None, commit: str = "unknown") -> dict:
    from catalog.room import brute_force, lightmap  # noqa: PLC0415
    from catalog.room.load import load_room  # noqa: PLC0415
    from catalog.room.transport import precompute  # noqa: PLC0415

    if only is not None and not set(only) & set(sweeps(quick)):
        return {"room": name, "sweeps": {}, "sweep_commits": {}}          # nothing to measure here
    room = load_room(name)
    rng = np.random.default_rng(11)
    radiance = window_radiance(room.window)
    points, normals, tris = brute_force.probe_points(room, probes, rng)
    start = time.perf_counter()
    e_ref, e_err = brute_force.irradiance(room, radiance, points, normals, paths, rng)
    reference_s = time.perf_counter() - start
    y_ref = e_ref @ LUMA
    scale = float(np.mean(y_ref))
    noise = float(np.sqrt(np.mean((e_err @ LUMA) ** 2)) / scale)
    rows = {}
    for sweep, configs in sweeps(quick).items():
        if only is not None and sweep not in only:
            continue
        rows[sweep] = []
        for params in configs:
            start = time.perf_counter()
            t = precompute(room, params, compress_operators=False)
            seconds = time.perf_counter() - start
            which = t.receiver_at(tris, points)
            ok = which >= 0
            e = t.irradiance(project_window(t, radiance), compressed=False)
            y = lightmap.irradiance_at(t, lightmap.corner_irradiance(t, e), which[ok], points[ok]) @ LUMA
            y_flat = e[which[ok]] @ LUMA
            err = float(np.sqrt(np.mean((y - y_ref[ok]) ** 2)) / scale)
            err_flat = float(np.sqrt(np.mean((y_flat - y_ref[ok]) ** 2)) / scale)
            value = {"patches": params.patches[0], "adaptive": params.max_receivers}.get(sweep)
            value = getattr(params, sweep) if value is None else value
            rows[sweep].append({"value": value, "rel_rms_error": err, "rel_rms_error_flat": err_flat,
                                "receivers": t.receivers.count,
                                "probes_used": int(ok.sum()), "precompute_s": seconds,
                                "refinement": t.timings_s.get("refinement")})
            print(f"{name:7s} {sweep:11s} {value!s:6s} error {err:.4f} (flat {err_flat:.4f})  receivers {t.receivers.count:5d}"
                  f"  {seconds:6.1f} s", flush=True)
    return {"room": name, "probes": probes, "paths_per_probe": paths, "reference_noise": noise,
            "reference_s": reference_s, "sweeps": rows, "sweep_commits": {k: commit for k in rows}}


def timing(name: str) -> dict:
    """The default precompute of a room (compressed, as the frame will use it) and the
    cache: its first call computes and stores, the second reads."""
    import os  # noqa: PLC0415
    import tempfile  # noqa: PLC0415

    from catalog.room.cache import room_transport  # noqa: PLC0415
    from catalog.room.load import load_room  # noqa: PLC0415
    from catalog.room.transport import TransportParams  # noqa: PLC0415

    room = load_room(name)
    with tempfile.TemporaryDirectory() as tmp:
        old = os.environ.get("CATALOG_CACHE")
        os.environ["CATALOG_CACHE"] = tmp
        try:
            start = time.perf_counter()
            first = room_transport(room, TransportParams())
            compute_s = time.perf_counter() - start
            start = time.perf_counter()
            room_transport(room, TransportParams())
            load_s = time.perf_counter() - start
            size = sum(f.stat().st_size for f in (os.scandir(os.path.join(tmp, "room_transport"))))
        finally:
            if old is None:
                os.environ.pop("CATALOG_CACHE")
            else:
                os.environ["CATALOG_CACHE"] = old
    from catalog.room import web_pack  # noqa: PLC0415

    webs = []
    for tolerance in WEB_TOLERANCES:
        start = time.perf_counter()
        web = web_pack.pack(first, window_tolerance=tolerance, bounce_tolerance=tolerance)
        webs.append({"bytes": web.nbytes(), "errors": web.errors, "pack_s": time.perf_counter() - start,
                     "window_tolerance": tolerance, "bounce_tolerance": tolerance})
    stages = {k: v for k, v in first.timings_s.items() if k not in ("from_cache", "refinement")}
    compressed = (first.window_basis.size + first.window_modes.size + first.bounce_left.size
                  + first.bounce_right.size + first.form_factors.nnz * 2) * 4
    return {"room": name, "params": TransportParams().key(), "receivers": first.receivers.count,
            "precompute_s": compute_s, "stages": stages, "cache_load_s": load_s,
            "cache_file_bytes": size, "compressed_float32_bytes": compressed,
            "refinement": first.timings_s.get("refinement"),
            "web": webs}


def run(quick: bool = False, rooms=("box", "living", "bedroom"), only=None, previous=None) -> dict:
    """The study; with ``only`` (sweep names) the other sweeps of each room come from
    ``previous`` (the JSON before) when it has them, with their commit."""
    result = {"commit": _commit(), "rooms": [], "timing": []}
    old = {r["room"]: r for r in (previous or {}).get("rooms", [])}
    for name in rooms:
        room = run_room(name, quick, probes=48 if quick else 96, paths=2048 if quick else 16384, only=only,
                        commit=result["commit"])
        if only is not None and name in old:
            before = old[name]
            for key in ("probes", "paths_per_probe", "reference_noise", "reference_s"):
                room.setdefault(key, before.get(key))
            for sweep, rows in before["sweeps"].items():
                if sweep not in room["sweeps"]:
                    room["sweeps"][sweep] = rows
                    room["sweep_commits"][sweep] = before.get("sweep_commits", {}).get(sweep, previous["commit"])
        result["rooms"].append(room)
    for name in rooms:
        result["timing"].append(timing(name))
        print(f"{name}: precompute {result['timing'][-1]['precompute_s']:.1f} s, cache load "
              f"{result['timing'][-1]['cache_load_s']:.2f} s", flush=True)
    return result


#: The web pack's error bounds (window and later bounces alike).
WEB_TOLERANCES = (1e-2, 3e-2, 1e-1)
SWEEP_ORDER = ("element_m", "adaptive", "patches", "order", "gather_rays")


def markdown_tables(result: dict) -> dict:
    lines = ["| room | resolution | value | receivers | rel. RMS error | flat | reference noise | commit |",
             "|---|---|---|---|---|---|---|---|"]
    for room in result["rooms"]:
        for sweep in SWEEP_ORDER:
            for row in room["sweeps"].get(sweep, []):
                lines.append(f"| {room['room']} | {sweep} | {row['value']} | {row['receivers']} | "
                             f"{fmt(row['rel_rms_error'])} | {fmt(row['rel_rms_error_flat'])} | "
                             f"{fmt(room['reference_noise'])} | "
                             f"{room.get('sweep_commits', {}).get(sweep, result['commit'])} |")
    timing = ["| room | receivers | precompute s | stages | cache load s | cache MB | compressed MB |",
              "|---|---|---|---|---|---|---|"]
    for t in result["timing"]:
        stages = ", ".join(f"{k} {fmt(v)}" for k, v in t["stages"].items() if k.endswith("_s"))
        timing.append(f"| {t['room']} | {t['receivers']} | {fmt(t['precompute_s'])} | {stages} | "
                      f"{fmt(t['cache_load_s'])} | {fmt(t['cache_file_bytes'] / 1e6)} | "
                      f"{fmt(t['compressed_float32_bytes'] / 1e6)} |")
    web = ["| room | receivers | bound | window modes (Frobenius share) | window MB | first bounce MB "
           "| later bounces MB | total MB | window error | beam-bounce error (transport's own) |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for t in result["timing"]:
        for w in t.get("web", []):
            b, e = w["bytes"], w["errors"]
            web.append(f"| {t['room']} | {t['receivers']} | {fmt(w['window_tolerance'])} | "
                       f"{e['window_rank']} ({fmt(e['window_rank_bound'])}) | "
                       f"{fmt(b['window'] / 1e6)} | {fmt(b['first_bounce'] / 1e6)} | {fmt(b['later_bounces'] / 1e6)} | "
                       f"{fmt(b['total'] / 1e6)} | {fmt(e['window_rel_rms'])} | {fmt(e['bounce_rel_rms'])} "
                       f"({fmt(e['bounce_rel_rms_transport'])}) |")
    return {"room_transport_convergence": "\n".join(lines), "room_transport_timing": "\n".join(timing),
            "room_transport_web": "\n".join(web)}


def plot(result: dict, path) -> None:
    """First panel: error against the receiver count, uniform (solid) and refined (dashed);
    then one panel per other sweep."""
    from benchmarks.plots import pyplot, save_figure  # noqa: PLC0415
    from matplotlib.ticker import NullFormatter, ScalarFormatter  # noqa: PLC0415

    plt = pyplot()
    others = [s for s in SWEEP_ORDER[2:] if any(s in r["sweeps"] for r in result["rooms"])]
    fig, axes = plt.subplots(1, 1 + len(others), figsize=(3.4 * (1 + len(others)), 3.1), squeeze=False,
                             sharey=True)
    labels = {"patches": "window patches per side", "order": "basis order",
              "gather_rays": "form-factor rays per receiver"}
    ax = axes[0][0]
    colours = {}
    for room in result["rooms"]:
        for sweep, style, tag in (("element_m", "o-", "uniform"), ("adaptive", "s--", "refined")):
            rows = room["sweeps"].get(sweep, [])
            if rows:
                line, = ax.plot([r["receivers"] for r in rows], [r["rel_rms_error"] for r in rows], style,
                                color=colours.get(room["room"]), label=f"{room['room']} {tag}")
                colours[room["room"]] = line.get_color()
        ax.axhline(room["reference_noise"], color=colours.get(room["room"]), ls=":", lw=0.8)
    ax.set_xlabel("receivers")
    ax.legend(fontsize=6)
    for ax, sweep in zip(axes[0][1:], others):
        for room in result["rooms"]:
            rows = room["sweeps"].get(sweep, [])
            if rows:
                ax.plot([r["value"] for r in rows], [r["rel_rms_error"] for r in rows], "o-",
                        color=colours.get(room["room"]), label=room["room"])
                ax.axhline(room["reference_noise"], color=colours.get(room["room"]), ls=":", lw=0.8)
        ax.set_xticks([r["value"] for r in next(r for r in result["rooms"] if sweep in r["sweeps"])["sweeps"][sweep]])
        ax.set_xlabel(labels.get(sweep, sweep))
    for ax in axes[0]:
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_formatter(ScalarFormatter())
            axis.set_minor_formatter(NullFormatter())
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_yticks([0.02, 0.05, 0.1, 0.2, 0.5])
    axes[0][0].set_ylabel("relative RMS error vs path tracer")
    fig.suptitle(f"room transport convergence (dotted: reference noise), commit {result['commit']} "
                 "(other sweeps: their commit in the JSON)", fontsize=8)
    save_figure(fig, path)


def main(argv=None) -> int:
    from benchmarks.results import study_main  # noqa: PLC0415
    from catalog.core.resources import PROJECT_ROOT  # noqa: PLC0415
    import sys  # noqa: PLC0415

    module = sys.modules[__name__]

    def add_arguments(parser):
        parser.add_argument("--quick", action="store_true", help="two sweeps, fewer probes and paths")
        parser.add_argument("--rooms", default="box,living,bedroom", help="built-in rooms, comma-separated")
        parser.add_argument("--sweeps", default=None,
                            help="measure only these sweeps (comma-separated); keep the others from the JSON")

    def make_result(args):
        import json  # noqa: PLC0415

        only = None if args.sweeps is None else tuple(args.sweeps.split(","))
        previous = json.loads(args.json_out.read_text()) if only and args.json_out.is_file() else None
        result = run(quick=args.quick, rooms=tuple(args.rooms.split(",")), only=only, previous=previous)
        plot(result, PROJECT_ROOT / FIGURE)
        return result

    return study_main(module, argv, make_result=make_result, add_arguments=add_arguments)


if __name__ == "__main__":
    raise SystemExit(main())
