// common.glsl: the physical terms of model.md, one small function per term.
// Included by every pass (catalog/render/shaderlib.py resolves #include and injects
// #defines: N_BANDS, NV4 = ceil(N_BANDS / 4), FLUORESCENCE_OFF | FLUORESCENCE_PAPER |
// FLUORESCENCE_PHYSICAL, SEE_THROUGH, ANISOTROPIC, GBUFFER). Band quantities travel as vec4 chunks.
// The float64 twin of every function is in catalog/reference.py.

#ifndef CATALOG_COMMON_GLSL
#define CATALOG_COMMON_GLSL

const float PI = 3.14159265358979;

// Henyey & Greenstein 1941, "Diffuse radiation in the galaxy"; model.md eq. 6 in the robust form of
// catalog/btdf.py (unchanged for g >= 0):
// 1 + g^2 - 2 g cos(theta) = (1 - g)^2 + 2 g (1 - cos theta) with 1 - cos theta = chord2 / 2, and
// = (1 + g)^2 - 2 g (1 + cos theta) with 1 + cos theta = anti2 / 2 for g < 0 (no cancellation
// near g = -1); the power 1.5 as d * sqrt(d). chord2 = |w_view - w_travel|^2, anti2 = |w_view + w_travel|^2.
float hg_phase_robust(float chord2, float anti2, float g) {
    float d = (g >= 0.0) ? (1.0 - g) * (1.0 - g) + g * chord2
                         : (1.0 + g) * (1.0 + g) - g * anti2;
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

// Tobitani et al. 2014, woven-cloth HG BTDF; model.md eq. 5 and 7 without LD (the see-through
// is the background term below): radiance per unit of a directional light's normal irradiance,
// |cos theta_i| (a_diff ph_diff + a_spec ph_spec), a_* = rho e^-tau k_*. Two-sided: only
// |n . l| and the angle between the light's travel and the view direction enter, so the same
// thin layer transmits light from behind and scatters it back towards a light in front.
float woven_transmission(vec3 to_light, vec3 to_viewer, vec3 t, vec3 b, vec3 n,
                         float a_diff, float g_diff, float a_spec, float g_spec, float anisotropy) {
    vec3 travel = -to_light;
    vec3 delta = to_viewer - travel;
    vec3 sum = to_viewer + travel;
    float chord2 = dot(delta, delta);
    float anti2 = dot(sum, sum);
    float ph_diff = hg_phase_robust(chord2, anti2, g_diff);                       // eq. 6
#ifdef ANISOTROPIC
    float ph_spec = hg_phase_robust(woven_chord2(delta, t, b, n, anisotropy), anti2, g_spec);
#else
    float ph_spec = hg_phase_robust(chord2, anti2, g_spec);                       // eq. 6
#endif
    return abs(dot(n, to_light)) * (a_diff * ph_diff + a_spec * ph_spec);      // eq. 5, 7
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

// Reinhard, Stark, Shirley, Ferwerda 2002, "Photographic tone reproduction", eq. 4 (extended,
// on luminance, so hue is kept): L_d = L (1 + L / L_white^2) / (1 + L), applied after exposure.
vec3 tone_map_reinhard_luminance(vec3 rgb, float white) {
    float lum = dot(rgb, vec3(0.2126, 0.7152, 0.0722));
    if (lum <= 0.0) {
        return vec3(0.0);
    }
    float mapped = lum * (1.0 + lum / (white * white)) / (1.0 + lum);
    return rgb * (mapped / lum);
}

// IEC 61966-2-1:1999 sRGB transfer function (the piecewise curve, not a 2.2 power).
vec3 srgb_encode(vec3 linear) {
    vec3 c = clamp(linear, 0.0, 1.0);
    vec3 lo = 12.92 * c;
    vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(c, vec3(0.0031308)));
}

#endif
