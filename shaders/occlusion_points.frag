#version 430
// occlusion_points.vert's value into its texel.
#include "common.glsl"
in vec3 v_value;

layout(location = 0) out vec4 out_value;

void main() {
    out_value = vec4(v_value, 1.0);
}
