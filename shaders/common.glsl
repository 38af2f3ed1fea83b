// common.glsl: the physical terms of model.md, one small function per term.
// Included by every pass (catalog/gl/shaderlib.py resolves #include and injects
// #defines: the constants of catalog/core/constants.py, HG_MIRROR_BELOW, into every program;
// per program e.g. N_BANDS, NV4 = ceil(N_BANDS / 4), FLUORESCENCE_OFF | FLUORESCENCE_PAPER |
// FLUORESCENCE_PHYSICAL, SEE_THROUGH, ANISOTROPIC, GBUFFER, SHARED_DIVISION, PATTERN, OIT,
// ROOM_LIGHTING). Band quantities travel as vec4 chunks.
// The float64 twin of every function is in catalog/optics/shading_reference.py.

#ifndef CATALOG_COMMON_GLSL
#define CATALOG_COMMON_GLSL

const float PI = 3.14159265358979;

// Henyey & Greenstein 1941, "Diffuse radiation in the galaxy"; model.md eq. 6 in the robust form of
// catalog/optics/btdf.py (unchanged for g >= 0):
// 1 + g^2 - 2 g cos(theta) = (1 - g)^2 + 2 g (1 - cos theta) with 1 - cos theta = chord2 / 2, and
// = (1 + g)^2 - 2 g (1 + cos theta) with 1 + cos theta = anti2 / 2 for g < HG_MIRROR_BELOW (no
// cancellation near g = -1; hg_d below); the power 1.5 as d * sqrt(d). chord2 = |w_view - w_travel|^2, anti2 = |w_view + w_travel|^2.
float hg_d(float chord2, float anti2, float g);  // below: the one choice of form
float hg_phase_robust(float chord2, float anti2, float g) {
    float d = hg_d(chord2, anti2, g);
    // (1 - g)(1 + g) rather than 1 - g^2: exact in float32 for g near +-1
    return (1.0 - g) * (1.0 + g) / (4.0 * PI * d * sqrt(d));
}

// Anisotropic chord for the directional lobe (our extension of eq. 6: the warp and weft
// threads spread the straight-through peak differently). delta = w_view - w_travel written in
// the tangent frame (t = weft, b = warp, n); anisotropy 0 is eq. 6's isotropic chord.
float woven_chord2(vec3 delta, vec3 t, vec3 b, vec3 n, float anisotropy) {
    float dt = dot(delta, t);
    float db = dot(delta, b);
    float dn = dot(delta, n);
    return dt * dt * (1.0 - anisotropy) + db * db * (1.0 + anisotropy) + dn * dn;
}

// HG's d of eq. 6 (the lobe's denominator is d^1.5), as in hg_phase_robust but with the
// mirrored form only where it is needed: for g >= HG_MIRROR_BELOW the form
// (1 - g)^2 + g chord2 loses at most |g| * 5e-7 / (1 + g)^2 < 3e-7 (relative) to the rounding of a
// chord2 near 4 (theta near pi), so the anti-chord is only formed for a strongly backward lobe.
// With the scene's g compiled in as constants (SPECIALISED), the choice costs nothing.
// HG_MIRROR_BELOW is injected as a #define from catalog/core/constants.py (Python uses it too).
float hg_d(float chord2, float anti2, float g) {
    return (g >= HG_MIRROR_BELOW) ? (1.0 - g) * (1.0 - g) + g * chord2
                                  : (1.0 + g) * (1.0 + g) - g * anti2;
}

// What the anisotropic chord needs of a fragment, shared by every light: the view direction
// and the tangent frame without the warp vector or a normalised tangent.
// vn = v.n, vt = v.T, tn = T.n, inv_t2 = 1 / |T - (T.n) n|^2 (T: interpolated weft tangent).
struct WovenView { vec3 to_viewer; float vn; float vt; float tn; float inv_t2; };

WovenView woven_view(vec3 to_viewer, vec3 n, vec3 tangent) {
    float tn = dot(tangent, n);
    return WovenView(to_viewer, dot(to_viewer, n), dot(to_viewer, tangent), tn,
                     1.0 / (dot(tangent, tangent) - tn * tn));
}

