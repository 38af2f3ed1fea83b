#version 430
// The room's light map, direct part (issue 13, model.md section 9): per atlas texel (a point
// of the room box's inside, catalog/render/room_light.py), the irradiance (linear sRGB) from
//  - the window as an area light: the luminaire capture's texels are patches of the opening
//    (area u_patch_area_m2, normal +z) with the radiance the curtain (or the sky through the
//    opening) sends towards the room, E = sum L cos_p cos_r A / max(r^2, A);
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
uniform vec4 u_window_rect;          // x0, x1, y0, y1 of the opening (m)
uniform vec2 u_wall_z;               // the window wall's inner and outer planes (m)
uniform float u_patch_area_m2;

uniform sampler2D u_shadow;
uniform mat4 u_light_view_proj;
uniform float u_shadow_lod;
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

void main() {
    float x = v_uv.x * float(ROOM_FACES);
    int face = min(int(floor(x)), ROOM_FACES - 1);
    vec3 p = u_face_origin[face] + fract(x) * u_face_s[face] + v_uv.y * u_face_t[face];
    vec3 n = u_face_normal[face];

    vec3 e = vec3(0.0);
    vec2 cell = vec2(u_window_rect.y - u_window_rect.x, u_window_rect.w - u_window_rect.z)
              / vec2(u_luminaire_size);
    for (int j = 0; j < u_luminaire_size.y; ++j) {
        for (int i = 0; i < u_luminaire_size.x; ++i) {
            vec3 q = vec3(u_window_rect.x + (float(i) + 0.5) * cell.x,
                          u_window_rect.z + (float(j) + 0.5) * cell.y, u_wall_z.x);
            vec3 d = q - p;
            float r2 = dot(d, d);
            float inv_r = inversesqrt(r2);
            float cos_r = max(dot(n, d) * inv_r, 0.0);
            float cos_p = max(-d.z * inv_r, 0.0);
            e += texelFetch(u_luminaire, ivec2(i, j), u_luminaire_level).rgb
               * (cos_r * cos_p * u_patch_area_m2 / max(r2, u_patch_area_m2));
        }
    }

    vec3 e_beam = vec3(0.0);
    float cos_key = dot(n, u_key_to_light);
    if (cos_key > 0.0 && u_key_on > 0.0) {
        float beam = room_window_beam(p, u_key_to_light, u_window_rect, u_wall_z, u_tan_sun_radius);
        vec4 clip = u_light_view_proj * vec4(p, 1.0);
        vec3 t = textureLod(u_shadow, clip.xy * 0.5 + 0.5, u_shadow_lod).rgb;
        e_beam = u_key_rgb * (cos_key * beam) * t;
    }

    for (int k = 0; k < u_lamp_count; ++k) {
        vec3 d = u_lamp_position[k] - p;
        float r2 = dot(d, d);
        e += u_lamp_rgb[k] * (max(dot(n, d), 0.0) * inversesqrt(r2) / r2);
    }
    out_irradiance = vec4(e, 1.0);
    out_beam = vec4(e_beam, 1.0);
}
