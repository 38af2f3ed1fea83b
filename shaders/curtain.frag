#version 430
// Eq. 8 per fragment (model.md section 6) in N_BANDS bands, converted to linear sRGB radiance
// (683 * integral of the sRGB matching functions times radiance: cd m^-2 scale) at the end.
// Costed for a CPU rasteriser (llvmpipe), where every operation runs per fragment: the view
// ray is interpolated (curtain.vert), the tangent frame is used in the scalar form the chord
// needs, each light's two HG lobes come back as one ratio, and with SHARED_DIVISION (set by
// frame.py when float32 cannot underflow) the key, the fill (FILL_LIGHT: where the scene has
// one; curtain.py) and the fluorescence saturation
// share one division; constants are summed at compile time (SPECIALISED). docs/render.md has
// the measured cost of each step.
#include "common.glsl"
#ifndef INTERPOLATION
#define INTERPOLATION              // centroid on the MSAA path (curtain.vert says why)
#endif

INTERPOLATION in vec3 v_view_ray;                // position - camera, world space
INTERPOLATION in vec3 v_normal;
#if defined(ANISOTROPIC) || defined(GBUFFER) || defined(PATTERN)
INTERPOLATION in vec3 v_tangent;
#endif
#if defined(PATTERN) || defined(KEY_SHADOW)
INTERPOLATION in vec2 v_uv;                      // the fabric's texture coordinates (curtain.vert)
#endif
#ifdef PATTERN
uniform vec2 u_uv_to_repeats;      // fabric size / pattern repeat: uv -> pattern repeats
uniform float u_inv_mean_coverage; // 1 / mean(c): the fitted lobes belong to the threads alone
#endif
#ifdef OIT
uniform float u_oit_depth_ref;     // m: the view distance where the OIT depth weight is 1
#endif
#if defined(GBUFFER) || defined(N_ROOM_LAMPS)
INTERPOLATION in vec3 v_position;
#endif

// The scene's values (common.glsl SCENE_VALUE), fixed until the light, fabric, mode or band
// count changes.

SCENE_VALUE(vec3, u_key_to_light, S_KEY_TO_LIGHT);
SCENE_VALUE(vec3, u_fill_to_light, S_FILL_TO_LIGHT);
SCENE_VALUE(vec3, u_sun_direction, S_SUN_DIRECTION);        // to the sun's disc (the key light)
SCENE_VALUE(vec2, u_sun_chord2, S_SUN_CHORD2);              // disc edge: inner, outer chord^2
SCENE_VALUE(float, u_direct, S_DIRECT);                     // LD: the open-area see-through fraction
SCENE_VALUE(float, u_a_diff, S_A_DIFF);
SCENE_VALUE(float, u_g_diff, S_G_DIFF);
SCENE_VALUE(float, u_a_spec, S_A_SPEC);
SCENE_VALUE(float, u_g_spec, S_G_SPEC);
SCENE_VALUE(float, u_anisotropy, S_ANISOTROPY);

// per band, NV4 chunks of 4 bands
SCENE_VALUE(vec4, u_key_dyed[NV4], S_KEY_DYED);             // key light normal irradiance x dye
SCENE_VALUE(vec4, u_fill_dyed[NV4], S_FILL_DYED);           // fill light (viewer side) x dye
SCENE_VALUE(vec4, u_ambient[NV4], S_AMBIENT);               // cloth radiance from the diffuse surroundings
SCENE_VALUE(vec4, u_ambient_outside[NV4], S_AMBIENT_OUTSIDE); // the outside's share of it
// the ambient by view (issue 11, model.md section 9): its ratio to the normal view's at
// mu = |n . v| = i / (AMBIENT_VIEW_NODES - 1), the outside's share and the room's, as segments
// (view_segments: per segment i, the outside's node i and its step to the next, the room's)
SCENE_VALUE(vec4, u_ambient_view[AMBIENT_VIEW_NODES - 1], S_AMBIENT_VIEW);
// the outside through the lobes by the view's height (issue 11): the sky's share at
// x = (ray_y + 1) / 2 = i / (AMBIENT_VIEW_NODES - 1) (segments, xy), and the ambient's change per unit of
// it away from 1/2 (dye (a_diff fwd + a_spec fwd) (sky - ground); 0 with the viewer outside)
SCENE_VALUE(vec4, u_outside_sky_share[AMBIENT_VIEW_NODES - 1], S_OUTSIDE_SKY_SHARE);
SCENE_VALUE(vec4, u_ambient_tilt[NV4], S_AMBIENT_TILT);
float g_view_outside = 1.0;   // set in main
float g_view_room = 1.0;
float g_sky_tilt = 0.0;       // the sky's share minus 1/2, times g_view_outside (and the outside's
                              // share the wall leaves, SKY_OCCLUSION)
