#version 430
// The room's light map, direct part (issue 13, model.md section 9): per atlas texel (a point
// of the room box's inside, catalog/render/room_light.py), the irradiance (linear sRGB) from
//  - the window as an area light: the luminaire capture's texels are patches of the opening
//    (normal +z) with the radiance the curtain (or the sky through the opening) sends towards
//    the room, E = sum L F (F pi times the patch's exact form factor,
//    rectangle_irradiance_factor in common.glsl); behind the curtain's plane, the patches of
//    its window side (issue 11);
//  - the key light's beam through the window and the curtain (the transmittance shadow map,
//    read at the mip level of a light-map texel);
//  - lamps in the room (isotropic points): E = I cos_r / r^2.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform vec3 u_face_origin[6];
uniform vec3 u_face_s[6];
uniform vec3 u_face_t[6];
uniform vec3 u_face_normal[6];

uniform sampler2D u_luminaire;       // mipmapped; level u_luminaire_level = one texel a patch
uniform ivec2 u_luminaire_size;
uniform int u_luminaire_level;
#ifdef SIDE_EYES
// The same capture from two eyes towards the side walls (issue 11, sixth round; left then
// right, side by side, room_light.CAPTURE_SIDE_EYES): the folds' flanks face either way and
// glow unequally, so a wall seeing the window obliquely sees mostly one kind.
uniform sampler2D u_luminaire_sides;
uniform int u_luminaire_sides_level; // their level of one texel a patch
uniform vec3 u_side_eye[2];
uniform vec3 u_middle_eye;
#endif
uniform vec4 u_window_rect;          // x0, x1, y0, y1 of the opening (m)
uniform vec2 u_wall_z;               // the window wall's inner and outer planes (m)
uniform float u_face_texels;         // light-map texels per face side
uniform float u_supersample_m;       // room_light.WINDOW_SUPERSAMPLE_M
uniform vec3 u_lobe_rgb;             // key x a_spec x dye (0: the lobe travels in the beam)
uniform float u_g_spec;
uniform sampler2D u_luminaire_back;  // the closed curtain's window side (0 where no cloth)
uniform int u_luminaire_back_level;  // its level of one texel a patch
uniform float u_back_plane_z;        // its patches' plane (m), normal -z

uniform sampler2D u_shadow;
uniform mat4 u_light_view_proj;
uniform float u_beam_shadow_lod;     // the beam's samples' level (their spacing)
// BEAM_SAMPLES: the beam's samples a texel side (frame.py defines room_light.BEAM_SAMPLES)
uniform vec3 u_key_to_light;
uniform vec3 u_key_rgb;              // key light: normal irradiance as linear sRGB (x pi cd m^-2)
uniform float u_tan_sun_radius;
uniform float u_key_on;              // 0: no beam (the curtain capture alone)

uniform int u_lamp_count;
uniform vec3 u_lamp_position[4];
uniform vec3 u_lamp_rgb[4];          // intensity as linear sRGB (irradiance at 1 m)

layout(location = 0) out vec4 out_irradiance;   // area light and lamps (the room reads it)
layout(location = 1) out vec4 out_beam;         // the key's beam (per pixel in room.frag; here
                                                // only as a source of the bounce)

// The radiance window patch (i, j), centred at c, sends towards p: the middle capture's or,
// SIDE_EYES, the three captures blended piecewise linearly in the horizontal angle of the way
// from c to p between the angles at which c sees the eyes, clamped beyond the side eyes
// (float64 twin: room_light.capture_eye_weights); alpha (the key's reach on the patch's
// cloth) always the middle's.
vec4 captured_towards(int i, int j, vec3 c, vec3 p) {
    vec4 middle = texelFetch(u_luminaire, ivec2(i, j), u_luminaire_level);
#ifdef SIDE_EYES
    float a = atan(p.x - c.x, max(p.z - c.z, 1e-6));
    float a_left = atan(u_side_eye[0].x - c.x, max(u_side_eye[0].z - c.z, 1e-6));
    float a_mid = atan(u_middle_eye.x - c.x, max(u_middle_eye.z - c.z, 1e-6));
    float a_right = atan(u_side_eye[1].x - c.x, max(u_side_eye[1].z - c.z, 1e-6));
    vec3 rgb;
    if (a <= a_mid) {
        vec3 left = texelFetch(u_luminaire_sides, ivec2(i, j), u_luminaire_sides_level).rgb;
        rgb = mix(middle.rgb, left, clamp((a_mid - a) / (a_mid - a_left), 0.0, 1.0));
    } else {
        vec3 right = texelFetch(u_luminaire_sides, ivec2(i + u_luminaire_size.x, j), u_luminaire_sides_level).rgb;
        rgb = mix(middle.rgb, right, clamp((a - a_mid) / (a_right - a_mid), 0.0, 1.0));
    }
    return vec4(rgb, middle.a);
#else
    return middle;
#endif
}

