#version 430
// Test probe: evaluates common.glsl's hg_phase_robust in float32 for vectors given by the test
// (tests/test_render_hg.py compares with the float64 twin in catalog/optics/shading_reference.py).
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Travel { vec4 travel[]; };
layout(std430, binding = 1) readonly buffer View { vec4 view[]; };
layout(std430, binding = 2) writeonly buffer Result { float phase[]; };

uniform float u_g;
uniform int u_count;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_count) {
        return;
    }
    vec3 delta = view[i].xyz - travel[i].xyz;
    vec3 sum = view[i].xyz + travel[i].xyz;
    phase[i] = hg_phase_robust(dot(delta, delta), dot(sum, sum), u_g);
}
