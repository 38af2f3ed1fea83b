#version 430
// The transmittance shadow map (issue 13): the curtain seen from the key light, orthographic
// along its travel (catalog/render/curtain_frames.py: light_view_projection).
in vec3 in_position;
#ifdef HAS_UV
in vec2 in_uv;
#endif

uniform mat4 u_light_view_proj;
uniform vec3 u_mesh_offset;

out vec2 v_uv;

void main() {
#ifdef HAS_UV
    v_uv = in_uv;
#else
    v_uv = vec2(0.5);
#endif
    gl_Position = u_light_view_proj * vec4(in_position + u_mesh_offset, 1.0);
}
