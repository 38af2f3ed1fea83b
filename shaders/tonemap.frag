#version 430
// HDR -> display: exposure, the luminance Reinhard curve, the sRGB transfer function.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform sampler2D u_hdr;
uniform vec4 u_hdr_rect;          // (u0, v0, du, dv): the part of the HDR target this viewport shows
uniform float u_exposure;         // multiplies the linear radiance (cd m^-2 -> scene units of 1 = "white")
uniform float u_white;            // the luminance (after exposure) that maps to 1

layout(location = 0) out vec4 out_colour;

void main() {
    vec3 hdr = texture(u_hdr, u_hdr_rect.xy + v_uv * u_hdr_rect.zw).rgb;
    vec3 mapped = tone_map_reinhard_luminance(u_exposure * hdr, u_white);
    out_colour = vec4(srgb_encode(mapped), 1.0);
}
