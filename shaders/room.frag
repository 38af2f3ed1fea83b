#version 430
// Room props: grey Lambertian surfaces (albedo u_albedo), radiance = albedo / pi x irradiance.
// ROOM_LIGHTING (issue 13, model.md section 9): the irradiance is
//  - the key light's beam through the window opening and the curtain, per pixel: the
//    transmittance shadow map (room_shadow.frag) filtered over the penumbra a source of the
//    sun's angular radius casts at the receiver's distance from the curtain (PCSS with the
//    blocker distance known: the curtain hangs in the plane u_curtain_z), times the opening's
//    soft mask (room_window_beam);
//  - the light map (room_lightmap.frag + room_bounce.frag): the curtain as an area light,
//    lamps in the room, one bounce, ambient occlusion.
// Without it, the earlier scene design: a constant fraction of the key plus the fill light.
#include "common.glsl"

in vec3 v_normal;
in vec3 v_position;

uniform vec3 u_room_rgb;          // radiance of the walls under the room's diffuse light
uniform vec3 u_fill_rgb;          // radiance added by the fill light at normal incidence
uniform vec3 u_fill_to_light;

#ifdef ROOM_LIGHTING
uniform vec3 u_face_origin[6];
uniform vec3 u_face_s[6];
uniform vec3 u_face_t[6];
uniform float u_face_texels;
uniform sampler2D u_lightmap;     // irradiance, linear sRGB (x pi cd m^-2)
uniform sampler2D u_shadow;       // the key light's transmittance through the curtain
uniform mat4 u_light_view_proj;
uniform float u_shadow_texel_m;
uniform vec3 u_key_to_light;
uniform vec3 u_key_rgb;           // key light: normal irradiance as linear sRGB
uniform vec4 u_window_rect;
uniform vec2 u_wall_z;
uniform float u_curtain_z;
uniform float u_tan_sun_radius;
uniform float u_albedo;

// 8 taps on a disc (a rotated Vogel spiral) plus the centre, radius 1.
const vec2 PCF_TAPS[8] = vec2[8](vec2(0.250, 0.000), vec2(-0.318, 0.291), vec2(0.042, -0.559),
                                 vec2(0.440, 0.487), vec2(-0.733, -0.108), vec2(0.628, -0.509),
                                 vec2(-0.159, 0.857), vec2(-0.507, -0.803));

vec3 key_beam(vec3 p, vec3 n) {
    float cos_key = dot(n, u_key_to_light);
    if (cos_key <= 0.0) {
        return vec3(0.0);
    }
    float beam = room_window_beam(p, u_key_to_light, u_window_rect, u_wall_z, u_tan_sun_radius);
    if (beam <= 0.0) {
        return vec3(0.0);
    }
    // penumbra radius at this receiver: its distance to the curtain along the beam x tan(radius)
    float blocker = max((u_curtain_z - p.z) / u_key_to_light.z, 0.0);
    float radius_m = max(blocker * u_tan_sun_radius, 0.5 * u_shadow_texel_m);
    vec4 clip = u_light_view_proj * vec4(p, 1.0);
    vec2 uv = clip.xy * 0.5 + 0.5;
    vec2 step_uv = vec2(radius_m / u_shadow_texel_m) / vec2(textureSize(u_shadow, 0));
    vec3 t = texture(u_shadow, uv).rgb;
    for (int k = 0; k < 8; ++k) {
        t += texture(u_shadow, uv + PCF_TAPS[k] * step_uv).rgb;
    }
    return u_key_rgb * (cos_key * beam / 9.0) * t;
}
#endif

layout(location = 0) out vec4 out_radiance;

void main() {
    vec3 n = normalize(v_normal);
#ifdef ROOM_LIGHTING
    int face = room_face_of_normal(n);
    vec2 uv = room_atlas_uv(face, v_position, u_face_origin[face], u_face_s[face],
                            u_face_t[face], u_face_texels);
    vec3 irradiance = texture(u_lightmap, uv).rgb + key_beam(v_position, n);
    out_radiance = vec4((u_albedo / PI) * irradiance, 1.0);
#else
    out_radiance = vec4(u_room_rgb + max(dot(n, u_fill_to_light), 0.0) * u_fill_rgb, 1.0);
#endif
}
