#version 430
// The window wall beside the opening at a finer grid than the light map's (issue 11, ninth
// round; room_light.window_near_points is the float64 twin): per texel of a rectangle of the
// wall round the opening (room_light.window_near_rect, WINDOW_NEAR_TEXELS a side), the
// window's direct light (common.glsl room_direct_irradiance) at the texel's centre, moved out
// of the opening onto the wall where it falls inside. The window's light falls there tenfold
// within a light-map texel (27 cm: the box's sides and the window side's patches stand a few
// cm away), and the light map's bilinear read smeared the texel at the edge over its
// neighbour; room.frag (WINDOW_NEAR) reads this instead of the light map's direct part.
#define WINDOW_LIGHT
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform vec4 u_near_rect;            // x0, x1, y0, y1 of the texture's rectangle (m)
uniform vec4 u_window_rect;          // x0, x1, y0, y1 of the opening (m)
uniform float u_wall_z;              // the window wall's inner plane (m)
uniform vec3 u_key_to_light;

layout(location = 0) out vec4 out_irradiance;

void main() {
    vec2 q = mix(u_near_rect.xz, u_near_rect.yw, v_uv);
    vec2 inside = min(q - u_window_rect.xz, u_window_rect.yw - q);   // > 0 on both: in the opening
    if (min(inside.x, inside.y) > -1e-3) {   // onto the nearest edge, 1 mm out on the wall
        if (inside.x < inside.y) {
            q.x = q.x - u_window_rect.x < u_window_rect.y - q.x ? u_window_rect.x - 1e-3 : u_window_rect.y + 1e-3;
        } else {
            q.y = q.y - u_window_rect.z < u_window_rect.w - q.y ? u_window_rect.z - 1e-3 : u_window_rect.w + 1e-3;
        }
    }
    vec3 p = vec3(q, u_wall_z);
    out_irradiance = vec4(room_direct_irradiance(p, vec3(0.0, 0.0, 1.0), u_window_rect, u_wall_z, u_key_to_light), 1.0);
}
