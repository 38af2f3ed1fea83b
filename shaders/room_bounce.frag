#version 430
// The room's light map, the diffuse bounces (issues 13 and 11): per atlas texel, the direct
// light map adds the light that the room's own walls reflect onto it, gathered from the
// coarse patches (face area / RC^2): E = sum_j (rho_j / pi) T_j F_j, F_j pi times the exact
// form factor of patch j (rectangle_irradiance_factor, common.glsl),
// with rho_j = m_j rho + (1 - m_j) rho_curtain (m_j the patch's wall fraction, 0 in the window
// opening, where the closed curtain reflects part of the room's light) and T_j the patch's
// total irradiance, every bounce (room_radiosity.frag). The room is a convex box, so
// every patch sees every other; the precomputed ambient occlusion (corners, the window's
// reveals) scales the bounce.
// CURTAIN_SIDE (issue 11, fourth round): the same gather at a grid of points over the window
// opening in the wall's plane, facing the room, from every face but the window wall: the
// irradiance the room sends to the curtain's room side (curtain.frag ROOM_SIDE), with no
// direct light and no obscurance (the room's own light, every bounce, no stand-in).
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform vec3 u_face_origin[6];
uniform vec3 u_face_s[6];
uniform vec3 u_face_t[6];
uniform vec3 u_face_normal[6];

uniform sampler2D u_direct;          // the direct light map (area light, lamps), mipmapped
uniform sampler2D u_beam;            // the key's beam at the light map's texels, mipmapped
uniform sampler2D u_total;           // ALL_BOUNCES: each coarse patch's total irradiance
uniform sampler2D u_ao_mask;         // r: ambient occlusion, g: wall fraction; mipmapped
uniform int u_bounce_level;          // the mip level gathered
uniform int u_coarse_texels;         // face texels at that level
uniform float u_albedo;
uniform vec3 u_window_albedo;       // the closed curtain's room-side reflectance (0: open)
#ifdef CURTAIN_SIDE
uniform vec4 u_side_rect;            // the grid's extent: x from, y from, width, height (m)
uniform float u_side_z;              // its plane (m): the window wall's
#endif

layout(location = 0) out vec4 out_irradiance;

void main() {
#ifdef CURTAIN_SIDE
    int face = ROOM_FACES - 1;   // the window wall, left out below: the cloth lies in front of it
    vec3 p = vec3(u_side_rect.xy + v_uv * u_side_rect.zw, u_side_z);
    vec3 n = vec3(0.0, 0.0, 1.0);
    vec3 direct = vec3(0.0);
    float ao = 1.0;
#else
    float x = v_uv.x * float(ROOM_FACES);
    int face = min(int(floor(x)), ROOM_FACES - 1);
    vec3 p = u_face_origin[face] + fract(x) * u_face_s[face] + v_uv.y * u_face_t[face];
    vec3 n = u_face_normal[face];
    ivec2 own = ivec2(v_uv * vec2(textureSize(u_direct, 0)));
    vec3 direct = texelFetch(u_direct, own, 0).rgb;
    float ao = texelFetch(u_ao_mask, own, 0).r;
#endif

    vec3 bounce = vec3(0.0);
    float rc = float(u_coarse_texels);
    for (int f = 0; f < ROOM_FACES; ++f) {
        if (f == face) {
            continue;  // a flat face does not light itself
        }
        for (int v = 0; v < u_coarse_texels; ++v) {
            for (int u = 0; u < u_coarse_texels; ++u) {
                ivec2 texel = ivec2(f * u_coarse_texels + u, v);
                vec3 corner = u_face_origin[f] + (float(u) / rc) * u_face_s[f]
                            + (float(v) / rc) * u_face_t[f];
                float geometry = rectangle_irradiance_factor(p, n, corner, u_face_s[f] / rc,
                                                             u_face_t[f] / rc);
                float wall = texelFetch(u_ao_mask, texel, u_bounce_level).g;
                vec3 source = texelFetch(u_total, texel, 0).rgb;
                bounce += source * ((wall * u_albedo + (1.0 - wall) * u_window_albedo) * geometry);
            }
        }
    }
    out_irradiance = vec4(direct + ao * (1.0 / PI) * bounce, 1.0);
}