// The window's light at point p (normal n): the room side's patches in the opening and,
// behind the curtain's plane (the window wall beside the opening, in the gap between wall and
// cloth), the patches of its window side: the glow and the light it scatters back.
vec3 window_irradiance(vec3 p, vec3 n, vec2 cell) {
    vec3 e = vec3(0.0);
    vec3 s = vec3(cell.x, 0.0, 0.0);
    vec3 t = vec3(0.0, cell.y, 0.0);
    float hg_k = (1.0 - u_g_spec) * (1.0 + u_g_spec) / (4.0 * PI);
    for (int j = 0; j < u_luminaire_size.y; ++j) {
        for (int i = 0; i < u_luminaire_size.x; ++i) {
            vec3 corner = vec3(u_window_rect.x + float(i) * cell.x,
                               u_window_rect.z + float(j) * cell.y, u_wall_z.x);
            vec4 captured = captured_towards(i, j, vec3(corner.xy + 0.5 * cell, u_wall_z.x), p);
            vec3 radiance = captured.rgb;
            if (u_lobe_rgb != vec3(0.0) && u_key_on > 0.0) {
                // the key's directional lobe through the cloth of this patch, towards p (eq. 7:
                // E cos_i a_spec ph(theta), theta between the key's travel and the way to p
                // from the patch's centre in the opening, where its rectangle is); the key's
                // irradiance on the patch's cloth, |cos_i| x the window's mask x what a layer
                // nearer the light passes, is the capture's alpha (its mean over the patch)
                vec3 w = normalize(p - vec3(corner.xy + 0.5 * cell, u_wall_z.x));
                float chord2 = dot(w + u_key_to_light, w + u_key_to_light);
                float d = (1.0 - u_g_spec) * (1.0 - u_g_spec) + u_g_spec * chord2;
                radiance += u_lobe_rgb * (captured.a * hg_k / (d * sqrt(d)));
            }
            e += radiance * rectangle_irradiance_factor(p, n, corner, s, t);
        }
    }
    if (p.z < u_back_plane_z) {
        for (int j = 0; j < u_luminaire_size.y; ++j) {
            for (int i = 0; i < u_luminaire_size.x; ++i) {
                vec3 corner = vec3(u_window_rect.x + float(i) * cell.x,
                                   u_window_rect.z + float(j) * cell.y, u_back_plane_z);
                e += texelFetch(u_luminaire_back, ivec2(i, j), u_luminaire_back_level).rgb
                   * rectangle_irradiance_factor(p, n, corner, s, t);
            }
        }
    }
    return e;
}

void main() {
    float x = v_uv.x * float(ROOM_FACES);
    int face = min(int(floor(x)), ROOM_FACES - 1);
    vec3 p = u_face_origin[face] + fract(x) * u_face_s[face] + v_uv.y * u_face_t[face];
    vec3 n = u_face_normal[face];

    // the texel's mean over 2x2 points, not its centre's value: a texel beside the opening
    // spans irradiance that falls several-fold across it
    vec2 cell = vec2(u_window_rect.y - u_window_rect.x, u_window_rect.w - u_window_rect.z)
              / vec2(u_luminaire_size);
    // (the points on the wall: none inside the opening, where there is no surface). Texels
    // further than WINDOW_SUPERSAMPLE_M (room_light.py) from the window's plane vary slowly
    // across: their centre suffices.
    vec3 sum = vec3(0.0);
    float count = 0.0;
    int samples = p.z < u_wall_z.x + u_supersample_m ? 4 : 1;
    for (int k = 0; k < samples; ++k) {
        vec2 offset = samples == 1 ? vec2(0.0)
                    : (vec2(float(k & 1), float(k >> 1)) - 0.5) * (0.5 / u_face_texels);
        vec3 q = p + offset.x * u_face_s[face] + offset.y * u_face_t[face];
        bool in_opening = q.z < u_wall_z.x + 1e-4 && q.x > u_window_rect.x && q.x < u_window_rect.y
                          && q.y > u_window_rect.z && q.y < u_window_rect.w;
        if (!in_opening) {
            sum += window_irradiance(q, n, cell);
            count += 1.0;
        }
    }
    vec3 e = count > 0.0 ? sum / count : vec3(0.0);

    // the beam (the bounces' source only): the mean over BEAM_SAMPLES^2 points of the texel of
    // the opening's mask times the map's transmittance at their spacing's level (issue 11,
    // sixth round: from the texel's centre at the texel's level, the map's clear border blurred
    // into the footprint's edge and the beam's flux into the room was 1.3x the path tracer's
    // under the voile's low key)
    vec3 e_beam = vec3(0.0);
    float cos_key = dot(n, u_key_to_light);
    if (cos_key > 0.0 && u_key_on > 0.0) {
        vec3 t_sum = vec3(0.0);
        for (int k = 0; k < BEAM_SAMPLES * BEAM_SAMPLES; ++k) {
            vec2 offset = (vec2(float(k % BEAM_SAMPLES), float(k / BEAM_SAMPLES)) + 0.5)
                        / float(BEAM_SAMPLES) - 0.5;
            vec3 q = p + (offset.x * u_face_s[face] + offset.y * u_face_t[face]) / u_face_texels;
            float beam = room_window_beam(q, u_key_to_light, u_window_rect, u_wall_z, u_tan_sun_radius);
            vec4 clip = u_light_view_proj * vec4(q, 1.0);
            t_sum += beam * textureLod(u_shadow, clip.xy * 0.5 + 0.5, u_beam_shadow_lod).rgb;
        }
        e_beam = u_key_rgb * cos_key * t_sum / float(BEAM_SAMPLES * BEAM_SAMPLES);
    }

    for (int k = 0; k < u_lamp_count; ++k) {
        vec3 d = u_lamp_position[k] - p;
        float r2 = dot(d, d);
        e += u_lamp_rgb[k] * (max(dot(n, d), 0.0) * inversesqrt(r2) / r2);
    }
    out_irradiance = vec4(e, 1.0);
    out_beam = vec4(e_beam, 1.0);
}
