#version 430
// The key light's visibility at a cloth point (issue 11, model.md section 9), baked over the
// fabric's uv once per update of the light or the mesh (it depends on neither the camera nor
// the frame): r the window's mask where the key shines through it (room_window_beam; a light
// in the room: 1), g and b the thread coverage of the first and second layers of cloth in
// front of the point towards the key (front_layers_coverage on the front-layer map and its
// peeled second layer, room_shadow.frag FRONT_LAYER / SECOND_LAYER). curtain.frag KEY_SHADOW
// reads it with one bilinear lookup, where it took eight texel fetches, eight depth ramps and
// the window's mask per fragment (docs/bench.md: the curtain's terms).
#include "common.glsl"

in vec3 v_position;
in vec3 v_normal;

uniform vec3 u_key_to_light;
uniform sampler2D u_key_front;     // r: the nearest layer's coverage, a: its depth (0..1)
uniform sampler2D u_key_second;    // the same of the second layer (cleared: coverage 0)
uniform mat4 u_light_view_proj;
uniform float u_key_normal_offset; // m: the lookup's offset along the normal at a grazing key
uniform vec3 u_key_depth_bias;     // depth (0..1 units) a point must lie behind to be shaded:
                                   // x + y tan(normal, key), the tangent at most z (slope-scaled)
uniform vec4 u_window_rect;
uniform vec2 u_wall_z;
uniform float u_tan_sun_radius;

layout(location = 0) out vec4 out_visibility;

void main() {
    float beam = u_key_to_light.z < 0.0
               ? room_window_beam(v_position, u_key_to_light, u_window_rect, u_wall_z, u_tan_sun_radius)
               : 1.0;
    // the lookup moved off the cloth towards the light along its normal, by
    // u_key_normal_offset x sin(normal, key) (normal-offset shadows: a flank lit at a grazing
    // angle does not shade itself, without a depth bias that would let a fold close in front
    // of it through)
    vec3 n = normalize(v_normal);
    float facing = dot(n, u_key_to_light);
    float cos_surface = abs(facing);
    float sin_surface = sqrt(max(1.0 - cos_surface * cos_surface, 0.0));
    vec3 offset = n * ((facing >= 0.0 ? 1.0 : -1.0) * u_key_normal_offset * sin_surface);
    vec4 clip = u_light_view_proj * vec4(v_position + offset, 1.0);
    float tan_surface = min(sin_surface / max(cos_surface, 1e-3), u_key_depth_bias.z);
    vec2 layers = front_layers_coverage(u_key_front, u_key_second, clip.xyz * 0.5 + 0.5,
                                        u_key_depth_bias.x + u_key_depth_bias.y * tan_surface);
    out_visibility = vec4(beam, layers, 1.0);
}
