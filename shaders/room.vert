#version 430
// Room props (walls with the window opening, the curtain rod): world-space triangles.
in vec3 in_position;
in vec3 in_normal;

uniform mat4 u_view_proj;

out vec3 v_normal;
out vec3 v_position;

void main() {
    v_normal = in_normal;
    v_position = in_position;
    gl_Position = u_view_proj * vec4(in_position, 1.0);
}
