#version 430
// The key light's visibility on the cloth baked over the fabric's uv (shadow.py ShadowPass
// _draw_key_visibility; curtain.frag KEY_SHADOW reads it): the curtain mesh rasterised in its
// own uv square, so texel (i, j) is the cloth point at uv ((i + 1/2) / W, (j + 1/2) / H). The
// position and normal are interpolated with the same barycentrics a camera's rasteriser gives
// that point (both are affine in them), so the baked value is the frame's own at texel centres.
in vec3 in_position;
in vec3 in_normal;
in vec2 in_uv;

uniform vec3 u_mesh_offset;

out vec3 v_position;
out vec3 v_normal;

void main() {
    v_position = in_position + u_mesh_offset;
    v_normal = in_normal;
    gl_Position = vec4(in_uv * 2.0 - 1.0, 0.0, 1.0);
}
