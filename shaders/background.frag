#version 430
// The background: what a camera ray sees behind everything else (the outside through the
// window: sky, ground, the sun's disc; or the room), in linear sRGB radiance.
// SKY_MODEL (issue 13, catalog/optics/sun/sky.py): the clear sky of Preetham et al. 1999 scaled to the
// project's atmosphere (catalog/optics/sun/model.py clear_sky), the ground below fading in from the
// horizon's haze over u_haze_rad of depression (no seam). ENVIRONMENT: an HDR image in
// latitude-longitude layout instead (scaled to the same sky's illuminance).
// SKY_BANDS (with SKY_MODEL; 6, 9 or 16 bands): the sky per band, Preetham's spectral
// reconstruction (a CIE daylight spectrum S0 + M1 S1 + M2 S2 per direction, luminance Y) whose
// band integrals, shown through the bands' display matrix, are the linear combination
// C0 + M1 C1 + M2 C2 of three colours computed once per scene (catalog/optics/sun/sky.py
// SpectralSky.band_colours): the same cost for any band count.
#include "common.glsl"

in vec2 v_ndc;
in vec2 v_uv;

uniform mat4 u_inverse_view_proj;
uniform vec3 u_camera_position;
uniform vec3 u_sun_direction;
uniform vec2 u_sun_chord2;
uniform vec3 u_sky_rgb;
uniform vec3 u_ground_rgb;
uniform vec3 u_sun_disc_rgb;
uniform vec3 u_room_rgb;

#ifdef SKY_MODEL
uniform vec3 u_perez[5];          // A..E, columns x, y, Y
uniform vec3 u_zenith_xyY;
uniform vec3 u_perez_sun;         // F(0, theta_sun)
uniform vec3 u_sky_scale;         // per channel, to the atmosphere's diffuse irradiance
uniform mat3 u_xyz_to_rgb;
uniform float u_haze_rad;
#ifdef SKY_BANDS
uniform vec3 u_sky_basis_rgb[3];    // C0, C1, C2: display colour of s(l) S_i(l) in the bands
uniform vec3 u_sky_basis_luminance; // Y0, Y1, Y2 of S0, S1, S2 (cd m^-2 scale)
#endif

vec3 sky_radiance(vec3 dir) {
    vec3 up = vec3(dir.x, max(dir.y, 0.0), dir.z);
    float gamma = acos(clamp(dot(normalize(up), u_sun_direction), -1.0, 1.0));
    vec3 xyY = u_zenith_xyY * perez_xyY(up.y / length(up), gamma, u_perez[0], u_perez[1],
                                        u_perez[2], u_perez[3], u_perez[4]) / u_perez_sun;
#ifdef SKY_BANDS
    // CIE D-series weights of the chromaticity (Preetham et al. 1999, appendix)
    float m = 0.0241 + 0.2562 * xyY.x - 0.7341 * xyY.y;
    float m1 = (-1.3515 - 1.7703 * xyY.x + 5.9114 * xyY.y) / m;
    float m2 = (0.0300 - 31.4424 * xyY.x + 30.0717 * xyY.y) / m;
    float luminance = dot(u_sky_basis_luminance, vec3(1.0, m1, m2));
    return (xyY.z / luminance) * (u_sky_basis_rgb[0] + m1 * u_sky_basis_rgb[1] + m2 * u_sky_basis_rgb[2]);
#else
    return u_sky_scale * (u_xyz_to_rgb * xyY_to_XYZ(xyY));
#endif
}
#endif

#ifdef ENVIRONMENT
uniform sampler2D u_environment;  // latitude-longitude, v = 0 at the nadir, u = 0 towards -z
uniform float u_environment_scale;

vec3 environment_radiance(vec3 dir) {
    return environment_lookup(u_environment, u_environment_scale, dir);
}
#endif

layout(location = 0) out vec4 out_radiance;

void main() {
    vec4 far_point = u_inverse_view_proj * vec4(v_ndc, 1.0, 1.0);
    vec3 ray = normalize(far_point.xyz / far_point.w - u_camera_position);
    vec4 w = background_weights(ray, u_sun_direction, u_sun_chord2.x, u_sun_chord2.y);
#if defined(ENVIRONMENT)
    vec3 outside = environment_radiance(ray);
    out_radiance = vec4((w.x + w.y) * outside + w.z * u_sun_disc_rgb + w.w * u_room_rgb, 1.0);
#elif defined(SKY_MODEL)
    vec3 sky = sky_radiance(ray);
    float fade = exp(-asin(clamp(-ray.y, 0.0, 1.0)) / u_haze_rad);
    vec3 below = fade * sky + (1.0 - fade) * u_ground_rgb;
    out_radiance = vec4(w.x * sky + w.y * below + w.z * u_sun_disc_rgb + w.w * u_room_rgb, 1.0);
#else
    out_radiance = vec4(w.x * u_sky_rgb + w.y * u_ground_rgb + w.z * u_sun_disc_rgb + w.w * u_room_rgb, 1.0);
#endif
}