// Tobitani et al. 2014, woven-cloth HG BTDF; model.md eq. 5 and 7 without LD (the see-through
// is the background term): radiance per unit of a directional light's normal irradiance,
// G = |cos theta_i| (a_diff ph_diff + a_spec ph_spec), a_* = rho e^-tau k_*, returned as the
// ratio vec2(numerator, denominator) so that the caller divides once for several lights.
// Two-sided: only |n . l| and the angle between the light's travel and the view direction
// enter, so the same thin layer transmits light from behind and scatters it back.
// to_light: unit, towards the light; cos_i = n . to_light; tan_i = T . to_light.
// Anisotropy (ANISOTROPIC, directional lobe with g >= 0): the chord in the frame (t weft,
// b warp, n), dt^2 (1 - a) + db^2 (1 + a) + dn^2, written with db^2 = chord2 - dt^2 - dn^2 as
// (1 + a) chord2 - a dn^2 - 2 a dt^2, where dt = delta . (T - (T.n) n) / |T - (T.n) n|.
vec2 woven_transmission_ratio(vec3 to_light, float cos_i, float tan_i, WovenView w,
                              float a_diff, float g_diff, float a_spec, float g_spec,
                              float anisotropy) {
    vec3 delta = w.to_viewer + to_light;          // w_view - w_travel, travel = -to_light
    float chord2 = dot(delta, delta);
    float anti2 = 0.0;
    if (min(g_diff, g_spec) < HG_MIRROR_BELOW) {
        vec3 sum = w.to_viewer - to_light;         // w_view + w_travel
        anti2 = dot(sum, sum);
    }
    float chord_spec = chord2;
#ifdef ANISOTROPIC
    if (g_spec >= 0.0) {
        float dn = w.vn + cos_i;
        float dtp = w.vt + tan_i - w.tn * dn;
        chord_spec = (1.0 + anisotropy) * chord2 - anisotropy * (dn * dn)
                   - (2.0 * anisotropy) * (dtp * dtp * w.inv_t2);
    }
#endif
    float d_diff = hg_d(chord2, anti2, g_diff);                                    // eq. 6
    float d_spec = hg_d(chord_spec, anti2, g_spec);                                // eq. 6
    float x_diff = d_diff * sqrt(d_diff);
    float x_spec = d_spec * sqrt(d_spec);
    // (1 - g)(1 + g) / (4 pi): exact in float32 for g near +-1; folded when specialised
    float k_diff = a_diff * ((1.0 - g_diff) * (1.0 + g_diff) / (4.0 * PI));
    float k_spec = a_spec * ((1.0 - g_spec) * (1.0 + g_spec) / (4.0 * PI));
    return vec2(abs(cos_i) * (k_diff * x_spec + k_spec * x_diff), x_diff * x_spec);  // eq. 5, 7
}

// Tobitani et al. 2014, eq. 8 paper mode: I_fluor F_c, a constant per light (pre-integrated
// per band on the CPU as radiance; it ignores angle, irradiance and geometry, as printed).
vec4 fluorescence_paper(vec4 paper_band) {
    return paper_band;
}

// Physical mode (model.md section 6): absorbed excitation photons (1e18 m^-2 s^-1 units),
// saturation N_eff = N_abs / (1 + N_abs / N_sat), emitted diffusely, half to each side;
// emission_band = quantum_yield * per-photon spectral radiance integrated over the band.
float fluorescence_effective_photons(float absorbed, float inv_saturation) {
    return absorbed / (1.0 + absorbed * inv_saturation);
}
vec4 fluorescence_physical(float effective_photons, vec4 emission_band) {
    return effective_photons * emission_band;
}

// The outside seen through the window (sky above the horizon, ground below, the sun's disc)
// or the room when a ray points back inside. Returns the weights of the four band radiances
// (sky, ground, sun disc, room) for a ray direction; the outside lies towards -z.
// The disc edge uses the chord |dir - sun|^2, not 1 - cos (float32 resolves it).
vec4 background_weights(vec3 dir, vec3 to_sun, float sun_chord2_inner, float sun_chord2_outer) {
    // branch-free (a CPU rasteriser runs fragments in SIMD lanes): outside = dir.z < 0,
    // above = dir.y >= 0
    float outside = 1.0 - step(0.0, dir.z);
    float above = step(0.0, dir.y);
    vec3 d = dir - to_sun;
    float disc = 1.0 - smoothstep(sun_chord2_inner, sun_chord2_outer, dot(d, d));
    float sky = outside * above;
    return vec4(sky, outside - sky, sky * disc, 1.0 - outside);
}

// background_weights' ingredients for the curtain (regrouped there): vec3(outside, above,
// disc), disc = 1 - smoothstep across the sun's rim (the reciprocal of its width folded).
vec3 background_terms(vec3 dir, vec3 to_sun, float sun_chord2_inner, float sun_chord2_outer) {
    vec3 d = dir - to_sun;
    float s = clamp((dot(d, d) - sun_chord2_inner) * (1.0 / (sun_chord2_outer - sun_chord2_inner)),
                    0.0, 1.0);
    return vec3(1.0 - step(0.0, dir.z), step(0.0, dir.y), 1.0 - s * s * (3.0 - 2.0 * s));
}

// ---------------------------------------------------------------- the fabric's pattern
// (model.md section 9; catalog/presets/patterns.py). u_pattern: RGBA, mipmapped, repeating: rgb = the
// thread's unit normal in the cloth's tangent frame (x weft, y warp, z the cloth normal), a =
// the thread coverage c in [0, 1]. The mip chain averages both: far away c -> mean(c) = 1 - LD
// (the fit's see-through) and the normals average to a shorter vector about the cloth normal
// (the first moment of LEAN mapping, Olano & Baker 2010), so highlights fade instead of
// sparkling. The room's shadow pass can call thread_coverage(uv) for the holes' shadow.
#ifdef PATTERN
uniform sampler2D u_pattern;

// The pattern's texel over one pixel (fragment stages: texture()'s LOD bias). The mip level the
// hardware picks has texels about a pixel wide, and its bilinear tent spreads them: a filter
// about three times the pixel's box in variance (T^2/12 + T^2/6 at texel side T). The frame
// passes PATTERN_LOD_BIAS = log2(1/sqrt(3)), the level whose filter has the box's variance
// (frame.py PATTERN_LOD_BIAS, issue 11's eighth round); a vertex stage #undefs it.
// HEM_BORDER: the band along the hem (a lace's scallops; patterns.py HemBorder), its rows
// from the hem (v = 0) up to u_border_repeats pattern repeats, across as the pattern; below
// that height it replaces the all-over pattern (where a scallop's edge cuts the cloth away its
// coverage is 0). Both are sampled on every fragment, so the derivatives stay defined.
#ifdef HEM_BORDER
uniform sampler2D u_border;
uniform float u_border_repeats;
vec2 border_uv(vec2 uv_repeats) {
    return vec2(uv_repeats.x, uv_repeats.y * (1.0 / u_border_repeats));
}
#endif
#ifdef PATTERN_LOD_BIAS
vec4 thread_texel(vec2 uv_repeats) {
    vec4 texel = texture(u_pattern, uv_repeats, PATTERN_LOD_BIAS);
#ifdef HEM_BORDER
    vec4 band = texture(u_border, border_uv(uv_repeats), PATTERN_LOD_BIAS);
    texel = uv_repeats.y < u_border_repeats ? band : texel;
#endif
    return texel;
}
#endif

