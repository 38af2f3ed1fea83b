#version 430
// Weighted blended OIT resolve (McGuire & Bavoil 2013): the curtain's layers over the scene
// behind them. Blended ONE, SRC_ALPHA onto the HDR target that holds the room and the
// background: result = average layer colour x (1 - revealage) + behind x revealage, where
// revealage = prod(1 - c_i), the product of the layers' open fractions (model.md section 9:
// layers multiply their transmittances; the holes show what is behind, undimmed).
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_accum;     // rgb: sum C a w, a: prod (1 - a)
uniform sampler2D u_weight;    // r: sum a w

layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 accum = texelFetch(u_accum, p, 0);
    float revealage = accum.a;
    if (revealage >= 1.0) {
        discard;   // no cloth here
    }
    out_radiance = oit_resolve(accum, texelFetch(u_weight, p, 0).r);
}
