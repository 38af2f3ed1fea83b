#version 430
#undef PATTERN_LOD_BIAS   // texture()'s bias is a fragment stage's (common.glsl thread_texel)
#include "common.glsl"
// The curtain mesh: positions (moved into the scene by u_mesh_offset: the cloth simulation's
// own frame has the rod elsewhere), normals and the weft tangent; shared by the shading pass,
// the G-buffer variant and the trivial floor shader. The view ray (position - camera) is
// linear in the position, so it is formed here and interpolated exactly: the fragment shader
// then needs no per-frame uniform. The tangent travels only where it is used. PATTERN,
// KEY_SHADOW: the fabric's texture coordinates (curtain.frag scales them to pattern repeats,
// catalog/presets/patterns.py).
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
// the key's visibility baked over uv (key_visibility.frag); the pattern's coordinates are
// this times a constant (curtain.frag), one varying for both
INTERPOLATION out vec2 v_uv;
#endif

#ifdef SKY_OCCLUSION
// The outside hidden from this vertex by the cloth and by the window wall (issue 11,
// common.glsl outside_occlusion), computed once per update of the room's light by
// occlusion_points.vert into one texel per vertex (u_vertex_occlusion, u_vertex_occlusion_width
// texels a row) and read here by the vertex's index.
uniform sampler2D u_vertex_occlusion;
uniform int u_vertex_occlusion_width;
// What the occlusion takes from eq. 8's ambient term (curtain.frag's bands, summed and
// projected to display RGB: scene_terms.py SceneTerms.scene_values_with): the fraction the
// cloth hides of what a layer does not pass, the wall's of all of the outside's share. Both
// are linear in the per-vertex occlusion, so their sum per vertex is exact when interpolated.
SCENE_VALUE(vec3, u_ambient_occluded_rgb, S_AMBIENT_OCCLUDED_RGB);
SCENE_VALUE(vec3, u_ambient_outside_rgb, S_AMBIENT_OUTSIDE_RGB);
INTERPOLATION out float v_outside_open;   // 1 - the wall's share: the sky's tilt is left that much
#ifdef GBUFFER
INTERPOLATION out vec3 v_occlusion; // the cloth's share, the wall's, the cloth's towards the room
#endif
#endif
#if defined(SKY_OCCLUSION) || defined(ROOM_SIDE)
// The terms curtain.frag adds in display RGB after the bands, per vertex (functions of the
// still mesh and the room's light): times the view's ratio of the outside's share
// (g_view_outside), the occlusion's change to the ambient term, the window side's light the
// folds pass where they hide the outside and the wall's light (WALL_GRID); times the room's
// (g_view_room), the room side's light reflected.
INTERPOLATION out vec3 v_outside_term;
#endif

uniform mat4 u_view_proj;
uniform vec3 u_mesh_offset;
uniform vec3 u_camera_position;

