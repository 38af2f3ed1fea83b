#version 430
// Eq. 8 per fragment (model.md section 6) in N_BANDS bands, converted to linear sRGB radiance
// (683 * integral of the sRGB matching functions times radiance: cd m^-2 scale) at the end.
#include "common.glsl"

in vec3 v_view_ray;                // position - camera, world space
in vec3 v_normal;
#if defined(ANISOTROPIC) || defined(GBUFFER)
in vec3 v_tangent;
#endif
#ifdef GBUFFER
in vec3 v_position;
#endif

// The scene's values, fixed until the light, fabric, mode or band count changes. SPECIALISED:
// compiled in as constants (catalog/render/frame.py injects S_<NAME> #defines with their
// values), so the compiler folds them (HG's (1 - g)^2, the sign of g) and a CPU rasteriser
// loads no uniforms per fragment; otherwise ordinary uniforms.
#ifdef SPECIALISED
#define SCENE_VALUE(type, name, value) const type name = value
#else
#define SCENE_VALUE(type, name, value) uniform type name
#endif

SCENE_VALUE(vec3, u_key_to_light, S_KEY_TO_LIGHT);
SCENE_VALUE(vec3, u_fill_to_light, S_FILL_TO_LIGHT);
SCENE_VALUE(vec3, u_sun_direction, S_SUN_DIRECTION);        // to the sun's disc (the key light)
SCENE_VALUE(vec2, u_sun_chord2, S_SUN_CHORD2);              // disc edge: inner, outer chord^2
SCENE_VALUE(float, u_direct, S_DIRECT);                     // LD: the open-area see-through fraction
SCENE_VALUE(float, u_a_diff, S_A_DIFF);
SCENE_VALUE(float, u_g_diff, S_G_DIFF);
SCENE_VALUE(float, u_a_spec, S_A_SPEC);
SCENE_VALUE(float, u_g_spec, S_G_SPEC);
SCENE_VALUE(float, u_anisotropy, S_ANISOTROPY);

// per band, NV4 chunks of 4 bands
SCENE_VALUE(vec4, u_key_dyed[NV4], S_KEY_DYED);             // key light normal irradiance x dye
SCENE_VALUE(vec4, u_fill_dyed[NV4], S_FILL_DYED);           // fill light (viewer side) x dye
SCENE_VALUE(vec4, u_ambient[NV4], S_AMBIENT);               // cloth radiance from the diffuse surroundings
SCENE_VALUE(vec4, u_sky[NV4], S_SKY);
SCENE_VALUE(vec4, u_ground[NV4], S_GROUND);
SCENE_VALUE(vec4, u_sun_disc[NV4], S_SUN_DISC);
SCENE_VALUE(vec4, u_room[NV4], S_ROOM);
SCENE_VALUE(vec4, u_fluorescence[NV4], S_FLUORESCENCE);     // paper: radiance; physical: per 1e18 effective photons
SCENE_VALUE(vec3, u_absorbed_photons, S_ABSORBED_PHOTONS);  // physical: key, fill, ambient at normal incidence, 1e18 m^-2 s^-1
SCENE_VALUE(float, u_inv_saturation, S_INV_SATURATION);     // 1e18 / N_sat (0: no saturation)
SCENE_VALUE(vec4, u_band_to_r[NV4], S_BAND_TO_R);
SCENE_VALUE(vec4, u_band_to_g[NV4], S_BAND_TO_G);
SCENE_VALUE(vec4, u_band_to_b[NV4], S_BAND_TO_B);

layout(location = 0) out vec4 out_radiance;
#ifdef GBUFFER
layout(location = 1) out vec4 out_position;
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_tangent;
#endif

// One chunk of 4 bands: eq. 8's terms summed, then projected to display colour. Called with a
// constant k (unrolled below by NV4), so every uniform array index is a compile-time constant.
vec3 shade_chunk(int k, float g_key, float g_fill, vec4 w_bg, float effective) {
    vec4 band = g_key * u_key_dyed[k] + g_fill * u_fill_dyed[k] + u_ambient[k];
#ifdef SEE_THROUGH
    band += w_bg.x * u_sky[k] + w_bg.y * u_ground[k] + w_bg.z * u_sun_disc[k] + w_bg.w * u_room[k];
#endif
#ifdef FLUORESCENCE_PAPER
    band += fluorescence_paper(u_fluorescence[k]);
#endif
#ifdef FLUORESCENCE_PHYSICAL
    band += fluorescence_physical(effective, u_fluorescence[k]);
#endif
#if N_BANDS == 3
    return band.rgb;  // RGB: the bands are linear sRGB already (bands.py: band_to_rgb = identity)
#else
    return vec3(dot(band, u_band_to_r[k]), dot(band, u_band_to_g[k]), dot(band, u_band_to_b[k]));
#endif
}

void main() {
    vec3 n = normalize(v_normal);
#ifdef ANISOTROPIC
    vec3 t = normalize(v_tangent - dot(v_tangent, n) * n);   // Gram-Schmidt: weft
    vec3 b = cross(n, t);                                     // warp
#else
    vec3 t = vec3(0.0);                                       // isotropic: the frame is not needed
    vec3 b = vec3(0.0);
#endif
    vec3 ray = normalize(v_view_ray);
    vec3 to_viewer = -ray;

    float g_key = woven_transmission(u_key_to_light, to_viewer, t, b, n,
                                     u_a_diff, u_g_diff, u_a_spec, u_g_spec, u_anisotropy);
    float g_fill = woven_transmission(u_fill_to_light, to_viewer, t, b, n,
                                      u_a_diff, u_g_diff, u_a_spec, u_g_spec, u_anisotropy);
    vec4 w_bg = vec4(0.0);
#ifdef SEE_THROUGH
    w_bg = u_direct * background_weights(ray, u_sun_direction, u_sun_chord2.x, u_sun_chord2.y);
#endif
    float effective = 0.0;
#ifdef FLUORESCENCE_PHYSICAL
    float absorbed = abs(dot(n, u_key_to_light)) * u_absorbed_photons.x
                   + abs(dot(n, u_fill_to_light)) * u_absorbed_photons.y + u_absorbed_photons.z;
    effective = fluorescence_effective_photons(absorbed, u_inv_saturation);
#endif

    vec3 rgb = shade_chunk(0, g_key, g_fill, w_bg, effective);
#if NV4 > 1
    rgb += shade_chunk(1, g_key, g_fill, w_bg, effective);
#endif
#if NV4 > 2
    rgb += shade_chunk(2, g_key, g_fill, w_bg, effective);
#endif
#if NV4 > 3
    rgb += shade_chunk(3, g_key, g_fill, w_bg, effective);
#endif
    out_radiance = vec4(rgb, 1.0);
#ifdef GBUFFER
    out_position = vec4(v_position, 1.0);
    out_normal = vec4(n, 1.0);
    out_tangent = vec4(normalize(v_tangent - dot(v_tangent, n) * n), 1.0);
#endif
}
