#version 430
#include "common.glsl"
// The curtain mesh: positions (moved into the scene by u_mesh_offset: the cloth simulation's
// own frame has the rod elsewhere), normals and the weft tangent; shared by the shading pass,
// the G-buffer variant and the trivial floor shader. The view ray (position - camera) is
// linear in the position, so it is formed here and interpolated exactly: the fragment shader
// then needs no per-frame uniform. The tangent travels only where it is used. PATTERN: the
// fabric's texture coordinates in pattern repeats (catalog/presets/patterns.py) for curtain.frag.
// INTERPOLATION: empty, or ``centroid`` on the MSAA path (frame.py), where a pixel whose centre
// lies outside the triangle is shaded once for its covered samples: its attributes must
// come from inside the triangle, not extrapolated past a fold's silhouette.
#ifndef INTERPOLATION
#define INTERPOLATION
#endif
in vec3 in_position;
in vec3 in_normal;
in vec3 in_tangent;
#ifdef PATTERN
in vec2 in_uv;                       // 0..1 across the fabric (u: weft), 0..1 along it (v: warp)
uniform vec2 u_uv_to_repeats;        // fabric size / pattern repeat: uv -> pattern repeats
INTERPOLATION out vec2 v_pattern_uv;
#endif

#ifdef SKY_OCCLUSION
// The outside hidden from this vertex by the cloth and by the window wall (issue 11,
// common.glsl outside_occlusion), computed once per update of the room's light by
// occlusion_points.vert into one texel per vertex (u_vertex_occlusion, u_vertex_occlusion_width
// texels a row) and read here by the vertex's index.
uniform sampler2D u_vertex_occlusion;
uniform int u_vertex_occlusion_width;
INTERPOLATION out vec3 v_occlusion; // the cloth's share, the wall's, the cloth's towards the room
#endif

uniform mat4 u_view_proj;
uniform vec3 u_mesh_offset;
uniform vec3 u_camera_position;

INTERPOLATION out vec3 v_view_ray;
INTERPOLATION out vec3 v_normal;
#if defined(ANISOTROPIC) || defined(GBUFFER) || defined(PATTERN)
INTERPOLATION out vec3 v_tangent;
#endif
#if defined(GBUFFER) || defined(N_ROOM_LAMPS) || defined(KEY_SHADOW) || defined(ROOM_SIDE)
INTERPOLATION out vec3 v_position;
#endif

void main() {
    vec3 position = in_position + u_mesh_offset;
    v_view_ray = position - u_camera_position;
    v_normal = in_normal;
#if defined(ANISOTROPIC) || defined(GBUFFER) || defined(PATTERN)
    v_tangent = in_tangent;
#endif
#ifdef PATTERN
    v_pattern_uv = in_uv * u_uv_to_repeats;
#endif
#if defined(GBUFFER) || defined(N_ROOM_LAMPS) || defined(KEY_SHADOW) || defined(ROOM_SIDE)
    v_position = position;
#endif
#ifdef SKY_OCCLUSION
    v_occlusion = texelFetch(u_vertex_occlusion, ivec2(gl_VertexID % u_vertex_occlusion_width,
                                                       gl_VertexID / u_vertex_occlusion_width), 0).xyz;
#endif
    gl_Position = u_view_proj * vec4(position, 1.0);
}
