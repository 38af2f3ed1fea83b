#version 430
// Eq. 8 per fragment (model.md section 6) in N_BANDS bands, converted to linear sRGB radiance
// (683 * integral of the sRGB matching functions times radiance: cd m^-2 scale) at the end.
#include "common.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec3 v_tangent;

uniform vec3 u_camera_position;
uniform vec3 u_key_to_light;
uniform vec3 u_fill_to_light;
uniform vec3 u_sun_direction;      // to the sun's disc (the key light)
uniform vec2 u_sun_chord2;         // disc edge: inner, outer chord^2
uniform float u_direct;            // LD: the open-area see-through fraction
uniform float u_a_diff;
uniform float u_g_diff;
uniform float u_a_spec;
uniform float u_g_spec;
uniform float u_anisotropy;

// per band, NV4 chunks of 4 bands
uniform vec4 u_key_dyed[NV4];      // key light normal irradiance x dye transmittance
uniform vec4 u_fill_dyed[NV4];     // fill light (viewer side) x dye
uniform vec4 u_ambient[NV4];       // cloth radiance from the diffuse surroundings (both sides)
uniform vec4 u_sky[NV4];
uniform vec4 u_ground[NV4];
uniform vec4 u_sun_disc[NV4];
uniform vec4 u_room[NV4];
uniform vec4 u_fluorescence[NV4];  // paper: radiance; physical: radiance per 1e18 effective photons
uniform vec3 u_absorbed_photons;   // physical: (key, fill, ambient) absorbed photons at normal incidence, 1e18 m^-2 s^-1
uniform float u_inv_saturation;    // 1e18 / N_sat (0: no saturation)
uniform vec4 u_band_to_r[NV4];
uniform vec4 u_band_to_g[NV4];
uniform vec4 u_band_to_b[NV4];

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
    vec3 ray = normalize(v_position - u_camera_position);
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
