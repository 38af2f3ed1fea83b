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

// The curtain's scene values (curtain.vert/.frag), fixed until the light, fabric, mode or band
// count changes. SPECIALISED: compiled in as constants (catalog/render/frame.py injects
// S_<NAME> #defines with their values), so the compiler folds them (HG's (1 - g)^2, the sign
// of g) and a CPU rasteriser loads no uniforms per fragment; otherwise ordinary uniforms.
#ifdef SPECIALISED
#define SCENE_VALUE(type, name, value) const type name = value
#else
#define SCENE_VALUE(type, name, value) uniform type name
#endif

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
// catalog/render/curtain_frames.py), the fraction in which a layer of cloth lies between p and
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

// ---- The window wall's mask of the key light on the curtain (curtain.frag KEY_SHADOW).
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

#endif
