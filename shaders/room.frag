#version 430
// Room props: grey Lambertian surfaces lit by the room's diffuse light and the fill light.
#include "common.glsl"

in vec3 v_normal;

uniform vec3 u_room_rgb;          // radiance of the walls under the room's diffuse light
uniform vec3 u_fill_rgb;          // radiance added by the fill light at normal incidence
uniform vec3 u_fill_to_light;

layout(location = 0) out vec4 out_radiance;

void main() {
    vec3 n = normalize(v_normal);
    out_radiance = vec4(u_room_rgb + max(dot(n, u_fill_to_light), 0.0) * u_fill_rgb, 1.0);
}
