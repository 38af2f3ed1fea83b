#version 430
// The benchmark problem (benchmarks/springs12.py): explicit mass-spring cloth, 12
// springs per particle, semi-implicit Euler, float32, one thread per particle gathering
// its springs from the old buffers and writing the new ones (no races, no atomics).

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer SrcX { vec4 src_x[]; };
layout(std430, binding = 1) readonly buffer SrcV { vec4 src_v[]; };
layout(std430, binding = 2) writeonly buffer DstX { vec4 dst_x[]; };
layout(std430, binding = 3) writeonly buffer DstV { vec4 dst_v[]; };

uniform int u_n;             // grid side
uniform ivec2 u_offset[12];  // (dr, dc) of the 12 springs (topology.GATHER_OFFSETS)
uniform float u_rest[12];    // rest lengths, m
uniform float u_ke[12];      // stiffness, N/m
uniform float u_kd;          // spring damping, N s/m
uniform float u_dt;          // s
uniform float u_inv_mass;    // 1/kg
uniform float u_gravity;     // m/s^2

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_n * u_n) return;
    int r = i / u_n;
    int c = i % u_n;
    vec3 p = src_x[i].xyz;
    vec3 vel = src_v[i].xyz;
    if (r == 0) {  // pinned
        dst_x[i] = vec4(p, 0.0);
        dst_v[i] = vec4(0.0);
        return;
    }
    vec3 f = vec3(0.0);
    for (int k = 0; k < 12; ++k) {
        int r2 = r + u_offset[k].x;
        int c2 = c + u_offset[k].y;
        if (r2 < 0 || r2 >= u_n || c2 < 0 || c2 >= u_n) continue;
        int j = r2 * u_n + c2;
        vec3 d = src_x[j].xyz - p;
        float len = length(d);
        vec3 dir = d / len;
        float along = dot(src_v[j].xyz - vel, dir);
        f += dir * (u_ke[k] * (len - u_rest[k]) + u_kd * along);  // Hooke + dashpot
    }
    vel += u_dt * (f * u_inv_mass + vec3(0.0, -u_gravity, 0.0));
    dst_v[i] = vec4(vel, 0.0);
    dst_x[i] = vec4(p + u_dt * vel, 0.0);
}
