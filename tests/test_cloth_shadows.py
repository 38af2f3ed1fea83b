"""Issue 11's terms in the frame, on read-back pixels against independent numpy geometry.

- the key light on the cloth shaded by the window wall (KEY_SHADOW's window mask) and by the
  folds nearer the light (the front-layer map), checked against rays cast in numpy;
- the outside hidden from the cloth by its own folds and by the window wall (SKY_OCCLUSION),
  checked against the same directions cast in numpy;
- the ambient term by view (the HG lobes over a hemisphere for a view at mu = |n . v|),
  checked against a brute-force quadrature;
- the sill and the reveals lit by the key (room_window_beam for points within the wall).

The shader's equations themselves (these terms in eq. 8) are checked per pixel against the
float64 reference in tests/test_render_frame.py (the G-buffer carries the shadow terms).
Bounds were set before looking at the measured values; each docstring states its bound.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from catalog.optics import shading_reference as ref
from catalog.render import curtain_frames
from catalog.render import scene as scene_lib
from catalog.render.frame import FrameRenderer
from benchmarks import key_shadow_bias
from catalog.render.raycast import first_hit, mesh_triangles
from catalog.render.settings import orbit
from catalog.render.scene import KEY_AZIMUTH_DEG

pytestmark = [pytest.mark.gl, pytest.mark.slow]   # each takes 0.5 s or more

SIZE = (96, 72)
LUMA = np.array([0.2126, 0.7152, 0.0722])


def _renderer(gl, preset, light="D65", mesh=None, camera=(0.0, 0.0, 1.6)):
    r = FrameRenderer(gl, SIZE)
    r.update(fabric=preset, light=light, fluorescence="off", camera=orbit(*camera))
    if mesh is not None:
        r.set_mesh(mesh.positions, mesh.normals, mesh.uvs, mesh.tangents, mesh.indices)
    return r


def _without_key_shadow(r, g) -> np.ndarray:
    """The luminance (cd m^-2) of the G-buffer's curtain pixels as the float64 twin shades
    them with the key's shadow taken away (the window's mask 1, no layer in front of the key;
    the outside's occlusion kept): the shadow-free frame the shaded one is compared with."""
    unshaded = dict(g)
    shadows = g["shadows"].copy()
    shadows[..., 0], shadows[..., 1] = 1.0, 0.0
    unshaded["shadows"] = shadows
    unshaded["second_coverage"] = np.zeros_like(g["second_coverage"])
    return r.twin_linear_srgb(unshaded, g["mask"]) @ LUMA


def _through_opening(p, d):
    """(P,) whether rays p + s d (s > 0) cross the window opening in both wall planes, and
    the distance (m) of the crossing points from the opening's edges (+ inside, - outside)."""
    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    z0 = scene_lib.ROOM_BOX[2][0]
    margin = np.full(p.shape[0], np.inf)
    for z in (z0, z0 - scene_lib.WALL_THICKNESS_M):
        s = (z - p[:, 2]) / d[:, 2]
        q = p[:, :2] + s[:, None] * d[:, :2]
        m = np.minimum.reduce([q[:, 0] - wx0, wx1 - q[:, 0], q[:, 1] - wy0, wy1 - q[:, 1]])
        margin = np.minimum(margin, np.where(s > 0, m, np.inf))
    return margin > 0, margin


def test_window_wall_shades_the_upper_curtain(gl, make_preset):
    """A flat curtain under a key 60 deg high: the G-buffer's window mask is 1 where the ray
    to the light leaves through the opening and 0 where the wall stops it, within 1e-3 at
    every pixel more than 1 cm from the shadow's edge (the penumbra there is < 1 mm), both
    sides present; the shaded pixels are at most half as bright as without the shadow (the
    float64 twin without it)."""
    mesh = scene_lib.draped_curtain(columns=40, rows=30, depth_m=0.0)
    r = _renderer(gl, make_preset(direct=0.0, fluorescent=False), mesh=mesh, camera=(0.0, 0.0, 2.6))
    r.update(key_direction_deg=(60.0, KEY_AZIMUTH_DEG))
    g = r.render_gbuffer()
    mask = g["mask"]
    p = g["position"][mask].astype(np.float64)
    to_light = r.shading_inputs().key_to_light
    lit, margin = _through_opening(p, np.repeat(to_light[None], p.shape[0], 0))
    sure = np.abs(margin) > 0.01
    beam = g["shadows"][mask][:, 0]
    assert sure.sum() > 0.8 * mask.sum()
    assert lit[sure].any() and (~lit[sure]).any()
    assert np.abs(beam[sure] - lit[sure]).max() < 1e-3
    shaded = g["radiance"][mask][sure & ~lit] @ LUMA
    unshaded = _without_key_shadow(r, g)[sure & ~lit]
    assert shaded.mean() < 0.5 * unshaded.mean()
    r.release()


