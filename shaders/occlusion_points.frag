#version 430
// occlusion_points.vert's value into its texel.
#include "common.glsl"
in vec3 v_occlusion;

layout(location = 0) out vec4 out_occlusion;

void main() {
    out_occlusion = vec4(v_occlusion, 1.0);
}
