#version 430
// Per vertex of the curtain, a value drawn as one point onto texel (index % width,
// index / width) of a float texture, when the room's light is updated (not every frame):
// common.glsl's outside_occlusion at the vertex's position and normal (issue 11, curtain.vert
// SKY_OCCLUSION).
#include "common.glsl"

in vec3 in_position;
in vec3 in_normal;

uniform vec3 u_mesh_offset;
uniform ivec2 u_target_size;        // the per-vertex texture (texels)

out vec3 v_value;

void main() {
    v_value = outside_occlusion(in_position + u_mesh_offset, in_normal);
    ivec2 texel = ivec2(gl_VertexID % u_target_size.x, gl_VertexID / u_target_size.x);
    gl_Position = vec4((vec2(texel) + 0.5) / vec2(u_target_size) * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 1.0;
}
