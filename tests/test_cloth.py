"""Cloth simulation: parameters, topology, numpy/numba agreement, stress, sleep, mesh.

The numpy backend is the float64 reference; the numba (``cpu``) backend runs the same
algorithm and must follow it to rounding. Physical invariants are checked on both:
energy never above what gravity can release, the strain limit, the wall and floor.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.cloth import ClothParams, ClothSimulation, curtain_mesh
from catalog.cloth.simulation import kinetic_energy_j, max_spring_strain
from catalog.cloth.state import attachments, rest_pose, ring_columns, ring_positions
from catalog.cloth.topology import (COLOUR_COUNT, FAMILIES, GATHER_OFFSETS, SELECTORS,
                                    rest_lengths_m, spring_pairs, triangle_indices)
from catalog.core.errors import InputError

STRAIN_SLACK = 1e-3  # the adaptive sweeps stop at 5e-4 over the limit; collisions nudge


# ---- parameters -----------------------------------------------------------------------

@pytest.mark.parametrize("changes, field", [
    ({"areal_density_kg_m2": -0.1}, "areal_density_kg_m2"),   # negative mass
    ({"areal_density_kg_m2": 0.0}, "areal_density_kg_m2"),
    ({"grid_w": 0}, "grid_w"),                                  # zero grid
    ({"grid_h": 1}, "grid_h"),
    ({"grid_w": 3.5}, "grid_w"),
    ({"wind_speed_m_s": math.nan}, "wind_speed_m_s"),           # NaN wind
    ({"wind_speed_m_s": -1.0}, "wind_speed_m_s"),
    ({"wind_direction": (0.0, 0.0, 0.0)}, "wind_direction"),
    ({"wind_direction": (0.0, math.inf, 1.0)}, "wind_direction"),
    ({"stretch_stiffness_n_m": 0.0}, "stretch_stiffness_n_m"),
    ({"bend_stiffness_n_m": -1.0}, "bend_stiffness_n_m"),
    ({"opening": 0.0}, "opening"),
    ({"opening": 1.5}, "opening"),
    ({"max_stretch": -0.1}, "max_stretch"),
    ({"contact_damping_per_s": -2.0}, "contact_damping_per_s"),
    ({"wall_gap_m": 0.001}, "wall_gap_m"),
    ({"max_substep_s": 0.0}, "max_substep_s"),
])
def test_bad_parameters_are_refused_naming_the_field(changes, field):
    with pytest.raises(InputError) as info:
        ClothParams(**changes)
    assert info.value.field == field
    assert field in str(info.value)


def test_frame_time_is_validated_and_substeps_ignore_stiffness():
    soft = ClothParams(stretch_stiffness_n_m=1e1)
    stiff = ClothParams(stretch_stiffness_n_m=1e6)
    for dt in (1 / 60, 1 / 30, 1 / 15):
        assert soft.substeps_for(dt) == stiff.substeps_for(dt) == math.ceil(dt / (1 / 600) - 1e-9)
    with pytest.raises(InputError, match="dt"):
        soft.substeps_for(math.nan)
    with pytest.raises(InputError, match="dt"):
        soft.substeps_for(0.0)


def test_preset_cloth_table_and_weave_defaults():
    class FakePreset:  # the one method ClothParams.from_preset uses
        path = "fabrics/x.toml"

        def __init__(self, table):
            self._table = table

        def table(self, key):
            return self._table if key == "cloth" else {}

    params = ClothParams.from_preset(FakePreset({"weave": "voile", "bend_stiffness_n_m": 0.1}),
                                     grid_w=8, grid_h=8)
    assert params.areal_density_kg_m2 == 0.05  # voile default
    assert params.bend_stiffness_n_m == 0.1  # from the table
    with pytest.raises(InputError, match=r"x\.toml: cloth\.weave"):
        ClothParams.from_preset(FakePreset({"weave": "knit"}))
    with pytest.raises(InputError, match=r"x\.toml: cloth\.areal_density_kg_m2"):
        ClothParams.from_preset(FakePreset({"areal_density_kg_m2": -1.0}))


def test_square_grid_spring_stiffness_is_the_membrane_stiffness():
    p = ClothParams(grid_w=11, grid_h=11, width_m=1.0, height_m=1.0,
                    stretch_stiffness_n_m=123.0)
    k = p.spring_stiffness_n_m()
    assert k["horizontal"] == pytest.approx(123.0) and k["vertical"] == pytest.approx(123.0)
    assert p.particle_mass_kg == pytest.approx(p.areal_density_kg_m2 * 0.01)


# ---- topology -------------------------------------------------------------------------

@pytest.mark.parametrize("w, h", [(2, 2), (3, 5), (7, 4), (10, 9)])
def test_selectors_visit_every_spring_once_and_colours_never_share_a_particle(w, h):
    a_all, b_all, fam_all = spring_pairs(w, h)
    # closed-form counts per family
    expected = {"horizontal": h * (w - 1), "vertical": (h - 1) * w,
                "diagonal": (h - 1) * (w - 1), "antidiagonal": (h - 1) * (w - 1),
                "bend_h": h * max(w - 2, 0), "bend_v": max(h - 2, 0) * w}
    for family, (name, *_rest) in enumerate(FAMILIES):
        assert np.sum(fam_all == family) == expected[name]
    seen = []
    by_colour: dict[int, list[int]] = {}
    for sel in SELECTORS:
        rows, cols = sel.ranges(w, h)
        for r in rows:
            for c in cols:
                a, b = r * w + c, (r + sel.di) * w + c + sel.dj
                seen.append((sel.family, a, b))
                by_colour.setdefault(sel.colour, []).extend([a, b])
    assert sorted(seen) == sorted(zip(fam_all.tolist(), a_all.tolist(), b_all.tolist()))
    for particles in by_colour.values():
        assert len(particles) == len(set(particles))
    assert COLOUR_COUNT == 12


def test_inner_particles_have_twelve_springs():
    a, b, _ = spring_pairs(9, 9)
    degree = np.bincount(np.concatenate([a, b]), minlength=81).reshape(9, 9)
    assert np.all(degree[2:-2, 2:-2] == 12) and len(GATHER_OFFSETS) == 12


def test_rest_pose_is_unstretched_and_within_its_attachments():
    for opening in (1.0, 0.7, 0.3):
        p = ClothParams(grid_w=23, grid_h=17, opening=opening)
        x = rest_pose(p)
        assert max_spring_strain(x, p) < 1e-12  # pleats keep the rest lengths along the V
        ring_index, limit = attachments(p)
        dist = np.linalg.norm(x - ring_positions(p)[ring_index], axis=-1)
        assert np.all(dist <= limit + 1e-12)
        np.testing.assert_allclose(x[0, ring_columns(p)], ring_positions(p))
        assert np.all(x[..., 2] > -p.wall_gap_m)


# ---- backends agree -------------------------------------------------------------------

def _params(**changes):
    base = dict(grid_w=14, grid_h=18, opening=0.7, wind_speed_m_s=1.5)
    base.update(changes)
    return ClothParams(**base)


@pytest.mark.slow
def test_numba_follows_the_numpy_reference_for_one_second():
    params = _params()
    ref = ClothSimulation(params, "numpy")
    fast = ClothSimulation(params, "cpu")
    for _ in range(60):
        ref.step(1 / 60)
        fast.step(1 / 60)
    moved = np.abs(ref.positions() - rest_pose(params)).max()
    assert moved > 0.01  # something happened
    np.testing.assert_allclose(fast.positions(), ref.positions(), rtol=0, atol=1e-8)
    np.testing.assert_allclose(fast.velocities(), ref.velocities(), rtol=0, atol=1e-6)
    assert fast.max_stretch == pytest.approx(ref.max_stretch, abs=1e-9)


@pytest.mark.slow
def test_rings_slide_to_a_new_opening_and_both_backends_agree():
    params = _params(wind_speed_m_s=0.0, opening=1.0, ring_speed_m_s=2.0)
    sims = [ClothSimulation(params, b) for b in ("numpy", "cpu")]
    for sim in sims:
        sim.set_opening(0.5)
        sim.run(45, 1 / 30)
        rings = sim.positions()[0, ring_columns(params)]
        np.testing.assert_allclose(rings, ring_positions(params, 0.5), atol=1e-12)
    np.testing.assert_allclose(sims[0].positions(), sims[1].positions(), atol=1e-8)


# ---- stress ---------------------------------------------------------------------------

def _energy_bound_j(p: ClothParams) -> float:
    """Gravity can release at most m g (rod height) per particle; wind is off."""
    return p.particle_count * p.particle_mass_kg * p.gravity_m_s2 * p.rod_y_m


@pytest.mark.parametrize("stiffness", [1e1, 1e3, 1e6])
@pytest.mark.parametrize("dt", [1 / 60, 1 / 30, 1 / 15])
@pytest.mark.slow
def test_no_wind_energy_bounded_stretch_limited(stiffness, dt):
    p = ClothParams(grid_w=10, grid_h=12, opening=0.6, stretch_stiffness_n_m=stiffness)
    sim = ClothSimulation(p, "cpu")
    bound = _energy_bound_j(p)
    for _ in range(int(2.0 / dt)):
        sim.step(dt)
        assert sim.finite
        assert sim.kinetic_energy < bound
        assert sim.max_stretch <= p.max_stretch + STRAIN_SLACK


@pytest.mark.parametrize("stiffness", [1e1, 1e6])
@pytest.mark.slow
def test_gusty_wind_stays_finite_and_limited(stiffness):
    p = ClothParams(grid_w=16, grid_h=20, opening=0.8, stretch_stiffness_n_m=stiffness,
                    wind_speed_m_s=1.0)
    sim = ClothSimulation(p, "cpu")
    for _ in range(90):
        sim.step(1 / 30)
        assert sim.max_stretch <= p.max_stretch + STRAIN_SLACK
    assert sim.finite and sim.kinetic_energy > 0.0 and not sim.sleeping


@pytest.mark.slow
def test_hundred_thousand_steps_stay_finite():
    p = ClothParams(grid_w=4, grid_h=4, wind_speed_m_s=2.0, stretch_stiffness_n_m=1e6)
    sim = ClothSimulation(p, "cpu", monitor_every=1000)
    sim.run(100_000, 1 / 60)
    assert sim.state.frames == 100_000
    assert sim.finite and np.isfinite(sim.positions()).all()
    assert sim.state.max_stretch_seen <= p.max_stretch + STRAIN_SLACK


@pytest.mark.parametrize("w, h, frames", [(4, 4, 60), (64, 64, 4), (256, 256, 1)])
@pytest.mark.slow
def test_grid_sizes(w, h, frames):
    p = ClothParams(grid_w=w, grid_h=h, opening=0.7, stretch_stiffness_n_m=1e6,
                    wind_speed_m_s=1.0)
    sim = ClothSimulation(p, "cpu")
    for _ in range(frames):
        sim.step(1 / 15)
        assert sim.finite
        assert sim.max_stretch <= p.max_stretch + STRAIN_SLACK


@pytest.mark.slow
def test_wall_and_floor_are_never_crossed():
    # wind blowing into the wall, and a curtain longer than the rod is high
    p = ClothParams(grid_w=12, grid_h=16, height_m=2.6, rod_height_m=2.2,
                    wind_speed_m_s=4.0, wind_direction=(0.0, 0.0, -1.0), gust_strength=0.0)
    sim = ClothSimulation(p, "cpu")
    lowest_wall = lowest_floor = math.inf
    for _ in range(120):
        sim.step(1 / 30)
        x = sim.positions()
        lowest_wall = min(lowest_wall, float(x[..., 2].min()))
        lowest_floor = min(lowest_floor, float(x[..., 1].min()))
    assert lowest_wall >= -p.wall_gap_m + p.thickness_m - 1e-12
    assert lowest_floor >= p.thickness_m - 1e-12
    assert lowest_wall < -p.wall_gap_m + 2 * p.thickness_m  # it did reach the wall
    assert lowest_floor < 2 * p.thickness_m  # and the floor
    assert sim.finite


# ---- sleep ----------------------------------------------------------------------------

@pytest.mark.slow
def test_sleeps_at_rest_and_wakes_on_change():
    p = ClothParams(grid_w=12, grid_h=12, opening=1.0, sleep_hold_s=1 / 3)
    sim = ClothSimulation(p, "cpu")
    simulated = sim.run(600, 1 / 30)
    assert sim.sleeping and simulated < 600
    before = sim.positions().copy()
    assert sim.step(1 / 30) is False  # asleep: nothing happens
    np.testing.assert_array_equal(sim.positions(), before)
    sim.set_wind(1.0)
    assert not sim.sleeping and sim.step(1 / 30) is True
    sim.run(30, 1 / 30)
    assert np.abs(sim.positions() - before).max() > 1e-3  # the wind moved it
    sim.set_wind(0.0)
    sim.set_opening(0.6)  # rings move: awake until they arrive and the cloth settles
    assert not sim.sleeping


def test_sleep_hysteresis():
    """A calm spell starts under both thresholds, survives a speed between the sleep and the
    wake threshold, ends above the wake one, with wind or with moving rings; it counts
    simulated time."""
    from catalog.cloth.simulation import calm_spell_s

    p = ClothParams(sleep_speed_m_s=5e-3, sleep_rms_speed_m_s=1e-3, wake_factor=2.0)
    assert calm_spell_s(-1.0, 4e-3, 5e-4, True, 0.1, p) == 0.0          # starts
    assert calm_spell_s(-1.0, 6e-3, 5e-4, True, 0.1, p) == -1.0         # not yet calm
    assert calm_spell_s(-1.0, 4e-3, 1.5e-3, True, 0.1, p) == -1.0       # RMS (energy) too high
    assert calm_spell_s(0.2, 9e-3, 1.9e-3, True, 0.1, p) == pytest.approx(0.3)  # between: lasts
    assert calm_spell_s(0.2, 1.1e-2, 5e-4, True, 0.1, p) == -1.0        # above wake: ends
    assert calm_spell_s(0.2, 4e-3, 2.1e-3, True, 0.1, p) == -1.0
    assert calm_spell_s(0.2, 0.0, 0.0, False, 0.1, p) == -1.0           # wind or rings moving
    for bad in (0.5, math.nan):
        with pytest.raises(InputError, match="wake_factor"):
            ClothParams(wake_factor=bad)


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["numpy", "cpu"])
def test_the_windless_drape_sleeps_within_five_seconds_and_wind_wakes_it(backend):
    """From the settled drape every catalog weave (lightest and heaviest) falls asleep within
    5 s of simulated time at wind 0 (docs/cloth.md, "Sleep"; before the drape was settled
    to rest it rang for 13 s), stays where it is, and the wind wakes and moves it."""
    from catalog.cloth.drape import drape_params, settled_simulation, settled_state

    for weave in ("voile", "twill"):
        params = drape_params({"weave": weave}, grid=(48, 28))
        rest = settled_state(params).positions_m
        sim = settled_simulation(params, backend=backend)
        frames = sim.run(300, 1 / 60)
        assert sim.sleeping and frames < 300, (weave, sim.peak_speed_m_s, sim.rms_speed_m_s)
        assert np.abs(sim.positions() - rest).max() < 2e-3  # it was at rest: barely moved
        assert sim.step(1 / 60) is False
        sim.set_wind(1.0)
        assert sim.run(30, 1 / 60) == 30 and not sim.sleeping
        assert np.abs(sim.positions() - rest).max() > 1e-2


def test_grid_cannot_change_on_a_running_simulation():
    from catalog.core.errors import CatalogError

    sim = ClothSimulation(ClothParams(grid_w=4, grid_h=4), "numpy")
    with pytest.raises(CatalogError, match="grid"):
        sim.set_params(grid_w=5)
    with pytest.raises(InputError, match="backend"):
        ClothSimulation(ClothParams(grid_w=4, grid_h=4), "fortran")


# ---- energy and strain helpers against hand computations ------------------------------

def test_strain_and_energy_helpers():
    p = ClothParams(grid_w=3, grid_h=3, width_m=2.0, height_m=2.0, opening=1.0)
    x = rest_pose(p)
    x[2, 2, 1] -= 0.1  # the bottom-right particle pulled down 0.1 m: vertical spring 1 -> 1.1
    assert max_spring_strain(x, p) == pytest.approx(0.1, abs=1e-12)
    v = np.zeros_like(x)
    v[1, 1] = (3.0, 4.0, 0.0)
    assert kinetic_energy_j(v, p) == pytest.approx(0.5 * p.particle_mass_kg * 25.0)
    v[0, 0] = (100.0, 0.0, 0.0)  # a ring: driven, not counted
    assert kinetic_energy_j(v, p) == pytest.approx(0.5 * p.particle_mass_kg * 25.0)
    assert rest_lengths_m(1.0, 2.0)[2] == pytest.approx(math.sqrt(5.0))


# ---- mesh -----------------------------------------------------------------------------

def test_curtain_mesh_frames_and_winding():
    p = ClothParams(grid_w=9, grid_h=7, opening=1.0)
    mesh = curtain_mesh(p)
    n = p.particle_count
    assert mesh.positions.shape == (n, 3) and mesh.indices.shape == (2 * 8 * 6, 3)
    np.testing.assert_allclose(mesh.normals, np.tile([0, 0, 1], (n, 1)), atol=1e-7)
    np.testing.assert_allclose(mesh.tangents, np.tile([1, 0, 0, 1], (n, 1)), atol=1e-7)
    np.testing.assert_allclose(mesh.warp_directions, np.tile([0, 1, 0], (n, 1)), atol=1e-7)
    tri = mesh.positions[mesh.indices]
    face_normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert np.all(face_normals[:, 2] > 0)  # counter-clockwise seen from the room (+z)
    assert mesh.uv.min() == 0.0 and mesh.uv.max() == 1.0
    np.testing.assert_allclose(mesh.uv_m.max(axis=0), [p.width_m, p.height_m], rtol=1e-6)
    vd = mesh.vertex_data()
    assert vd.shape == (n, 12) and np.all(vd[:, 3] == 1) and np.all(vd[:, 7] == 0)
    assert triangle_indices(2, 2).tolist() == [[0, 2, 3], [0, 3, 1]]


def test_pleated_mesh_frames_are_orthonormal():
    mesh = curtain_mesh(ClothParams(grid_w=30, grid_h=10, opening=0.5))
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(mesh.tangents[:, :3], axis=1), 1.0, atol=1e-6)
    assert np.abs(np.sum(mesh.normals * mesh.tangents[:, :3], axis=1)).max() < 1e-6
    assert np.abs(mesh.normals[:, 0]).max() > 0.3  # the pleats turn the normals


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".glb"])
def test_exports_round_trip(tmp_path, suffix):
    import trimesh

    from catalog.cloth import export_mesh, export_sequence

    sim = ClothSimulation(ClothParams(grid_w=6, grid_h=5, wind_speed_m_s=1.0), "numpy")
    sim.step(1 / 30)
    mesh = sim.mesh()
    path = export_mesh(mesh, tmp_path / f"c{suffix}")
    loaded = trimesh.load(path, force="mesh", process=False)
    assert len(loaded.vertices) == len(mesh.positions)
    assert len(loaded.faces) == len(mesh.indices)
    np.testing.assert_allclose(np.asarray(loaded.vertices), mesh.positions, atol=1e-5)
    paths = export_sequence([mesh, sim.mesh()], tmp_path / f"seq_{{frame:03d}}{suffix}")
    assert [p.name for p in paths] == [f"seq_000{suffix}", f"seq_001{suffix}"]
    assert sorted(q.name for q in tmp_path.iterdir() if q.name.startswith(".")) == []


def test_export_refuses_unknown_format(tmp_path):
    from catalog.cloth import export_mesh

    with pytest.raises(InputError, match="unsupported mesh format"):
        export_mesh(curtain_mesh(ClothParams(grid_w=4, grid_h=4)), tmp_path / "c.stl")
    assert list(tmp_path.iterdir()) == []


def test_every_backend_follows_the_declared_protocol():
    """The backends implement catalog.cloth.backend's protocol; only the GPU one is a
    device backend (loaded once, ring targets uploaded, a vertex buffer to draw)."""
    from catalog.cloth.backend import ClothBackend, DeviceBackend
    from catalog.cloth.backend_gpu import GpuBackend
    from catalog.cloth.backend_numba import NumbaBackend
    from catalog.cloth.backend_numpy import NumpyBackend
    from catalog.cloth.simulation import BACKENDS

    for cls in (NumpyBackend, NumbaBackend, GpuBackend):
        assert cls.name in BACKENDS
        assert all(callable(getattr(cls, m, None)) for m in ("set_params", "advance", "sync"))
    assert all(callable(getattr(GpuBackend, m, None))
               for m in ("load", "set_ring_targets", "bind_to_vertex_array"))
    backend = NumpyBackend(ClothParams(grid_w=4, grid_h=4))
    assert isinstance(backend, ClothBackend) and not isinstance(backend, DeviceBackend)
    backend.set_params(ClothParams(grid_w=4, grid_h=4, wind_speed_m_s=3.0))
    assert backend.params.wind_speed_m_s == 3.0 and backend.constants is not None
