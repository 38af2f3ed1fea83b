#version 430
// Glare (issue 13), step 3: HDR bloom before the tone map, energy-preserving. The scene's
// radiance keeps 1 - u_strength of itself and takes u_strength of the glow (bloom_glow.frag:
// a weighted sum of wide box blurs of the frame, each keeping the image's integral), so the
// frame's total radiance is unchanged and only its distribution widens, most visibly around
// the sun's disc and the cloth it backlights. One full-size tap of the half-size glow.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_hdr;             // the HDR frame (full size, read per pixel)
uniform sampler2D u_glow;            // bloom_glow.frag's half-size glow (bilinear)
uniform vec4 u_glow_rect;            // (u0, v0, du, dv) of the part drawn, in u_glow
uniform float u_strength;

layout(location = 0) out vec4 out_radiance;

void main() {
    vec3 sharp = texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb;
    vec3 glow = texture(u_glow, u_glow_rect.xy + v_uv * u_glow_rect.zw).rgb;
    out_radiance = vec4((1.0 - u_strength) * sharp + u_strength * glow, 1.0);
}
