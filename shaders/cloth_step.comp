#version 430
// One substep of the curtain (catalog/cloth/backend_numpy.py is the reference; the order
// and the formulas are the same). One program per pass, chosen by a #define:
//   PASS_WIND      gusty wind at each particle, once per frame (catalog/cloth/wind.py)
//   PASS_NORMALS   normals by central differences
//   PASS_PREDICT   damping, gravity, semi-implicit normal drag, x_prev = x, x += h v
//   PASS_RINGS     rings slide towards their targets; ring particles follow them
//   PASS_SPRINGS   XPBD distance constraints of one selector (Macklin, Mueller, Chentanez
//                  2016), with Provot's strain limit; or the strain-limit sweep alone
//   PASS_ATTACH    long-range attachments (Kim, Chentanez, Mueller 2012), floor and wall
//   PASS_UPDATE    clamp again, v = (x - x_prev) / h, contact damping
//   PASS_VERTICES  positions, normals, tangents into the renderer's vertex buffer
// Positions are vec4 (w unused) in std430 buffers; particle index = row * W + col.

layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer Positions { vec4 x[]; };
layout(std430, binding = 1) buffer Velocities { vec4 v[]; };
layout(std430, binding = 2) buffer Previous { vec4 x_prev[]; };
layout(std430, binding = 3) buffer Normals { vec4 normal[]; };
layout(std430, binding = 4) buffer Wind { vec4 wind[]; };
// per particle: inverse mass (1/kg), LRA limit (m), LRA ring index, unused
layout(std430, binding = 5) readonly buffer Static { vec4 particle[]; };
layout(std430, binding = 6) buffer Rings { vec4 ring[]; };
layout(std430, binding = 7) readonly buffer RingTargets { vec4 ring_target[]; };
layout(std430, binding = 8) readonly buffer RingCols { int ring_col[]; };
// 3 vec4 per vertex: position (w = 1), normal (w = 0), tangent (w = handedness)
layout(std430, binding = 9) writeonly buffer Vertices { vec4 vertex_out[]; };

uniform ivec2 u_grid;  // (W, H)
uniform float u_h;     // substep, s

vec3 grid_normal(int r, int c) {
    int w = u_grid.x;
    int h = u_grid.y;
    vec3 down = x[min(r + 1, h - 1) * w + c].xyz - x[max(r - 1, 0) * w + c].xyz;
    vec3 across = x[r * w + min(c + 1, w - 1)].xyz - x[r * w + max(c - 1, 0)].xyz;
    vec3 n = cross(down, across);
    float len = length(n);
    return len > 0.0 ? n / len : n;
}

#ifdef PASS_WIND
uniform float u_time;
uniform float u_wind_speed;
uniform vec3 u_wind_dir;
uniform float u_gust;
uniform float u_gust_length;
uniform float u_gust_period;
uniform vec4 u_gust_k[3];      // wave vector (per gust length), frequency (per period)
uniform float u_gust_phase[3];
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_grid.x * u_grid.y) return;
    float factor = 0.0;
    if (u_wind_speed != 0.0) {
        float g = 0.0;
        for (int k = 0; k < 3; ++k) {
            float phase = 6.283185307179586 * (dot(x[i].xyz, u_gust_k[k].xyz) / u_gust_length
                                               + u_gust_k[k].w * u_time / u_gust_period)
                          + u_gust_phase[k];
            g += sin(phase);
        }
        factor = u_wind_speed * max(0.0, 1.0 + u_gust * g / 3.0);
    }
    wind[i] = vec4(factor * u_wind_dir, 0.0);
}
#endif

#ifdef PASS_NORMALS
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_grid.x * u_grid.y) return;
    normal[i] = vec4(grid_normal(i / u_grid.x, i % u_grid.x), 0.0);
}
#endif

#ifdef PASS_PREDICT
uniform float u_damping;   // 1/s
uniform float u_gravity;   // m/s^2
uniform float u_aero;      // 1/2 rho C_d / areal density, 1/m
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_grid.x * u_grid.y) return;
    vec3 vel = v[i].xyz / (1.0 + u_damping * u_h);
    vel.y -= u_h * u_gravity;
    vec3 n = normal[i].xyz;
    float vn = dot(vel - wind[i].xyz, n);
    vel += n * (vn / (1.0 + u_aero * abs(vn) * u_h) - vn);  // semi-implicit normal drag
    v[i] = vec4(vel, 0.0);
    x_prev[i] = x[i];
    x[i] = vec4(x[i].xyz + u_h * vel, 0.0);
}
#endif

#ifdef PASS_RINGS
uniform int u_ring_count;
uniform float u_ring_speed;  // m/s
void main() {
    int j = int(gl_GlobalInvocationID.x);
    if (j >= u_ring_count) return;
    vec3 before = ring[j].xyz;
    vec3 step = ring_target[j].xyz - before;
    float dist = length(step);
    float max_move = u_ring_speed * u_h;
    vec3 after = dist > max_move ? before + step * (max_move / dist) : before + step;
    ring[j] = vec4(after, 0.0);
    x_prev[ring_col[j]] = vec4(before, 0.0);
    x[ring_col[j]] = vec4(after, 0.0);
}
#endif

