"""The frame's room light by the room's precomputed transport (docs/room-light.md).

Each room update (the curtain moved, the light moved):

1. the window's radiance into the room, from the curtain's own shading: the flat cloth and
   the outside drawn in oblique parallel views of the aperture, one per direction of a Gauss
   hemisphere quadrature in the window's frame (catalog.room.sh.hemisphere_quadrature;
   exact for the basis' products), a texel block per window patch averaged by the mip chain
   to the patch level, projected onto the hemispherical basis: c_pk = sum_j w_j L_pj H_k(w_j);
2. the receivers' irradiance E = T c (every bounce), plus the bounces of the direct light the
   window's operator does not hold: the key's beam (normal irradiance x cos x the curtain's
   transmittance map x the room's visibility to the key, read from the room's depth map as
   the room's pass reads it per pixel), the outside on receivers outside the aperture (the
   reveals) and the lamps, through the bounce operator; the beam itself is drawn per pixel;
3. the closed cloth reflects the room's light back in: its room side's irradiance at the
   window's patches (cosine-weighted rays from the aperture into the room, each landing on a
   receiver: E_side = G rho E) times its diffuse reflectance, a uniform radiance per patch
   added to c, solved by fixed-point iteration (its gain is well under one);
4. the curtain's room side: the same gather from the points of the cloth's room-side grid
   (curtain.frag ROOM_SIDE) and from the cloth's plane towards the window (WALL_GRID); where
   the folds hide the room from a fold, the folds' own exitance towards the room (the window
   patches' coefficients integrated against the cosine: M_p = sum_k c_pk int H_k cos); where
   they hide the outside, the folds' window side, from the same parallel views of the aperture
   along the outward hemisphere's quadrature (its cosine-weighted mean radiance per patch).

Numpy on the host for 2-4 (catalog/render/room_operators.py: compressed operators, a few
milliseconds each); GL for the views and the draw (catalog/render/passes/room_transport.py).
"""

from __future__ import annotations

import math

import numpy as np

from catalog.gl.host_step import host_step
from catalog.render import scene as scene_lib
from catalog.render.camera import gl_bytes
from catalog.render.passes.gl_common import Pass, set_uniform
from catalog.room import sh

#: Gauss-Legendre nodes in cos(theta) and uniform azimuths of the capture's directions
#: (3 x 6 = 18 views: exact for the products of the order-3 basis, degree 4 in z, |m| <= 4).
CAPTURE_THETA = 3
CAPTURE_PHI = 6
#: Texels a window patch takes in a capture (a power of two: the mip chain averages them).
CAPTURE_TEXELS_PER_PATCH = 8
#: The views draw the mesh's coarse grid (its 40 rows and columns: a patch's 8 texels span
#: about 6 of its cells), not every triangle: a CPU rasteriser's cost is the triangles'.
CAPTURE_COARSE = True
#: Cosine-weighted rays from each point of the cloth's grids into the room.
GATHER_RAYS = 512
#: Fixed-point iterations of the cloth's reflection of the room's light back into it.
REFLECTION_ITERATIONS = 4
#: The room's depth map from the key (texels a side).
ROOM_DEPTH_TEXELS = 1024
#: The outside's radiance sampled for its basis (receivers outside the aperture): Gauss nodes
#: in cos(theta) and azimuths over the outward hemisphere.
OUTSIDE_THETA = 4
OUTSIDE_PHI = 8
#: The cloth's window side's views (outward hemisphere): Gauss nodes in cos(theta) and
#: azimuths; only its cosine-weighted mean per patch is used (exact for radiance linear in
#: the direction's cosine), so fewer than the room side's.
WINDOW_SIDE_THETA = 2
WINDOW_SIDE_PHI = 3
#: Points of each receiver where the key's visibility is read (the beam's bounces).
VISIBILITY_SAMPLES = 4
#: The depth map's offset along the receiver's normal (m) against self-shadowing.
DEPTH_OFFSET_M = 0.01


def aperture_view_projection(corners, normal, direction, near_m: float = 1.5, far_m: float = 30.0) -> np.ndarray:
    """The oblique parallel projection of the window seen along -``direction`` (a unit
    direction, into the room or out of it): a point maps to the aperture point it projects
    onto along the direction (NDC x, y = 2 (s, t) - 1 over the window's u and v edges), its
    depth its distance into the room along the normal, from ``near_m`` (near) to -``far_m``
    (far) for a direction into the room, the other way round for one out of it (a view from
    outside: the nearest point is the farthest out)."""
    corners = np.asarray(corners, dtype=np.float64)
    o, u, v, n = corners[0], corners[1] - corners[0], corners[3] - corners[0], np.asarray(normal, dtype=np.float64)
    w = np.asarray(direction, dtype=np.float64)
    m = np.eye(4)
    # p - o = s u + t v + d (w / (w.n)); solve for (s, t, d) with the plane's dual basis
    basis = np.stack([u, v, w / float(w @ n)], axis=1)
    inv = np.linalg.inv(basis)
    m[:3, :3] = inv
    m[:3, 3] = -inv @ o
    ndc = np.eye(4)
    ndc[0, 0], ndc[0, 3] = 2.0, -1.0
    ndc[1, 1], ndc[1, 3] = 2.0, -1.0
    # depth d (m into the room): near_m -> -1, -far_m -> +1
    ndc[2, 2] = -2.0 / (near_m + far_m)
    ndc[2, 3] = (near_m - far_m) / (near_m + far_m)
    if float(w @ n) < 0.0:     # from outside: nearer is farther out
        ndc[2, 2:] = -ndc[2, 2:]
    return ndc @ m


