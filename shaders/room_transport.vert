#version 430
// A room drawn with its light map from the precomputed transport (catalog/room/transport.py):
// each receiver's triangle, its irradiance at the corners (welded across receivers of one
// plane, interpolated between them) and its albedo.
in vec3 in_position;
in vec3 in_irradiance;   // W m^-2 (the window's units x sr), at this corner
in vec3 in_albedo;       // the receiver's mean albedo

uniform mat4 u_view_proj;

out vec3 v_irradiance;
flat out vec3 v_albedo;

void main() {
    v_irradiance = in_irradiance;
    v_albedo = in_albedo;
    gl_Position = u_view_proj * vec4(in_position, 1.0);
}