// Thread coverage at uv (in pattern repeats), mip-filtered by the hardware's footprint.
float thread_coverage(vec2 uv_repeats) {
    float c = texture(u_pattern, uv_repeats).a;
#ifdef HEM_BORDER
    float band = texture(u_border, border_uv(uv_repeats)).a;
    c = uv_repeats.y < u_border_repeats ? band : c;
#endif
    return c;
}

// The shading normal: the cloth normal n tilted by the pattern's mip-averaged normal m in
// the frame (t weft, n x t, n). |m| < 1 where the mip averages slopes: m is used unnormalised,
// so the tilt shrinks with the filtered slope variance (Toksvig 2005's shortening).
vec3 thread_normal(vec3 n, vec3 tangent, vec3 m) {
    vec3 t = tangent - dot(tangent, n) * n;
    float len2 = dot(t, t);
    t = len2 > 1e-12 ? t * inversesqrt(len2) : vec3(0.0);
    vec3 b = cross(n, t);
    return normalize(m.x * t + m.y * b + m.z * n);
}
#endif

// The key's two layers of cloth in front of a point (issue 11; the second since its seventh
// round): the front-layer map ``first`` (room_shadow.frag FRONT_LAYER) and the second layer's
// ``second`` (SECOND_LAYER, the first peeled); r: a layer's thread coverage, a: its depth. At
// map point q (xy: texture coordinates, z: depth, 0..1), returns (c1, c2): each layer's
// coverage where q lies behind it, 0 where q is that layer itself. The depth test is a ramp
// from half to one and a half times the bias and the four nearest texels are blended
// bilinearly (percentage-closer filtering), so that the answer changes continuously across a
// shadow's edge and along a fold's flank instead of flipping on rounding. A third layer is
// not seen.
vec2 front_layers_coverage(sampler2D first, sampler2D second, vec3 q, float bias) {
    vec2 size = vec2(textureSize(first, 0));
    vec2 st = q.xy * size - 0.5;
    vec2 f = fract(st);
    ivec2 i0 = ivec2(floor(st));
    ivec2 top = ivec2(size) - 1;
    vec2 c[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 texel = clamp(i0 + ivec2(k & 1, k >> 1), ivec2(0), top);
        vec4 one = texelFetch(first, texel, 0);
        vec4 two = texelFetch(second, texel, 0);
        c[k] = vec2(one.r * smoothstep(0.5 * bias, 1.5 * bias, q.z - one.a),
                    two.r * smoothstep(0.5 * bias, 1.5 * bias, q.z - two.a));
    }
    return mix(mix(c[0], c[1], f.x), mix(c[2], c[3], f.x), f.y);
}

#ifdef OCCLUSION_MAPS
// The outside hidden from a point p of the cloth (normal `normal`; issue 11, model.md
// section 9): of N_OCCLUSION directions (cosine-weighted about the window's normal,
// catalog/render/room_light/), the fraction in which a layer of cloth lies between p and
// the outside (one depth map per direction, tiles of u_occlusion_maps: the layer nearest the
// outside), and the fraction that does not leave through the window opening (the wall); and
// (issue 11, fourth round) the room's side: of the opposite directions (cosine-weighted about
// the room's normal), the fraction in which a layer lies between p and the room (the same
// maps' farthest layer). Returns (cloth, wall, cloth towards the room).
uniform sampler2D u_occlusion_maps; // a: the nearest layer's depth, g: the farthest's; tile j of a square grid
uniform mat4 u_occlusion_view_proj[N_OCCLUSION];
uniform float u_occlusion_depth_bias[N_OCCLUSION];
uniform vec3 u_occlusion_direction[N_OCCLUSION];   // towards the outside
uniform float u_occlusion_grid;     // tiles per side
uniform float u_occlusion_offset_m; // the lookup moved off the surface towards the direction
uniform vec4 u_occlusion_window;    // the opening (x0, x1, y0, y1), m
uniform vec2 u_occlusion_wall_z;    // the window wall's inner and outer planes, m

// Tile j's four nearest texels at q (moved off the surface), a ramp in depth over 0.5..1.5
// times the bias, blended bilinearly: how far a layer lies in front of q (towards the outside,
// the nearest layer: room = false) or behind it (towards the room, the farthest: room = true).
float occlusion_lookup(int j, vec3 q, bool room) {
    vec4 clip = u_occlusion_view_proj[j] * vec4(q, 1.0);
    vec2 tile = vec2(mod(float(j), u_occlusion_grid), floor(float(j) / u_occlusion_grid));
    float n = float(textureSize(u_occlusion_maps, 0).x) / u_occlusion_grid;
    vec2 st = clamp(clip.xy * 0.5 + 0.5, 0.0, 1.0) * n - 0.5;
    vec2 f = fract(st);
    ivec2 i0 = ivec2(floor(st));
    float z = clip.z * 0.5 + 0.5;
    float b = u_occlusion_depth_bias[j];
    float h[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 texel = clamp(i0 + ivec2(k & 1, k >> 1), ivec2(0), ivec2(int(n) - 1))
                    + ivec2(tile * n);
        vec4 layers = texelFetch(u_occlusion_maps, texel, 0);
        h[k] = smoothstep(0.5 * b, 1.5 * b, room ? layers.g - z : z - layers.a);
    }
    return mix(mix(h[0], h[1], f.x), mix(h[2], h[3], f.x), f.y);
}

