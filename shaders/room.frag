#version 430
// Room props: grey Lambertian surfaces (albedo u_albedo), radiance = albedo / pi x irradiance.
// ROOM_LIGHTING (issue 13, model.md section 9): the irradiance is
//  - the key light's beam through the window opening and the curtain, per pixel: the
//    transmittance shadow map (room_shadow.frag) filtered over the penumbra a source of the
//    sun's angular radius casts at the receiver's distance from the curtain (PCSS with the
//    blocker distance known: the curtain hangs in the plane u_curtain_z; the filter is the
//    map's mip level of that width, one tap), times the opening's soft mask (room_window_beam);
//    the window's reveals, outside the wall's inner plane, lie before the cloth: undimmed;
//  - the light map (room_lightmap.frag + room_bounce.frag): the curtain as an area light,
//    lamps in the room, the room's bounces, ambient occlusion.
// Without it, the earlier scene design: a constant fraction of the key plus the fill light.
#ifdef ROOM_LIGHTING
#define WINDOW_LIGHT   // common.glsl: the window's light (the reveals' window side, WINDOW_NEAR)
#endif
#include "common.glsl"

in vec3 v_normal;
in vec3 v_position;

uniform vec3 u_room_rgb;          // radiance of the walls under the room's diffuse light
uniform vec3 u_fill_rgb;          // radiance added by the fill light at normal incidence
uniform vec3 u_fill_to_light;

#ifdef ROOM_LIGHTING
in vec2 v_atlas;                  // light-map atlas coordinates (room.vert)
flat in vec4 v_atlas_box;
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
// The window's reveals and the wall's outer face, outside the wall's inner plane (issue 11,
// fourth round): not in the room's light map (its faces are the box's), they take the outside
// on the half of their hemisphere facing it (the sky above the horizon, the ground below:
// 0.5 pi L each quarter, the outer face the whole) and the closed curtain's window side on the
// half facing the room (the window-side capture at the reveal's place, a texel of 2 x 2
// patches); the path-traced reveals were 20x the light map's clamped edge they read before.
uniform vec3 u_reveal_sky;           // 0.5 pi x the sky's radiance (linear sRGB)
uniform vec3 u_reveal_ground;        // 0.5 pi x the ground's
// (u_luminaire_back, the curtain's window side (0 where no cloth, or open): common.glsl
// WINDOW_LIGHT, which frame.py defines with ROOM_LIGHTING)
uniform int u_reveal_back_level;
uniform ivec2 u_reveal_back_size;    // that level's texels

#ifdef WINDOW_NEAR
// The window wall beside the opening (issue 11, ninth round): the window's direct light there
// from the finer grid of room_window_near.frag in place of the light map's direct part (it
// falls tenfold within a light-map texel); the bounces stay the light map's. The grid fades
// into the light map over the last u_near_fade_m before WINDOW_NEAR_M from the opening: a
// switch at the grid's edge left a seam of a few levels.
uniform sampler2D u_lightmap_direct; // the light map's direct part (room_lightmap.frag)
uniform sampler2D u_window_near;     // room_window_near.frag's grid
uniform vec4 u_near_rect;            // its rectangle on the wall (x0, x1, y0, y1, m)
uniform float u_near_m;              // room_light.WINDOW_NEAR_M
uniform float u_near_fade_m;         // room_light.WINDOW_NEAR_FADE_M

