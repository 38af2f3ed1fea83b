#version 430
// The curtain mesh: world-space positions (the model matrix is the identity), normals and the
// weft tangent; shared by the shading pass, the G-buffer variant and the trivial floor shader.
in vec3 in_position;
in vec3 in_normal;
in vec3 in_tangent;

uniform mat4 u_view_proj;

out vec3 v_position;
out vec3 v_normal;
out vec3 v_tangent;

void main() {
    v_position = in_position;
    v_normal = in_normal;
    v_tangent = in_tangent;
    gl_Position = u_view_proj * vec4(in_position, 1.0);
}
