#version 430
// Test only: the interpolated normal, alpha 1 where the curtain covers the pixel.
in vec3 v_normal;
out vec4 frag;
void main() {
    frag = vec4(normalize(v_normal), 1.0);
}