vec3 outside_occlusion(vec3 p, vec3 normal) {
    vec3 ng = normalize(normal);
    float hidden = 0.0;
    float walled = 0.0;
    float hidden_room = 0.0;
    for (int j = 0; j < N_OCCLUSION; ++j) {
        vec3 d = u_occlusion_direction[j];
        // through the opening? (the ray must cross it in both of the wall's planes)
        vec2 q_in = p.xy + ((u_occlusion_wall_z.x - p.z) / d.z) * d.xy;
        vec2 q_out = p.xy + ((u_occlusion_wall_z.y - p.z) / d.z) * d.xy;
        vec4 inside = step(u_occlusion_window.xzxz, vec4(q_in, q_out))
                    * step(vec4(q_in, q_out), u_occlusion_window.ywyw);
        float open = inside.x * inside.y * inside.z * inside.w;
        // off the surface on the direction's side (normal offset: no self-shadowing)
        float side = sign(dot(ng, d));
        hidden += open * occlusion_lookup(j, p + (u_occlusion_offset_m * side) * ng, false);
        walled += 1.0 - open;
        hidden_room += occlusion_lookup(j, p - (u_occlusion_offset_m * side) * ng, true);
    }
    return vec3(hidden, walled, hidden_room) / float(N_OCCLUSION);
}
#endif

// Weighted blended order-independent transparency (McGuire & Bavoil 2013, JCGT 2(2)): each
// layer adds C a w and a w, and multiplies the revealage by (1 - a); nearer layers weigh more.
// depth_m: view distance beyond the reference, clamped to [0, 3] m; 2^(-30 m^-1 depth) keeps the
// weights normal in float32 (>= 2^-90).
float oit_weight(float depth_m) {
    return exp2(-30.0 * clamp(depth_m, 0.0, 3.0));
}

// The resolve of weighted blended OIT: (mean layer colour x (1 - revealage), revealage) to be
// blended ONE, SRC_ALPHA over what is behind. accum = (sum C a w, prod (1 - a)), weight = sum a w.
vec4 oit_resolve(vec4 accum, float weight) {
    return vec4(accum.rgb / max(weight, 1e-30) * (1.0 - accum.a), accum.a);
}

// Luma of a display-encoded colour (ITU-R BT.601 weights, as FXAA uses): edge detection only.
float display_luma(vec3 encoded) {
    return dot(encoded, vec3(0.299, 0.587, 0.114));
}

// IEC 61966-2-1:1999 sRGB transfer function (the piecewise curve, not a 2.2 power).
vec3 srgb_encode(vec3 linear) {
    vec3 c = clamp(linear, 0.0, 1.0);
    vec3 lo = 12.92 * c;
    vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(c, vec3(0.0031308)));
}

// ---- The room (issue 13, model.md section 9): catalog/render/room_light/ has the layout.
// The room box's six inside faces, P(s, t) = origin + s axis_s + t axis_t, side by side in a
// light-map atlas (face k covers u in [k / 6, (k + 1) / 6]). Face order: floor, ceiling, left,
// right, back, window wall.
const int ROOM_FACES = 6;

// The face a room surface belongs to, by its normal's dominant axis (into the room).
int room_face_of_normal(vec3 n) {
    vec3 a = abs(n);
    if (a.y >= a.x && a.y >= a.z) {
        return n.y > 0.0 ? 0 : 1;
    }
    if (a.x >= a.z) {
        return n.x > 0.0 ? 2 : 3;
    }
    return n.z < 0.0 ? 4 : 5;
}

// Atlas coordinates of world point p on face k (clamped half a texel inside the face).
vec2 room_atlas_uv(int face, vec3 p, vec3 origin, vec3 axis_s, vec3 axis_t, float face_texels) {
    vec3 d = p - origin;
    float edge = 0.5 / face_texels;
    float s = clamp(dot(d, axis_s) / dot(axis_s, axis_s), edge, 1.0 - edge);
    float t = clamp(dot(d, axis_t) / dot(axis_t, axis_t), edge, 1.0 - edge);
    return vec2((float(face) + s) / float(ROOM_FACES), t);
}

// A box mask in 2D with soft edges of half-width w (the penumbra): 1 inside, 0 outside.
float soft_rect(vec2 q, vec4 box, float half_width) {
    vec2 lo = smoothstep(box.xz - half_width, box.xz + half_width, q);
    vec2 hi = 1.0 - smoothstep(box.yw - half_width, box.yw + half_width, q);
    return lo.x * lo.y * hi.x * hi.y;
}

