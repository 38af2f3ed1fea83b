"""A standalone GL pass: a room drawn with its light map from the precomputed transport.

Input: a :class:`catalog.room.transport.Transport` and the receivers' irradiance (E, 3)
(:meth:`Transport.irradiance` of the window's coefficients, plus :meth:`Transport.bounced`
of the sun's beam); the pass draws the light map of catalog.room.lightmap (corners welded
on each plane, linear inside each receiver) as albedo x E / pi (room_transport.vert/.frag) into the bound
framebuffer. Not yet wired into the frame (catalog/render/frame.py): the lead places it
among the passes; until then the tests draw it alone.
"""

from __future__ import annotations

import numpy as np

from catalog.render.camera import gl_bytes
from catalog.room.lightmap import corner_irradiance

def look_at_view_projection(position, forward, up, fov_y_deg: float, aspect: float,
                            near_m: float = 0.05, far_m: float = 50.0) -> np.ndarray:
    """The 4x4 view-projection of a camera (a room's ``camera`` node)."""
    f = np.asarray(forward, dtype=np.float64) / np.linalg.norm(forward)
    right = np.cross(f, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, true_up, -f
    view[:3, 3] = -view[:3, :3] @ np.asarray(position, dtype=np.float64)
    t = 1.0 / np.tan(np.radians(fov_y_deg) / 2)
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = t / aspect, t
    proj[2, 2] = (far_m + near_m) / (near_m - far_m)
    proj[2, 3] = 2 * far_m * near_m / (near_m - far_m)
    proj[3, 2] = -1.0
    return proj @ view


class RoomTransportPass:
    """Owns its program and vertex buffer; :meth:`update` uploads a new light map (the
    curtain moved, the sun moved), :meth:`draw` draws it depth-tested."""

    def __init__(self, ctx, transport):
        from catalog.gl.shaderlib import create_program  # noqa: PLC0415

        self.ctx = ctx
        self.transport = transport
        self.program = create_program(ctx, "room_transport.vert", "room_transport.frag")
        rec = transport.receivers
        self._positions = rec.corners.reshape(-1, 3).astype("f4")
        self._albedo = np.repeat(rec.albedo, 3, axis=0).astype("f4")
        self._buffer = ctx.buffer(reserve=self._positions.shape[0] * 9 * 4)
        self._vao = ctx.vertex_array(self.program, [(self._buffer, "3f 3f 3f", "in_position",
                                                     "in_irradiance", "in_albedo")])
        self.update(np.zeros((rec.count, 3)))

    def update(self, irradiance: np.ndarray) -> None:
        """Upload the receivers' irradiance (E, 3)."""
        corner = corner_irradiance(self.transport, np.asarray(irradiance, dtype=np.float64))
        data = np.concatenate([self._positions, corner.reshape(-1, 3).astype("f4"), self._albedo], axis=1)
        self._buffer.write(np.ascontiguousarray(data, dtype="f4").tobytes())

    def draw(self, view_projection: np.ndarray) -> None:
        import moderngl  # noqa: PLC0415

        self.program["u_view_proj"].write(gl_bytes(view_projection))
        self.ctx.enable(moderngl.DEPTH_TEST)
        self.ctx.disable(moderngl.CULL_FACE)
        self._vao.render(moderngl.TRIANGLES)
        self.ctx.disable(moderngl.DEPTH_TEST)   # the state the other passes start from

    def release(self) -> None:
        for obj in (self._vao, self._buffer, self.program):
            obj.release()
