#version 430
// Glare, step 1: the HDR frame averaged over 4 x 4 pixels into a quarter-size target (the
// box filter of the frame's mip level 2, so the image's integral is kept), whose mip chain
// bloom_glow.frag then reads. Pixels past the drawn part repeat its last row and column.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_hdr;
uniform ivec2 u_hdr_size;            // the part of the HDR target drawn (pixels)

layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 p = 4 * ivec2(gl_FragCoord.xy);
    ivec2 last = u_hdr_size - 1;
    vec3 sum = vec3(0.0);
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
            sum += texelFetch(u_hdr, min(p + ivec2(i, j), last), 0).rgb;
        }
    }
    out_radiance = vec4(0.0625 * sum, 1.0);
}