// The key light's beam through the window opening at room point p (to_light.z < 0: the light
// is outside): the ray p + s to_light must cross the opening (x0, x1, y0, y1) = rect in both
// the wall's inner plane z = wall_z.x and outer plane z = wall_z.y (the reveals shade); a
// point within the wall's depth (the reveals themselves, the sill) only in the planes still
// ahead of it. The edge is soft by the penumbra of a source of angular radius
// atan(tan_radius) at the distance travelled (PCSS's estimate for a distant disc).
float room_window_beam(vec3 p, vec3 to_light, vec4 opening, vec2 wall_z, float tan_radius) {
    float s_in = (wall_z.x - p.z) / to_light.z;
    float s_out = (wall_z.y - p.z) / to_light.z;
    vec2 q_in = p.xy + s_in * to_light.xy;
    vec2 q_out = p.xy + s_out * to_light.xy;
    float inner = s_in > 0.0 ? soft_rect(q_in, opening, s_in * tan_radius + 1e-3) : 1.0;
    return step(0.0, s_out) * inner * soft_rect(q_out, opening, s_out * tan_radius + 1e-3);
}


// The irradiance of a point p with normal n on the window's reveals or the wall's outer face,
// outside the wall's inner plane (issue 11, fourth round; room_light.reveal_irradiance is the
// float64 twin), the key left out: the outside over the half of its hemisphere facing it (the
// sky above the horizon, the ground below: sky_half and ground_half are 0.5 pi x their
// radiance; the outer face takes the whole) and the closed curtain's window side over the half
// facing the room (``back``: the window-side capture at ``level``, ``size`` texels, read at
// p's place in the opening).
vec3 reveal_irradiance(vec3 p, vec3 n, vec4 opening, vec3 sky_half, vec3 ground_half,
                       sampler2D back, int level, ivec2 size) {
    float up = 0.5 + 0.5 * n.y;
    vec3 outside = (1.0 + max(-n.z, 0.0)) * (up * sky_half + (1.0 - up) * ground_half);
    vec2 f = clamp((p.xy - opening.xz) / (opening.yw - opening.xz), 0.0, 0.999);
    vec3 window_side = texelFetch(back, ivec2(f * vec2(size)), level).rgb;
    return outside + (0.5 * PI * (1.0 - abs(n.z))) * window_side;
}

// ---- The room's light between surfaces (issue 11; room_light.rectangle_irradiance_factor is
// the float64 twin). pi times the form factor from a point x with normal n to a uniformly
// emitting rectangle corner + [0,1] s + [0,1] t: E(x) = L * factor. Lambert's formula for a
// polygon (the vector irradiance): half the sum over its edges of the angle each subtends at x
// times the cosine between n and the normal of the plane through x and that edge. Exact near
// the patch, where the point form cos cos A / r^2 of its centre is not (a 55 cm patch of the
// floor seen from the wall beside it); the rectangle must lie on n's side of x's plane
// (every face of the convex room does for every other).
float polygon_edge_term(vec3 a, vec3 b, vec3 n) {
    vec3 c = cross(a, b);
    float sine = length(c);
    return sine > 1e-9 ? atan(sine, dot(a, b)) * dot(c, n) / sine : 0.0;
}

float rectangle_irradiance_factor(vec3 x, vec3 n, vec3 corner, vec3 s, vec3 t) {
    vec3 v0 = normalize(corner - x);
    vec3 v1 = normalize(corner + s - x);
    vec3 v2 = normalize(corner + s + t - x);
    vec3 v3 = normalize(corner + t - x);
    return 0.5 * abs(polygon_edge_term(v0, v1, n) + polygon_edge_term(v1, v2, n)
                     + polygon_edge_term(v2, v3, n) + polygon_edge_term(v3, v0, n));
}

#ifdef WINDOW_LIGHT
// ---- The closed window as the room's area light (issue 13; issue 11's sixth and ninth
// rounds; room_light.window_irradiance is the float64 twin). room_lightmap.frag evaluates it
// at the light map's points; room.frag (WINDOW_NEAR) per pixel on the window wall beside the
// opening, where it falls tenfold within a light-map texel.
//
// The room sees the curtain through a box around its folds: its front (the plane u_front_z,
// the opening's rectangle in 12 x 9 patches) carries the room's captures (the middle eye's
// and the two side eyes', blended by angle); its sides (the opening's edges x = x0, x1,
// from the curtain's plane u_back_plane_z to the front, normal -x and +x) the edge column of
// the eye towards that side; its top and bottom (y = y1, y0) the middle's edge row; between
// the window wall and the curtain's plane, the sides' gaps show the cloth's window side
// (its capture's edge column) to points in front of that plane, and points behind it see
// the window side's patches (plane u_back_plane_z, normal -z). Light leaving the folds
// sideways, which a rectangle in the opening's plane sends nowhere, reaches the walls that
// see the window edge-on. With u_front_z at the opening's plane (no box: the curtain open)
// the front alone.
uniform sampler2D u_luminaire;       // mipmapped; level u_luminaire_level = one texel a patch
uniform ivec2 u_luminaire_size;
uniform int u_luminaire_level;
// The same capture from two eyes towards the side walls (left then right, side by side,
// room_light.CAPTURE_SIDE_EYES): the folds' flanks face either way and glow unequally.
uniform sampler2D u_luminaire_sides;
uniform int u_luminaire_sides_level; // their level of one texel a patch
uniform vec3 u_side_eye[2];
uniform vec3 u_middle_eye;
uniform sampler2D u_luminaire_back;  // the closed curtain's window side (0 where no cloth)
uniform int u_luminaire_back_level;  // its level of one texel a patch
uniform float u_back_plane_z;        // its patches' plane (m), normal -z: the curtain's
uniform float u_front_z;             // the box's front (m); the opening's plane: no box
uniform vec3 u_lobe_rgb;             // key x a_spec x dye (0: the lobe travels in the beam)
uniform float u_g_spec;
uniform int u_lamp_count;
uniform vec3 u_lamp_position[4];
uniform vec3 u_lamp_rgb[4];          // intensity as linear sRGB (irradiance at 1 m)

