#version 430
// One triangle covering the viewport at the far plane; v_ndc in [-1, 1]^2, v_uv in [0, 1]^2.
out vec2 v_ndc;
out vec2 v_uv;

void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    v_uv = corner;
    v_ndc = corner * 2.0 - 1.0;
    gl_Position = vec4(v_ndc, 1.0, 1.0);  // on the far plane: drawn last, only where nothing else is
}