def project_captures(basis: np.ndarray, weights: np.ndarray, radiance: np.ndarray) -> np.ndarray:
    """(P, K, 3) the patches' coefficients from captures (J, nv, nu, 3) along the quadrature's
    directions (basis (J, K) there, weights (J,) sr): c_pk = sum_j w_j L_pj H_k(w_j)."""
    per_patch = radiance.reshape(len(weights), -1, 3)      # (J, P, 3), p = iu + nu iv
    return np.einsum("jk,j,jpc->pkc", basis, weights, per_patch)


def exitance_basis(basis: np.ndarray, weights: np.ndarray, cos_theta: np.ndarray) -> np.ndarray:
    """(K,) the exitance of a patch per unit of each basis coefficient, int H_k(w) cos(theta) dw
    by the quadrature (directions' basis (J, K), weights (J,) sr, their cos theta (J,)): a
    patch's exitance towards the room is M_p = sum_k c_pk m_k."""
    return np.einsum("jk,j,j->k", basis, weights, cos_theta)


def outward_mean_quadrature(n_theta: int, n_phi: int) -> tuple[np.ndarray, np.ndarray]:
    """Directions (J, 3) out of the room in the window's local frame (z < 0: the normal points
    into the room) and weights (J,) of the cosine-weighted mean over that hemisphere,
    sum_j v_j L(w_j) = (1 / pi) int L cos dw (Gauss in cos theta: exact for polynomials of
    degree 2 n_theta - 2 in cos theta times the cosine)."""
    dirs, weights = sh.hemisphere_quadrature(n_theta, n_phi)
    return dirs * np.array([1.0, 1.0, -1.0]), weights * dirs[:, 2] / math.pi