// The radiance window patch (i, j), centred at c, sends towards p: the three captures blended piecewise linearly in the horizontal angle of the way
// from c to p between the angles at which c sees the eyes, clamped beyond the side eyes
// (float64 twin: room_light.capture_eye_weights); alpha (the key's reach on the patch's
// cloth) always the middle's.
vec4 captured_towards(int i, int j, vec3 c, vec3 p) {
    vec4 middle = texelFetch(u_luminaire, ivec2(i, j), u_luminaire_level);
    float a = atan(p.x - c.x, max(p.z - c.z, 1e-6));
    float a_left = atan(u_side_eye[0].x - c.x, max(u_side_eye[0].z - c.z, 1e-6));
    float a_mid = atan(u_middle_eye.x - c.x, max(u_middle_eye.z - c.z, 1e-6));
    float a_right = atan(u_side_eye[1].x - c.x, max(u_side_eye[1].z - c.z, 1e-6));
    vec3 rgb;
    if (a <= a_mid) {
        vec3 left = texelFetch(u_luminaire_sides, ivec2(i, j), u_luminaire_sides_level).rgb;
        rgb = mix(middle.rgb, left, clamp((a_mid - a) / (a_mid - a_left), 0.0, 1.0));
    } else {
        vec3 right = texelFetch(u_luminaire_sides, ivec2(i + u_luminaire_size.x, j), u_luminaire_sides_level).rgb;
        rgb = mix(middle.rgb, right, clamp((a - a_mid) / (a_right - a_mid), 0.0, 1.0));
    }
    return vec4(rgb, middle.a);
}

#ifdef WALL_EYES
// The box's sides captured from eyes by the window wall (room_light.WALL_EYES; left then
// right, a column of patch rows each): what the wall beside the opening sees through them.
uniform sampler2D u_luminaire_walls;
uniform int u_luminaire_walls_level; // their level of one texel a patch
uniform vec3 u_wall_eye[2];
#endif

// The angle (rad) of the way from c on the box's side (right: x = x1, else x0) to q, up from
// the side's outward normal towards +z (into the room).
float box_side_angle(vec3 c, vec3 q, bool right) {
    return atan(q.z - c.z, right ? q.x - c.x : c.x - q.x);
}

// What the box's left (or right) side, row j, centred at c, sends to p: the edge column of the
// capture from the eye towards that side's wall; WALL_EYES,
// blended with the wall eye's capture linearly in box_side_angle from the wall eye's angle
// (the wall eye's alone) to level (the room's eye's alone), clamped: a way level with the
// side's centre or falling crosses the folds as the room's eyes see them, one rising from
// below it (from the window wall beside the opening) mostly passes in front of the folds and
// leaves by the box's front (room_light.wall_eye_weight is the float64 twin). alpha (the
// key's reach, for the lobe) the middle's edge column.
vec4 box_side_radiance(int j, bool right, vec3 c, vec3 p) {
    int column = right ? u_luminaire_size.x - 1 : 0;
    float alpha = texelFetch(u_luminaire, ivec2(column, j), u_luminaire_level).a;
    vec3 rgb = texelFetch(u_luminaire_sides, ivec2(column + (right ? u_luminaire_size.x : 0), j),
                          u_luminaire_sides_level).rgb;
#ifdef WALL_EYES
    vec3 wall = texelFetch(u_luminaire_walls, ivec2(right ? 1 : 0, j), u_luminaire_walls_level).rgb;
    float a_wall = box_side_angle(c, u_wall_eye[right ? 1 : 0], right);
    rgb = mix(wall, rgb, clamp((box_side_angle(c, p, right) - a_wall) / (0.0 - a_wall), 0.0, 1.0));
#endif
    return vec4(rgb, alpha);
}

// The key's directional lobe through the cloth of a patch centred at c, towards p (eq. 7:
// E cos_i a_spec ph(theta), theta between the key's travel and the way to p from the patch's
// centre); alpha, the key's irradiance on the patch's cloth per unit of its normal irradiance
// (|cos_i| x the window's mask x what a layer nearer the light passes), is the capture's.
vec3 key_lobe(float alpha, vec3 c, vec3 p, vec3 key_to_light) {
    if (u_lobe_rgb == vec3(0.0)) {
        return vec3(0.0);
    }
    float hg_k = (1.0 - u_g_spec) * (1.0 + u_g_spec) / (4.0 * PI);
    vec3 w = normalize(p - c);
    float chord2 = dot(w + key_to_light, w + key_to_light);
    float d = (1.0 - u_g_spec) * (1.0 - u_g_spec) + u_g_spec * chord2;
    return u_lobe_rgb * (alpha * hg_k / (d * sqrt(d)));
}

