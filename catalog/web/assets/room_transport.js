// The room's precomputed transport on the page: reads the room's web pack (room_pack.js,
// catalog/room/web_pack.py page_script), checks it as read_page_script does (a bad pack is
// refused in one line naming the file and the field) and applies its operators in float64,
// as catalog/room/web_pack.py WebPack and catalog/room/lightmap.py do in numpy:
//   irradiance(c)   E = U_r (S V^T)_r c                  the window's light, every bounce
//   bounced(direct) E = direct + F rho direct + B2 direct  a direct light's bounces
//   corners(E)      the light map's welded corner values (exposed-area weights)
//   gather(name, x) a CSR gather (the window's patches, the cloth's room-side and wall grids)
// window.CatalogRoom.load(window.CATALOG_ROOM_PACK, file) -> Promise of the pack; its byte
// helpers b64bytes and inflate serve app.js too.
'use strict';
(function () {
  const FORMAT = 'catalog-room-pack/2';
  const DTYPES = { float16: [2, Uint16Array], float32: [4, Float32Array], float64: [8, Float64Array], uint8: [1, Uint8Array],
                   uint16: [2, Uint16Array], uint32: [4, Uint32Array], int32: [4, Int32Array] };
  const NEED = ['window_left', 'window_right', 'albedo', 'f_counts', 'f_indices', 'f_indptr',
                'bounce_left', 'bounce_right', 'bounce_scale', 'vertex', 'weld_weight_m2',
                'hang_vertex', 'hang_data', 'hang_indices', 'hang_indptr', 'gather_patch_data', 'gather_patch_indices', 'gather_patch_indptr', 'gather_side_data',
                'gather_side_indices', 'gather_side_indptr', 'gather_wall_data', 'gather_wall_indices',
                'gather_wall_indptr', 'outside', 'outside_frame', 'window_back'];

  class PackError extends Error {}

  function b64bytes(text) {
    const s = atob(text);
    const out = new Uint8Array(s.length);
    for (let i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
    return out;
  }
  async function inflate(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }
  function half(h) {   // IEEE 754 binary16 -> number
    const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 0x1f, f = h & 0x3ff;
    if (e === 0) return s * f * 5.960464477539063e-8;   // 2^-24
    if (e === 31) return f ? NaN : s * Infinity;
    return s * (1 + f / 1024) * Math.pow(2, e - 15);
  }
  const HALF = new Float32Array(65536);
  for (let i = 0; i < 65536; i++) HALF[i] = half(i);
  const hex = (buf) => Array.from(new Uint8Array(buf), (b) => b.toString(16).padStart(2, '0')).join('');
  const shapeSize = (shape) => shape.reduce((a, b) => a * b, 1);

  async function load(pack, file) {
    const refuse = (field, problem) => { throw new PackError(file + ': ' + field + ': ' + problem); };
    if (!pack || typeof pack.header !== 'object' || typeof pack.payload !== 'string') refuse('file', 'not a room pack\'s JSON (header and payload)');
    const h = pack.header;
    if (h.format !== FORMAT) refuse('header.format', JSON.stringify(h.format) + ', expected ' + JSON.stringify(FORMAT));
    let payload;
    try { payload = await inflate(b64bytes(pack.payload)); } catch (e) { refuse('payload', 'not base64 of zlib data'); }
    if (payload.length !== h.payload_bytes) refuse('payload', payload.length + ' bytes, the header says ' + h.payload_bytes);
    if (window.crypto && crypto.subtle) {
      if (hex(await crypto.subtle.digest('SHA-256', payload)) !== h.payload_sha256) refuse('payload', 'its SHA-256 differs from the header\'s (the file is damaged)');
    }
    const a = {}, shapes = {};
    for (const entry of h.arrays || []) {
      const dt = DTYPES[entry.dtype];
      if (!dt) refuse('arrays.' + entry.name, 'dtype ' + JSON.stringify(entry.dtype));
      const n = shapeSize(entry.shape), end = entry.offset + n * dt[0];
      if (entry.offset % 8 || end > payload.length) refuse('arrays.' + entry.name, 'outside the payload');
      const view = new dt[1](payload.buffer, payload.byteOffset + entry.offset, n);
      a[entry.name] = entry.dtype === 'float16' ? Float32Array.from(view, (v) => HALF[v]) : view;
      shapes[entry.name] = entry.shape;
    }
    for (const name of NEED) if (!(name in a)) refuse('arrays.' + name, 'missing');
    const E = h.receivers, [nu, nv] = h.patches, K = h.order * (h.order + 1) / 2;
    const r = shapes.window_left[2], rb = shapes.bounce_scale[1];
    const want = { window_left: [3, E, r], window_right: [r, nu * nv * K], albedo: [E, 3], vertex: [3 * E],
                   weld_weight_m2: [E], window_back: [E], outside_frame: [3, 3], f_indptr: [E + 1],
                   bounce_left: [3, E, rb], bounce_right: [3, rb, E], bounce_scale: [3, rb] };
    for (const [name, shape] of Object.entries(want)) {
      if (JSON.stringify(shapes[name]) !== JSON.stringify(shape)) refuse('arrays.' + name, 'shape ' + JSON.stringify(shapes[name]) + ', expected ' + JSON.stringify(shape));
    }
    if (shapes.outside[0] !== E) refuse('arrays.outside', shapes.outside[0] + ' rows, expected ' + E);
    const [tw, th] = h.side_grid;
    for (let i = 0; i < a.vertex.length; i++) if (a.vertex[i] < 0 || a.vertex[i] >= 3 * E) refuse('arrays.vertex', 'a light-map vertex out of range');
    let V = 0;
    for (let i = 0; i < a.vertex.length; i++) if (a.vertex[i] + 1 > V) V = a.vertex[i] + 1;
    // each CSR operator: its rows, its values' array, and what its columns index
    for (const [prefix, rows, data, cols, what] of [['f', E, 'f_counts', E, 'receivers'], ['gather_patch', nu * nv, 'gather_patch_data', E, 'receivers'],
                                                    ['gather_side', tw * th, 'gather_side_data', E, 'receivers'], ['gather_wall', tw * th, 'gather_wall_data', E, 'receivers'],
                                                    ['hang', a.hang_vertex.length, 'hang_data', V, 'light-map vertices']]) {
      const ptr = a[prefix + '_indptr'], idx = a[prefix + '_indices'];
      let ok = ptr.length === rows + 1 && ptr[0] === 0 && ptr[rows] === idx.length && a[data].length === idx.length;
      for (let i = 0; ok && i < rows; i++) ok = ptr[i + 1] >= ptr[i];
      if (!ok) refuse('arrays.' + prefix + '_indptr', 'not a CSR row index of its entries');
      let top = -1;
      for (let i = 0; i < idx.length; i++) if (idx[i] > top) top = idx[i];
      if (top >= cols) refuse('arrays.' + prefix + '_indices', 'a column ' + top + ' >= ' + cols + ' ' + what);
    }
    let topHung = -1;
    for (let i = 0; i < a.hang_vertex.length; i++) if (a.hang_vertex[i] > topHung) topHung = a.hang_vertex[i];
    if (topHung >= V) refuse('arrays.hang_vertex', 'a vertex ' + topHung + ' >= ' + V + ' light-map vertices');
    for (const name of ['window_left', 'window_right', 'bounce_left', 'bounce_right', 'bounce_scale', 'albedo', 'outside', 'window_back', 'weld_weight_m2', 'hang_data']) {
      const v = a[name];
      for (let i = 0; i < v.length; i++) if (!Number.isFinite(v[i])) refuse('arrays.' + name, 'a value is not finite');
    }
    return new RoomPack(h, a, { E, P: nu * nv, K, r, rb, vertices: V });
  }

  class RoomPack {
    constructor(header, arrays, dims) {
      this.header = header; this.a = arrays; Object.assign(this, dims);
    }
    // (E * 3) receivers' irradiance [e][ch] from window coefficients (P K * 3) [p][k][ch]
    irradiance(c) {
      const { E, r, P, K } = this, { window_left: U, window_right: SV } = this.a, PK = P * K;
      const modes = new Float64Array(r * 3);
      for (let i = 0; i < r; i++) {
        let m0 = 0, m1 = 0, m2 = 0;
        for (let j = 0; j < PK; j++) { const w = SV[i * PK + j]; m0 += w * c[3 * j]; m1 += w * c[3 * j + 1]; m2 += w * c[3 * j + 2]; }
        modes[3 * i] = m0; modes[3 * i + 1] = m1; modes[3 * i + 2] = m2;
      }
      const out = new Float64Array(E * 3);
      for (let ch = 0; ch < 3; ch++) {
        for (let e = 0; e < E; e++) {
          let s = 0;
          const row = (ch * E + e) * r;
          for (let i = 0; i < r; i++) s += U[row + i] * modes[3 * i + ch];
          out[3 * e + ch] = s;
        }
      }
      return out;
    }
    // (E * 3) the direct irradiance plus every bounce: direct + F (rho direct) + left diag(s) right direct
    bounced(direct) {
      const { E, rb } = this, a = this.a, rays = this.header.gather_rays;
      const out = Float64Array.from(direct);
      const lit = new Float64Array(E * 3);
      for (let i = 0; i < E * 3; i++) lit[i] = a.albedo[i] * direct[i];
      for (let e = 0; e < E; e++) {
        let s0 = 0, s1 = 0, s2 = 0;
        for (let q = a.f_indptr[e]; q < a.f_indptr[e + 1]; q++) {
          const w = a.f_counts[q] / rays, j = 3 * a.f_indices[q];
          s0 += w * lit[j]; s1 += w * lit[j + 1]; s2 += w * lit[j + 2];
        }
        out[3 * e] += s0; out[3 * e + 1] += s1; out[3 * e + 2] += s2;
      }
      const right = new Float64Array(rb);
      for (let ch = 0; ch < 3; ch++) {
        for (let i = 0; i < rb; i++) {
          let s = 0;
          const row = (ch * rb + i) * E;
          for (let e = 0; e < E; e++) s += a.bounce_right[row + e] * direct[3 * e + ch];
          right[i] = s * a.bounce_scale[ch * rb + i];
        }
        for (let e = 0; e < E; e++) {
          let s = 0;
          const row = (ch * E + e) * rb;
          for (let i = 0; i < rb; i++) s += a.bounce_left[row + i] * right[i];
          out[3 * e + ch] += s;
        }
      }
      return out;
    }
    // (E * 3 * 3) each receiver corner's light-map value [e][corner][ch] (catalog/room/lightmap.py)
    corners(irradiance) {
      const { E } = this, a = this.a, V = this.vertices;
      const total = new Float64Array(V * 3), norm = new Float64Array(V);
      for (let q = 0; q < 3 * E; q++) {
        const e = Math.floor(q / 3), v = a.vertex[q], w = a.weld_weight_m2[e];
        total[3 * v] += w * irradiance[3 * e]; total[3 * v + 1] += w * irradiance[3 * e + 1]; total[3 * v + 2] += w * irradiance[3 * e + 2];
        norm[v] += w;
      }
      const value = new Float64Array(V * 3);
      for (let v = 0; v < V; v++) for (let ch = 0; ch < 3; ch++) value[3 * v + ch] = total[3 * v + ch] / norm[v];
      // a hanging vertex takes its coarser neighbour's edge there (from free vertices only)
      const hung = this.gather('hang', value);
      for (let i = 0; i < a.hang_vertex.length; i++) {
        const v = a.hang_vertex[i];
        for (let ch = 0; ch < 3; ch++) value[3 * v + ch] = hung[3 * i + ch];
      }
      const out = new Float64Array(E * 9);
      for (let q = 0; q < 3 * E; q++) {
        const v = a.vertex[q];
        for (let ch = 0; ch < 3; ch++) out[3 * q + ch] = value[3 * v + ch];
      }
      return out;
    }
    // (rows * 3) a gather (gather_patch | gather_side | gather_wall) of receiver values (E * 3)
    gather(name, x) {
      const data = this.a[name + '_data'], idx = this.a[name + '_indices'], ptr = this.a[name + '_indptr'];
      const rows = ptr.length - 1, out = new Float64Array(rows * 3);
      for (let i = 0; i < rows; i++) {
        let s0 = 0, s1 = 0, s2 = 0;
        for (let q = ptr[i]; q < ptr[i + 1]; q++) { const w = data[q], j = 3 * idx[q]; s0 += w * x[j]; s1 += w * x[j + 1]; s2 += w * x[j + 2]; }
        out[3 * i] = s0; out[3 * i + 1] = s1; out[3 * i + 2] = s2;
      }
      return out;
    }
  }

  window.CatalogRoom = { load, PackError, FORMAT, b64bytes, inflate };
})();
