#version 430
// The room's light map, direct part (issue 13, model.md section 9): per atlas texel (a point
// of the room box's inside, catalog/render/room_light/), the irradiance (linear sRGB) from
//  - the window as an area light (common.glsl WINDOW_LIGHT, window_irradiance): the luminaire
//    captures' texels are patches of a box around the curtain's folds with the radiance the
//    curtain (or the sky through the opening) sends towards the room, E = sum L F (F pi times
//    the patch's exact form factor, rectangle_irradiance_factor); behind the curtain's plane,
//    the patches of its window side (issue 11);
//  - the key light's beam through the window and the curtain (the transmittance shadow map,
//    read at the mip level of a light-map texel);
//  - lamps in the room (isotropic points): E = I cos_r / r^2.
#define WINDOW_LIGHT
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform vec3 u_face_origin[6];
uniform vec3 u_face_s[6];
uniform vec3 u_face_t[6];
uniform vec3 u_face_normal[6];

uniform vec4 u_window_rect;          // x0, x1, y0, y1 of the opening (m)
uniform vec2 u_wall_z;               // the window wall's inner and outer planes (m)
uniform float u_face_texels;         // light-map texels per face side
uniform float u_supersample_m;       // room_light.WINDOW_SUPERSAMPLE_M

uniform sampler2D u_shadow;
uniform mat4 u_light_view_proj;
uniform float u_beam_shadow_lod;     // the beam's samples' level (their spacing)
// BEAM_SAMPLES: the beam's samples a texel side (frame.py defines room_light.BEAM_SAMPLES)
uniform vec3 u_key_to_light;
uniform vec3 u_key_rgb;              // key light: normal irradiance as linear sRGB (x pi cd m^-2)
uniform float u_tan_sun_radius;
uniform float u_key_on;              // 0: no beam (the curtain capture alone)

layout(location = 0) out vec4 out_irradiance;   // area light and lamps (the room reads it)
layout(location = 1) out vec4 out_beam;         // the key's beam (per pixel in room.frag; here
                                                // only as a source of the bounce)

void main() {
    float x = v_uv.x * float(ROOM_FACES);
    int face = min(int(floor(x)), ROOM_FACES - 1);
    vec3 p = u_face_origin[face] + fract(x) * u_face_s[face] + v_uv.y * u_face_t[face];
    vec3 n = u_face_normal[face];

    // the texel's mean over 2x2 points, not its centre's value: a texel beside the opening
    // spans irradiance that falls several-fold across it
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
            sum += room_direct_irradiance(q, n, u_window_rect, u_wall_z.x, u_key_to_light);
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

    out_irradiance = vec4(e, 1.0);
    out_beam = vec4(e_beam, 1.0);
}
