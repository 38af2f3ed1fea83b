#version 430
// Test only (tests/test_cloth_gpu.py): draws the simulated curtain from the vertex buffer
// the GPU backend writes, fitting the rest rectangle (x in [-0.7, 0.7], y in [0.05, 2.25])
// into clip space.
in vec4 in_position;
in vec4 in_normal;
out vec3 v_normal;
void main() {
    vec2 p = vec2(in_position.x / 0.7, (in_position.y - 1.15) / 1.1);
    gl_Position = vec4(p * 1.05, 0.0, 1.0);
    v_normal = in_normal.xyz;
}