class RoomTransportLight(Pass):
    """The room's light by the precomputed transport, for the frame's room (a built-in name
    or a .glb): the captures, the operator, the cloth's reflection, the beam's bounces, the
    curtain's room side; draws the room (:meth:`draw`).

    In: the curtain and background passes (the captures), the shadow pass's transmittance
    map, the scene terms. Out: the receivers' irradiance (:attr:`irradiance`), the room-side
    grid ``room_side`` of frame.room_targets, the room into the HDR target."""

    def __init__(self, frame, room):
        """``room``: a loaded Room, a built-in name or a .glb path (its bundle from the cache,
        built when absent)."""
        super().__init__(frame)
        from catalog.render.passes.room_transport import RoomTransportPass  # noqa: PLC0415
        from catalog.render.room_operators import room_operators  # noqa: PLC0415

        from catalog.render.placement import placement_of  # noqa: PLC0415

        self.ops = room_operators(room)
        ops = self.ops
        #: the curtain, rod and camera of this room, from its window (catalog.render.placement)
        self.placement = placement_of(ops.window_corners, ops.window_normal, ops.triangles,
                                      str(getattr(room, "source", room)))
        self.draw_pass = RoomTransportPass(self.ctx, ops)
        dirs, weights = sh.hemisphere_quadrature(CAPTURE_THETA, CAPTURE_PHI)
        self._weights = weights
        self._world_dirs = dirs @ ops.frame        # rows x, y, z: local -> world
        self._basis = sh.hemi_basis(dirs, ops.order)   # (J, K)
        nu, nv = ops.patches
        self._patches = (nu, nv)
        self._side_size = (int(ops.side_grid[0]), int(ops.side_grid[1]))
        # the basis' uniform radiance: c_0 of L = 1 (H_0 is constant)
        self._uniform_c0 = float(2 * math.pi * self._basis[0, 0])
        # points of each receiver where the key's visibility is read from the depth map
        rng = np.random.default_rng(2)
        r1, r2 = rng.random((2, ops.count, VISIBILITY_SAMPLES))
        root = np.sqrt(r1)
        bary = np.stack([1 - root, root * (1 - r2), root * r2], axis=-1)    # (E, S, 3)
        self._visibility_points = np.einsum("esk,ekj->esj", bary, ops.corners)
        from catalog.render.room_operators import OUTSIDE_ORDER  # noqa: PLC0415

        out_dirs, out_weights = sh.hemisphere_quadrature(OUTSIDE_THETA, OUTSIDE_PHI)
        self._outside_weights = out_weights
        self._outside_dirs = out_dirs @ ops.outside_frame
        self._outside_basis = sh.hemi_basis(out_dirs, OUTSIDE_ORDER)
        # the cloth's window side: the outward hemisphere's quadrature (z flipped: out of the room)
        side_dirs, self._back_weights = outward_mean_quadrature(WINDOW_SIDE_THETA, WINDOW_SIDE_PHI)
        self._back_world_dirs = side_dirs @ ops.frame
        # the cloth's exitance towards the room per unit coefficient: int H_k cos (exact: the
        # capture's quadrature integrates degree 4 in cos theta)
        self._exitance_basis = exitance_basis(self._basis, weights, dirs[:, 2])
        self._outside_target = None
        self._capture = None
        self._back_capture = None
        self._cloth_textures = None
        self._back_mean = np.zeros((nv, nu, 3))
        self._room_depth = None
        self._lamp_key = None
        self._room_side = np.zeros((self._side_size[1], self._side_size[0], 3))
        self._walled = np.zeros_like(self._room_side)
        self._exitance = np.zeros((nv, nu, 3))
        self._window_mean = np.zeros(3)
        self.irradiance = np.zeros((ops.count, 3))
        self.coefficients = np.zeros((nu * nv, self._basis.shape[1], 3))

    # ------------------------------------------------------------------ GL targets
    def _targets(self):
        if self._capture is None:
            mgl = self.mgl
            nu, nv = self._patches
            k = CAPTURE_TEXELS_PER_PATCH
            count = len(self._weights)
            size = (nu * k * count, nv * k)
            texture = self.ctx.texture(size, 4, dtype="f4")
            texture.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            depth = self.ctx.depth_renderbuffer(size)
            self._capture = (texture, depth, self.ctx.framebuffer([texture], depth))
            n = ROOM_DEPTH_TEXELS
            room_depth = self.ctx.depth_texture((n, n))
            room_depth.compare_func = "<="
            room_depth.filter = (mgl.LINEAR, mgl.LINEAR)
            room_depth.repeat_x = room_depth.repeat_y = False
            self._room_depth = (room_depth, self.ctx.framebuffer(depth_attachment=room_depth))
        return self._capture

    def _back_targets(self):
        if self._back_capture is None:
            mgl = self.mgl
            nu, nv = self._patches
            k = CAPTURE_TEXELS_PER_PATCH
            size = (nu * k * len(self._back_weights), nv * k)
            texture = self.ctx.texture(size, 4, dtype="f4")
            texture.filter = (mgl.NEAREST_MIPMAP_NEAREST, mgl.NEAREST)
            depth = self.ctx.depth_renderbuffer(size)
            self._back_capture = (texture, depth, self.ctx.framebuffer([texture], depth))
        return self._back_capture

    def cloth_textures(self):
        """(room side, window side) textures of the window's patches (nu x nv, linear): the
        cloth's exitance towards the room (x pi cd m^-2, curtain.vert's fold-hidden room side)
        and its window side's cosine-weighted mean radiance (the folds in front of the window side)."""
        if self._cloth_textures is None:
            nu, nv = self._patches
            out = []
            for _ in range(2):
                texture = self.ctx.texture((nu, nv), 4, data=np.zeros((nv, nu, 4), "f4").tobytes(), dtype="f4")
                texture.filter = (self.mgl.LINEAR, self.mgl.LINEAR)
                texture.repeat_x = texture.repeat_y = False
                out.append(texture)
            self._cloth_textures = tuple(out)
        return self._cloth_textures

    def wall_grid_texture(self):
        """The cloth's window side's light from the room's surfaces round the window (WALL_GRID)."""
        if getattr(self, "_wall_grid", None) is None:
            tw, th = self._side_size
            texture = self.ctx.texture((tw, th), 4, data=np.zeros((th, tw, 4), "f4").tobytes(), dtype="f4")
            texture.filter = (self.mgl.LINEAR, self.mgl.LINEAR)
            texture.repeat_x = texture.repeat_y = False
            self._wall_grid = texture
        return self._wall_grid

    def draw_outside(self, inputs) -> None:
        """The outside (the background without the sun's disc, which the beam carries) one
        texel per direction of the outward hemisphere's quadrature (:meth:`outside_radiance`
        reads them)."""
        from catalog.render.passes.room_transport import look_at_view_projection  # noqa: PLC0415

        count = len(self._outside_weights)
        if self._outside_target is None:
            texture = self.ctx.texture((count, 1), 4, dtype="f4")
            self._outside_target = (texture, self.ctx.framebuffer([texture]))
        _texture, fbo = self._outside_target
        fbo.use()
        self.ctx.disable(self.mgl.DEPTH_TEST)
        for j, d in enumerate(self._outside_dirs):
            up = (0.0, 1.0, 0.0) if abs(d[1]) < 0.9 else (1.0, 0.0, 0.0)
            self.ctx.viewport = (j, 0, 1, 1)
            view_proj = look_at_view_projection((0.0, 0.0, 0.0), d, up, 0.5, 1.0)
            self.frame.background.draw(view_proj, inputs, camera_position=(0.0, 0.0, 0.0), sun_disc=False)

    def outside_radiance(self) -> np.ndarray:
        """(K, 3) the outside's radiance in the outward hemispherical basis, from
        :meth:`draw_outside`'s texels."""
        count = len(self._outside_weights)
        texture = self._outside_target[0]
        radiance = np.frombuffer(texture.read(), dtype="f4").reshape(count, 4)[:, :3].astype(np.float64)
        return np.einsum("jk,j,jc->kc", self._outside_basis, self._outside_weights, radiance)

    def outside_irradiance(self) -> np.ndarray:
        """(E, 3) what receivers outside the aperture (the reveals, a sill) take directly from
        the outside and from the closed curtain's window side (its capture's mean radiance)."""
        ops = self.ops
        e = ops.outside @ self.outside_radiance()
        if not self.frame.curtain_open and np.any(ops.window_back):
            e = e + ops.window_back[:, None] * self._back_mean.reshape(-1, 3).mean(axis=0)[None, :]
        return e

    def framebuffers(self) -> list:
        out = []
        if self._capture is not None:
            out.append(self._capture[2])
        if self._room_depth is not None:
            out.append(self._room_depth[1])
        if self._outside_target is not None:
            out.append(self._outside_target[1])
        if self._back_capture is not None:
            out.append(self._back_capture[2])
        return out

    def release(self) -> None:
        for group in (self._capture, self._room_depth, self._outside_target, self._back_capture,
                      self._cloth_textures):
            for obj in group or ():
                obj.release()
        self._capture = self._room_depth = self._outside_target = None
        self._back_capture = self._cloth_textures = None
        if getattr(self, "_wall_grid", None) is not None:
            self._wall_grid.release()
            self._wall_grid = None
        self.draw_pass.release()

    # ------------------------------------------------------------------ 1. the captures
    def capture_overrides(self) -> dict:
        """The curtain's values as the room sees them: SceneTerms.capture_overrides' (no sun disc
        seen through it, which the beam carries; no room light on its room side, which step 3
        reflects), with the directional lobe kept: the views resolve it by direction."""
        out = self.frame.terms.capture_overrides()
        out["u_a_spec"] = self.frame.terms.scene_values()["u_a_spec"]
        return out

    def draw_captures(self, inputs) -> None:
        texture, _depth, fbo = self._targets()
        overrides = self.capture_overrides()
        for view_proj, eye in self._aperture_views(fbo, self._world_dirs):
            if not self.frame.curtain_open:
                self.frame.curtain.draw_flat(view_proj, eye, overrides, coarse=CAPTURE_COARSE)
            self.frame.background.draw(view_proj, inputs, camera_position=eye, sun_disc=False)
        texture.build_mipmaps()

    def _aperture_views(self, fbo, world_dirs):
        """Into ``fbo``, one viewport a direction (side by side, CAPTURE_TEXELS_PER_PATCH texels
        a patch): yields each parallel view of the aperture along -w as (view_proj, eye) with the
        depth test on and blending off, and restores the frame's depth state after the last."""
        mgl = self.mgl
        nu, nv = self._patches
        k = CAPTURE_TEXELS_PER_PATCH
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        self.ctx.depth_func = "<="
        centre = self.ops.window_centre
        for j, w in enumerate(world_dirs):
            self.ctx.viewport = (j * nu * k, 0, nu * k, nv * k)
            view_proj = aperture_view_projection(self.ops.window_corners, self.ops.window_normal, w)
            yield view_proj, tuple(float(v) for v in centre + 1e3 * w)   # the rays all ~ -w
        self.ctx.depth_func = "<"
        self.ctx.disable(mgl.DEPTH_TEST)

    def _patch_radiance(self, texture, count: int) -> np.ndarray:
        """(count, nv, nu, 3) each view's mean radiance over each patch: the mip level where a
        patch is one texel (row 0: the v edge's start)."""
        nu, nv = self._patches
        level = int(math.log2(CAPTURE_TEXELS_PER_PATCH))
        data = np.frombuffer(texture.read(level=level), dtype="f4").reshape(nv, count * nu, 4)[..., :3]
        return data.reshape(nv, count, nu, 3).transpose(1, 0, 2, 3).astype(np.float64)

    def draw_window_side(self) -> None:
        """The cloth's window side in parallel views of the aperture from outside (the
        outward quadrature's directions), as the room's light sees it there: its back capture's
        values (catalog.render.passes.scene_terms.back_capture_overrides: no see-through, the
        outside reflected), nothing where there is no cloth (:meth:`read_window_side`)."""
        if self.frame.curtain_open:
            return
        texture, _depth, fbo = self._back_targets()
        overrides = self.frame.terms.back_capture_overrides()
        for view_proj, eye in self._aperture_views(fbo, self._back_world_dirs):
            self.frame.curtain.draw_flat(view_proj, eye, overrides, coarse=CAPTURE_COARSE)
        texture.build_mipmaps()

    def read_window_side(self) -> np.ndarray:
        """(nv, nu, 3) the cloth's window side's cosine-weighted mean radiance per patch
        (:meth:`draw_window_side`'s views; zero with the curtain open)."""
        nu, nv = self._patches
        if self.frame.curtain_open:
            return np.zeros((nv, nu, 3))
        radiance = self._patch_radiance(self._back_targets()[0], len(self._back_weights))
        return np.einsum("j,jvuc->vuc", self._back_weights, radiance)

    def read_captures(self) -> np.ndarray:
        """(J, nv, nu, 3) each direction's mean radiance over each patch (row 0: the v edge's start)."""
        return self._patch_radiance(self._capture[0], len(self._weights))

    def project(self, radiance: np.ndarray) -> np.ndarray:
        """(P, K, 3) coefficients of captures (J, nv, nu, 3) (:func:`project_captures`)."""
        return project_captures(self._basis, self._weights, radiance)

    # ------------------------------------------------------------------ 2. the beam
    def room_depth_view_projection(self, to_light) -> np.ndarray:
        """The key's parallel view of the window's cross-section (the transmittance map's),
        its depth over the whole room."""
        from catalog.render.curtain_frames import light_view_projection  # noqa: PLC0415

        m = light_view_projection(to_light, placement=self.frame.placement).copy()
        to_light = np.asarray(to_light, dtype=np.float64) / np.linalg.norm(to_light)
        b = self.ops.bounds
        corners = np.array([[x, y, z] for x in b[:, 0] for y in b[:, 1] for z in b[:, 2]])
        depth = corners @ to_light                  # view z (towards the light)
        near, far = -(depth.max() + 0.1), -(depth.min() - 0.1)
        # view space looks down -z with z = to_light . p: map -near..-far to -1..1
        m[2, :3] = -2.0 / (far - near) * to_light
        m[2, 3] = -(far + near) / (far - near)
        return m

    def draw_room_depth(self, inputs) -> None:
        self._targets()
        texture, fbo = self._room_depth
        fbo.use()
        n = ROOM_DEPTH_TEXELS
        self.ctx.viewport = (0, 0, n, n)
        fbo.clear(depth=1.0)
        self.ctx.depth_func = "<"
        self.draw_pass.draw_depth(self.room_depth_view_projection(inputs.key_to_light))
        self.ctx.disable(self.mgl.DEPTH_TEST)

    def _key_visibility(self, to_light) -> np.ndarray:
        """(E,) cos x each receiver's share of its points that see the key, read from the room's
        depth map as the room's pass reads it per pixel (the same normal offset, the same test)."""
        ops = self.ops
        texture = self._room_depth[0]
        n = ROOM_DEPTH_TEXELS
        depth = np.frombuffer(texture.read(), dtype="f4").reshape(n, n)
        m = self.room_depth_view_projection(to_light)
        p = (self._visibility_points + DEPTH_OFFSET_M * ops.normal[:, None, :]).reshape(-1, 3)
        clip = np.c_[p, np.ones(len(p))] @ m.T
        duv = clip[:, :3] * 0.5 + 0.5
        inside = np.all((duv[:, :2] >= 0.0) & (duv[:, :2] <= 1.0), axis=1)
        ij = np.clip((duv[:, :2] * n).astype(int), 0, n - 1)
        lit = inside & (duv[:, 2] <= depth[ij[:, 1], ij[:, 0]])
        cos = np.clip(ops.normal @ np.asarray(to_light, dtype=np.float64), 0.0, None)
        return cos * lit.reshape(ops.count, -1).mean(axis=1)

    def beam_irradiance(self, inputs) -> np.ndarray:
        """(E, 3) the key's beam at the receivers: key x cos x visibility x the curtain's
        transmittance (the map's coarse level read back at the receivers' centres)."""
        from catalog.render.curtain_frames import light_view_projection  # noqa: PLC0415

        vis = self._key_visibility(inputs.key_to_light)
        key_rgb = np.asarray(self.frame.terms.room_colours(inputs)["u_key_rgb"], dtype=np.float64)
        if not np.any(vis > 0) or not np.any(key_rgb > 0):
            return np.zeros((vis.size, 3))
        shadow = self.frame.room_targets.get()["shadow"]
        n = self.frame.shadow_texels
        level = max(0, int(math.log2(n)) - 7)      # 128 texels a side at most
        side = max(n >> level, 1)
        t = np.frombuffer(shadow.read(level=level), dtype=np.float16).reshape(side, side, 4)[..., :3]
        m = light_view_projection(inputs.key_to_light, placement=self.frame.placement)
        centre = self.ops.centre
        clip = np.c_[centre, np.ones(len(centre))] @ m.T
        uv = np.clip(clip[:, :2] * 0.5 + 0.5, 0.0, 1.0 - 1e-6)
        trans = t[(uv[:, 1] * side).astype(int), (uv[:, 0] * side).astype(int)].astype(np.float64)
        before = (inputs.key_to_light[2] < 0) & (centre[:, 2] < self.placement.window_z - 1e-4)
        trans[before] = 1.0
        return vis[:, None] * key_rgb[None, :] * trans

    def lamp_irradiance(self) -> np.ndarray:
        """(E, 3) the room's lamps at the receivers' centres: rgb x cos / r^2 x visibility
        (a ray to each lamp), the isotropic points of FrameRenderer.set_room_lamps."""
        from catalog.render import bands as band_lib  # noqa: PLC0415

        from catalog.room.rays import NumpyRays  # noqa: PLC0415  (numpy: no Mitsuba in a frame)

        ops = self.ops
        out = np.zeros((ops.count, 3))
        key = tuple((light.name, tuple(position)) for light, position in self.frame.room_lamps)
        if self._lamp_key == key:
            return self._lamp_e
        caster = NumpyRays(ops.triangles)
        centre = ops.centre + 1e-4 * ops.normal
        for light, position in self.frame.room_lamps:
            to = np.asarray(position, dtype=np.float64)[None, :] - centre
            r = np.linalg.norm(to, axis=1)
            d = to / r[:, None]
            dist, tri = caster.intersect(centre, np.ascontiguousarray(d))
            visible = (tri < 0) | (dist >= r - 1e-4)
            cos = np.clip(np.einsum("ni,ni->n", ops.normal, d), 0.0, None)
            rgb = band_lib.spectrum_to_display_rgb(light.irradiance_w_m2_nm)
            out += (visible * cos / np.maximum(r * r, 1e-4))[:, None] * np.asarray(rgb)[None, :]
        self._lamp_key, self._lamp_e = key, out
        return out

    # ------------------------------------------------------------------ the whole update
    def update(self, inputs) -> None:
        """Steps 1-4 (the shadow pass has drawn the transmittance map): the views drawn, then
        the host step (catalog.gl.host_step: read back, computed, uploaded)."""
        self.draw_window_side()
        self.draw_captures(inputs)
        self.draw_room_depth(inputs)
        self.draw_outside(inputs)
        with host_step(self.ctx, "room_transport", self.host_inputs()):
            self._host_update(inputs)

    def host_inputs(self) -> dict:
        """The host step's inputs (catalog.gl.host_step): the textures it reads back and the
        ones it writes, the vertex buffer of the light map, and the quadratures' constants."""
        nu, nv = self._patches
        return {
            "patches": [nu, nv], "capture_level": int(math.log2(CAPTURE_TEXELS_PER_PATCH)),
            "captures": {"texture": self._capture[0], "basis": self._basis, "weights": self._weights},
            "window_side": {"texture": None if self._back_capture is None else self._back_capture[0],
                            "weights": self._back_weights},
            "outside": {"texture": self._outside_target[0], "basis": self._outside_basis,
                        "weights": self._outside_weights},
            "room_depth": {"texture": self._room_depth[0], "offset_m": DEPTH_OFFSET_M},
            "shadow": self.frame.room_targets.get()["shadow"],
            "uniform_c0": self._uniform_c0, "exitance_basis": self._exitance_basis,
            "reflection_iterations": REFLECTION_ITERATIONS,
            "outputs": {"light_map": self.draw_pass.buffer, "room_side": self.frame.room_targets.get()["room_side"],
                        "wall_grid": self.wall_grid_texture(),
                        "cloth": list(self.cloth_textures())},
        }

    def _host_update(self, inputs) -> None:
        self._back_mean = self.read_window_side()
        c_window = self.project(self.read_captures())
        t = self.ops
        rho = t.albedo
        beam = self.beam_irradiance(inputs)
        # the direct light the window's operator does not hold (the operator is linear: one
        # bounced() of their sum): the beam (drawn per pixel, so only its bounces are added),
        # the outside on the receivers outside the aperture, the lamps
        direct = beam + self.outside_irradiance()
        if self.frame.room_lamps:
            direct = direct + self.lamp_irradiance()
        beam_bounces = t.bounced(direct) - beam
        e_window = t.irradiance(c_window)
        reflectance = np.asarray(self.frame.terms.window_albedo_rgb(inputs), dtype=np.float64)
        c = c_window
        e = e_window
        if np.any(reflectance > 0):
            for _ in range(REFLECTION_ITERATIONS):
                side = t.gather_patch.dot(rho * (e + beam_bounces + beam))   # (P, 3) irradiance
                c = c_window.copy()
                c[:, 0, :] += self._uniform_c0 * reflectance[None, :] * side / math.pi
                e = t.irradiance(c)
        self.coefficients = c
        self.irradiance = e + beam_bounces
        self.draw_pass.set_key(inputs.key_to_light)
        self.draw_pass.update(self.irradiance)
        room_side = t.gather_side.dot(rho * (self.irradiance + beam))
        tw, th = self._side_size
        walled = t.gather_wall.dot(rho * (self.irradiance + beam))
        self.wall_grid_texture().write(np.ascontiguousarray(np.concatenate(
            [walled.reshape(th, tw, 3), np.ones((th, tw, 1))], axis=-1), dtype="f4").tobytes())
        self._room_side = room_side.reshape(th, tw, 3)
        self._walled = walled.reshape(th, tw, 3)
        self._window_mean = c_window[:, 0, :].mean(axis=0) / self._uniform_c0   # mean radiance
        rgba = np.concatenate([room_side.reshape(th, tw, 3), np.ones((th, tw, 1))], axis=-1)
        self.frame.room_targets.get()["room_side"].write(np.ascontiguousarray(rgba, dtype="f4").tobytes())
        nu, nv = self._patches
        self._exitance = np.clip(np.einsum("pkc,k->pc", c, self._exitance_basis).reshape(nv, nu, 3), 0.0, None)
        for texture, value in zip(self.cloth_textures(), (self._exitance, self._back_mean)):
            texture.write(np.ascontiguousarray(np.concatenate(
                [value, np.ones((nv, nu, 1))], axis=-1), dtype="f4").tobytes())

    def cloth_light_at(self, positions, room_hidden) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """curtain.vert ROOM_SIDE's light in float64 at world ``positions`` (P, 3) with the room's
        side hidden by ``room_hidden`` (P,), as the shader reads the last update's textures
        (GL's bilinear filter, clamped): the room side's irradiance (the gather's grid where
        open, the folds' exitance where hidden), the window side's mean radiance, and the
        wall's irradiance on the cloth's plane (WALL_GRID), (P, 3) each."""
        from catalog.render.curtain_frames import sample_bilinear  # noqa: PLC0415

        p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        _tw, _th, x0, y0, w, h = self.ops.side_grid
        side_uv = np.stack([(p[:, 0] - x0) / w, (p[:, 1] - y0) / h], axis=-1)
        corners = np.asarray(self.ops.window_corners, dtype=np.float64)
        u, v = corners[1] - corners[0], corners[3] - corners[0]
        aperture_uv = np.stack([(p - corners[0]) @ (u / (u @ u)), (p - corners[0]) @ (v / (v @ v))], axis=-1)
        hidden = np.asarray(room_hidden, dtype=np.float64).reshape(-1, 1)
        room = ((1.0 - hidden) * sample_bilinear(self._room_side, side_uv)
                + hidden * sample_bilinear(self._exitance, aperture_uv))
        return room, sample_bilinear(self._back_mean, aperture_uv), sample_bilinear(self._walled, side_uv)

    def cloth_uniforms(self, program) -> None:
        """curtain.vert/.frag ROOM_SIDE's inputs: the room's irradiance on the cloth's room side
        (the gather's grid) and its rectangle, the cloth's two sides at the window's patches
        (:meth:`cloth_textures`) and the aperture's coordinates, the cloth's reflectance of the
        room's light and its forward transmittance of the window side's, the wall round the
        window (WALL_GRID)."""
        from catalog.render.passes.gl_common import (OCCLUSION_MAPS_UNIT, ROOM_SIDE_CLOTH_UNIT,  # noqa: PLC0415
                                                     ROOM_SIDE_UNIT, WALL_GRID_UNIT,
                                                     WINDOW_SIDE_CLOTH_UNIT)

        s = set_uniform
        terms = self.frame.terms
        inputs = terms.shading_inputs()
        self.frame.room_targets.get()["room_side"].use(location=ROOM_SIDE_UNIT)
        s(program, "u_room_side", ROOM_SIDE_UNIT)
        _tw, _th, x0, y0, w, h = self.ops.side_grid
        s(program, "u_room_side_rect", (float(x0), float(y0), 1.0 / float(w), 1.0 / float(h)))
        s(program, "u_room_side_reflectance", terms.curtain_room_reflectance_rgb(inputs))
        room_side, window_side = self.cloth_textures()
        room_side.use(location=ROOM_SIDE_CLOTH_UNIT)
        s(program, "u_room_side_cloth", ROOM_SIDE_CLOTH_UNIT)
        window_side.use(location=WINDOW_SIDE_CLOTH_UNIT)
        s(program, "u_window_side_cloth", WINDOW_SIDE_CLOTH_UNIT)
        corners = np.asarray(self.ops.window_corners, dtype=np.float64)
        u, v = corners[1] - corners[0], corners[3] - corners[0]
        s(program, "u_aperture_origin", tuple(float(x) for x in corners[0]))
        s(program, "u_aperture_s", tuple(float(x) for x in u / float(u @ u)))
        s(program, "u_aperture_t", tuple(float(x) for x in v / float(v @ v)))
        diffuse, directional = terms.curtain_forward_rgb(inputs)
        s(program, "u_window_side_diffuse", diffuse)
        s(program, "u_window_side_directional", directional)
        if "u_occlusion_maps" in program:   # beside the per-vertex occlusion (OCCLUSION_UNIT)
            self.frame.shadow.occlusion_uniforms(program, OCCLUSION_MAPS_UNIT)
        if "u_wall_grid" in program:
            self.wall_grid_texture().use(location=WALL_GRID_UNIT)
            s(program, "u_wall_grid", WALL_GRID_UNIT)

    def beam_uniforms(self, program, inputs) -> None:
        from catalog.render.curtain_frames import light_view_projection, shadow_texel_m  # noqa: PLC0415

        gl = self.frame.room_targets.get()
        s = set_uniform
        s(program, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_key_rgb", self.frame.terms.room_colours(inputs)["u_key_rgb"])
        gl["shadow"].use(location=2)
        s(program, "u_shadow", 2)
        s(program, "u_light_view_proj", gl_bytes(light_view_projection(inputs.key_to_light, placement=self.frame.placement)))
        s(program, "u_shadow_texel_m", shadow_texel_m(inputs.key_to_light, self.frame.shadow_texels, placement=self.frame.placement))
        s(program, "u_curtain_z", self.placement.curtain_z)
        s(program, "u_tan_sun_radius", math.tan(scene_lib.SUN_RADIUS_RAD))
        s(program, "u_window_z", self.placement.window_z)
        self._room_depth[0].use(location=4)
        s(program, "u_room_depth", 4)
        s(program, "u_room_depth_view_proj", gl_bytes(self.room_depth_view_projection(inputs.key_to_light)))
        s(program, "u_room_depth_offset_m", DEPTH_OFFSET_M)

    def prop_irradiance(self, positions, normals) -> np.ndarray:
        """(N, 3) the irradiance of the curtain's rod and rings (not in the room's file, so not
        receivers): the room's side (the room-side grid at the point, clamped) over the half
        of the sphere facing the room and the window's mean radiance x pi over the half facing
        it, blended by the normal (a sphere split in two halves, exact for a point on the
        window's plane seeing the room on one side and the window on the other)."""
        tw, th, x0, y0, w, h = self.ops.side_grid
        side = self._room_side
        i = np.clip(((positions[:, 0] - x0) / w * tw).astype(int), 0, tw - 1)
        j = np.clip(((positions[:, 1] - y0) / h * th).astype(int), 0, th - 1)
        towards_room = 0.5 * (1.0 + normals @ self.ops.window_normal)
        window = math.pi * self._window_mean
        return towards_room[:, None] * side[j, i] + (1.0 - towards_room)[:, None] * window[None, :]

    def _props(self):
        rod_p, rod_n = scene_lib.rod_mesh(self.placement)   # on the room's own window
        ring_p, ring_n = self.frame.ring_arrays
        positions = np.concatenate([rod_p, np.asarray(ring_p, "f4").reshape(-1, 3)])
        normals = np.concatenate([rod_n, np.asarray(ring_n, "f4").reshape(-1, 3)])
        return positions, normals

    def draw(self, view_proj, inputs) -> None:
        """The room, then the curtain's rod and rings, into the bound framebuffer (depth-tested)."""
        self._targets()
        beam = lambda program: self.beam_uniforms(program, inputs)  # noqa: E731
        self.draw_pass.draw(view_proj, beam)
        positions, normals = self._props()
        irradiance = self.prop_irradiance(positions.astype(np.float64), normals.astype(np.float64))
        self.draw_pass.draw_props(view_proj, positions, normals, irradiance, scene_lib.ROOM_ALBEDO, beam)

    def constant_irradiance(self, inputs, normals) -> np.ndarray:
        """(N, 3) the constant room's irradiance (room lighting off) at surfaces of ``normals``:
        the room's diffuse radiance as a grey wall of the scene's albedo shows it, pi L / rho,
        plus the fill light's normal irradiance x cos (the stand-ins eq. 8 takes for the room)."""
        colours = self.frame.terms.display_colours(inputs)
        ambient = math.pi * np.asarray(colours["u_room_rgb"], dtype=np.float64) / scene_lib.ROOM_ALBEDO
        fill = math.pi * np.asarray(colours["u_fill_rgb"], dtype=np.float64) / scene_lib.ROOM_ALBEDO
        cos = np.clip(np.asarray(normals, dtype=np.float64) @ np.asarray(inputs.fill_to_light, dtype=np.float64),
                      0.0, None)
        return ambient[None, :] + cos[:, None] * fill[None, :]

    def draw_constant(self, view_proj, inputs) -> None:
        """The room, the rod and the rings in the constant room's light (no beam, no window)."""
        # uploaded with every frame: a recorded frame's commands must not depend on the one before
        self.draw_pass.update(self.constant_irradiance(inputs, self.ops.normal))
        self.draw_pass.draw(view_proj, None)
        positions, normals = self._props()
        irradiance = self.constant_irradiance(inputs, normals.astype(np.float64))
        self.draw_pass.draw_props(view_proj, positions, normals, irradiance, scene_lib.ROOM_ALBEDO, None)
