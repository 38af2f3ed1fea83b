#version 430
#undef PATTERN_LOD_BIAS   // texture()'s bias is a fragment stage's (common.glsl thread_texel)
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
#if defined(PATTERN) || defined(KEY_SHADOW)
in vec2 in_uv;                       // 0..1 across the fabric (u: weft), 0..1 along it (v: warp)
#endif
#ifdef KEY_SHADOW
INTERPOLATION out vec2 v_key_uv;     // the key's visibility baked over uv (key_visibility.frag)
#endif
#ifdef PATTERN
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

#ifdef ROOM_SIDE
// The light on the cloth's two sides (issue 11, fourth round; curtain.frag ROOM_SIDE), per
// vertex: the room's irradiance (room_bounce.frag CURTAIN_SIDE's grid over the opening,
// bilinear) where the folds leave the room's side open, and where they hide it (the per-vertex
// occlusion's z) the cloth's room side, pi x the room's capture at this patch; the radiance of
// the cloth's window side at this patch (the window-side capture); and whether the view's
// continuation meets a fold (OCCLUSION_MAPS: the occlusion map whose direction lies nearest it;
// the room's captures and the G-buffer only).
uniform sampler2D u_room_side;       // irradiance, linear sRGB (x pi cd m^-2)
uniform vec4 u_room_side_rect;       // the grid: x from, y from, 1 / width, 1 / height (m)
uniform sampler2D u_room_side_cloth; // the room's capture of the cloth (the window's patches)
uniform int u_room_side_cloth_level; // its level of one texel a patch
uniform ivec2 u_room_side_cloth_size;
uniform sampler2D u_window_side_cloth;
uniform int u_window_side_cloth_level;
INTERPOLATION out vec3 v_room_side_light;
INTERPOLATION out vec3 v_window_side_light;
INTERPOLATION out float v_view_occlusion;
#ifdef WALL_LIGHT
// What the window wall and its reveals show the cloth's window side (issue 11, fifth round),
// each lobe's share passed by its forward transmittance:
//  - the diffuse lobe: over the walled share of the hemisphere, the per-vertex walled_radiance
//    the room's update drew (read like the occlusion);
//  - the directional lobe: over WALL_LOBE_SAMPLES directions drawn from its HG lobe about the
//    view's continuation, the wall's radiance where they meet it, less the outside (the sky
//    above the horizon, the ground below) the frame's outside term gave them; and back the
//    directional lobe's part of what the outside's occlusion took for the walled share (it
//    takes both lobes' hemisphere mean: right for the diffuse lobe, while the directional
//    lobe sees the wall only where its samples meet it). From a room view looking down, the
//    continuation meets the sunlit sill; through the view's one ray instead of the lobe's
//    spread, the curtain's bottom was 1.1-1.3x the path tracer's.
uniform sampler2D u_vertex_wall_light;
uniform vec3 u_wall_lobe[WALL_LOBE_SAMPLES];   // the directional lobe's directions about +z
uniform vec3 u_window_side_diffuse;      // dye a_diff forward(g_diff)
uniform vec3 u_window_side_directional;  // dye a_spec forward(g_spec)
INTERPOLATION out vec3 v_wall_light;
#endif
#ifdef WALL_GRID
// The room's surfaces round the window (the wall beside the opening, its reveals, a frame)
// as the cloth's window side sees them (the room's transport: catalog/render/passes/
// room_transport_light.py): their irradiance on the cloth's plane from that side, a grid over
// the room side's rectangle; both lobes pass it by their forward transmittance of diffuse light.
uniform sampler2D u_wall_grid;           // irradiance, linear sRGB (x pi cd m^-2)
uniform vec3 u_window_side_diffuse;      // dye a_diff forward(g_diff)
uniform vec3 u_window_side_directional;  // dye a_spec forward(g_spec)
INTERPOLATION out vec3 v_wall_light;
#endif
#endif

INTERPOLATION out vec3 v_view_ray;
INTERPOLATION out vec3 v_normal;
#if defined(ANISOTROPIC) || defined(GBUFFER) || defined(PATTERN)
INTERPOLATION out vec3 v_tangent;
#endif
#if defined(GBUFFER) || defined(N_ROOM_LAMPS)
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
#if defined(GBUFFER) || defined(N_ROOM_LAMPS)
    v_position = position;
#endif
#ifdef KEY_SHADOW
    v_key_uv = in_uv;
