#version 430
// A Lambertian receiver's radiance: albedo x irradiance / pi (eq. of a diffuse surface),
// linear, before exposure. Scene-referred HDR out.
#include "common.glsl"

in vec3 v_irradiance;
flat in vec3 v_albedo;

out vec4 f_color;

void main() {
    f_color = vec4(v_albedo * max(v_irradiance, vec3(0.0)) / PI, 1.0);
}
