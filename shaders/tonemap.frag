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
uniform mat3 u_rgb_to_lms;        // OKLab M1 after sRGB -> XYZ
uniform mat3 u_lms_to_rgb;
uniform mat3 u_lms_to_lab;        // OKLab M2
uniform vec2 u_tone;              // (S0, G): y = (x / (x + S0))^G
uniform float u_lightness_ceiling; // the largest OKLab L kept (display.lightness_ceiling)
uniform vec3 u_gamut;             // (R_KNEE, R_LIMIT, CUBE_TOP): chroma ratios kept / approached, cube
#ifdef GLARE
// the glare mixed in first (glare.py; energy-preserving): (1 - s) sharp + s glow
uniform sampler2D u_glow;         // bloom_glow.frag's quarter-size glow (bilinear)
uniform vec4 u_glow_rect;         // (u0, v0, du, dv) of the part drawn, in u_glow
uniform float u_glare_strength;
#endif

layout(location = 0) out vec4 out_colour;

const int GAMUT_STEPS = 8;        // display.GAMUT_STEPS

// DISPLAY_STAGES (the benchmark's variants; default all): 0 exposure and the sRGB curve
// only, 1 + white balance, 2 + tone curve, 3 + gamut compression.
#ifndef DISPLAY_STAGES
#define DISPLAY_STAGES 3
#endif

vec3 signed_cbrt(vec3 v) {
    return sign(v) * pow(abs(v), vec3(1.0 / 3.0));
}

// OKLab's M2 maps LMS' = (L, L, L) to (L, 0, 0) (its first row sums to 1, the others to 0),
// so the colour at lightness L and chroma scale t on this colour's hue is
// LMS' = L + t (lms' - L_own): no trip through Lab. rgb at chroma scale t:
vec3 rgb_at(vec3 lms_prime, float own_l, float l, float t) {
    vec3 lms = vec3(l) + t * (lms_prime - vec3(own_l));
    return u_lms_to_rgb * (lms * lms * lms);
}

bool in_cube(vec3 rgb) {
    return all(greaterThanEqual(rgb, vec3(0.0))) && all(lessThanEqual(rgb, vec3(u_gamut.z)));
}

// Chroma ratio r = C / C_boundary at this L and hue: identity below the knee, then rolled off
// toward the limit (< 1) so no channel lands on the cube's faces.
vec3 gamut_compress(vec3 rgb) {
    vec3 lms_prime = signed_cbrt(u_rgb_to_lms * rgb);
    float own_l = (u_lms_to_lab * lms_prime).x;
    float lightness = clamp(own_l, 0.0, u_lightness_ceiling);
    bool clamped = lightness != own_l;
    float t_hi = 1.0 / u_gamut.x;
    if (!clamped && in_cube(rgb_at(lms_prime, own_l, lightness, t_hi))) {
        return rgb;
    }
    float lo = 0.0;
    float hi = t_hi;
    for (int i = 0; i < GAMUT_STEPS; ++i) {
        float mid = 0.5 * (lo + hi);
        if (in_cube(rgb_at(lms_prime, own_l, lightness, mid))) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    float r = 1.0 / max(lo, 1e-12);   // lo: the boundary from below
    float span = u_gamut.y - u_gamut.x;
    float u = max(r - u_gamut.x, 0.0) / span;
    float compressed = (r <= u_gamut.x) ? r : u_gamut.x + span * u / (1.0 + u);
    return rgb_at(lms_prime, own_l, lightness, compressed / r);
}

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
    c *= pow(x, u_tone.y) / y;
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
