#version 430
// A full-viewport layer at depth u_depth (the alpha-to-coverage study, benchmarks/alpha_to_coverage.py).
uniform float u_depth;

void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0 - 1.0, u_depth, 1.0);
}