def _key_across_the_folds(gl, make_preset, mesh):
    """A cloth with no holes on ``mesh`` under a key 20 deg high and 60 deg aside (across the
    folds), the room unlit so that its light is off the cloth's room side (the room's capture draws the cloth with the
    key's shadows, and these tests are about the key on the cloth alone): the renderer, its
    G-buffer, the curtain mask, the pixels' positions and the direction to the light."""
    r = _renderer(gl, make_preset(direct=0.0, fluorescent=False), mesh=mesh)
    r.update(key_direction_deg=(20.0, 60.0), room_lighting=False)
    g = r.render_gbuffer()
    mask = g["mask"]
    p = g["position"][mask].astype(np.float64)
    return r, g, mask, p, np.asarray(r.shading_inputs().key_to_light, dtype=np.float64)


@pytest.mark.slow
def test_folds_shade_the_cloth_behind_them(gl, make_preset):
    """The default drape under a key 20 deg high and 60 deg aside (across the folds): a pixel
    counts as behind a fold (front coverage > 0.5 in the G-buffer: the maps are read with a
    depth ramp and a 2x2 filter) exactly where a ray cast in numpy towards the light meets the
    mesh more than 3 mm away, on at least 98 % of the pixels more than 1.5 map texels from a
    shadow's edge (the map is looked up at its nearest texels). Issue 11 replaced the constant
    2 cm depth bias, which this test had to exclude (occluders within 1-3 cm), by a
    slope-scaled one chosen on this drape (benchmarks/key_shadow_bias.py: 100 % here, the
    2 cm bias 99.2 %; the bound 98 % was set with the choice). The shaded pixels' key light is
    dimmed to the layer's transmittance: their luminance falls by more than 20 % against the
    shadow taken away (the float64 twin without it), the rest changes by less than 1e-3."""
    mesh = scene_lib.draped_curtain(columns=60, rows=40)
    r, g, mask, p, to_light = _key_across_the_folds(gl, make_preset, mesh)
    expected, clear = key_shadow_bias.shadow_truth(p, to_light, mesh)
    behind = g["shadows"][mask][:, 1] > 0.5   # coverage 1 (LD 0): the ramp's and the 2x2 filter's midpoint
    beam = g["shadows"][mask][:, 0]
    assert expected[clear].mean() > 0.05   # the light really crosses folds
    assert (behind[clear] == expected[clear]).mean() > 0.98
    on = g["radiance"][mask] @ LUMA
    off = _without_key_shadow(r, g)
    cover = g["shadows"][mask][:, 1]
    shaded = behind & (beam > 0.999)
    free = (cover == 0) & (beam > 0.999)
    assert shaded.sum() > 20 and free.sum() > 20
    assert np.median(on[shaded] / off[shaded]) < 0.8
    assert np.abs(on[free] / off[free] - 1).max() < 1e-3
    r.release()


def _layers_towards(points, to_light, triangles, gap_m=0.01, most=4):
    """(P,) how many layers of the mesh a ray from each point towards the light crosses, hits
    closer than ``gap_m`` after the last one counted as the same layer."""
    count = np.zeros(points.shape[0], dtype=int)
    origin = points + 1e-4 * to_light
    alive = np.ones(points.shape[0], dtype=bool)
    for _ in range(most):
        distance = first_hit(origin, to_light, triangles)
        hit = alive & np.isfinite(distance)
        count += hit
        origin = np.where(hit[:, None], origin + (np.where(hit, distance, 0.0) + gap_m)[:, None] * to_light, origin)
        alive = hit
    return count