// The direct part read as the light map itself is (bilinear at level 0): its texture filters
// nearest (the bounces' gather fetches its texels), and a nearest read subtracted from the
// bilinear light map left steps at its texels' edges.
vec3 direct_bilinear(vec2 uv) {
    ivec2 size = textureSize(u_lightmap_direct, 0);
    vec2 st = uv * vec2(size) - 0.5;
    ivec2 i = ivec2(floor(st));
    vec2 f = st - floor(st);
    ivec2 hi = size - 1;
    vec3 a = texelFetch(u_lightmap_direct, clamp(i, ivec2(0), hi), 0).rgb;
    vec3 b = texelFetch(u_lightmap_direct, clamp(i + ivec2(1, 0), ivec2(0), hi), 0).rgb;
    vec3 c = texelFetch(u_lightmap_direct, clamp(i + ivec2(0, 1), ivec2(0), hi), 0).rgb;
    vec3 d = texelFetch(u_lightmap_direct, clamp(i + ivec2(1, 1), ivec2(0), hi), 0).rgb;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

vec3 near_window_irradiance(vec3 p, vec3 n, vec2 uv, vec3 lightmap) {
    vec2 outside = max(max(u_window_rect.xz - p.xy, p.xy - u_window_rect.yw), vec2(0.0));
    float weight = 1.0 - smoothstep(u_near_m - u_near_fade_m, u_near_m, length(outside));
    if (n.z < 0.5 || p.z > u_wall_z.x + 1e-3 || weight <= 0.0) {
        return lightmap;
    }
    vec2 f = (p.xy - u_near_rect.xz) / (u_near_rect.yw - u_near_rect.xz);
    return lightmap + weight * (texture(u_window_near, f).rgb - direct_bilinear(uv));
}
#endif

#ifdef KEY_BEAM
vec3 key_beam(vec3 p, vec3 n) {
    float cos_key = dot(n, u_key_to_light);
    if (cos_key <= 0.0) {
        return vec3(0.0);
    }
    // the wall's outer face meets the key before the opening does: nothing of the window shades it
    float beam = p.z < u_wall_z.y + 1e-4 ? 1.0
               : room_window_beam(p, u_key_to_light, u_window_rect, u_wall_z, u_tan_sun_radius);
    if (beam <= 0.0) {
        return vec3(0.0);
    }
    // penumbra radius at this receiver: its distance to the curtain along the beam x tan(radius)
    float blocker = max((u_curtain_z - p.z) / u_key_to_light.z, 0.0);
    float radius_m = max(blocker * u_tan_sun_radius, 0.5 * u_shadow_texel_m);
    vec4 clip = u_light_view_proj * vec4(p, 1.0);
    vec2 uv = clip.xy * 0.5 + 0.5;
    // the penumbra as a prefiltered lookup: the mip level whose texel spans its diameter
    // (one trilinear tap where PCF would take many; a CPU rasteriser pays per tap)
    vec3 t = textureLod(u_shadow, uv, log2(max(2.0 * radius_m / u_shadow_texel_m, 1.0))).rgb;
    // the map holds no depth: it dims whatever lies in the beam's path behind the window. The
    // window's reveals lie outside the wall's inner plane, on the light's side of every fold
    // (the cloth hangs in the room), so a key from outside reaches them undimmed (issue 11,
    // fourth round: the sunlit sill, seen through the lace's holes, was 0.2x the traced one)
    bool before_cloth = u_key_to_light.z < 0.0 && p.z < u_wall_z.x - 1e-4;
    return u_key_rgb * (cos_key * beam) * (before_cloth ? vec3(1.0) : t);
}
#else
// faces turned away from the key light (frame.py draws them apart: a CPU rasteriser runs
// both sides of a branch, so the beam's arithmetic is compiled only where it can be lit)
vec3 key_beam(vec3 p, vec3 n) {
    return vec3(0.0);
}
#endif
#endif

layout(location = 0) out vec4 out_radiance;

void main() {
    vec3 n = normalize(v_normal);
#ifdef ROOM_LIGHTING
    vec2 uv = clamp(v_atlas, v_atlas_box.xz, v_atlas_box.yw);
    vec3 diffuse = v_position.z < u_wall_z.x - 1e-4 ? reveal_irradiance(v_position, n, u_window_rect, u_reveal_sky,
                                                                       u_reveal_ground, u_luminaire_back,
                                                                       u_reveal_back_level, u_reveal_back_size)
                                                   : texture(u_lightmap, uv).rgb;
#ifdef WINDOW_NEAR
    if (v_position.z >= u_wall_z.x - 1e-4) {
        diffuse = near_window_irradiance(v_position, n, uv, diffuse);
    }
#endif
    vec3 irradiance = diffuse + key_beam(v_position, n);
    out_radiance = vec4((u_albedo / PI) * irradiance, 1.0);
#else
    out_radiance = vec4(u_room_rgb + max(dot(n, u_fill_to_light), 0.0) * u_fill_rgb, 1.0);
#endif
}
