#version 430
// The least arithmetic eq. 5-7 asks of a fragment for the scene's two directional lights, as a
// benchmark row (not a renderer): both varyings normalised, each light's chord |v - travel|^2,
// two isotropic HG lobes per light (d^1.5: a square root each), one division shared by the four
// lobes, |n . l|, three channels. No anisotropy, see-through, fluorescence or band constants;
// the numbers are typical of a fabric (the cost does not depend on them).
#include "common.glsl"

in vec3 v_view_ray;
in vec3 v_normal;

layout(location = 0) out vec4 out_radiance;

const vec3 KEY_TO_LIGHT = vec3(0.0, 0.42261826, -0.90630779);    // 25 deg up, behind the window
const vec3 FILL_TO_LIGHT = vec3(0.0, 0.25881905, 0.96592583);    // behind the viewer
const float G_DIFF = 0.2;
const float G_SPEC = 0.9;

void main() {
    vec3 n = normalize(v_normal);
    vec3 to_viewer = -normalize(v_view_ray);
    vec3 delta_key = to_viewer + KEY_TO_LIGHT;
    vec3 delta_fill = to_viewer + FILL_TO_LIGHT;
    float chord_key = dot(delta_key, delta_key);
    float chord_fill = dot(delta_fill, delta_fill);
    float d_kd = hg_d(chord_key, 0.0, G_DIFF);     // eq. 6, as curtain.frag forms it
    float d_ks = hg_d(chord_key, 0.0, G_SPEC);
    float d_fd = hg_d(chord_fill, 0.0, G_DIFF);
    float d_fs = hg_d(chord_fill, 0.0, G_SPEC);
    float x_kd = d_kd * sqrt(d_kd);
    float x_ks = d_ks * sqrt(d_ks);
    float x_fd = d_fd * sqrt(d_fd);
    float x_fs = d_fs * sqrt(d_fs);
    float q_key = x_kd * x_ks;
    float q_fill = x_fd * x_fs;
    float inv = 1.0 / (q_key * q_fill);
    float g_key = abs(dot(n, KEY_TO_LIGHT)) * (0.03 * x_ks + 0.02 * x_kd) * q_fill * inv;
    float g_fill = abs(dot(n, FILL_TO_LIGHT)) * (0.03 * x_fs + 0.02 * x_fd) * q_key * inv;
    out_radiance = vec4(g_key * vec3(900.0, 1000.0, 1100.0) + g_fill * vec3(36.0, 40.0, 44.0), 1.0);
}