def test_the_key_shadow_counts_a_second_layer(gl, make_preset):
    """KEY_SHADOW's second layer (issue 11, seventh round; the front-layer map peeled) on a
    drape folded 15 cm deep, the key 20 deg high and 60 deg aside, a cloth with no holes
    (coverage 1): against the layers a ray cast in numpy towards the light crosses (more than
    1 cm apart), the G-buffer's second coverage is above 0.5 on at least 80 % of the pixels
    behind two layers or more, and below 0.5 on at least 95 % of those behind one; the shaded
    luminance behind two layers is below that with the second layer off (set_key_second_layer)
    in the median. Bounds set before the first run."""
    mesh = scene_lib.draped_curtain(columns=60, rows=40, depth_m=0.15)
    r, g, mask, p, to_light = _key_across_the_folds(gl, make_preset, mesh)
    layers = _layers_towards(p, to_light, mesh_triangles(mesh))
    second = g["second_coverage"][mask]
    two, one = layers >= 2, layers == 1
    assert two.sum() > 50 and one.sum() > 50
    assert (second[two] > 0.5).mean() >= 0.8, (second[two] > 0.5).mean()
    assert (second[one] < 0.5).mean() >= 0.95, (second[one] < 0.5).mean()
    on = g["radiance"][mask] @ LUMA
    r.update(key_second_layer=False)
    g_off = r.render_gbuffer()
    assert not g_off["second_coverage"][mask].any()
    off = g_off["radiance"][mask] @ LUMA
    assert np.median(on[two] / off[two]) < 1.0
    r.release()


@pytest.mark.slow
def test_outside_occlusion_matches_rays_cast_in_numpy(gl, make_preset):
    """The G-buffer's occlusion of the outside on the default drape against the same 16
    directions cast in numpy from the pixels' positions (the vertex values are interpolated,
    the maps' texels are 2 cm): the wall's share within 0.1 on 95 % of the pixels and the
    cloth's share within 0.15 in the mean; the folds' troughs (the cloth farthest from the
    window) are hidden more than their crests by at least 0.1 (folds 15 cm deep; the default
    7 cm drape gave 0.03 in a first run, too shallow to test this on: changed after seeing
    it). A flat curtain hides nothing of itself (cloth share < 0.02 everywhere). The room's
    side (issue 11, fourth round: the opposite directions, from the same maps' farthest layer):
    within 0.15 of the numpy rays in the mean, the folds' room-side troughs (the cloth nearest the
    window) hidden more than their crests by at least 0.1, and nothing on the flat curtain; the
    view's continuation (ROOM_SIDE: the map nearest the view ray) within 0.15 in the mean of a
    ray cast along that direction."""
    mesh = scene_lib.draped_curtain(columns=60, rows=40, depth_m=0.15)
    r = _renderer(gl, make_preset(direct=0.0, fluorescent=False), mesh=mesh)
    g = r.render_gbuffer()
    mask = g["mask"]
    p = g["position"][mask].astype(np.float64)
    shadows = g["shadows"][mask]
    rng = np.random.default_rng(0)
    pick = rng.choice(p.shape[0], size=min(400, p.shape[0]), replace=False)
    q = p[pick]
    triangles = mesh_triangles(mesh)
    cloth = np.zeros(q.shape[0])
    wall = np.zeros(q.shape[0])
    room = np.zeros(q.shape[0])
    directions = curtain_frames.occlusion_directions()
    for d in directions:
        opening, _ = _through_opening(q, np.repeat(d[None], q.shape[0], 0))
        hit = np.isfinite(first_hit(q + 0.03 * d, d, triangles))
        cloth += opening & hit
        wall += ~opening
        room += np.isfinite(first_hit(q - 0.03 * d, -d, triangles))
    cloth /= len(directions)
    wall /= len(directions)
    room /= len(directions)
    hidden_room = g["room_occlusion"][mask]
    assert (np.abs(shadows[pick, 3] - wall) < 0.1).mean() > 0.95
    assert np.abs(shadows[pick, 2] - cloth).mean() < 0.15
    assert np.abs(hidden_room[pick] - room).mean() < 0.15
    # ROOM_SIDE's view's continuation, seen obliquely across the folds: the direction nearest
    # the view ray, cast from the pixel
    r.update(camera=orbit(55.0, 0.0, 2.0))
    oblique = r.render_gbuffer()
    assert r.room_side_active()
    all_o = oblique["position"][oblique["mask"]].astype(np.float64)
    chosen = rng.choice(all_o.shape[0], size=min(400, all_o.shape[0]), replace=False)
    qo = all_o[chosen]
    ray = qo - np.asarray(r.camera.position, dtype=np.float64)
    ray /= np.linalg.norm(ray, axis=1, keepdims=True)
    nearest = directions[np.argmax(ray @ directions.T, axis=1)]
    view_hit = np.array([np.isfinite(first_hit(qo[k:k + 1] + 0.03 * nearest[k], nearest[k], triangles))[0]
                         for k in range(qo.shape[0])])
    assert view_hit.mean() > 0.1   # the folds hide part of the continuations
    seen = oblique["room_occlusion_view"][oblique["mask"]][chosen]
    assert np.abs(seen - view_hit).mean() < 0.15
    r.update(camera=orbit(0.0, 0.0, 2.0))
    amplitude = np.ptp(np.asarray(mesh.positions)[:, 2]) / 2
    trough = p[:, 2] > scene_lib.CURTAIN_Z + 0.6 * amplitude
    crest = p[:, 2] < scene_lib.CURTAIN_Z - 0.6 * amplitude
    assert trough.sum() > 20 and crest.sum() > 20
    assert shadows[trough, 2].mean() - shadows[crest, 2].mean() > 0.1
    assert hidden_room[crest].mean() - hidden_room[trough].mean() > 0.1

    flat = scene_lib.draped_curtain(columns=40, rows=30, depth_m=0.0)
    r.set_mesh(flat.positions, flat.normals, flat.uvs, flat.tangents, flat.indices)
    g = r.render_gbuffer()
    assert g["shadows"][g["mask"]][:, 2].max() < 0.02
    assert g["room_occlusion"][g["mask"]].max() < 0.02
    r.release()


