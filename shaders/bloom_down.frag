#version 430
// Glare, step 1: the HDR frame averaged over 2 x 2 pixels into a half-size target (exactly
// the box filter of a mip level, so the image's integral is kept), whose mip chain
// bloom.frag then reads.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_hdr;
uniform ivec2 u_hdr_size;            // the part of the HDR target drawn (pixels)

layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 p = 2 * ivec2(gl_FragCoord.xy);
    ivec2 last = u_hdr_size - 1;
    vec3 sum = texelFetch(u_hdr, min(p, last), 0).rgb
             + texelFetch(u_hdr, min(p + ivec2(1, 0), last), 0).rgb
             + texelFetch(u_hdr, min(p + ivec2(0, 1), last), 0).rgb
             + texelFetch(u_hdr, min(p + ivec2(1, 1), last), 0).rgb;
    out_radiance = vec4(0.25 * sum, 1.0);
}
