#version 430
// The transmittance shadow map (issue 13, model.md section 9): each layer of cloth the key
// light's beam crosses multiplies it by its transmittance (blending dst *= src, cleared to 1;
// folds and layers multiply). Per layer, with thread coverage c(uv) (mean 1 - LD):
//   T = (1 - c) + c * u_thread_beam_rgb,
// the holes pass the beam undimmed, a thread passes the forward-scattered part of the
// directional lobe (a_spec x forward(g_spec) x the dye's colour under the key light, divided
// by the mean coverage so that the average over a repeat is the fitted cloth: LD + a_spec fwd).
#include "common.glsl"

in vec2 v_uv;

uniform float u_mean_coverage;       // 1 - LD
uniform vec3 u_thread_beam_rgb;      // per thread: a_spec forward(g_spec) dye / (1 - LD)
#ifdef SECOND_LAYER
uniform sampler2D u_first_layer;     // the front-layer map (a: the nearest layer's depth)
uniform float u_peel_bias;           // depth (0..1 units) the second layer lies behind the first, at least
#endif

layout(location = 0) out vec4 out_transmittance;

// THE PATTERN HOOK: thread coverage at cloth coordinate uv (0..1 across the fabric). With
// PATTERN (the fabric's [pattern] coverage map of issue 12: u_pattern and thread_coverage in
// common.glsl, uv scaled to pattern repeats by u_uv_to_repeats), the holes are projected and
// the texture's mip level follows this pass's footprint (motifs larger than a shadow-map texel
// show, single threads average to the mean). Without it the cloth is uniform: every point has
// the mean coverage, so the patch is dimmed and tinted, patterned only by folds and layers.
#ifdef PATTERN
uniform vec2 u_uv_to_repeats;
float curtain_coverage(vec2 uv) {
    return thread_coverage(uv * u_uv_to_repeats);
}
#else
float curtain_coverage(vec2 uv) {
    return u_mean_coverage;
}
#endif

void main() {
    float c = curtain_coverage(v_uv);
#if defined(FRONT_LAYER) && defined(BOTH_LAYERS)
    // the occlusion maps (curtain.frag SKY_OCCLUSION, ROOM_SIDE): blended without a depth test,
    // rgb by MAX and alpha by MIN (frame.py), so g keeps the layer farthest from the light (the
    // one nearest the room) and a the nearest
    out_transmittance = vec4(0.0, gl_FragCoord.z, 0.0, gl_FragCoord.z);
#elif defined(FRONT_LAYER)
    // the front-layer map (curtain.frag, KEY_SHADOW and SKY_OCCLUSION): the nearest layer's
    // thread coverage and its depth, kept by the depth test (no blending)
    out_transmittance = vec4(c, 0.0, 0.0, gl_FragCoord.z);
#elif defined(SECOND_LAYER)
    // the second layer's map (issue 11, seventh round; curtain.frag KEY_SHADOW): the front-layer
    // map peeled, the nearest layer behind the first by more than u_peel_bias plus the depth
    // this surface spans across 1.5 texels (else a fold at a grazing angle to the light would
    // count as its own second layer), kept by the depth test: its coverage and depth
    float first = texelFetch(u_first_layer, ivec2(gl_FragCoord.xy), 0).a;
    float span = PEEL_SPAN_TEXELS * (abs(dFdx(gl_FragCoord.z)) + abs(dFdy(gl_FragCoord.z)));
    if (gl_FragCoord.z <= first + u_peel_bias + span) {
        discard;
    }
    out_transmittance = vec4(c, 0.0, 0.0, gl_FragCoord.z);
#else
    out_transmittance = vec4(vec3(1.0 - c) + c * u_thread_beam_rgb, 1.0);
#endif
}