SCENE_VALUE(vec4, u_sky[NV4], S_SKY);
SCENE_VALUE(vec4, u_ground[NV4], S_GROUND);
SCENE_VALUE(vec4, u_sun_disc[NV4], S_SUN_DISC);
SCENE_VALUE(vec4, u_room[NV4], S_ROOM);
SCENE_VALUE(vec4, u_fluorescence[NV4], S_FLUORESCENCE);     // paper: radiance; physical: per 1e18 effective photons
SCENE_VALUE(vec3, u_absorbed_photons, S_ABSORBED_PHOTONS);  // physical: key, fill, ambient at normal incidence, 1e18 m^-2 s^-1
SCENE_VALUE(float, u_inv_saturation, S_INV_SATURATION);     // 1e18 / N_sat (0: no saturation)
SCENE_VALUE(vec4, u_band_to_r[NV4], S_BAND_TO_R);
SCENE_VALUE(vec4, u_band_to_g[NV4], S_BAND_TO_G);
SCENE_VALUE(vec4, u_band_to_b[NV4], S_BAND_TO_B);

layout(location = 0) out vec4 out_radiance;
#ifdef OIT
layout(location = 1) out vec4 out_oit_weight;
#endif
#ifdef GBUFFER
layout(location = 1) out vec4 out_position;
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_tangent;
layout(location = 4) out vec4 out_shadows;   // key beam, front coverage, the outside's occlusion: cloth, wall
layout(location = 5) out vec4 out_wall_light;      // WALL_GRID's per-vertex light, interpolated
layout(location = 6) out vec4 out_room_side_light;  // ROOM_SIDE's per-vertex light, interpolated
layout(location = 7) out vec4 out_window_side_light;
#endif

// One chunk of 4 bands: eq. 8's terms summed, then projected to display colour. Called with a
// constant k (unrolled below by NV4), so every array index is a compile-time constant and the
// sums of constants fold. The see-through (LD = u_direct) is background_weights regrouped:
// sky above / ground below the horizon and the sun's disc outside, the room inside:
// LD (room + outside (ground - room + above (sky - ground + disc sun_disc))), disc = 1 - the
// rim's smoothstep (exactly 0 off the disc: the disc's huge radiance must not be cancelled).
#ifdef CURTAIN_ENVIRONMENT
// --environment with the flat cloth's see-through (issue 13): LD times the image where the ray
// leaves through the window (the sky and ground band terms dropped; the image is RGB, a sum,
// so it is added after the bands' display conversion, exact in any basis).
uniform sampler2D u_environment;
uniform float u_environment_scale;
#endif

#ifdef N_ROOM_LAMPS
// Lamps in the room (issue 13; isotropic points, eq. 8's lobes with the lamp as the light):
// position (m) and intensity x dye per band (irradiance at 1 m), chunk k of lamp j at j NV4 + k.
uniform vec3 u_room_lamp_position[N_ROOM_LAMPS];
uniform vec4 u_room_lamp_dyed[N_ROOM_LAMPS * NV4];
float g_room_lamp[N_ROOM_LAMPS];   // G / r^2 of each lamp at this fragment (set in main)
#endif

