#version 430
// A Lambertian receiver's radiance: albedo x irradiance / pi, linear, before exposure;
// scene-referred HDR out. The albedo is the surface's base colour x its texture (the room
// format); the irradiance is the light map (the window's light and every bounce of it and of
// the key's beam, catalog/render/passes/room_transport_light.py) plus, with KEY_BEAM, the
// key's beam itself per pixel: the normal irradiance x cos x the curtain's transmittance map
// (room_shadow.frag, filtered over the sun's penumbra at the receiver's distance from the
// cloth, as a prefiltered mip lookup) x the room's own visibility to the key (its depth map
// seen from the key: the wall round the window, the frame, the furniture).
#include "common.glsl"

#ifdef DEPTH_ONLY
void main() {}
#else
in vec3 v_irradiance;
in vec3 v_position;
flat in vec3 v_normal;
in vec2 v_uv;

uniform vec3 u_albedo_factor;
uniform sampler2D u_albedo_texture;   // linear reflectance (1x1 white where none)

#ifdef KEY_BEAM
uniform vec3 u_key_to_light;
uniform vec3 u_key_rgb;               // the key's normal irradiance, linear sRGB
uniform sampler2D u_shadow;           // the curtain's transmittance along the key
uniform mat4 u_light_view_proj;
uniform float u_shadow_texel_m;
uniform float u_curtain_z;
uniform float u_tan_sun_radius;
uniform sampler2DShadow u_room_depth; // the room seen from the key
uniform mat4 u_room_depth_view_proj;
uniform float u_room_depth_offset_m;  // normal offset against self-shadowing (a texel or two)
uniform float u_window_z;             // the window's plane (the reveals lie beyond it)

vec3 key_beam(vec3 p, vec3 n) {
    float cos_key = dot(n, u_key_to_light);
    if (cos_key <= 0.0) {
        return vec3(0.0);
    }
    vec4 d = u_room_depth_view_proj * vec4(p + u_room_depth_offset_m * n, 1.0);
    vec3 duv = d.xyz * 0.5 + 0.5;
    if (any(lessThan(duv.xy, vec2(0.0))) || any(greaterThan(duv.xy, vec2(1.0)))) {
        return vec3(0.0);   // outside the window's cross-section along the key: no beam
    }
    float visible = texture(u_room_depth, duv);
    if (visible <= 0.0) {
        return vec3(0.0);
    }
    float blocker = max((u_curtain_z - p.z) / max(abs(u_key_to_light.z), 1e-3), 0.0);
    float radius_m = max(blocker * u_tan_sun_radius, 0.5 * u_shadow_texel_m);
    vec4 clip = u_light_view_proj * vec4(p, 1.0);
    vec2 uv = clip.xy * 0.5 + 0.5;
    vec3 t = textureLod(u_shadow, uv, log2(max(2.0 * radius_m / u_shadow_texel_m, 1.0))).rgb;
    // a point on the light's side of the cloth (the reveals outside it) takes the beam undimmed
    bool before_cloth = u_key_to_light.z < 0.0 && p.z < u_window_z - 1e-4;
    return u_key_rgb * (cos_key * visible) * (before_cloth ? vec3(1.0) : t);
}
#endif

layout(location = 0) out vec4 out_radiance;

void main() {
    vec3 albedo = u_albedo_factor * texture(u_albedo_texture, v_uv).rgb;
    vec3 irradiance = max(v_irradiance, vec3(0.0));
#ifdef KEY_BEAM
    irradiance += key_beam(v_position, normalize(v_normal));
#endif
    out_radiance = vec4(albedo * irradiance / PI, 1.0);
}
#endif