def test_ambient_by_view_against_a_brute_force_quadrature():
    """hg_hemisphere_factors_by_view: at mu = 1 the closed form (1e-6); at mu = 0.5 and 0.2,
    for g = 0.5 and -0.3, a 2-D midpoint rule over the light's hemisphere (1200 x 2400 cells)
    within 0.5 %; the forward lobe of g = 0.83 falls below a third of its normal-view value
    at grazing views (mu = 0.1)."""
    for g in (0.5, -0.3, 0.83):
        forward, backward = ref.hg_hemisphere_factors_by_view(g)
        closed = ref.hg_hemisphere_factors(g)
        assert abs(forward[-1] - closed[0]) < 1e-6 and abs(backward[-1] - closed[1]) < 1e-6
    n_t, n_p = 1200, 2400
    theta = (np.arange(n_t) + 0.5) * (math.pi / 2) / n_t
    phi = (np.arange(n_p) + 0.5) * 2 * math.pi / n_p
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    t = np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)], -1)
    weight = np.cos(tt) * np.sin(tt) * (math.pi / 2 / n_t) * (2 * math.pi / n_p)
    for g in (0.5, -0.3):
        forward, backward = ref.hg_hemisphere_factors_by_view(g)
        for mu in (0.5, 0.25):
            v = np.array([math.sqrt(1 - mu * mu), 0.0, mu])
            node = int(round(mu * (len(ref.AMBIENT_VIEW_NODES) - 1)))
            assert abs(ref.AMBIENT_VIEW_NODES[node] - mu) < 1e-12
            for sign, table in ((1.0, forward), (-1.0, backward)):
                cos_g = (t * np.array([1.0, 1.0, sign])) @ v    # travel from that hemisphere
                phase = (1 - g * g) / (4 * math.pi * (1 + g * g - 2 * g * cos_g) ** 1.5)
                brute = float(np.sum(phase * weight))
                assert abs(table[node] - brute) < 5e-3 * brute, (g, mu, sign, table[node], brute)
    forward, _ = ref.hg_hemisphere_factors_by_view(0.83)
    grazing = np.interp(0.1, ref.AMBIENT_VIEW_NODES, forward)
    assert grazing < forward[-1] / 3


