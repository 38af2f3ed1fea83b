"""The room-transport GL pass (catalog.render.passes.room_transport) on read-back pixels:
each pixel is albedo x E / pi of what the pixel's centre ray meets, E interpolated in the
receiver from its welded corners, computed here in float64 numpy."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.room.rays import NumpyRays
from catalog.room.transport import TransportParams, precompute_geometry


@pytest.fixture(scope="module")
def cube_transport():
    from tests.test_room_transport import constant_albedo, open_cube

    tris, window = open_cube((0.25, 0.75, 0.3, 0.8))
    params = TransportParams(element_m=0.2, max_receivers=600, patches=(2, 2), order=2, gather_rays=64,
                             window_samples=4)
    t = precompute_geometry(tris, constant_albedo(0.5), window, params, backend="numpy",
                            compress_operators=False)
    return tris, t


@pytest.mark.slow
def test_pass_draws_albedo_times_interpolated_irradiance(gl, cube_transport):
    from catalog.render.passes.room_transport import RoomTransportPass, look_at_view_projection
    from catalog.room.lightmap import corner_irradiance

    tris, t = cube_transport
    coefficients = np.zeros((4, 3, 3))
    coefficients[:, 0] = [1.0, 2.0, 3.0]           # a uniform window, R:G:B = 1:2:3
    coefficients[:, 2] = [0.3, 0.0, -0.3]          # and a sideways lean, per channel
    e = t.irradiance(coefficients, compressed=False)
    width, height = 96, 72
    vp = look_at_view_projection((0.5, 0.55, 0.05), (0.1, -0.35, 1.0), (0, 1, 0), 70.0, width / height)
    colour = gl.texture((width, height), 4, dtype="f4")
    depth = gl.depth_renderbuffer((width, height))
    fbo = gl.framebuffer([colour], depth)
    fbo.use()
    fbo.clear(0, 0, 0, 0, depth=1.0)
    room_pass = RoomTransportPass(gl, t)
    room_pass.update(e)
    room_pass.draw(vp)
    pixels = np.frombuffer(fbo.read(components=4, dtype="f4"), dtype="f4").reshape(height, width, 4)[..., :3]
    room_pass.release()
    (gl.screen or gl.detect_framebuffer(0)).use()   # never leave a deleted framebuffer bound
    fbo.release(), colour.release(), depth.release()
    # the expected image: rays through pixel centres (read-back row 0 is the bottom)
    inv = np.linalg.inv(vp)
    jj, ii = np.mgrid[0:height, 0:width]
    ndc = np.stack([(ii + 0.5) / width * 2 - 1, (jj + 0.5) / height * 2 - 1], -1).reshape(-1, 2)
    near = np.c_[ndc, -np.ones(len(ndc)), np.ones(len(ndc))] @ inv.T
    far = np.c_[ndc, np.ones(len(ndc)), np.ones(len(ndc))] @ inv.T
    o = near[:, :3] / near[:, 3:]
    d = far[:, :3] / far[:, 3:] - o
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    dist, tri = NumpyRays(tris).intersect(o, d)
    assert (tri >= 0).all()
    p = o + dist[:, None] * d
    rec = t.receivers
    which = t.receiver_at(tri, p)
    assert (which >= 0).all()
    corner = corner_irradiance(t, e)                                   # (E, 3 corners, 3)
    c = rec.corners[which]
    area = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    n2 = np.einsum("ni,ni->n", area, area)
    b1 = np.einsum("ni,ni->n", np.cross(c[:, 2] - c[:, 1], p - c[:, 1]), area) / n2
    b2 = np.einsum("ni,ni->n", np.cross(c[:, 0] - c[:, 2], p - c[:, 2]), area) / n2
    bary = np.stack([b1, b2, 1 - b1 - b2], 1)
    expected = rec.albedo[which] * np.einsum("nk,nkc->nc", bary, corner[which]) / np.pi
    rel = np.abs(pixels.reshape(-1, 3) - expected) / np.maximum(expected, 1e-6)
    assert np.percentile(rel, 99) < 1e-2 and np.median(rel) < 1e-3
    # the light map is continuous across receivers: neighbouring pixels on one wall differ
    # little
    same_wall = np.all(np.diff(rec.normal[which].reshape(height, width, 3), axis=1) == 0, axis=-1)
    step = np.abs(np.diff(pixels[..., 1], axis=1)) / pixels[..., 1].mean()
    assert same_wall.mean() > 0.8 and np.percentile(step[same_wall], 99.5) < 0.05
    assert pixels[..., 2].mean() > pixels[..., 0].mean()               # blue window, blue room