#ifdef ROOM_SIDE
// The light on the cloth's two sides (curtain.frag ROOM_SIDE), per vertex, from the room's
// transport (catalog/render/passes/room_transport_light.py): the room's irradiance on the
// cloth's room side (the transport's gather over the room-side grid, bilinear) where the folds
// leave the room's side open, and where they hide it (the per-vertex occlusion's z) the folds'
// own exitance towards the room (the window's patches' coefficients integrated against the
// cosine); the cosine-weighted mean radiance of the cloth's window side at this point's window
// patch (the transport's outward views of the aperture); both read at the point's aperture
// coordinates (the window's u and v edges), bilinear; and whether the view's continuation
// meets a fold (OCCLUSION_MAPS: the occlusion map whose direction lies nearest it; written to
// the G-buffer only).
uniform sampler2D u_room_side;       // irradiance, linear sRGB (x pi cd m^-2)
uniform vec4 u_room_side_rect;       // the grid: x from, y from, 1 / width, 1 / height (m)
uniform sampler2D u_room_side_cloth; // the cloth's exitance towards the room at the window's patches
uniform sampler2D u_window_side_cloth; // the cloth's window side's mean radiance there
uniform vec3 u_aperture_origin;      // the window's first corner (m)
uniform vec3 u_aperture_s;           // its u edge / |u|^2 (aperture s = (p - origin) . this)
uniform vec3 u_aperture_t;           // its v edge / |v|^2
uniform vec3 u_window_side_diffuse;      // dye a_diff forward(g_diff)
uniform vec3 u_window_side_directional;  // dye a_spec forward(g_spec)
uniform vec3 u_room_side_reflectance;  // dye (a_diff backward(g_diff) + a_spec backward(g_spec))
INTERPOLATION out vec3 v_room_term;    // the room side's light reflected, / pi (x g_view_room)
#ifdef GBUFFER   // the parts apart (the float64 twin's inputs)
INTERPOLATION out vec3 v_room_side_light;
INTERPOLATION out vec3 v_window_side_light;
INTERPOLATION out float v_view_occlusion;
#endif
#ifdef WALL_GRID
// The room's surfaces round the window (the wall beside the opening, its reveals, a frame)
// as the cloth's window side sees them (the room's transport): their irradiance on the cloth's
// plane from that side, a grid over the room side's rectangle; both lobes pass it by their
// forward transmittance of diffuse light.
uniform sampler2D u_wall_grid;           // irradiance, linear sRGB (x pi cd m^-2)
#ifdef GBUFFER
INTERPOLATION out vec3 v_wall_light;
#endif
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
#if defined(GBUFFER) || defined(N_ROOM_LAMPS)
    v_position = position;
#endif
#if defined(PATTERN) || defined(KEY_SHADOW)
    v_uv = in_uv;
#endif
#ifdef SKY_OCCLUSION
    vec3 occlusion = texelFetch(u_vertex_occlusion, ivec2(gl_VertexID % u_vertex_occlusion_width,
                                                          gl_VertexID / u_vertex_occlusion_width), 0).xyz;
    v_outside_open = 1.0 - occlusion.y;
    vec3 outside_term = -(occlusion.x * u_ambient_occluded_rgb + occlusion.y * u_ambient_outside_rgb);
#ifdef GBUFFER
    v_occlusion = occlusion;
#endif
#else
    vec3 occlusion = vec3(0.0);
    vec3 outside_term = vec3(0.0);
#endif
#ifdef ROOM_SIDE
    vec2 side_uv = (position.xy - u_room_side_rect.xy) * u_room_side_rect.zw;
    vec3 from_origin = position - u_aperture_origin;
    vec2 aperture_uv = vec2(dot(from_origin, u_aperture_s), dot(from_origin, u_aperture_t));
    vec3 room_light = textureLod(u_room_side, side_uv, 0.0).rgb;
    vec3 cloth_light = textureLod(u_room_side_cloth, aperture_uv, 0.0).rgb;
    vec3 forward = u_window_side_diffuse + u_window_side_directional;
#ifdef SKY_OCCLUSION
    vec3 room_side_light = mix(room_light, cloth_light, occlusion.z);
#else
    vec3 room_side_light = room_light;
#endif
    vec3 window_side_light = textureLod(u_window_side_cloth, aperture_uv, 0.0).rgb;
    v_room_term = (1.0 / PI) * u_room_side_reflectance * room_side_light;
    // the window side passed towards the viewer by both lobes over the share the folds hide
    outside_term += occlusion.x * forward * window_side_light;
#ifdef WALL_GRID
    vec3 wall_light = forward * ((1.0 / PI) * textureLod(u_wall_grid, side_uv, 0.0).rgb);
    outside_term += wall_light;   // the wall and its reveals where the outside is walled
#endif
#ifdef GBUFFER
    v_room_side_light = room_side_light;
    v_window_side_light = window_side_light;
#ifdef WALL_GRID
    v_wall_light = wall_light;
#endif
    v_view_occlusion = 0.0;
#endif
#endif
#if defined(SKY_OCCLUSION) || defined(ROOM_SIDE)
    v_outside_term = outside_term;
#endif
#if defined(ROOM_SIDE) && defined(SKY_OCCLUSION) && defined(OCCLUSION_MAPS) && defined(GBUFFER)
    // (written to the G-buffer; the frame's own shading does not use it)
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
    gl_Position = u_view_proj * vec4(position, 1.0);
}