#ifdef KEY_SHADOW
// The key light's visibility on the cloth (issue 11, model.md section 9): the window wall's
// shadow (the opening's soft mask, room_window_beam) times the folds' shadow: the key's
// front-layer map (room_shadow.frag, FRONT_LAYER: per texel the thread coverage c of the
// layer of cloth nearest the light and its depth); a fragment behind that layer receives the
// beam through it, (1 - c) key dye + c key dye thread (u_key_thread: c = 1), the float64
// twin's layer_beam_transmittance, and the excitation through its holes, 1 - c. Since issue
// 11's seventh round a second layer too (u_key_second, the front-layer map peeled;
// front_layers_coverage): the beam through both, the product of the two layers'
// transmittances, (1 - c1)(1 - c2) key dye + ((1 - c1) c2 + c1 (1 - c2)) key dye thread +
// c1 c2 key dye thread^2 (u_key_thread2). With one layer, a point behind two folds of voile
// was 1.15-1.55x the path tracer's.
SCENE_VALUE(vec4, u_key_thread[NV4], S_KEY_THREAD);
SCENE_VALUE(vec4, u_key_thread2[NV4], S_KEY_THREAD2);
// The window's mask and the two layers' coverage do not depend on the view: they are baked
// over the fabric's uv when the light or the mesh changes (key_visibility.frag: r the mask,
// g, b the first and second layers' coverage) and read here with one bilinear lookup.
uniform sampler2D u_key_visibility;
float g_key_beam = 1.0;            // the window's mask (set in main)
float g_front_coverage = 0.0;      // coverage of the layer in front (0: none; set in main)
float g_second_coverage = 0.0;     // coverage of a second layer in front (0: none; set in main)
#else
const float g_second_coverage = 0.0;
#endif
#ifdef ROOM_SIDE
// The curtain's room side lit by the room's own light, not by the stand-ins (the fill light
// and the room's share of the ambient term, which frame.py then leaves out:
// scene.with_room_solved), and the cloth by its own folds, all from the room's transport
// (catalog/render/passes/room_transport_light.py); curtain.vert reads the light per vertex
// and sums it (v_room_term, v_outside_term): the irradiance on the room side, scattered back
// towards the viewer by the lobes' backward factors as the room's share of eq. 8's ambient
// term is (u_room_side_reflectance: dye (a_diff backward(g_diff) + a_spec backward(g_spec))
// in display RGB) at the view's ratio g_view_room; and the mean radiance of the cloth's window
// side, passed towards the viewer by both lobes over the hemisphere's share the folds hide,
// the share the outside's term takes away for both lobes, with the wall's light (WALL_GRID),
// at g_view_outside. RGB like the room's light, so added after the bands' conversion.
INTERPOLATION in vec3 v_room_term;
#ifdef GBUFFER   // the parts apart, for the G-buffer
INTERPOLATION in vec3 v_room_side_light;
INTERPOLATION in vec3 v_window_side_light;
INTERPOLATION in float v_view_occlusion;
#ifdef WALL_GRID
INTERPOLATION in vec3 v_wall_light;   // curtain.vert: the wall and its reveals, both lobes' share passed
#endif
#endif
#endif
float g_room_occlusion = 0.0;       // the room's side hidden by the cloth's own folds (SKY_OCCLUSION)
#ifdef SKY_OCCLUSION
// The outside hidden by the cloth's own folds and by the window wall (issue 11, model.md
// section 9), per vertex (curtain.vert) and interpolated: the ambient term loses that
// fraction of what a layer of cloth does not pass (the float64 twin's
// outside_occluded_radiance), and all of the outside where the wall hides it; curtain.vert
// sums that loss in display RGB into v_outside_term (it is linear in the occlusion).
INTERPOLATION in float v_outside_open;   // 1 - the wall's share of the outside
#ifdef GBUFFER
INTERPOLATION in vec3 v_occlusion;  // the cloth's share, the window wall's, the cloth's towards the room
#endif
#endif
#if defined(SKY_OCCLUSION) || defined(ROOM_SIDE)
INTERPOLATION in vec3 v_outside_term;   // curtain.vert: the outside's terms per g_view_outside
#endif
float g_occlusion = 0.0;            // set in main (GBUFFER)
float g_wall_occlusion = 0.0;

// Tables of AMBIENT_VIEW_NODES values at mu = i / (nodes - 1), linear between nodes, as
// segments (bands.py view_segments: per segment a vec4 of two tables' node and step): both
// tables at mu, one indexed read (an indexed read is a gather per fragment on a CPU rasteriser).
vec2 view_segments(vec4 segments[AMBIENT_VIEW_NODES - 1], float mu) {
    float x = clamp(mu, 0.0, 1.0) * float(AMBIENT_VIEW_NODES - 1);
    int i = min(int(x), AMBIENT_VIEW_NODES - 2);
    vec4 s = segments[i];
    float f = x - float(i);
    return vec2(s.x + f * s.y, s.z + f * s.w);
}

