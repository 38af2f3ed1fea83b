#version 430
// The rasteriser's floor for the benchmark: the same mesh and vertex shader, a constant colour
// written to the same float target.
layout(location = 0) out vec4 out_radiance;

void main() {
    out_radiance = vec4(0.5, 0.5, 0.5, 1.0);
}
