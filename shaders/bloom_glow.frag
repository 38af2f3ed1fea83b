#version 430
// Glare, step 2 (half size): the sum of ever wider box blurs of the frame, the mip levels of
// bloom_down.frag's half-size average (the frame's levels 1..BLOOM_LEVELS), weighted by
// u_level_weight (summing to 1). Each level is a box filter, so the sum keeps the integral.
#include "common.glsl"

#ifndef BLOOM_LEVELS
#define BLOOM_LEVELS 6
#endif

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_half;            // the frame's 2 x 2 average, mipmapped
uniform vec4 u_half_rect;            // (u0, v0, du, dv) of the part drawn
uniform float u_level_weight[BLOOM_LEVELS];

layout(location = 0) out vec4 out_glow;

void main() {
    vec2 uv = u_half_rect.xy + v_uv * u_half_rect.zw;
    vec3 glow = vec3(0.0);
    for (int level = 0; level < BLOOM_LEVELS; ++level) {
        glow += u_level_weight[level] * textureLod(u_half, uv, float(level)).rgb;
    }
    out_glow = vec4(glow, 1.0);
}
