"""The frame's room light by the precomputed transport (docs/room-transport.md).

Each room update:

1. the window's radiance into the room, from the curtain's own shading: the flat cloth and
   the outside drawn in oblique parallel views of the aperture, one per direction of a Gauss
   hemisphere quadrature in the window's frame (catalog.room.sh.hemisphere_quadrature;
   exact for the basis' products), a texel block per window patch averaged by the mip chain
   to the patch level, projected onto the hemispherical basis: c_pk = sum_j w_j L_pj H_k(w_j);
2. the receivers' irradiance E = T c (:meth:`Transport.irradiance`, every bounce), plus the
   bounces of the key's beam: its irradiance at each receiver (the normal irradiance x cos x
   the curtain's transmittance map x the room's own visibility to the key, by rays through
   the room's geometry) through :meth:`Transport.bounced` less the beam itself, which the
   room's pass draws per pixel;
3. the closed cloth reflects the room's light back in: its room side's irradiance at the
   window's patches (cosine-weighted rays from the aperture into the room, each landing on a
   receiver: E_side = G rho E) times its diffuse reflectance, a uniform radiance per patch
   added to c; the loop solved by fixed-point iteration (its gain, reflectance x the room's
   return, is well under one);
4. the curtain's room side: the same gather from the points of the cloth's room-side grid
   (the texture curtain.frag ROOM_SIDE reads per vertex).

Numpy on the host for 2-4 (the operators are compressed: a few milliseconds); GL for the
captures and the draw (catalog/render/passes/room_transport.py).
"""

from __future__ import annotations

import math

import numpy as np

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
#: Cosine-weighted rays from each point of the cloth's grids into the room.
GATHER_RAYS = 512
#: Fixed-point iterations of the cloth's reflection of the room's light back into it.
REFLECTION_ITERATIONS = 4
#: The room's depth map from the key (texels a side).
ROOM_DEPTH_TEXELS = 1024


def aperture_view_projection(window, direction, near_m: float = 1.5, far_m: float = 30.0) -> np.ndarray:
    """The oblique parallel projection of the window seen along -``direction`` (a unit
    direction into the room): a point maps to the aperture point it projects onto along the
    direction (NDC x, y = 2 (s, t) - 1 over the window's u and v edges), its depth its
    distance into the room along the normal, from ``near_m`` (near) to -``far_m`` (far)."""
    o, u, v, n = window.origin, window.u_edge, window.v_edge, window.normal
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
    return ndc @ m


def gather_operator(transport, points: np.ndarray, normal: np.ndarray, rays_per_point: int,
                    rng, caster=None) -> "object":
    """G (N, E), sparse: the share of cosine-weighted rays from ``points`` about ``normal``
    that land on the front of each receiver (rays that leave through the window or meet a
    back face carry nothing): the irradiance there is pi x G (rho E / pi) = G rho E."""
    import scipy.sparse  # noqa: PLC0415

    from catalog.room.receivers import cosine_directions  # noqa: PLC0415

    rec = transport.receivers
    n = np.broadcast_to(np.asarray(normal, dtype=np.float64), (len(points) * rays_per_point, 3))
    o = np.repeat(points, rays_per_point, axis=0) + 1e-4 * n
    d = cosine_directions(np.ascontiguousarray(n), rng)
    dist, tri = caster.intersect(o, d)
    hit = tri >= 0
    rows = np.repeat(np.arange(len(points)), rays_per_point)
    p = o[hit] + dist[hit, None] * d[hit]
    receiver = transport.receiver_at(tri[hit], p)
    front = np.einsum("ni,ni->n", d[hit], rec.normal[np.maximum(receiver, 0)]) < 0
    ok = (receiver >= 0) & front
    return scipy.sparse.csr_matrix((np.full(int(ok.sum()), 1.0 / rays_per_point),
                                    (rows[hit][ok], receiver[ok])), shape=(len(points), rec.count))


