#version 430
// Room props (walls with the window opening, the curtain rod): world-space triangles.
// ROOM_LIGHTING: the light-map atlas coordinates are affine across a flat face, so they are
// formed here (room_atlas_uv of the face the normal picks) and interpolated; the fragment
// shader clamps them into the face's rectangle (flat), so it indexes no uniform array.
#include "common.glsl"

in vec3 in_position;
in vec3 in_normal;

uniform mat4 u_view_proj;

out vec3 v_normal;
out vec3 v_position;
#ifdef ROOM_LIGHTING
uniform vec3 u_face_origin[6];
uniform vec3 u_face_s[6];
uniform vec3 u_face_t[6];
uniform float u_face_texels;
out vec2 v_atlas;
flat out vec4 v_atlas_box;        // u min, u max, v min, v max (half a texel inside the face)
#endif

void main() {
    v_normal = in_normal;
    v_position = in_position;
#ifdef ROOM_LIGHTING
    int face = room_face_of_normal(in_normal);
    vec3 d = in_position - u_face_origin[face];
    vec3 axis_s = u_face_s[face];
    vec3 axis_t = u_face_t[face];
    float s = dot(d, axis_s) / dot(axis_s, axis_s);
    float t = dot(d, axis_t) / dot(axis_t, axis_t);
    v_atlas = vec2((float(face) + s) / float(ROOM_FACES), t);
    float edge = 0.5 / u_face_texels;
    v_atlas_box = vec4((float(face) + edge) / float(ROOM_FACES), (float(face) + 1.0 - edge) / float(ROOM_FACES),
                       edge, 1.0 - edge);
#endif
    gl_Position = u_view_proj * vec4(in_position, 1.0);
}
