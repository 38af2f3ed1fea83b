#version 430
// A room drawn with its light map from the precomputed transport (catalog/room/transport.py):
// each receiver's triangle with its irradiance at the corners (welded across receivers of
// one plane, interpolated between them), its normal and the surface's texture coordinates.
// DEPTH_ONLY: the room's geometry alone (the key light's depth map of the room).
in vec3 in_position;
#ifndef DEPTH_ONLY
in vec3 in_irradiance;   // W m^-2 (the window's units x sr), at this corner
in vec3 in_normal;
in vec2 in_uv;
out vec3 v_irradiance;
out vec3 v_position;
flat out vec3 v_normal;
out vec2 v_uv;
#endif

uniform mat4 u_view_proj;

void main() {
#ifndef DEPTH_ONLY
    v_irradiance = in_irradiance;
    v_position = in_position;
    v_normal = in_normal;
    v_uv = in_uv;
#endif
    gl_Position = u_view_proj * vec4(in_position, 1.0);
}
