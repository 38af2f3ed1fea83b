#version 430
// The room's bounces at the coarse patches (issue 11): per coarse atlas texel i (one patch of
// face area / RC^2), its total irradiance T_i = S_i + sum_k op_ik S_k, where S is the direct
// light map's coarse mip level plus the key's beam there, and op = (I - K)^-1 - I is every
// bounce of the room's radiosity system, precomputed once (room_light.radiosity_operator: the
// room is static). room_bounce.frag then gathers T instead of S.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_direct;          // the direct light map (area light, lamps), mipmapped
uniform sampler2D u_beam;            // the key's beam at the light map's texels, mipmapped
uniform sampler2D u_operator;        // (N, N) op_ik per colour channel: row i, column k
uniform int u_bounce_level;          // the coarse mip level
uniform int u_coarse_texels;         // face texels at that level (RC)

layout(location = 0) out vec4 out_total;

vec3 coarse_source(int k) {
    int rc = u_coarse_texels;
    int face = k / (rc * rc);
    int v = (k / rc) % rc;
    int u = k % rc;
    ivec2 texel = ivec2(face * rc + u, v);
    return texelFetch(u_direct, texel, u_bounce_level).rgb + texelFetch(u_beam, texel, u_bounce_level).rgb;
}

void main() {
    int rc = u_coarse_texels;
    ivec2 own = ivec2(gl_FragCoord.xy);
    int face = own.x / rc;
    int i = (face * rc + own.y) * rc + (own.x % rc);
    vec3 total = coarse_source(i);
    int count = ROOM_FACES * rc * rc;
    for (int k = 0; k < count; ++k) {
        total += texelFetch(u_operator, ivec2(k, i), 0).rgb * coarse_source(k);
    }
    out_total = vec4(total, 1.0);
}