// The window's light at point p (normal n) of the room, outside the opening: the box's
// faces it lies in front of (E = sum L F, F pi times each rectangle's exact form factor),
// and behind the curtain's plane the window side's patches. ``opening``: x0, x1, y0, y1 (m);
// ``wall_z``: the window wall's inner plane.
vec3 window_irradiance(vec3 p, vec3 n, vec4 opening, float wall_z, vec3 key_to_light) {
    vec2 cell = vec2(opening.y - opening.x, opening.w - opening.z) / vec2(u_luminaire_size);
    vec3 s = vec3(cell.x, 0.0, 0.0);
    vec3 t = vec3(0.0, cell.y, 0.0);
    vec3 e = vec3(0.0);
    if (p.z > u_front_z + 1e-4) {
        for (int j = 0; j < u_luminaire_size.y; ++j) {
            for (int i = 0; i < u_luminaire_size.x; ++i) {
                vec3 corner = vec3(opening.x + float(i) * cell.x, opening.z + float(j) * cell.y, u_front_z);
                vec3 centre = corner + 0.5 * (s + t);
                vec4 captured = captured_towards(i, j, centre, p);
                e += (captured.rgb + key_lobe(captured.a, centre, p, key_to_light))
                   * rectangle_irradiance_factor(p, n, corner, s, t);
            }
        }
    }
    if (u_front_z > u_back_plane_z) {
        vec3 depth = vec3(0.0, 0.0, u_front_z - u_back_plane_z);
        vec3 gap = vec3(0.0, 0.0, u_back_plane_z - wall_z);
        bool before = p.z > u_back_plane_z;
        for (int j = 0; j < u_luminaire_size.y; ++j) {   // the sides, row by row
            float y = opening.z + float(j) * cell.y;
            for (int k = 0; k < 2; ++k) {
                bool right = k == 1;
                float x = right ? opening.y : opening.x;
                if (right ? p.x <= x + 1e-4 : p.x >= x - 1e-4) {
                    continue;
                }
                vec3 corner = vec3(x, y, u_back_plane_z);
                vec3 centre = corner + 0.5 * (depth + t);
                vec4 side = box_side_radiance(j, right, centre, p);
                e += (side.rgb + key_lobe(side.a, centre, p, key_to_light))
                   * rectangle_irradiance_factor(p, n, corner, depth, t);
                if (before) {
                    int column = right ? u_luminaire_size.x - 1 : 0;
                    e += texelFetch(u_luminaire_back, ivec2(column, j), u_luminaire_back_level).rgb
                       * rectangle_irradiance_factor(p, n, vec3(x, y, wall_z), gap, t);
                }
            }
        }
        for (int i = 0; i < u_luminaire_size.x; ++i) {   // the bottom and the top
            float x = opening.x + float(i) * cell.x;
            for (int k = 0; k < 2; ++k) {
                bool top = k == 1;
                float y = top ? opening.w : opening.z;
                if (top ? p.y <= y + 1e-4 : p.y >= y - 1e-4) {
                    continue;
                }
                vec3 corner = vec3(x, y, u_back_plane_z);
                vec3 centre = corner + 0.5 * (depth + s);
                vec4 captured = captured_towards(i, top ? u_luminaire_size.y - 1 : 0, centre, p);
                e += (captured.rgb + key_lobe(captured.a, centre, p, key_to_light))
                   * rectangle_irradiance_factor(p, n, corner, depth, s);
            }
        }
    }
    if (p.z < u_back_plane_z) {
        for (int j = 0; j < u_luminaire_size.y; ++j) {
            for (int i = 0; i < u_luminaire_size.x; ++i) {
                vec3 corner = vec3(opening.x + float(i) * cell.x, opening.z + float(j) * cell.y, u_back_plane_z);
                e += texelFetch(u_luminaire_back, ivec2(i, j), u_luminaire_back_level).rgb
                   * rectangle_irradiance_factor(p, n, corner, s, t);
            }
        }
    }
    return e;
}

// The room's direct light at p besides the key's beam: the window and the lamps in the room
// (isotropic points, E = I cos_r / r^2).
vec3 room_direct_irradiance(vec3 p, vec3 n, vec4 opening, float wall_z, vec3 key_to_light) {
    vec3 e = window_irradiance(p, n, opening, wall_z, key_to_light);
    for (int k = 0; k < u_lamp_count; ++k) {
        vec3 d = u_lamp_position[k] - p;
        float r2 = dot(d, d);
        e += u_lamp_rgb[k] * (max(dot(n, d), 0.0) * inversesqrt(r2) / r2);
    }
    return e;
}
#endif

// ---- An environment image (issue 13): latitude-longitude, v = 0 at the nadir, u = 0 towards
// -z (catalog/render/environment.py); the radiance towards dir, times its scale to the sky.
vec3 environment_lookup(sampler2D image, float scale, vec3 dir) {
    float u = atan(dir.x, -dir.z) / (2.0 * PI) + 0.5;
    float v = acos(clamp(-dir.y, -1.0, 1.0)) / PI;
    return scale * textureLod(image, vec2(u, v), 0.0).rgb;
}

// ---- The clear sky (issue 13; catalog/optics/sun/sky.py is the float64 twin). Preetham, Shirley & Smits
// 1999, the Perez et al. 1993 function F(theta, gamma) = (1 + A e^(B / cos theta))
// (1 + C e^(D gamma) + E cos^2 gamma) for x, y and Y at once (columns of the coefficients).
vec3 perez_xyY(float cos_theta, float gamma, vec3 a, vec3 b, vec3 c, vec3 d, vec3 e) {
    float cos_gamma = cos(gamma);
    return (1.0 + a * exp(b / max(cos_theta, 0.01)))
         * (1.0 + c * exp(d * gamma) + e * (cos_gamma * cos_gamma));
}

// xyY -> XYZ.
vec3 xyY_to_XYZ(vec3 xyY) {
    return vec3(xyY.x * xyY.z / xyY.y, xyY.z, (1.0 - xyY.x - xyY.y) * xyY.z / xyY.y);
}


