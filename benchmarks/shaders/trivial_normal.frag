#version 430
// A second floor for the benchmark: the trivial shader plus one interpolated varying (the
// normal as a colour), on the same mesh, vertex shader and float target: what reading the
// geometry costs before any shading. (common.glsl is included as by every program; nothing
// of it is used.)
#include "common.glsl"

in vec3 v_normal;

layout(location = 0) out vec4 out_radiance;

void main() {
    out_radiance = vec4(0.5 * v_normal + 0.5, 1.0);
}
