#version 430
// The curtain mesh: positions (moved into the scene by u_mesh_offset: the cloth simulation's
// own frame has the rod elsewhere), normals and the weft tangent; shared by the shading pass,
// the G-buffer variant and the trivial floor shader.
in vec3 in_position;
in vec3 in_normal;
in vec3 in_tangent;

uniform mat4 u_view_proj;
uniform vec3 u_mesh_offset;

out vec3 v_position;
out vec3 v_normal;
out vec3 v_tangent;

void main() {
    v_position = in_position + u_mesh_offset;
    v_normal = in_normal;
    v_tangent = in_tangent;
    gl_Position = u_view_proj * vec4(v_position, 1.0);
}