#ifdef WALL_LIGHT
// What the window wall and its reveals show the cloth's window side (issue 11, fifth round;
// room_light.wall_radiance_along and walled_radiance are the float64 twins). The outside's
// occlusion (outside_occlusion) counts the directions that miss the opening as dark; in the
// path-traced room they meet the wall's inner face (the room's light) or a reveal (the
// outside, the key, the cloth's window side): the sunlit sill, seen through the directional
// lobe from a room view looking down, was 40-57 % of the curtain's bottom. Names apart from
// the passes' own (curtain.frag declares the window's rectangle and the key's direction).
uniform sampler2D u_wall_lightmap;   // the room's light map (irradiance, linear sRGB)
uniform vec3 u_wall_face_origin[6];
uniform vec3 u_wall_face_s[6];
uniform vec3 u_wall_face_t[6];
uniform float u_wall_face_texels;
uniform vec3 u_wall_box_lo;          // the room box (m)
uniform vec3 u_wall_box_hi;
uniform vec4 u_wall_opening;         // the window opening (x0, x1, y0, y1), m
uniform vec2 u_wall_planes;          // the wall's inner and outer planes (z, m)
uniform vec3 u_wall_sky_half;        // 0.5 pi x the sky's radiance (linear sRGB)
uniform vec3 u_wall_ground_half;     // 0.5 pi x the ground's
uniform sampler2D u_wall_back;       // the window-side capture (reveal_irradiance)
uniform int u_wall_back_level;
uniform ivec2 u_wall_back_size;
uniform vec3 u_wall_key_to_light;
uniform vec3 u_wall_key_rgb;         // the key's normal irradiance, linear sRGB
uniform float u_wall_tan_sun;
uniform float u_wall_albedo;

// The distance along d from p to the plane lo or hi of one axis that the ray leaves by.
float axis_exit(float p, float d, float lo, float hi) {
    return abs(d) > 1e-12 ? ((d > 0.0 ? hi : lo) - p) / d : 1e30;
}

// The radiance met from p along d (towards the window, d.z < 0) where it misses the opening
// (a: 1), 0 where it passes (a: 0): the room's face where it leaves the room box (albedo / pi x the light
// map), or, through the wall's inner plane inside the opening but not its outer plane, the
// reveal it meets (albedo / pi x (reveal_irradiance + the key, cos x the window's mask,
// undimmed: the reveals lie before the cloth)).
vec4 wall_radiance_along(vec3 p, vec3 d) {
    float t_x = axis_exit(p.x, d.x, u_wall_box_lo.x, u_wall_box_hi.x);
    float t_y = axis_exit(p.y, d.y, u_wall_box_lo.y, u_wall_box_hi.y);
    float t_z = (u_wall_planes.x - p.z) / d.z;
    vec2 q_in = p.xy + t_z * d.xy;
    vec2 q_out = p.xy + ((u_wall_planes.y - p.z) / d.z) * d.xy;
    bool inner = all(greaterThanEqual(q_in, u_wall_opening.xz)) && all(lessThanEqual(q_in, u_wall_opening.yw));
    bool outer = all(greaterThanEqual(q_out, u_wall_opening.xz)) && all(lessThanEqual(q_out, u_wall_opening.yw));
    bool tunnel = inner && t_z <= min(t_x, t_y);
    if (tunnel && outer) {
        return vec4(0.0);
    }
    vec3 irradiance;
    if (tunnel) {
        float tx = axis_exit(p.x, d.x, u_wall_opening.x, u_wall_opening.y);
        float ty = axis_exit(p.y, d.y, u_wall_opening.z, u_wall_opening.w);
        vec3 n = tx <= ty ? vec3(-sign(d.x), 0.0, 0.0) : vec3(0.0, -sign(d.y), 0.0);
        vec3 hit = p + min(tx, ty) * d;
        irradiance = reveal_irradiance(hit, n, u_wall_opening, u_wall_sky_half, u_wall_ground_half,
                                       u_wall_back, u_wall_back_level, u_wall_back_size);
        if (u_wall_key_to_light.z < 0.0) {
            irradiance += u_wall_key_rgb * (max(dot(n, u_wall_key_to_light), 0.0)
                * room_window_beam(hit, u_wall_key_to_light, u_wall_opening, u_wall_planes, u_wall_tan_sun));
        }
    } else {
        float t = min(min(t_x, t_y), t_z);
        int face = t == t_z ? 5 : (t_x <= t_y ? (d.x > 0.0 ? 3 : 2) : (d.y > 0.0 ? 1 : 0));
        vec2 uv = room_atlas_uv(face, p + t * d, u_wall_face_origin[face], u_wall_face_s[face],
                                u_wall_face_t[face], u_wall_face_texels);
        irradiance = textureLod(u_wall_lightmap, uv, 0.0).rgb;
    }
    return vec4((u_wall_albedo / PI) * irradiance, 1.0);
}

#ifdef OCCLUSION_MAPS
// Over the outside's occlusion directions (cosine-weighted about -z), the mean radiance of
// the wall they meet (0 for those through the opening): the light the walled share of the
// cloth's window-side hemisphere receives, per unit of that hemisphere's cosine weight.
vec3 walled_radiance(vec3 p) {
    vec3 total = vec3(0.0);
    for (int j = 0; j < N_OCCLUSION; ++j) {
        total += wall_radiance_along(p, u_occlusion_direction[j]).rgb;
    }
    return total / float(N_OCCLUSION);
}
#endif
#endif

#endif
