"""The frame's room light by the precomputed transport (catalog/render/passes/
room_transport_light.py, catalog/render/room_operators.py): the captures' geometry and
projection in closed form, the numpy bundle against the transport's own operators, and the
frame drawing the built-in rooms (read-back pixels)."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.render.passes.room_transport_light import (CAPTURE_PHI, CAPTURE_THETA,
                                                        aperture_view_projection, project_captures)
from catalog.room import sh

CORNERS = np.array([[-0.95, -0.9, -0.2], [0.95, -0.9, -0.2], [0.95, 1.35, -0.2], [-0.95, 1.35, -0.2]])
NORMAL = np.array([0.0, 0.0, 1.0])


def ndc(matrix, points):
    clip = np.c_[points, np.ones(len(points))] @ matrix.T
    return clip[:, :3] / clip[:, 3:]


@pytest.mark.parametrize("direction", [(0.0, 0.0, 1.0), (0.5, -0.3, 0.81), (-0.7, 0.2, 0.3)])
def test_aperture_view_maps_the_window_to_the_viewport_along_the_direction(direction):
    w = np.asarray(direction) / np.linalg.norm(direction)
    m = aperture_view_projection(CORNERS, NORMAL, w)
    np.testing.assert_allclose(ndc(m, CORNERS)[:, :2], [[-1, -1], [1, -1], [1, 1], [-1, 1]], atol=1e-12)
    # a point moved along the direction lands on the same aperture point, nearer (into the room)
    p = np.array([[0.3, 0.2, -0.2]])
    a, b = ndc(m, p), ndc(m, p + 0.4 * w)
    np.testing.assert_allclose(a[:, :2], b[:, :2], atol=1e-12)
    assert b[0, 2] < a[0, 2]
    assert -1.0 < ndc(m, p - 5.0 * w)[0, 2] < 1.0     # the outside, 5 m back, is inside the depth range


def test_projection_recovers_a_band_limited_radiance_exactly():
    """Radiance that is a combination of the order-3 basis, sampled at the capture's
    quadrature, projects back onto its coefficients (the quadrature is exact for products)."""
    dirs, weights = sh.hemisphere_quadrature(CAPTURE_THETA, CAPTURE_PHI)
    basis = sh.hemi_basis(dirs, 3)
    rng = np.random.default_rng(5)
    truth = rng.normal(size=(4, basis.shape[1], 3))                # 2 x 2 patches
    radiance = np.einsum("jk,pkc->jpc", basis, truth).reshape(len(weights), 2, 2, 3)
    np.testing.assert_allclose(project_captures(basis, weights, radiance), truth, atol=1e-10)


@pytest.mark.slow
def test_bundle_operators_match_the_transport():
    """The numpy bundle the frame loads (sparse products, the light map's weld) against the
    transport's scipy operators and catalog.room.lightmap on the box (1e-9 relative)."""
    from catalog.render.room_operators import room_operators
    from catalog.room.cache import room_transport
    from catalog.room.lightmap import corner_irradiance
    from catalog.room.load import load_room

    ops = room_operators("box")
    t = room_transport(load_room("box"))
    rng = np.random.default_rng(3)
    c = rng.random((t.coefficient_count, 3))
    e = t.irradiance(c)
    np.testing.assert_allclose(ops.irradiance(c), e, rtol=1e-9, atol=1e-9 * np.abs(e).max())
    direct = rng.random((ops.count, 3))
    np.testing.assert_allclose(ops.bounced(direct), t.bounced(direct), rtol=1e-9)
    np.testing.assert_allclose(ops.corner_irradiance(e), corner_irradiance(t, e), rtol=1e-9)
    # the gathers are shares of rays: each row at most 1, and the cloth's room side sees the room
    for g in (ops.gather_patch, ops.gather_side, ops.gather_wall):
        rows = g.dot(np.ones((ops.count, 1)))[:, 0]
        assert (rows <= 1 + 1e-12).all()
    assert ops.gather_side.dot(np.ones((ops.count, 1))).mean() > 0.9
    # only receivers outside the aperture's plane see the outside
    outside = ((ops.centre - ops.window_corners[0]) @ ops.window_normal) < 0
    assert np.abs(ops.outside[~outside]).max() == 0.0 and np.abs(ops.outside[outside]).max() > 0


@pytest.mark.slow
def test_frame_draws_each_built_in_room(gl):
    """The frame in the box and in living: finite, the room lit (the floor under the window
    brighter than black, living's wood floor warmer than the box's grey) and a bad room
    refused before anything changes."""
    from catalog.core.errors import InputError
    from catalog.render.frame import FrameRenderer
    from catalog.render.settings import orbit
    from catalog.render.scene import draped_curtain

    means = {}
    for room in ("box", "living"):
        renderer = FrameRenderer(gl, (96, 54))
        try:
            renderer.update(fabric="lace-fwa",
                            light="D65",
                            room=room,
                            camera=orbit(0.0, -25.0, 2.5, inside=True))   # looking down at the floor
            mesh = draped_curtain()
            renderer.set_mesh(mesh.positions, mesh.normals, mesh.uvs, mesh.tangents, mesh.indices)
            renderer.render()
            linear = renderer.read_linear()
            assert np.isfinite(linear).all()
            floor = linear[-8:]   # the image's bottom rows: the floor
            assert floor.mean() > 0.0
            means[room] = floor.reshape(-1, 3).mean(axis=0)
            with pytest.raises(InputError):
                renderer.update(room="attic")
            assert renderer.room_spec == room
        finally:
            renderer.release()
    r_over_b = {room: m[0] / m[2] for room, m in means.items()}
    assert r_over_b["living"] > 1.2 * r_over_b["box"]
