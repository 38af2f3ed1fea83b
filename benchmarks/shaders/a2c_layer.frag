#version 430
// A white layer of thread coverage u_coverage, written as alpha for alpha-to-coverage.
uniform float u_coverage;

layout(location = 0) out vec4 out_colour;

void main() {
    out_colour = vec4(1.0, 1.0, 1.0, u_coverage);
}
