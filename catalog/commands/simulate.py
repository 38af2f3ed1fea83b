"""``catalog simulate``: run the curtain simulation headless and report on it."""

from __future__ import annotations

import argparse

RESOURCES = ("fabrics",)
#: Options read and written (checked before the work by catalog.commands.cli.check_outputs).
INPUT_FILES = ("fabric",)
OUTPUT_FILES = ("out",)
HELP = "simulate a curtain (mass-spring cloth) headless; report stretch, energy and speed"

#: ClothParams field -> the option that sets it (for error messages)
_OPTION_OF_FIELD = {
    "grid_w": "--grid", "grid_h": "--grid", "stretch_stiffness_n_m": "--stiffness",
    "wind_speed_m_s": "--wind", "dt": "--dt", "opening": "--opening",
}


#: Limits of the options (beyond them a run cannot finish or the physics is meaningless):
#: frames in one run; wind, m/s (50 m/s is a hurricane, not a breeze at a window);
#: particles along a side (1024^2 particles already take minutes a second on a CPU).
MAX_STEPS = 10_000_000
MAX_WIND_M_S = 50.0
MAX_GRID_SIDE = 1024


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--grid", required=True, metavar="WxH",
                        help="particles across and down, e.g. 64x96")
    from catalog.core.cliargs import number_type  # noqa: PLC0415
    from catalog.core.constants import FRAME_DT_S  # noqa: PLC0415

    parser.add_argument("--steps", required=True, type=number_type(1, MAX_STEPS, whole=True),
                        metavar="N",
                        help="frames to simulate")
    parser.add_argument("--dt", type=float, default=FRAME_DT_S, metavar="S",
                        help="frame time in seconds (substeps are chosen inside; default 1/60)")
    parser.add_argument("--stiffness", type=float, default=None, metavar="K",
                        help="stretch stiffness, N/m (default: the fabric's or the weave's)")
    parser.add_argument("--wind", type=number_type(0.0, MAX_WIND_M_S, unit="m/s"), default=0.0,
                        metavar="SPEED",
                        help="mean wind speed from the window, m/s (gusty)")
    parser.add_argument("--opening", type=float, default=None, metavar="F",
                        help="fraction of the rest width the rings span (1 = closed)")
    parser.add_argument("--fabric", default=None, metavar="NAME_OR_TOML",
                        help="take areal density and stiffness from a preset's [cloth] table")
    parser.add_argument("--backend", choices=("numpy", "cpu", "gpu"), default="cpu",
                        help="numpy (reference), cpu (numba), gpu (GLSL compute)")
    parser.add_argument("--out", default=None, metavar="FILE",
                        help="write the last frame (.obj, .ply, .glb), or every frame if "
                             "FILE has a {frame} field, e.g. out/c_{frame:04d}.ply")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def _parse_grid(text: str) -> tuple[int, int]:
    from catalog.core.cliargs import parse_wxh

    return parse_wxh(text, "--grid", 2, MAX_GRID_SIDE, unit="particles", example="64x96")


def run(args: argparse.Namespace) -> int:
    import contextlib
    import math
    import time

    from catalog.core.errors import CatalogError, InputError

    w, h = _parse_grid(args.grid)
    if args.out is not None and "{" in args.out:
        from catalog.core.validate import check_frame_template

        check_frame_template(args.out, "--out")  # before the simulation is built
    if args.steps < 1:
        raise CatalogError(f"--steps: must be >= 1, found {args.steps}")
    if not math.isfinite(args.dt) or not 0.0 < args.dt <= 1.0:
        raise CatalogError(f"--dt: must be a frame time in (0, 1] s, found {args.dt}")
    if not math.isfinite(args.wind) or args.wind < 0:
        raise CatalogError(f"--wind: must be a finite speed >= 0 m/s, found {args.wind}")
    if args.stiffness is not None and (not math.isfinite(args.stiffness)
                                       or args.stiffness <= 0):
        raise CatalogError(f"--stiffness: must be a finite stiffness > 0 N/m, "
                           f"found {args.stiffness}")

    from catalog.cloth import ClothParams, ClothSimulation
    from catalog.cloth.mesh import export_mesh

    overrides: dict = {"grid_w": w, "grid_h": h, "wind_speed_m_s": args.wind}
    if args.stiffness is not None:
        overrides["stretch_stiffness_n_m"] = args.stiffness
    if args.opening is not None:
        overrides["opening"] = args.opening
    try:
        if args.fabric:
            from catalog.presets import find_preset, load_preset
            params = ClothParams.from_preset(load_preset(find_preset(args.fabric)), **overrides)
        else:
            params = ClothParams(**overrides)
        if args.backend == "cpu":  # compile (or load the cached code) outside the timing
            from catalog.cloth.simulation import warm_up_numba
            warm_up_numba()
        sim = ClothSimulation(params, args.backend, monitor_every=1)
    except InputError as exc:
        option = _OPTION_OF_FIELD.get(exc.field or "")
        if option and exc.path is None:
            raise CatalogError(f"{option}: {exc.problem}") from None
        raise

    sequence = args.out is not None and "{frame" in args.out
    simulated = 0
    with contextlib.ExitStack() as stack:
        if sequence:
            # every frame's file, or none: staged beside the folder, moved in at the end
            from pathlib import Path

            from catalog.core.atomic import staged_folder

            try:
                names = [Path(args.out.format(frame=f)) for f in (0, 1)]
            except (ValueError, KeyError, IndexError) as exc:
                raise CatalogError(f"--out: {args.out!r} is not a pattern with one "
                                   f"{{frame}} field ({exc})") from None
            if names[0].parent != names[1].parent or names[0] == names[1]:
                raise CatalogError(f"--out: {args.out!r}: put {{frame}} in the file name, "
                                   "not in a folder name")
            stage = stack.enter_context(staged_folder(names[0].parent))
        start = time.perf_counter()
        for frame in range(args.steps):
            simulated += bool(sim.step(args.dt))
            if sequence:
                export_mesh(sim.mesh(), stage / Path(args.out.format(frame=frame)).name)
        seconds = time.perf_counter() - start
    if args.out is not None and not sequence:
        export_mesh(sim.mesh(), args.out)

    result = {
        "steps": args.steps,
        "dt": args.dt,
        "substeps": params.substeps_for(args.dt),
        "finite": sim.finite,
        "max_stretch": sim.state.max_stretch_seen if sim.finite else math.inf,
        "kinetic_energy": sim.kinetic_energy,
        "steps_per_second": args.steps / seconds if seconds > 0 else math.inf,
        "backend": args.backend,
        "grid": [w, h],
        "stretch_stiffness_n_m": params.stretch_stiffness_n_m,
        "wind_m_s": params.wind_speed_m_s,
        "steps_simulated": simulated,
        "sleeping": sim.sleeping,
        "final_max_stretch": sim.max_stretch,
        "seconds": seconds,
    }
    if args.json:
        from catalog.core.jsonout import print_json
        print_json(result)
    else:
        for key, value in result.items():
            print(f"{key:>20}: {value}")
    return 0 if sim.finite else 1
