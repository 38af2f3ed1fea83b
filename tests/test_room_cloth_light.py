"""The curtain's room side lit by the room's transport (catalog/render/passes/
room_transport_light.py, curtain.vert ROOM_SIDE / WALL_GRID): the cloth's exitance from its
basis coefficients and the window side's cosine-weighted mean against closed forms, the
outward views of the aperture, and the per-vertex light the shader reads against its float64
evaluation at the G-buffer's pixels."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.render.passes.room_transport_light import (CAPTURE_PHI, CAPTURE_THETA, WINDOW_SIDE_PHI,
                                                        WINDOW_SIDE_THETA, aperture_view_projection,
                                                        exitance_basis, outward_mean_quadrature,
                                                        project_captures)
from catalog.room import sh


def _luma(rgb):
    return np.asarray(rgb, dtype=np.float64) @ np.array([0.2126, 0.7152, 0.0722])


@pytest.mark.parametrize("order", [2, 3])
def test_exitance_from_coefficients_matches_closed_forms(order):
    """A patch of radiance L(w) in the basis' span projected from the capture's quadrature,
    then integrated against the cosine: uniform L = 1 gives pi, L = 1 + x (a sideways lean)
    pi (the lean integrates to 0), and with order 3, L = z^2 gives pi / 2, to 1e-12."""
    dirs, weights = sh.hemisphere_quadrature(CAPTURE_THETA, CAPTURE_PHI)
    basis = sh.hemi_basis(dirs, order)
    m = exitance_basis(basis, weights, dirs[:, 2])
    cases = [(np.ones(len(dirs)), math.pi), (1.0 + dirs[:, 0], math.pi)]
    if order >= 3:
        cases.append((dirs[:, 2] ** 2, math.pi / 2))
    for radiance, want in cases:
        captures = np.repeat(radiance[:, None, None, None], 3, axis=-1)   # (J, 1, 1, 3)
        c = project_captures(basis, weights, captures)                    # (1, K, 3)
        got = np.einsum("pkc,k->pc", c, m)
        assert np.allclose(got, want, rtol=0, atol=1e-12), (got, want)


def test_window_side_mean_is_the_cosine_weighted_mean():
    """The outward quadrature lies in z < 0 and its weights give the cosine-weighted mean:
    1 for a uniform radiance, 2/3 for L = |cos theta|, 0 for a lean in x (closed forms)."""
    dirs, v = outward_mean_quadrature(WINDOW_SIDE_THETA, WINDOW_SIDE_PHI)
    assert np.all(dirs[:, 2] < 0)
    assert np.allclose(np.linalg.norm(dirs, axis=1), 1.0)
    assert abs(v.sum() - 1.0) < 1e-12
    assert abs(v @ np.abs(dirs[:, 2]) - 2.0 / 3.0) < 1e-12
    assert abs(v @ dirs[:, 0]) < 1e-12


def test_outward_view_maps_the_aperture_and_orders_depth_from_outside():
    """A view of the aperture from outside (a direction out of the room): a point projects
    along the direction onto the aperture point (s, t) -> NDC 2 (s, t) - 1; a point farther
    out is nearer (smaller depth), the reverse of a view from inside."""
    corners = np.array([[-1.0, 0.5, 0.0], [1.0, 0.5, 0.0], [1.0, 2.0, 0.0], [-1.0, 2.0, 0.0]])
    normal = np.array([0.0, 0.0, 1.0])          # into the room
    out = np.array([0.3, -0.2, -0.9])
    out /= np.linalg.norm(out)
    m_out = aperture_view_projection(corners, normal, out)
    m_in = aperture_view_projection(corners, normal, -out)
    s, t = 0.25, 0.6
    on = corners[0] + s * (corners[1] - corners[0]) + t * (corners[3] - corners[0])
    for d in (0.0, 0.12, -0.3):                  # distance into the room along the normal
        p = on + d * out / (out @ normal)
        clip = m_out @ np.r_[p, 1.0]
        assert np.allclose(clip[:2] / clip[3], [2 * s - 1, 2 * t - 1], atol=1e-12)
    z = lambda m, d: (m @ np.r_[on + np.array([0, 0, d]), 1.0])[2]   # noqa: E731
    assert z(m_out, -0.2) < z(m_out, 0.1)        # from outside, the farther-out point is nearer
    assert z(m_in, 0.1) < z(m_in, -0.2)          # from inside, the reverse


@pytest.mark.slow
@pytest.mark.parametrize("room", ["box", "living"])
def test_cloth_light_per_vertex_matches_its_float64_evaluation(gl, room):
    """curtain.vert ROOM_SIDE reads the transport's room-side grid, the folds' exitance and the
    window side's mean per vertex, WALL_GRID the wall's grid: at the G-buffer's pixels the
    interpolated light against RoomTransportLight.cloth_light_at, the same lookups in float64
    at each pixel (the room's side hidden as the G-buffer has it). With the drape's folds:
    the means over the cloth within 3 %, the median pixel within 3 % and 80 % within 10 % (a
    patch's value ramps between two vertices where the per-pixel one bends). The folds hide
    part of the room (the exitance is used) and the cloth's room side sees more of its own
    folds' glow than of the room under a bright sky (both terms not zero)."""
    from catalog.render.frame import FrameRenderer
    from catalog.render.settings import orbit

    r = FrameRenderer(gl, (160, 120))
    try:
        r.update(fabric="safety-yellow", light="D65", room=room, curtain_open=False,
                 camera=orbit(15.0, 5.0, 2.6, inside=True))
        g = r.render_gbuffer()
        mask = g["mask"]
        assert mask.sum() > 2000
        hidden = g["room_occlusion"][mask]
        assert hidden.mean() > 0.05
        room_light, window_light = r.twin.room_side_light_at(g["position"][mask], hidden)
        walled = r.twin.wall_light_at(g["position"][mask])
        for got, want in ((g["room_side_light"][mask], room_light), (g["window_side_light"][mask], window_light),
                          (g["wall_light"][mask][:, :3], walled)):
            got, want = _luma(got), _luma(want)
            assert want.mean() > 0
            assert abs(got.mean() / want.mean() - 1) < 0.03, (got.mean(), want.mean())
            rel = np.abs(got / np.maximum(want, 1e-9) - 1)
            assert np.median(rel) < 0.03 and np.mean(rel < 0.10) > 0.8, (np.median(rel), np.mean(rel < 0.1))
        exitance = r.room_transport.cloth_textures()[0]
        assert np.frombuffer(exitance.read(), "f4").reshape(-1, 4)[:, :3].mean() > 0
    finally:
        r.release()