def test_sky_share_against_a_brute_force_quadrature():
    """hg_sky_share (issue 11, round 2): the share of an HG lobe about r above the horizon
    against a 2-D midpoint rule over the sphere (1200 x 2400 cells) within 2e-3 at r_y = 0.5,
    -0.25 and 0.875 for g = 0.83 and -0.3; 1/2 at r_y = 0 and for g = 0 at any r_y (1e-9 and
    1e-6); the forward lobe looking up sees mostly sky, looking down mostly ground."""
    n_t, n_p = 1200, 2400
    theta = (np.arange(n_t) + 0.5) * math.pi / n_t
    phi = (np.arange(n_p) + 0.5) * 2 * math.pi / n_p
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    t = np.stack([np.sin(tt) * np.cos(pp), np.cos(tt), np.sin(tt) * np.sin(pp)], -1)  # y = cos theta
    weight = np.sin(tt) * (math.pi / n_t) * (2 * math.pi / n_p)
    nodes = ref.AMBIENT_VIEW_NODES
    for g in (0.83, -0.3):
        table = ref.hg_sky_share(g)
        assert abs(table[len(nodes) // 2] - 0.5) < 1e-9
        for ry in (0.5, -0.25, 0.875):
            node = int(round((ry + 1) / 2 * (len(nodes) - 1)))
            assert abs(2 * nodes[node] - 1 - ry) < 1e-12
            r = np.array([math.sqrt(1 - ry * ry), ry, 0.0])
            cos_g = t @ r
            phase = (1 - g * g) / (4 * math.pi * (1 + g * g - 2 * g * cos_g) ** 1.5)
            brute = float(np.sum(phase * weight * (t[..., 1] > 0)) / np.sum(phase * weight))
            assert abs(table[node] - brute) < 2e-3, (g, ry, table[node], brute)
    assert np.allclose(ref.hg_sky_share(0.0), 0.5, atol=1e-6)
    forward = ref.hg_sky_share(0.83)
    assert forward[-1] > 0.9 and forward[0] < 0.1


@pytest.mark.slow
def test_the_sill_is_lit_by_the_sun(gl, make_preset):
    """Curtain open, a key 60 deg high, the living room (its window frame fills the wall's
    depth round the aperture): the frame's bottom (its top face at the aperture's bottom,
    between the wall's planes) seen from the room receives the beam: its radiance is at least
    90 % of albedo / pi x the key's luminance x cos(incidence) where the sun's ray from it
    leaves through the outer plane 2 cm or more inside the opening (it was black before issue 11)."""
    r = _renderer(gl, make_preset(direct=0.0, fluorescent=False), camera=(0.0, 35.0, 1.2))
    r.update(key_direction_deg=(60.0, KEY_AZIMUTH_DEG), curtain_open=True, bloom=False, room="living")
    r.render()
    img = r.read_linear()
    w, h = r.size
    eye = np.asarray(r.camera.position, dtype=np.float64)
    d = curtain_frames.pixel_rays(r.camera.view_projection(w / h), eye, r.size)
    # the pixels whose centre ray first meets the frame's bottom facing up (the room's own
    # triangles, float64 rays)
    from catalog.room.rays import NumpyRays

    ops = r.room_transport.ops
    names = [surface.name for surface in ops.surfaces]
    dist, hit = NumpyRays(ops.corners).intersect(np.repeat(eye[None], d[..., 0].size, 0), d.reshape(-1, 3))
    hit = hit.reshape(d.shape[:2])
    frame_bottom = (ops.surface == names.index("window_frame_bottom")) & (ops.normal[:, 1] > 0.99)
    sill = (hit >= 0) & frame_bottom[np.maximum(hit, 0)]
    p = eye + dist.reshape(d.shape[:2])[..., None] * d
    to_light = np.asarray(r.shading_inputs().key_to_light, dtype=np.float64)
    _, margin = _through_opening(p[sill], np.repeat(to_light[None], sill.sum(), 0))
    assert sill.sum() >= 10
    open_ = margin > 0.02
    assert open_.sum() >= 10
    albedo = float(np.asarray(ops.surfaces[names.index("window_frame_bottom")].factor) @ LUMA)
    key_y = float(np.asarray(r.terms.display_colours(r.shading_inputs())["u_key_rgb"]) @ LUMA)
    expected = albedo / math.pi * key_y * to_light[1]
    assert (img[sill][open_] @ LUMA).min() > 0.9 * expected
    r.release()


def _cloth_maps(r) -> dict:
    """The cloth's shadow maps as drawn (bytes): the key's front layer, its visibility over
    the uv, the occlusion atlas and each vertex's occlusion."""
    gl = r.room_targets.get()
    return {name: gl[name].read() for name in ("key_front", "key_visibility", "occlusion",
                                              "vertex_occlusion") if name in gl}


def test_cloth_shadow_maps_kept_while_their_inputs_do_not_change(gl, monkeypatch):
    """The shadow pass keeps the maps whose inputs did not change (ShadowPass._kept): after a
    change of fluorescence and room lamp (the key's direction, the mesh and the room the
    same) the occlusion maps are not drawn again, after a change of the sun's hour the key's
    are and the occlusion's are not; each frame's maps and image are bit for bit those of a
    renderer that draws the same scene from nothing. A recording context (the web export's)
    notes the maps' draws in every frame."""
    from catalog.render.passes.shadow import ShadowPass
    from catalog.render.settings import SunHour
    from catalog.web.record import RecordingContext

    calls = {"occlusion": 0, "key": 0}
    draw_occlusion, draw_key = ShadowPass._draw_occlusion_maps, ShadowPass._draw_key_front
    monkeypatch.setattr(ShadowPass, "_draw_occlusion_maps",
                        lambda self: (calls.__setitem__("occlusion", calls["occlusion"] + 1),
                                      draw_occlusion(self))[1])
    monkeypatch.setattr(ShadowPass, "_draw_key_front",
                        lambda self, *a: (calls.__setitem__("key", calls["key"] + 1),
                                          draw_key(self, *a))[1])
    scenes = [dict(light=SunHour(10.0), fluorescence="physical", lamps=[]),
              dict(light=SunHour(10.0), fluorescence="off", lamps=[("A", (1.3, 0.2, 1.0))]),
              dict(light=SunHour(15.0), fluorescence="off", lamps=[])]
    common = dict(fabric="lace-fwa", patterned=True, room_lighting=False, camera=orbit(0.0, 0.0, 1.6))
    kept = FrameRenderer(gl, SIZE)
    counts = []
    try:
        for scene in scenes:
            kept.update(**common, **scene)
            kept.render()
            counts.append(dict(calls))
            fresh = FrameRenderer(gl, SIZE)
            try:
                fresh.update(**common, **scene)
                fresh.render()
                assert np.array_equal(kept.read_srgb8(), fresh.read_srgb8())
                want = _cloth_maps(fresh)
                assert _cloth_maps(kept) == want and len(want) == 4
            finally:
                fresh.release()
            calls["occlusion"] -= 1   # the fresh renderer's own draws
            calls["key"] -= 1
    finally:
        kept.release()
    assert counts == [{"occlusion": 1, "key": 1}, {"occlusion": 1, "key": 1},
                      {"occlusion": 1, "key": 2}], counts

    rec = RecordingContext(gl)
    recorder = FrameRenderer(rec, SIZE, specialise=False)
    try:
        recorder.update(**common, **scenes[0], ev=12.0)   # a fixed exposure, as the export
        before = dict(calls)                                # records: no meter read-back
        for dry in (False, True, True):
            recorder.invalidate_room_light()
            rec.recording.start(dry=dry)
            recorder.render()
            rec.recording.stop()
        assert calls["occlusion"] - before["occlusion"] == 3
    finally:
        recorder.release()
