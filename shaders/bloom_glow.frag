#version 430
// Glare, step 2 (quarter size): the sum of ever wider box blurs of the frame, the mip levels
// of bloom_down.frag's quarter-size average (the frame's levels 2..BLOOM_LEVELS + 1), weighted
// by u_level_weight (summing to 1). Each level is a box filter, so the sum keeps the integral.
// Drawn at quarter size, the frame's level 1 (a 2 x 2 box) read at this target's pixel
// centres is its level 2, so its weight is folded into level 0 here (glare.py).
#include "common.glsl"

#ifndef BLOOM_LEVELS
#define BLOOM_LEVELS 5
#endif

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_quarter;         // the frame's 4 x 4 average, mipmapped
uniform vec4 u_quarter_rect;         // (u0, v0, du, dv) of the part drawn
uniform float u_level_weight[BLOOM_LEVELS];

layout(location = 0) out vec4 out_glow;

void main() {
    vec2 uv = u_quarter_rect.xy + v_uv * u_quarter_rect.zw;
    vec3 glow = vec3(0.0);
    for (int level = 0; level < BLOOM_LEVELS; ++level) {
        glow += u_level_weight[level] * textureLod(u_quarter, uv, float(level)).rgb;
    }
    out_glow = vec4(glow, 1.0);
}
