#version 430
// The background: what a camera ray sees behind everything else (the outside through the
// window: sky, ground, the sun's disc; or the room), in linear sRGB radiance.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform mat4 u_inverse_view_proj;
uniform vec3 u_camera_position;
uniform vec3 u_sun_direction;
uniform vec2 u_sun_chord2;
uniform vec3 u_sky_rgb;
uniform vec3 u_ground_rgb;
uniform vec3 u_sun_disc_rgb;
uniform vec3 u_room_rgb;

layout(location = 0) out vec4 out_radiance;

void main() {
    vec4 far_point = u_inverse_view_proj * vec4(v_ndc, 1.0, 1.0);
    vec3 ray = normalize(far_point.xyz / far_point.w - u_camera_position);
    vec4 w = background_weights(ray, u_sun_direction, u_sun_chord2.x, u_sun_chord2.y);
    out_radiance = vec4(w.x * u_sky_rgb + w.y * u_ground_rgb + w.z * u_sun_disc_rgb + w.w * u_room_rgb, 1.0);
}
