#version 430
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
// The outside hidden from this vertex (issue 11, model.md section 9): of N_OCCLUSION
// directions (cosine-weighted about the window's normal, catalog/render/room_light.py), the
// fraction in which a layer of cloth lies between the vertex and the outside (one front-layer
// depth map per direction, tiles of u_occlusion_maps), and the fraction that does not leave
// through the window opening (the wall). Per vertex: the occlusion varies over a fold, not a
// pixel, and a CPU rasteriser pays it once a vertex instead of once a fragment.
uniform sampler2D u_occlusion_maps; // a: the nearest layer's depth, tile j of a square grid
uniform mat4 u_occlusion_view_proj[N_OCCLUSION];
uniform float u_occlusion_depth_bias[N_OCCLUSION];
uniform vec3 u_occlusion_direction[N_OCCLUSION];   // towards the outside
uniform float u_occlusion_grid;     // tiles per side
uniform float u_occlusion_offset_m; // the lookup moved off the surface towards the direction
uniform vec4 u_occlusion_window;    // the opening (x0, x1, y0, y1), m
uniform vec2 u_occlusion_wall_z;    // the window wall's inner and outer planes, m
INTERPOLATION out vec2 v_occlusion; // the cloth's share, the wall's

vec2 outside_occlusion(vec3 p, vec3 normal) {
    vec3 ng = normalize(normal);
    float hidden = 0.0;
    float walled = 0.0;
    for (int j = 0; j < N_OCCLUSION; ++j) {
        vec3 d = u_occlusion_direction[j];
        // through the opening? (the ray must cross it in both of the wall's planes)
        vec2 q_in = p.xy + ((u_occlusion_wall_z.x - p.z) / d.z) * d.xy;
        vec2 q_out = p.xy + ((u_occlusion_wall_z.y - p.z) / d.z) * d.xy;
        vec4 inside = step(u_occlusion_window.xzxz, vec4(q_in, q_out))
                    * step(vec4(q_in, q_out), u_occlusion_window.ywyw);
        float open = inside.x * inside.y * inside.z * inside.w;
        // off the surface on the direction's side (normal offset: no self-shadowing)
        vec3 q = p + (u_occlusion_offset_m * sign(dot(ng, d))) * ng;
        vec4 clip = u_occlusion_view_proj[j] * vec4(q, 1.0);
        vec2 tile = vec2(mod(float(j), u_occlusion_grid), floor(float(j) / u_occlusion_grid));
        vec2 uv = (tile + clamp(clip.xy * 0.5 + 0.5, 0.0, 1.0)) / u_occlusion_grid;
        float depth = textureLod(u_occlusion_maps, uv, 0.0).a;
        hidden += open * step(depth + u_occlusion_depth_bias[j], clip.z * 0.5 + 0.5);
        walled += 1.0 - open;
    }
    return vec2(hidden, walled) / float(N_OCCLUSION);
}
#endif

uniform mat4 u_view_proj;
uniform vec3 u_mesh_offset;
uniform vec3 u_camera_position;

INTERPOLATION out vec3 v_view_ray;
INTERPOLATION out vec3 v_normal;
#if defined(ANISOTROPIC) || defined(GBUFFER) || defined(PATTERN)
INTERPOLATION out vec3 v_tangent;
#endif
#if defined(GBUFFER) || defined(N_ROOM_LAMPS) || defined(KEY_SHADOW)
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
#if defined(GBUFFER) || defined(N_ROOM_LAMPS) || defined(KEY_SHADOW)
    v_position = position;
#endif
#ifdef SKY_OCCLUSION
    v_occlusion = outside_occlusion(position, in_normal);
#endif
    gl_Position = u_view_proj * vec4(position, 1.0);
}
