#version 430
// Post-process anti-aliasing on the display image (after the tone map): the idea of FXAA
// (Lottes 2009, "FXAA", NVIDIA white paper) in its simplest form, written for this project:
// where the local luma contrast is high, find whether the edge runs horizontally or
// vertically and blend the centre toward its neighbour across the edge, weighted by how far
// the centre's luma is from its neighbours' mean (sub-pixel aliasing: a thread or a
// silhouette that lands on a pixel centre or misses it). Five texel fetches and no filtered
// sample (the blend is done here: what a bilinear read between the two texels would give),
// which a CPU rasteriser runs at about half the cost of filtered reads (docs/pattern.md).
// Chosen over MSAA on llvmpipe because the curtain is drawn into float OIT targets, which it
// multisamples slowly (docs/pattern.md has the measurement). GLSL ES 3.00-compatible.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_ldr;       // sRGB-encoded display colour
uniform vec2 u_size_px;        // (w, h): u_ldr's corner [0, w) x [0, h) holds the image

layout(location = 0) out vec4 out_colour;

const float CONTRAST_MIN = 0.0312;     // below this absolute contrast: no edge
const float CONTRAST_REL = 0.125;      // ... or below this fraction of the local maximum

void main() {
    ivec2 last = ivec2(u_size_px) - 1;
    ivec2 p = min(ivec2(v_uv * u_size_px), last);
    vec3 m = texelFetch(u_ldr, p, 0).rgb;
    vec3 cn = texelFetch(u_ldr, ivec2(p.x, min(p.y + 1, last.y)), 0).rgb;
    vec3 cs = texelFetch(u_ldr, ivec2(p.x, max(p.y - 1, 0)), 0).rgb;
    vec3 ce = texelFetch(u_ldr, ivec2(min(p.x + 1, last.x), p.y), 0).rgb;
    vec3 cw = texelFetch(u_ldr, ivec2(max(p.x - 1, 0), p.y), 0).rgb;
    float lm = display_luma(m);
    float ln = display_luma(cn);
    float ls = display_luma(cs);
    float le = display_luma(ce);
    float lw = display_luma(cw);
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
    bool positive = abs(step_pos - lm) >= abs(step_neg - lm);
    vec3 neighbour = horizontal ? (positive ? cn : cs) : (positive ? ce : cw);
    float sub = clamp(abs(0.25 * (ln + ls + le + lw) - lm) / range, 0.0, 1.0);
    float blend = sub * sub * (3.0 - 2.0 * sub) * 0.75;   // smoothstep, at most 3/4 px
    out_colour = vec4(mix(m, neighbour, blend), 1.0);
}