#endif
#ifdef SKY_OCCLUSION
    v_occlusion = texelFetch(u_vertex_occlusion, ivec2(gl_VertexID % u_vertex_occlusion_width,
                                                       gl_VertexID / u_vertex_occlusion_width), 0).xyz;
#endif
#ifdef ROOM_SIDE
    vec2 side_uv = (position.xy - u_room_side_rect.xy) * u_room_side_rect.zw;
    ivec2 cloth_patch = ivec2(clamp(side_uv, 0.0, 0.999) * vec2(u_room_side_cloth_size));
#ifdef ROOM_CAPTURE
    // the room's window capture (FOLDS_BEHIND) takes only the folds' window side: the room's
    // light off the cloth is the radiosity's (room_radiosity.frag), and the room's capture of
    // the cloth is the target being drawn
    v_room_side_light = vec3(0.0);
#else
    vec3 room_light = textureLod(u_room_side, side_uv, 0.0).rgb;
    vec3 cloth_light = PI * texelFetch(u_room_side_cloth, cloth_patch, u_room_side_cloth_level).rgb;
#ifdef SKY_OCCLUSION
    v_room_side_light = mix(room_light, cloth_light, v_occlusion.z);
#else
    v_room_side_light = room_light;
#endif
#endif
    v_window_side_light = texelFetch(u_window_side_cloth, cloth_patch, u_window_side_cloth_level).rgb;
    v_view_occlusion = 0.0;
#ifdef WALL_LIGHT
    {
        vec3 walled = texelFetch(u_vertex_wall_light, ivec2(gl_VertexID % u_vertex_occlusion_width,
                                                             gl_VertexID / u_vertex_occlusion_width), 0).rgb;
        vec3 view = normalize(v_view_ray);
        vec3 across = normalize(cross(abs(view.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0), view));
        vec3 up = cross(view, across);
        vec3 sky = (2.0 / PI) * u_wall_sky_half;
        vec3 ground = (2.0 / PI) * u_wall_ground_half;
        vec3 lobe = vec3(0.0);
        for (int k = 0; k < WALL_LOBE_SAMPLES; ++k) {
            vec3 d = u_wall_lobe[k].x * across + u_wall_lobe[k].y * up + u_wall_lobe[k].z * view;
            if (d.z < -1e-6) {
                vec4 wall = wall_radiance_along(position, d);
                lobe += wall.a * (wall.rgb - (d.y > 0.0 ? sky : ground));
            }
        }
        vec3 directional = lobe / float(WALL_LOBE_SAMPLES) + v_occlusion.y * 0.5 * (sky + ground);
        v_wall_light = u_window_side_diffuse * walled + u_window_side_directional * directional;
    }
#endif
#ifdef WALL_GRID
    v_wall_light = (u_window_side_diffuse + u_window_side_directional)
                 * ((1.0 / PI) * textureLod(u_wall_grid, side_uv, 0.0).rgb);
#endif
#if defined(SKY_OCCLUSION) && defined(OCCLUSION_MAPS) && (defined(FOLDS_BEHIND) || defined(GBUFFER))
    // (read by the room's captures, FOLDS_BEHIND, and written to the G-buffer; the frame's
    // own shading has not used it since issue 11's sixth round)
    vec3 ray = normalize(v_view_ray);
    if (ray.z < 0.0) {   // the view goes on towards the window
        // the two maps nearest it, blended by how near each is: where the nearest changes
        // from one map to the next the value does not jump (a choice that flips between two
        // near-equal directions, as two GPUs' rounding may, would change a whole triangle)
        int first = 0;
        int second = 0;
        float c1 = -2.0;
        float c2 = -2.0;
        for (int j = 0; j < N_OCCLUSION; ++j) {
            float c = dot(u_occlusion_direction[j], ray);
            if (c > c1) {
                second = first;
                c2 = c1;
                first = j;
                c1 = c;
            } else if (c > c2) {
                second = j;
                c2 = c;
            }
        }
        vec3 ng = normalize(in_normal);
        vec3 q = position + (u_occlusion_offset_m * sign(dot(ng, ray))) * ng;
        float w = clamp(0.5 + (c1 - c2) * 20.0, 0.5, 1.0);   // all the nearest's beyond 0.025 apart
        v_view_occlusion = w * occlusion_lookup(first, q, false)
                         + (1.0 - w) * occlusion_lookup(second, q, false);
    }
#endif
#endif
    gl_Position = u_view_proj * vec4(position, 1.0);
}
