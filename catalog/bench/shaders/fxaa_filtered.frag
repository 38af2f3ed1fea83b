#version 430
// The FXAA shader as issue 12 first wrote it (six filtered reads), kept for the pattern
// benchmark only (catalog/bench/pattern.py times it against shaders/fxaa.frag).
// Post-process anti-aliasing on the display image (after the tone map): the idea of FXAA
// (Lottes 2009, "FXAA", NVIDIA white paper) in its simplest form, written for this project:
// where the local luma contrast is high, find whether the edge runs horizontally or
// vertically and re-sample half a pixel across it, weighted by how far the centre's luma is
// from its neighbours' mean (sub-pixel aliasing: a thread or a silhouette that lands on a
// pixel centre or misses it). Chosen over MSAA because the curtain is drawn into float OIT
// targets, which llvmpipe multisamples slowly (docs/pattern.md has the measurement).
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_ldr;       // sRGB-encoded display colour, linear filtering
uniform vec4 u_rect;           // (u0, v0, du, dv): the part of u_ldr to show
uniform vec2 u_texel;          // 1 / size of u_ldr in texels

layout(location = 0) out vec4 out_colour;

const float CONTRAST_MIN = 0.0312;     // below this absolute contrast: no edge
const float CONTRAST_REL = 0.125;      // ... or below this fraction of the local maximum

void main() {
    vec2 uv = u_rect.xy + v_uv * u_rect.zw;
    vec3 m = texture(u_ldr, uv).rgb;
    float lm = display_luma(m);
    float ln = display_luma(texture(u_ldr, uv + vec2(0.0, u_texel.y)).rgb);
    float ls = display_luma(texture(u_ldr, uv - vec2(0.0, u_texel.y)).rgb);
    float le = display_luma(texture(u_ldr, uv + vec2(u_texel.x, 0.0)).rgb);
    float lw = display_luma(texture(u_ldr, uv - vec2(u_texel.x, 0.0)).rgb);
    float lo = min(lm, min(min(ln, ls), min(le, lw)));
    float hi = max(lm, max(max(ln, ls), max(le, lw)));
    float range = hi - lo;
    if (range < max(CONTRAST_MIN, CONTRAST_REL * hi)) {
        out_colour = vec4(m, 1.0);
        return;
    }
    // edge orientation from the second differences across each axis
    float across_v = abs(ln + ls - 2.0 * lm);   // large: a horizontal edge (varies along y)
    float across_h = abs(le + lw - 2.0 * lm);   // large: a vertical edge (varies along x)
    bool horizontal = across_v >= across_h;
    float step_pos = horizontal ? ln : le;
    float step_neg = horizontal ? ls : lw;
    // move towards the neighbour across the edge that differs most from the centre
    float side = abs(step_pos - lm) >= abs(step_neg - lm) ? 1.0 : -1.0;
    float sub = clamp(abs(0.25 * (ln + ls + le + lw) - lm) / range, 0.0, 1.0);
    float blend = sub * sub * (3.0 - 2.0 * sub) * 0.75;   // smoothstep, at most 3/4 px
    vec2 offset = horizontal ? vec2(0.0, u_texel.y) : vec2(u_texel.x, 0.0);
    vec3 across = texture(u_ldr, uv + side * blend * offset).rgb;   // bilinear: (1 - blend) m + blend neighbour
    out_colour = vec4(across, 1.0);
}