vec3 shade_chunk(int k, float g_key, float g_fill, vec3 bg, float effective) {
#ifdef KEY_SHADOW
    float c1 = g_front_coverage;
    float c2 = g_second_coverage;
    vec4 key_seen = g_key_beam * ((1.0 - c1) * (1.0 - c2) * u_key_dyed[k]
                                  + ((1.0 - c1) * c2 + c1 * (1.0 - c2)) * u_key_thread[k]
                                  + (c1 * c2) * u_key_thread2[k]);
    vec4 band = g_key * key_seen + g_fill * u_fill_dyed[k];
#else
    vec4 band = g_key * u_key_dyed[k] + g_fill * u_fill_dyed[k];
#endif
#ifdef N_ROOM_LAMPS
    for (int j = 0; j < N_ROOM_LAMPS; ++j) {
        band += g_room_lamp[j] * u_room_lamp_dyed[j * NV4 + k];
    }
#endif
    vec4 constant = g_view_room * u_ambient[k] + (g_view_outside - g_view_room) * u_ambient_outside[k]
                  + g_sky_tilt * u_ambient_tilt[k];
#ifdef FLUORESCENCE_PAPER
    constant += fluorescence_paper(u_fluorescence[k]);
#endif
#if defined(SEE_THROUGH) && defined(CURTAIN_ENVIRONMENT)
    vec4 outside = bg.y * bg.z * (u_direct * u_sun_disc[k]) - u_direct * u_room[k];
    band += bg.x * outside;
    constant += u_direct * u_room[k];
#elif defined(SEE_THROUGH)
    vec4 outside = bg.y * (u_direct * (u_sky[k] - u_ground[k]) + bg.z * (u_direct * u_sun_disc[k]))
                 + u_direct * (u_ground[k] - u_room[k]);
    band += bg.x * outside;
    constant += u_direct * u_room[k];
#endif
    band += constant;
#ifdef FLUORESCENCE_PHYSICAL
    band += fluorescence_physical(effective, u_fluorescence[k]);
#endif
#if N_BANDS == 3
    return band.rgb;  // RGB: the bands are linear sRGB already (bands.py: band_to_rgb = identity)
#else
    return vec3(dot(band, u_band_to_r[k]), dot(band, u_band_to_g[k]), dot(band, u_band_to_b[k]));
#endif
}