#ifdef PASS_SPRINGS
// One selector of springs (catalog/cloth/topology.py), a spring from (r, c) to
// (r + di, c + dj) per invocation; the selectors' numbers sit in a buffer so a dispatch
// only sets u_selector.
struct Selector {
    ivec4 offset_first;   // di, dj, first row, first col
    ivec4 step_count;     // row step, col step, rows, cols
    vec4 rest_k_limit;    // flat rest (m), k (N/m), (1 + max_stretch) flat rest (m), strain-limited
    ivec4 family;         // the family (topology.FAMILIES), unused x3
};
layout(std430, binding = 10) readonly buffer Selectors { Selector selector[]; };
// per family and first particle: the spring's rest length (m), family * W * H + particle
layout(std430, binding = 11) readonly buffer SpringRest { float spring_rest[]; };
uniform int u_selector;
uniform bool u_limit_only;  // the strain-limit sweep: only what exceeds the limit
void main() {
    Selector s = selector[u_selector];
    ivec2 id = ivec2(gl_GlobalInvocationID.y, gl_GlobalInvocationID.x);  // (row k, col m)
    if (id.x >= s.step_count.z || id.y >= s.step_count.w) return;
    int r = s.offset_first.z + id.x * s.step_count.x;
    int c = s.offset_first.w + id.y * s.step_count.y;
    int a = r * u_grid.x + c;
    int b = (r + s.offset_first.x) * u_grid.x + (c + s.offset_first.y);
    float wa = particle[a].x;
    float wb = particle[b].x;
    float wsum = wa + wb;
    vec3 d = x[b].xyz - x[a].xyz;
    float len = length(d);
    if (wsum <= 0.0 || len <= 0.0) return;
    float rest = s.rest_k_limit.x;
    float limit = s.rest_k_limit.z;
    // the elastic rest: the spring's length in the pleated pose (catalog/cloth/state.py
    // spring_rest_lengths_m); the strain limit stays at the fabric's own (flat) length
    rest = spring_rest[s.family.x * u_grid.x * u_grid.y + a];
    float shorten;
    if (u_limit_only) {
        shorten = max(len - limit, 0.0);
    } else {
        // XPBD, one iteration: dlambda = -C / (wa + wb + alpha / h^2), alpha = 1 / k
        float kh2 = s.rest_k_limit.y * u_h * u_h;
        shorten = (len - rest) * wsum * kh2 / (wsum * kh2 + 1.0);
        if (s.rest_k_limit.w > 0.5) shorten = max(shorten, len - limit);  // Provot
    }
    float scale = shorten / (wsum * len);
    x[a] = vec4(x[a].xyz + (wa * scale) * d, 0.0);
    x[b] = vec4(x[b].xyz - (wb * scale) * d, 0.0);
}
#endif

#ifdef PASS_ATTACH
uniform float u_floor;  // y of the floor plus the thickness, m
uniform float u_wall;   // z of the wall plus the thickness, m
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_grid.x * u_grid.y) return;
    vec4 info = particle[i];
    vec3 p = x[i].xyz;
    if (info.x > 0.0) {
        vec3 anchor = ring[int(info.z)].xyz;
        vec3 d = p - anchor;
        float dist = length(d);
        if (dist > info.y) p = anchor + d * (info.y / dist);
    }
    p.y = max(p.y, u_floor);
    p.z = max(p.z, u_wall);
    x[i] = vec4(p, 0.0);
}
#endif

#ifdef PASS_UPDATE
uniform float u_floor;
uniform float u_wall;
uniform float u_contact_damping;  // tangential velocity lost per second in contact
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_grid.x * u_grid.y) return;
    vec3 p = x[i].xyz;
    bool on_floor = p.y <= u_floor;
    bool on_wall = p.z <= u_wall;
    p.y = max(p.y, u_floor);
    p.z = max(p.z, u_wall);
    x[i] = vec4(p, 0.0);
    vec3 vel = (p - x_prev[i].xyz) / u_h;
    float keep = 1.0 / (1.0 + u_contact_damping * u_h);
    if (on_floor || on_wall) vel.x *= keep;
    if (on_floor) vel.z *= keep;
    if (on_wall) vel.y *= keep;
    v[i] = vec4(vel, 0.0);
}
#endif

#ifdef PASS_VERTICES
void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= u_grid.x * u_grid.y) return;
    int r = i / u_grid.x;
    int c = i % u_grid.x;
    vec3 n = grid_normal(r, c);
    vec3 across = x[r * u_grid.x + min(c + 1, u_grid.x - 1)].xyz
                - x[r * u_grid.x + max(c - 1, 0)].xyz;
    vec3 t = across - dot(across, n) * n;  // weft direction, orthogonal to the normal
    float len = length(t);
    t = len > 0.0 ? t / len : t;
    vertex_out[3 * i + 0] = vec4(x[i].xyz, 1.0);
    vertex_out[3 * i + 1] = vec4(n, 0.0);
    vertex_out[3 * i + 2] = vec4(t, 1.0);
}
#endif