class RoomTransportLight(Pass):
    """The room's light by the precomputed transport, for the frame's room (a built-in name
    or a .glb): the captures, the operator, the cloth's reflection, the beam's bounces, the
    curtain's room side; draws the room (:meth:`draw`).

    In: the curtain and background passes (the captures), the shadow pass's transmittance
    map, the scene terms. Out: the receivers' irradiance (:attr:`irradiance`), the room-side
    grid ``room_side`` of frame.room_targets, the room into the HDR target."""

    def __init__(self, frame, room):
        super().__init__(frame)
        from catalog.render.passes.room_transport import RoomTransportPass  # noqa: PLC0415
        from catalog.room.cache import room_transport  # noqa: PLC0415
        from catalog.room.rays import ray_caster  # noqa: PLC0415

        self.room = room
        self.transport = room_transport(room)
        self.window = room.window
        self.draw_pass = RoomTransportPass(self.ctx, self.transport, room)
        tris = room.triangles()
        self._caster = ray_caster(tris)
        dirs, weights = sh.hemisphere_quadrature(CAPTURE_THETA, CAPTURE_PHI)
        self._local_dirs, self._weights = dirs, weights
        self._world_dirs = dirs @ self.transport.frame        # rows x, y, z: local -> world
        self._basis = sh.hemi_basis(dirs, self.transport.params.order)   # (J, K)
        nu, nv = self.transport.params.patches
        self._patches = (nu, nv)
        rng = np.random.default_rng(1)
        # the window's patch centres and the cloth's room-side grid: the gathers
        su, tv = np.meshgrid((np.arange(nu) + 0.5) / nu, (np.arange(nv) + 0.5) / nv)
        self._g_patch = gather_operator(self.transport, self._aperture_points(su.ravel(), tv.ravel()),
                                        self.window.normal, GATHER_RAYS, rng, self._caster)
        from catalog.render import room_light  # noqa: PLC0415  (the cloth's room-side grid)

        tw, th = room_light.CURTAIN_SIDE_TEXELS
        x0, y0, w, h = room_light.curtain_side_rect()
        gx, gy = np.meshgrid(x0 + (np.arange(tw) + 0.5) / tw * w, y0 + (np.arange(th) + 0.5) / th * h)
        plane_z = float(self.window.centre @ self.window.normal) / float(self.window.normal[2])
        side = np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, plane_z)], axis=1)
        self._side_size = (tw, th)
        self._g_side = gather_operator(self.transport, side, self.window.normal, GATHER_RAYS // 4,
                                       rng, self._caster)
        # the basis' uniform radiance: c_0 of L = 1 (H_0 is constant)
        self._uniform_c0 = float(2 * math.pi * self._basis[0, 0])
        self._capture = None
        self._room_depth = None
        self._visibility_key = None
        self.irradiance = np.zeros((self.transport.receivers.count, 3))
        self.coefficients = np.zeros((nu * nv, self._basis.shape[1], 3))

    def _aperture_points(self, s, t) -> np.ndarray:
        c = self.window.corners
        return (((1 - s) * (1 - t))[:, None] * c[0] + (s * (1 - t))[:, None] * c[1]
                + (s * t)[:, None] * c[2] + ((1 - s) * t)[:, None] * c[3])

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

    def framebuffers(self) -> list:
        out = []
        if self._capture is not None:
            out.append(self._capture[2])
        if self._room_depth is not None:
            out.append(self._room_depth[1])
        return out

    def release(self) -> None:
        for group in (self._capture, self._room_depth):
            for obj in group or ():
                obj.release()
        self._capture = self._room_depth = None
        self.draw_pass.release()

    # ------------------------------------------------------------------ 1. the captures
    def capture_overrides(self) -> dict:
        """The curtain's values as the room sees them: the luminaire capture's (no sun disc
        seen through it, which the beam carries; no room light on its room side, which step 3
        reflects), with the directional lobe kept: the views resolve it by direction."""
        out = self.frame.terms.capture_overrides()
        out["u_a_spec"] = self.frame.terms.scene_values()["u_a_spec"]
        return out

    def draw_captures(self, inputs) -> None:
        mgl = self.mgl
        texture, _depth, fbo = self._targets()
        nu, nv = self._patches
        k = CAPTURE_TEXELS_PER_PATCH
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.disable(mgl.BLEND)
        self.ctx.depth_func = "<="
        overrides = self.capture_overrides()
        centre = self.window.centre
        for j, w in enumerate(self._world_dirs):
            self.ctx.viewport = (j * nu * k, 0, nu * k, nv * k)
            view_proj = aperture_view_projection(self.window, w)
            eye = tuple(float(v) for v in centre + 1e3 * w)   # the view's rays all ~ -w
            if not self.frame.curtain_open:
                self.frame.curtain.draw_flat(view_proj, eye, overrides)
            self.frame.background.draw(view_proj, inputs, camera_position=eye, sun_disc=False, capture=True)
        self.ctx.depth_func = "<"
        self.ctx.disable(mgl.DEPTH_TEST)
        texture.build_mipmaps()

    def read_captures(self) -> np.ndarray:
        """(J, nv, nu, 3) each direction's mean radiance over each patch (row 0: the v edge's start)."""
        texture = self._capture[0]
        nu, nv = self._patches
        level = int(math.log2(CAPTURE_TEXELS_PER_PATCH))
        count = len(self._weights)
        data = np.frombuffer(texture.read(level=level), dtype="f4").reshape(nv, count * nu, 4)[..., :3]
        return data.reshape(nv, count, nu, 3).transpose(1, 0, 2, 3).astype(np.float64)

    def project(self, radiance: np.ndarray) -> np.ndarray:
        """(P, K, 3) coefficients of captures (J, nv, nu, 3): c_pk = sum_j w_j L_pj H_k(w_j)."""
        per_patch = radiance.reshape(len(self._weights), -1, 3)      # (J, P, 3), p = iu + nu iv
        return np.einsum("jk,j,jpc->pkc", self._basis, self._weights, per_patch)

    # ------------------------------------------------------------------ 2. the beam
    def room_depth_view_projection(self, to_light) -> np.ndarray:
        """The key's parallel view of the window's cross-section (the transmittance map's),
        its depth over the whole room."""
        from catalog.render import room_light  # noqa: PLC0415

        m = room_light.light_view_projection(to_light).copy()
        to_light = np.asarray(to_light, dtype=np.float64) / np.linalg.norm(to_light)
        corners = np.array([[x, y, z] for x in self.room.bounds()[:, 0] for y in self.room.bounds()[:, 1]
                            for z in self.room.bounds()[:, 2]])
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
        """(E,) each receiver's share of 4 points that see the key through the window (rays)."""
        key = tuple(round(float(v), 6) for v in to_light)
        if key != self._visibility_key:
            rec = self.transport.receivers
            rng = np.random.default_rng(2)
            samples = 4
            idx = np.repeat(np.arange(rec.count), samples)
            d = np.broadcast_to(np.asarray(to_light, dtype=np.float64), (idx.size, 3))
            o = rec.sample_points(idx, rng) + 1e-4 * rec.normal[idx]
            from catalog.room.rays import ray_caster  # noqa: PLC0415

            if not hasattr(self, "_window_caster"):
                self._window_caster = ray_caster(self.window.triangles())
            _, tri_room = self._caster.intersect(o, np.ascontiguousarray(d))
            dist_w, tri_w = self._window_caster.intersect(o, np.ascontiguousarray(d))
            through = (tri_w >= 0) & (tri_room < 0)
            cos = np.clip(rec.normal @ np.asarray(to_light, dtype=np.float64), 0.0, None)
            self._visibility = cos * through.reshape(rec.count, samples).mean(axis=1)
            self._visibility_points = (o.reshape(rec.count, samples, 3)[:, 0])
            self._visibility_key = key
        return self._visibility

    def beam_irradiance(self, inputs) -> np.ndarray:
        """(E, 3) the key's beam at the receivers: key x cos x visibility x the curtain's
        transmittance (the map's coarse level read back at the receivers' centres)."""
        from catalog.render import room_light  # noqa: PLC0415

        vis = self._key_visibility(inputs.key_to_light)
        key_rgb = np.asarray(self.frame.terms.room_colours(inputs)["u_key_rgb"], dtype=np.float64)
        if not np.any(vis > 0) or not np.any(key_rgb > 0):
            return np.zeros((vis.size, 3))
        shadow = self.frame.room_targets.get()["shadow"]
        n = self.frame.shadow_texels
        level = max(0, int(math.log2(n)) - 7)      # 128 texels a side at most
        side = max(n >> level, 1)
        t = np.frombuffer(shadow.read(level=level), dtype=np.float16).reshape(side, side, 4)[..., :3]
        m = room_light.light_view_projection(inputs.key_to_light)
        centre = self.transport.receivers.centre
        clip = np.c_[centre, np.ones(len(centre))] @ m.T
        uv = np.clip(clip[:, :2] * 0.5 + 0.5, 0.0, 1.0 - 1e-6)
        trans = t[(uv[:, 1] * side).astype(int), (uv[:, 0] * side).astype(int)].astype(np.float64)
        before = (inputs.key_to_light[2] < 0) & (centre[:, 2] < scene_lib.WINDOW_Z - 1e-4)
        trans[before] = 1.0
        return vis[:, None] * key_rgb[None, :] * trans

    # ------------------------------------------------------------------ the whole update
    def update(self, inputs) -> None:
        """Steps 1-4 (the shadow pass has drawn the transmittance map)."""
        self.draw_captures(inputs)
        self.draw_room_depth(inputs)
        c_window = self.project(self.read_captures())
        t = self.transport
        rho = t.receivers.albedo
        beam = self.beam_irradiance(inputs)
        beam_bounces = t.bounced(beam) - beam if np.any(beam) else np.zeros_like(beam)
        e_window = t.irradiance(c_window)
        reflectance = np.asarray(self.frame.terms.window_albedo_rgb(inputs), dtype=np.float64)
        c = c_window
        e = e_window
        if np.any(reflectance > 0):
            for _ in range(REFLECTION_ITERATIONS):
                side = self._g_patch @ (rho * (e + beam_bounces + beam))     # (P, 3) irradiance
                c = c_window.copy()
                c[:, 0, :] += self._uniform_c0 * reflectance[None, :] * side / math.pi
                e = t.irradiance(c)
        self.coefficients = c
        self.irradiance = e + beam_bounces
        self.draw_pass.update(self.irradiance)
        room_side = self._g_side @ (rho * (self.irradiance + beam))
        tw, th = self._side_size
        rgba = np.concatenate([room_side.reshape(th, tw, 3), np.ones((th, tw, 1))], axis=-1)
        self.frame.room_targets.get()["room_side"].write(np.ascontiguousarray(rgba, dtype="f4").tobytes())

    def beam_uniforms(self, program, inputs) -> None:
        from catalog.render import room_light  # noqa: PLC0415

        gl = self.frame.room_targets.get()
        s = set_uniform
        s(program, "u_key_to_light", tuple(float(v) for v in inputs.key_to_light))
        s(program, "u_key_rgb", self.frame.terms.room_colours(inputs)["u_key_rgb"])
        gl["shadow"].use(location=2)
        s(program, "u_shadow", 2)
        s(program, "u_light_view_proj", gl_bytes(room_light.light_view_projection(inputs.key_to_light)))
        s(program, "u_shadow_texel_m", room_light.shadow_texel_m(inputs.key_to_light, self.frame.shadow_texels))
        s(program, "u_curtain_z", scene_lib.CURTAIN_Z)
        s(program, "u_tan_sun_radius", math.tan(scene_lib.SUN_RADIUS_RAD))
        s(program, "u_window_z", scene_lib.WINDOW_Z)
        self._room_depth[0].use(location=4)
        s(program, "u_room_depth", 4)
        s(program, "u_room_depth_view_proj", gl_bytes(self.room_depth_view_projection(inputs.key_to_light)))
        s(program, "u_room_depth_offset_m", 0.01)

    def draw(self, view_proj, inputs) -> None:
        """The room into the bound framebuffer (depth-tested)."""
        self._targets()
        self.draw_pass.draw(view_proj, lambda program: self.beam_uniforms(program, inputs))