void main() {
    vec3 n = normalize(v_normal);
    vec3 ray = normalize(v_view_ray);
#ifdef PATTERN
    // the fabric's own structure (model.md section 9): thread coverage and the thread's
    // normal, both mip-filtered (far away: c -> mean(c) = 1 - LD, the normal -> the cloth's)
    vec4 thread = thread_texel(v_uv * u_uv_to_repeats);
    n = thread_normal(n, v_tangent, thread.xyz);
#endif
#ifdef ANISOTROPIC
    WovenView view = woven_view(-ray, n, v_tangent);
    float tan_key = dot(v_tangent, u_key_to_light);
    float tan_fill = dot(v_tangent, u_fill_to_light);
#else
    WovenView view = WovenView(-ray, 0.0, 0.0, 0.0, 0.0);
    float tan_key = 0.0;
    float tan_fill = 0.0;
#endif
    float cos_key = dot(n, u_key_to_light);
    float cos_fill = dot(n, u_fill_to_light);
    float mu_view = abs(dot(n, ray));
    vec2 view_ratios = view_segments(u_ambient_view, mu_view);
    g_view_outside = view_ratios.x;
    g_view_room = view_ratios.y;
    g_sky_tilt = g_view_outside * (view_segments(u_outside_sky_share, 0.5 * (ray.y + 1.0)).x - 0.5);
    vec2 key = woven_transmission_ratio(u_key_to_light, cos_key, tan_key, view,
                                        u_a_diff, u_g_diff, u_a_spec, u_g_spec, u_anisotropy);
#ifdef FILL_LIGHT
    vec2 fill = woven_transmission_ratio(u_fill_to_light, cos_fill, tan_fill, view,
                                         u_a_diff, u_g_diff, u_a_spec, u_g_spec, u_anisotropy);
#else
    // no fill light (its irradiance 0: the room's own light on the room side, ROOM_SIDE):
    // no lobes to evaluate; g_fill = 0 and the shared division's factor 1
    vec2 fill = vec2(0.0, 1.0);
#endif
    // eq. 8 fluorescence, physical: fluorescence_effective_photons, N / (1 + N / N_sat), with its
    // denominator kept apart so that SHARED_DIVISION can fold it into the one division
    float key_uv = 1.0;   // the key's excitation reaching the fragment (KEY_SHADOW)
#ifdef KEY_SHADOW
    {
        vec3 visibility = texture(u_key_visibility, v_uv).rgb;
        g_key_beam = visibility.r;
        g_front_coverage = visibility.g;
        g_second_coverage = visibility.b;
        key_uv = g_key_beam * (1.0 - g_front_coverage) * (1.0 - g_second_coverage);   // UV passes the holes only
    }
#endif
#ifdef SKY_OCCLUSION
    g_sky_tilt *= v_outside_open;   // where the wall hides the outside, no sky or ground
#ifdef GBUFFER
    g_occlusion = v_occlusion.x;
    g_wall_occlusion = v_occlusion.y;
    g_room_occlusion = v_occlusion.z;
#endif
#endif
    float absorbed = 0.0;
    float saturation = 1.0;
#ifdef FLUORESCENCE_PHYSICAL
    absorbed = abs(cos_key) * key_uv * u_absorbed_photons.x + abs(cos_fill) * u_absorbed_photons.y
             + u_absorbed_photons.z;
    saturation = 1.0 + absorbed * u_inv_saturation;
#endif
#ifdef SHARED_DIVISION
    float inv = 1.0 / (key.y * fill.y * saturation);
    float g_key = key.x * (fill.y * saturation) * inv;
    float g_fill = fill.x * (key.y * saturation) * inv;
    float effective = absorbed * (key.y * fill.y) * inv;
#else
    float g_key = key.x / key.y;
    float g_fill = fill.x / fill.y;
    float effective = fluorescence_effective_photons(absorbed, u_inv_saturation);
#endif
#ifdef N_ROOM_LAMPS
    for (int j = 0; j < N_ROOM_LAMPS; ++j) {
        vec3 d = u_room_lamp_position[j] - v_position;
        float r2 = dot(d, d);
        vec3 to_lamp = d * inversesqrt(r2);
#ifdef ANISOTROPIC
        float tan_lamp = dot(v_tangent, to_lamp);
#else
        float tan_lamp = 0.0;
#endif
        vec2 g = woven_transmission_ratio(to_lamp, dot(n, to_lamp), tan_lamp, view,
                                          u_a_diff, u_g_diff, u_a_spec, u_g_spec, u_anisotropy);
        g_room_lamp[j] = g.x / (g.y * r2);
    }
#endif
    vec3 bg = vec3(0.0);   // outside, above, sun disc
#ifdef SEE_THROUGH
    bg = background_terms(ray, u_sun_direction, u_sun_chord2.x, u_sun_chord2.y);
#endif

    vec3 rgb = shade_chunk(0, g_key, g_fill, bg, effective);
#if NV4 > 1
    rgb += shade_chunk(1, g_key, g_fill, bg, effective);
#endif
#if NV4 > 2
    rgb += shade_chunk(2, g_key, g_fill, bg, effective);
#endif
#if NV4 > 3
    rgb += shade_chunk(3, g_key, g_fill, bg, effective);
#endif
#if defined(SEE_THROUGH) && defined(CURTAIN_ENVIRONMENT)
    rgb += (bg.x * u_direct) * environment_lookup(u_environment, u_environment_scale, ray);
#endif
#if defined(SKY_OCCLUSION) || defined(ROOM_SIDE)
    rgb += g_view_outside * v_outside_term;   // the occlusion's loss, the window side's and wall's light
#endif
#ifdef ROOM_SIDE
    rgb += g_view_room * v_room_term;
#endif
#ifdef PATTERN
    // threads: eq. 8 without LD, the lobes divided by mean(c) (the fit describes the whole
    // cloth; its light leaves through the threads, a fraction mean(c) of the area); holes
    // (1 - c) let the scene behind through undimmed (the OIT composite)
    rgb *= u_inv_mean_coverage;
    float alpha = thread.a;
#else
    float alpha = 1.0;
#endif
#ifdef OIT
    float w = oit_weight(length(v_view_ray) - u_oit_depth_ref);
    out_radiance = vec4(rgb * (alpha * w), alpha);
    out_oit_weight = vec4(alpha * w, 0.0, 0.0, 0.0);
#else
    out_radiance = vec4(rgb, 1.0);
#endif
#ifdef GBUFFER
    out_position = vec4(v_position, 1.0);
    // w: the room's side hidden by the folds (normal), the view's continuation hidden (tangent)
    float room_hidden = g_room_occlusion;
    float view_hidden = 0.0;
#ifdef ROOM_SIDE
    view_hidden = v_view_occlusion;
#endif
    out_normal = vec4(n, room_hidden);
    out_tangent = vec4(normalize(v_tangent - dot(v_tangent, n) * n), view_hidden);
    vec4 shadows = vec4(1.0, 0.0, 0.0, 0.0);
#ifdef KEY_SHADOW
    shadows.xy = vec2(g_key_beam, g_front_coverage);
#endif
#ifdef SKY_OCCLUSION
    shadows.zw = vec2(g_occlusion, g_wall_occlusion);
#endif
    out_shadows = shadows;
    out_wall_light = vec4(0.0, 0.0, 0.0, g_second_coverage);   // w: the second layer's coverage
#ifdef ROOM_SIDE
    out_room_side_light = vec4(v_room_side_light, 1.0);
    out_window_side_light = vec4(v_window_side_light, 1.0);
#ifdef WALL_GRID
    out_wall_light = vec4(v_wall_light, g_second_coverage);
#endif
#else
    out_room_side_light = vec4(0.0);
    out_window_side_light = vec4(0.0);
#endif
#endif
}
