#version 430
// HDR radiance -> display (docs/display.md; numpy twin: catalog/render/display.py):
// exposure, white balance (a CAT16 3x3), the tone curve on luminance, gamut compression in
// OKLab at constant lightness and hue, the sRGB transfer function. GLSL ES 3.00-compatible.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_hdr;
uniform vec4 u_hdr_rect;          // (u0, v0, du, dv): the part of the HDR target this viewport shows
uniform float u_exposure;         // cd m^-2 -> scene value (EV100 and compensation folded in)
uniform mat3 u_white_balance;     // linear sRGB -> linear sRGB adapted to D65 (CAT16)
uniform vec3 u_luminance;         // Y row of linear sRGB -> XYZ
uniform vec2 u_tone;              // (S0, G): y = (x / (x + S0))^G
#ifdef GLARE
// the glare mixed in first (glare.py; energy-preserving): (1 - s) sharp + s glow
uniform sampler2D u_glow;         // bloom_glow.frag's quarter-size glow (bilinear)
uniform vec4 u_glow_rect;         // (u0, v0, du, dv) of the part drawn, in u_glow
uniform float u_glare_strength;
#endif

layout(location = 0) out vec4 out_colour;

// DISPLAY_STAGES (the benchmark's variants; default all): 0 exposure and the sRGB curve
// only, 1 + white balance, 2 + tone curve, 3 + gamut compression.
#ifndef DISPLAY_STAGES
#define DISPLAY_STAGES 3
#endif

#if DISPLAY_STAGES >= 3
// The gamut boundary read from its table (catalog/render/display_lut.py, the numpy twin):
// OKLab chroma where the cube is left, at (hue as the diamond angle / 4, L / ceiling).
uniform sampler2D u_gamut_boundary;
uniform mat3 u_rgb_to_lms;        // OKLab M1 after sRGB -> XYZ
uniform mat3 u_lms_to_rgb;
uniform mat3 u_lms_to_lab;        // OKLab M2
uniform vec3 u_lab_grey;          // LMS' of OKLab (1, 0, 0): about (1, 1, 1)
uniform vec3 u_gamut;             // (R_KNEE, R_LIMIT, lightness ceiling)

vec3 signed_cbrt(vec3 v) {
    return sign(v) * pow(abs(v), vec3(1.0 / 3.0));
}

// Chroma ratio r = C / C_boundary at this L and hue: identity below the knee, then rolled off
// toward the limit (< 1) so no channel lands on the cube's faces; L clamped below the ceiling.
vec3 gamut_compress(vec3 rgb) {
    vec3 lms_prime = signed_cbrt(u_rgb_to_lms * rgb);
    vec3 lab = u_lms_to_lab * lms_prime;
    float lightness = clamp(lab.x, 0.0, u_gamut.z);
    float chroma = length(lab.yz);
    float a_unit = lab.y / max(abs(lab.y) + abs(lab.z), 1e-30);
    float p = lab.z >= 0.0 ? 1.0 - a_unit : 3.0 + a_unit;
    vec2 size = vec2(textureSize(u_gamut_boundary, 0));
    float row = lightness / u_gamut.z * (size.y - 1.0) + 0.5;
    float boundary = texture(u_gamut_boundary, vec2(0.25 * p, row / size.y)).r;
    float r = chroma / max(boundary, 1e-12);
    if (lightness == lab.x && r <= u_gamut.x) {
        return rgb;
    }
    float span = u_gamut.y - u_gamut.x;
    float u = max(r - u_gamut.x, 0.0) / span;
    float compressed = (r <= u_gamut.x) ? r : u_gamut.x + span * u / (1.0 + u);
    vec3 lms = lightness * u_lab_grey + (compressed / max(r, 1e-30)) * (lms_prime - lab.x * u_lab_grey);
    return u_lms_to_rgb * (lms * lms * lms);
}
#endif

vec3 display_linear(vec3 hdr) {
    vec3 c = u_exposure * hdr;
#if DISPLAY_STAGES >= 1
    c = u_white_balance * c;
#endif
#if DISPLAY_STAGES >= 2
    float y = dot(c, u_luminance);
    if (!(y > 0.0)) {
        return vec3(0.0);
    }
    float x = y / (y + u_tone.x);
    float shown = pow(x, u_tone.y);
    c *= shown / y;
#endif
#if DISPLAY_STAGES >= 3
    c = gamut_compress(c);
#endif
    return clamp(c, 0.0, 1.0);
}

void main() {
    vec3 hdr = texture(u_hdr, u_hdr_rect.xy + v_uv * u_hdr_rect.zw).rgb;
#ifdef GLARE
    vec3 glow = texture(u_glow, u_glow_rect.xy + v_uv * u_glow_rect.zw).rgb;
    hdr = (1.0 - u_glare_strength) * hdr + u_glare_strength * glow;
#endif
    out_colour = vec4(srgb_encode(display_linear(hdr)), 1.0);
}
