// The web catalog: replays the desktop frame recorded by catalog/web/export.py with WebGL2 and
// the GLSL ES variant of the project's shader files (data.js). docs/web.md describes the data.
// No network: data.js and anim/*.js are loaded by <script> tags (works from file://).
'use strict';
(function () {
  // base64 -> bytes and deflate -> bytes: room_transport.js's (loaded before this file)
  const { b64bytes, inflate } = window.CatalogRoom;
  // data.js (catalog/web/site.py pack_data): the JSON and the bulky bytes, each deflated;
  // {"binary": i} in the JSON names the i-th bytes (bin() below)
  const unpackStart = performance.now();
  async function unpack(packed) {
    const [text, ...binary] = await Promise.all([packed.json, ...packed.binary].map((z) => inflate(b64bytes(z))));
    const data = JSON.parse(new TextDecoder().decode(text));
    data.binary = binary;
    return data;
  }
  // a data.js of plain JSON (window.CATALOG_DATA, bytes as base64: site.plain_data_js, the
  // form before packing; the benchmark loads both) is brought to the same shape
  function plain(data) {
    data.binary = [];
    const move = (text) => { data.binary.push(b64bytes(text)); return { binary: data.binary.length - 1 }; };
    for (const section of ['textures', 'buffers']) {
      for (const entry of Object.values(data[section])) if (typeof entry.data === 'string') entry.data = move(entry.data);
    }
    data.blobs = data.blobs.map(move);
    data.value_pool = [];
    for (const scene of Object.values(data.scenes)) scene.values = scene.values.map((v) => data.value_pool.push(v) - 1);
    return data;
  }
  (window.CATALOG_PACKED ? unpack(window.CATALOG_PACKED) : Promise.resolve().then(() => plain(window.CATALOG_DATA))).then(start, (e) => {
    window.catalogStartError = String(e);
    document.getElementById('status').textContent = 'cannot read the catalog data: ' + (e.message || e);
    console.error(e);
  });

  function start(D) {
  const unpackMs = performance.now() - unpackStart;
  const bin = (ref) => D.binary[ref.binary];  // the bytes of a {"binary": i}
  const value = (scene, slot) => D.value_pool[scene.values[slot]];  // site.pack_data's pool

  // ---------------------------------------------------------------- camera
  // The orbit camera of catalog/render/camera.py (float64 here, float32 on upload).
  const Camera = {
    position(c) {
      const yaw = c.yaw_deg * Math.PI / 180, pitch = c.pitch_deg * Math.PI / 180, t = D.camera.target;
      return [t[0] + c.distance_m * Math.sin(yaw) * Math.cos(pitch),
              t[1] + c.distance_m * Math.sin(pitch),
              t[2] + c.distance_m * Math.cos(yaw) * Math.cos(pitch)];
    },
    view(c) {  // row-major 4x4
      const eye = this.position(c), t = D.camera.target;
      const f = norm([t[0] - eye[0], t[1] - eye[1], t[2] - eye[2]]);
      const r = norm(cross(f, [0, 1, 0]));
      const u = cross(r, f);
      const m = [r[0], r[1], r[2], 0, u[0], u[1], u[2], 0, -f[0], -f[1], -f[2], 0, 0, 0, 0, 1];
      for (let i = 0; i < 3; i++) m[i * 4 + 3] = -(m[i * 4] * eye[0] + m[i * 4 + 1] * eye[1] + m[i * 4 + 2] * eye[2]);
      return m;
    },
    projection(aspect) {
      const f = 1 / Math.tan(D.camera.fov_y_deg * Math.PI / 360), n = D.camera.near_m, fa = D.camera.far_m;
      const m = new Array(16).fill(0);
      m[0] = f / aspect; m[5] = f; m[10] = (fa + n) / (n - fa); m[11] = 2 * fa * n / (n - fa); m[14] = -1;
      return m;
    },
    viewProjection(c, aspect) { return matmul(this.projection(aspect), this.view(c)); },
  };
  function norm(v) { const l = Math.hypot(v[0], v[1], v[2]); return [v[0] / l, v[1] / l, v[2] / l]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function matmul(a, b) {
    const m = new Array(16).fill(0);
    for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) for (let k = 0; k < 4; k++) m[i * 4 + j] += a[i * 4 + k] * b[k * 4 + j];
    return m;
  }
  function invert(m) {  // Gauss-Jordan with partial pivoting, row-major
    const a = m.slice(), inv = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
    for (let c = 0; c < 4; c++) {
      let p = c;
      for (let r = c + 1; r < 4; r++) if (Math.abs(a[r * 4 + c]) > Math.abs(a[p * 4 + c])) p = r;
      for (let k = 0; k < 4; k++) {
        [a[c * 4 + k], a[p * 4 + k]] = [a[p * 4 + k], a[c * 4 + k]];
        [inv[c * 4 + k], inv[p * 4 + k]] = [inv[p * 4 + k], inv[c * 4 + k]];
      }
      const d = a[c * 4 + c];
      for (let k = 0; k < 4; k++) { a[c * 4 + k] /= d; inv[c * 4 + k] /= d; }
      for (let r = 0; r < 4; r++) if (r !== c) {
        const f = a[r * 4 + c];
        for (let k = 0; k < 4; k++) { a[r * 4 + k] -= f * a[c * 4 + k]; inv[r * 4 + k] -= f * inv[c * 4 + k]; }
      }
    }
    return inv;
  }
  function columnMajor(m) { const o = new Array(16); for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) o[c * 4 + r] = m[r * 4 + c]; return o; }
  function cameraUniforms(c, aspect) {
    const vp = Camera.viewProjection(c, aspect);
    return { view_proj: columnMajor(vp), inverse_view_proj: columnMajor(invert(vp)), camera_position: Camera.position(c),
             // FrameRenderer.oit_depth_reference_m: the OIT depth weight's 1 (m)
             oit_depth_ref: Math.max(0, c.distance_m - 1) };
  }

  // ---------------------------------------------------------------- baked cloth
  const animations = {};  // key -> Promise of {frames, positions[], normals[], tangents[], indices, ...}
  function loadScript(src) {
    return new Promise((resolve, reject) => {
      const s = document.createElement('script');
      s.src = src; s.onload = resolve; s.onerror = () => reject(new Error('cannot load ' + src));
      document.head.appendChild(s);
    });
  }
  // The decoder of catalog/web/bake.py (decode_frames): planes (x, y, z of every vertex) of
  // zigzag residuals, positions second differences mod 2^16 (q[k] = 2 q[k-1] - q[k-2] + d);
  // positions (lo + q step) + offset in float64 then float32; normals and weft tangents
  // computed from the float64 grid (lo + q step) as bake.frames_of_grid does, sums in its order.
  const unzigzag = (z) => (z >>> 1) ^ -(z & 1);
  function gridFrames(x, cols, rows, normals, tangents) {
    const at = (r, c, k) => x[3 * (r * cols + c) + k];
    for (let r = 0; r < rows; r++) {
      const r0 = r === 0 ? 0 : r === rows - 1 ? rows - 2 : r - 1, r1 = r === 0 ? 1 : r === rows - 1 ? rows - 1 : r + 1;
      for (let c = 0; c < cols; c++) {
        const c0 = c === 0 ? 0 : c === cols - 1 ? cols - 2 : c - 1, c1 = c === 0 ? 1 : c === cols - 1 ? cols - 1 : c + 1;
        const d0 = at(r1, c, 0) - at(r0, c, 0), d1 = at(r1, c, 1) - at(r0, c, 1), d2 = at(r1, c, 2) - at(r0, c, 2);
        const a0 = at(r, c1, 0) - at(r, c0, 0), a1 = at(r, c1, 1) - at(r, c0, 1), a2 = at(r, c1, 2) - at(r, c0, 2);
        let n0 = d1 * a2 - d2 * a1, n1 = d2 * a0 - d0 * a2, n2 = d0 * a1 - d1 * a0;
        let len = Math.sqrt(n0 * n0 + n1 * n1 + n2 * n2);
        if (!(len > 0)) len = 1;
        n0 /= len; n1 /= len; n2 /= len;
        const dot = a0 * n0 + a1 * n1 + a2 * n2;
        const t0 = a0 - dot * n0, t1 = a1 - dot * n1, t2 = a2 - dot * n2;
        let tl = Math.sqrt(t0 * t0 + t1 * t1 + t2 * t2);
        if (!(tl > 0)) tl = 1;
        const i = 3 * (r * cols + c);
        normals[i] = n0; normals[i + 1] = n1; normals[i + 2] = n2;
        tangents[i] = t0 / tl; tangents[i + 1] = t1 / tl; tangents[i + 2] = t2 / tl;
      }
    }
  }
  async function decodeAnimation(entry) {
    const m = entry.manifest, V = m.vertex_count, n = 3 * V, [cols, rows] = m.grid;
    if (cols * rows !== V) throw new Error('baked loop ' + m.key + ': grid is not ' + V + ' vertices');
    const planes = await inflate(b64bytes(entry.payload));
    const q1 = new Int32Array(n), q2 = new Int32Array(n), cloth = new Float64Array(n);
    const positions = [], normals = [], tangents = [];
    for (let f = 0; f < m.frames; f++) {
      const base = f * 6 * V;
      const p = new Float32Array(n), nn = new Float32Array(n), tt = new Float32Array(n);
      for (let c = 0; c < 3; c++) {
        for (let v = 0; v < V; v++) {
          const j = c * V + v, i = 3 * v + c;  // plane index, vertex-major index
          const d = unzigzag(planes[base + j] | (planes[base + n + j] << 8));
          const q = (f === 0 ? d : f === 1 ? q1[i] + d : 2 * q1[i] - q2[i] + d) & 0xFFFF;
          q2[i] = q1[i]; q1[i] = q;
          cloth[i] = m.lo_m[c] + q * m.step_m;
          p[i] = cloth[i] + m.offset_m[c];
        }
      }
      gridFrames(cloth, cols, rows, nn, tt);
      positions.push(p); normals.push(nn); tangents.push(tt);
    }
    const indices = new Uint32Array((await inflate(b64bytes(entry.indices))).buffer);
    const uv = new Float32Array((await inflate(b64bytes(entry.uv))).buffer);
    return { manifest: m, frames: m.frames, fps: m.fps, positions, normals, tangents, indices, uv };
  }
  function animation(key) {
    if (!animations[key]) {
      animations[key] = loadScript('anim/' + key + '.js')
        .then(() => decodeAnimation(window.CATALOG_ANIMATIONS[key]));
    }
    return animations[key];
  }
  // The curtain at time t (frames, wrapping): exact baked frames at whole numbers, linear between.
  function curtainAt(anim, t) {
    const f = ((t % anim.frames) + anim.frames) % anim.frames, k0 = Math.floor(f), k1 = (k0 + 1) % anim.frames, w = f - k0;
    if (w === 0) return { position: anim.positions[k0], normal: anim.normals[k0], tangent: anim.tangents[k0] };
    const mix = (a, b) => { const o = new Float32Array(a.length); for (let i = 0; i < a.length; i++) o[i] = a[i] + w * (b[i] - a[i]); return o; };
    return { position: mix(anim.positions[k0], anim.positions[k1]), normal: mix(anim.normals[k0], anim.normals[k1]),
             tangent: mix(anim.tangents[k0], anim.tangents[k1]) };
  }

  // A texture's texels as the desktop gave them, float32 for float textures: quantised ones
  // (export.encode_texels: channel planes of 8 or 16 bits, each between its lo and hi)
  // rebuilt as export.decode_texels does; decoded once per texture (both panes share them).
  const texelCache = {};
  function decodeTexels(t) {
    const bytes = bin(t.data), q = t.quantised;
    if (!q) return t.dtype === 'f4' ? new Float32Array(bytes.buffer, bytes.byteOffset, bytes.byteLength / 4) : bytes;
    if (texelCache[t.data.binary]) return texelCache[t.data.binary];
    const ints = q.bits === 16 ? new Uint16Array(bytes.buffer, bytes.byteOffset, bytes.byteLength / 2) : bytes;
    const top = (1 << q.bits) - 1, C = t.components, N = ints.length / C, texels = new Float32Array(ints.length);
    for (let ch = 0; ch < C; ch++) {
      const lo = q.lo[ch], span = q.hi[ch] - q.lo[ch];  // the reference's order of operations
      for (let i = 0; i < N; i++) texels[i * C + ch] = lo + ints[ch * N + i] * span / top;
    }
    return (texelCache[t.data.binary] = texels);
  }

  // ---------------------------------------------------------------- the replayer
  const DEPTH_FUNCS = { '<': 'LESS', '<=': 'LEQUAL', '>': 'GREATER', '>=': 'GEQUAL', '==': 'EQUAL', '!=': 'NOTEQUAL' };

  class Replayer {
    constructor(canvas) {
      this.canvas = canvas;
      const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true, alpha: false, depth: false });
      if (!gl) throw new Error('this browser has no WebGL2');
      if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('WebGL2 without EXT_color_buffer_float: cannot render into float targets');
      this.gl = gl;
      this.floatLinear = !!gl.getExtension('OES_texture_float_linear');
      gl.getExtension('EXT_float_blend');  // blending into float targets (layered cloth)
      this.aniso = gl.getExtension('EXT_texture_filter_anisotropic');
      this.shaders = {}; this.programs = {}; this.buffers = {}; this.vaos = {}; this.targets = null;
      this.size = [0, 0]; this.curtainCount = 0; this.curtainAnim = null;
    }
    program(rid) {
      const gl = this.gl, index = D.programs[rid];
      if (this.shaders[index]) return this.shaders[index];
      const src = D.shaders[index];
      const compile = (type, text, file) => {
        const s = gl.createShader(type); gl.shaderSource(s, text); gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(file + ': ' + gl.getShaderInfoLog(s));
        return s;
      };
      const p = gl.createProgram();
      gl.attachShader(p, compile(gl.VERTEX_SHADER, src.vertex, src.files[0]));
      gl.attachShader(p, compile(gl.FRAGMENT_SHADER, src.fragment, src.files[1]));
      gl.linkProgram(p);
      if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(src.files.join('+') + ': ' + gl.getProgramInfoLog(p));
      const uniforms = {};
      for (let i = 0; i < gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS); i++) {
        const info = gl.getActiveUniform(p, i);
        uniforms[info.name.replace(/\[0\]$/, '')] = { loc: gl.getUniformLocation(p, info.name), type: info.type, size: info.size };
      }
      return (this.shaders[index] = { program: p, uniforms });
    }
    buffer(rid) {
      if (this.buffers[rid]) return this.buffers[rid];
      const gl = this.gl, desc = D.buffers[rid], b = gl.createBuffer();
      const target = desc.curtain === 'index' || desc.index ? gl.ELEMENT_ARRAY_BUFFER : gl.ARRAY_BUFFER;
      gl.bindBuffer(target, b);
      if (desc.data) { const bytes = bin(desc.data); gl.bufferData(target, bytes, gl.STATIC_DRAW); b.bytes = bytes.length; }
      b.curtain = desc.curtain; b.target = target;
      return (this.buffers[rid] = b);
    }
    setCurtain(anim, t) {
      const gl = this.gl, c = curtainAt(anim, t);
      for (const rid of Object.keys(D.buffers)) {
        const tag = D.buffers[rid].curtain;
        if (!tag) continue;
        const b = this.buffer(rid);
        const data = tag === 'index' ? anim.indices : tag === 'uv' ? anim.uv : c[tag];
        if (tag === 'index') gl.bindVertexArray(null);
        gl.bindBuffer(b.target, b);
        if (tag === 'index' || tag === 'uv') {
          if (this.curtainAnim === anim) continue;
          gl.bufferData(b.target, data, gl.STATIC_DRAW);
        } else if (b.bytes === data.byteLength) {
          gl.bufferSubData(b.target, 0, data);
        } else {
          gl.bufferData(b.target, data, gl.DYNAMIC_DRAW);
        }
        b.bytes = data.byteLength;
      }
      this.curtainAnim = anim; this.curtainCount = anim.indices.length;
    }
    vao(rid) {
      if (this.vaos[rid]) return this.vaos[rid];
      const gl = this.gl, desc = D.vertex_arrays[rid], prog = this.program(desc.program).program;
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      vao.count = 0; vao.indexed = desc.index_buffer != null; vao.content = [];
      for (const entry of desc.content) {
        const b = this.buffer(entry.buffer);
        gl.bindBuffer(gl.ARRAY_BUFFER, b);
        const tokens = entry.layout.trim().split(/\s+/), parts = [];
        let stride = 0;
        for (const tok of tokens) {  // moderngl formats: "3f", "3f 4x", "16x" ...
          const m = /^(\d*)(f4?|x)$/.exec(tok);
          if (!m) throw new Error('vertex format ' + entry.layout + ' is not supported');
          const n = m[1] ? +m[1] : 1;
          if (m[2] === 'x') { stride += n; continue; }
          parts.push({ n, offset: stride }); stride += 4 * n;
        }
        parts.forEach((part, i) => {
          const loc = gl.getAttribLocation(prog, entry.attributes[i]);
          if (loc < 0) return;
          gl.enableVertexAttribArray(loc);
          gl.vertexAttribPointer(loc, part.n, gl.FLOAT, false, stride, part.offset);
        });
        vao.content.push({ buffer: b, stride });
      }
      if (vao.indexed) { const ib = this.buffer(desc.index_buffer); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib); vao.indexBuffer = ib; }
      gl.bindVertexArray(null);
      return (this.vaos[rid] = vao);
    }
    // export.canvas_level: the canvas size halved k times, rounded up (the glare's targets)
    canvasAt(k) {
      let [w, h] = this.size;
      for (let i = 0; i < k; i++) { w = Math.max(1, Math.ceil(w / 2)); h = Math.max(1, Math.ceil(h / 2)); }
      return [w, h];
    }
    resize() {
      const gl = this.gl, w = this.canvas.width, h = this.canvas.height;
      const canvasAt = (k) => this.canvasAt(k);
      if (this.targets && this.size[0] === w && this.size[1] === h) return;
      for (const t of Object.values(this.targets || {})) (t.tex ? gl.deleteTexture(t.tex) : null, t.rb ? gl.deleteRenderbuffer(t.rb) : null, t.fbo ? gl.deleteFramebuffer(t.fbo) : null);
      this.size = [w, h];
      const sized = (t) => (t.canvas_level != null ? canvasAt(t.canvas_level) : t.size);
      const textures = {}, renderbuffers = {};
      for (const [rid, t] of Object.entries(D.textures)) {
        const tex = gl.createTexture(), s = sized(t);
        gl.bindTexture(gl.TEXTURE_2D, tex);
        if (t.dtype === 'depth') {  // a depth texture the frame draws (record.py), its compare func
          CatalogHost.depthTexture(gl, t, s, DEPTH_FUNCS);
          textures[rid] = { tex, depth: true };
          continue;
        }
        const half = t.dtype === 'f2', float = t.dtype === 'f4' || half, c = t.components - 1;
        if (t.data && half) throw new Error('half-float texels given by the frame: not replayed');
        const formats = [gl.RED, gl.RG, gl.RGB, gl.RGBA];
        const internal = half ? [gl.R16F, gl.RG16F, gl.RGB16F, gl.RGBA16F]
          : float ? [gl.R32F, gl.RG32F, gl.RGB32F, gl.RGBA32F] : [gl.R8, gl.RG8, gl.RGB8, gl.RGBA8];
        let texels = null;
        if (t.data) {  // a texture the frame filled (e.g. a pattern): its texels as recorded
          texels = decodeTexels(t);
        }
        gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
        const type = half ? gl.HALF_FLOAT : float ? gl.FLOAT : gl.UNSIGNED_BYTE;
        const level0 = texels && t.levels ? texels.subarray(0, s[0] * s[1] * t.components) : texels;
        gl.texImage2D(gl.TEXTURE_2D, 0, internal[c], s[0], s[1], 0, formats[c], type, level0);
        // float textures filter linearly only with OES_texture_float_linear
        const linearOk = !float || half || this.floatLinear;  // half floats always filter
        const pick = (f) => (linearOk ? f : (f === gl.LINEAR || f === gl.LINEAR_MIPMAP_LINEAR || f === gl.LINEAR_MIPMAP_NEAREST || f === gl.NEAREST_MIPMAP_LINEAR ? gl.NEAREST : f));
        const filter = t.filter || [gl.LINEAR, gl.LINEAR];
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, t.mipmaps ? pick(filter[0]) : pick(filter[0] === gl.LINEAR_MIPMAP_LINEAR ? gl.LINEAR : filter[0]));
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, pick(filter[1]));
        // moderngl's default is repeat (GL's); the frame says where it wants clamping
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, t.repeat_x === false ? gl.CLAMP_TO_EDGE : gl.REPEAT);
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, t.repeat_y === false ? gl.CLAMP_TO_EDGE : gl.REPEAT);
        if (t.mipmaps) gl.generateMipmap(gl.TEXTURE_2D);
        // the desktop's prefiltered levels 1..n (export.given_texels: after level 0, each
        // w >> k by h >> k) written over generateMipmap's box chain, as the desktop does
        for (let k = 1, at = s[0] * s[1] * t.components; k <= (t.levels || 0); k++) {
          const w = Math.max(1, s[0] >> k), h = Math.max(1, s[1] >> k), n = w * h * t.components;
          gl.texImage2D(gl.TEXTURE_2D, k, internal[c], w, h, 0, formats[c], type, texels.subarray(at, at + n));
          at += n;
        }
        if (t.anisotropy > 1 && this.aniso) {  // the desktop's anisotropic filter (record.py)
          gl.texParameterf(gl.TEXTURE_2D, this.aniso.TEXTURE_MAX_ANISOTROPY_EXT,
            Math.min(t.anisotropy, gl.getParameter(this.aniso.MAX_TEXTURE_MAX_ANISOTROPY_EXT)));
        }
        textures[rid] = { tex };
      }
      for (const [rid, r] of Object.entries(D.renderbuffers)) {
        const rb = gl.createRenderbuffer(), s = sized(r);
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb);
        gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, s[0], s[1]);
        renderbuffers[rid] = { rb };
      }
      const targets = { ...textures, ...renderbuffers };
      for (const [rid, f] of Object.entries(D.framebuffers)) {
        const fbo = gl.createFramebuffer();
        gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
        f.colour.forEach((t, i) => gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, textures[t].tex, 0));
        gl.drawBuffers(f.colour.map((_, i) => gl.COLOR_ATTACHMENT0 + i));
        if (f.depth != null && textures[f.depth]) gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.TEXTURE_2D, textures[f.depth].tex, 0);
        else if (f.depth != null) gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, renderbuffers[f.depth].rb);
        targets['fbo' + rid] = { fbo };
      }
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      this.targets = targets;
    }
    setUniform(u, value) {
      const gl = this.gl, v = Array.isArray(value) ? value : [value];
      switch (u.type) {
        case gl.FLOAT: gl.uniform1fv(u.loc, v); break;
        case gl.FLOAT_VEC2: gl.uniform2fv(u.loc, v); break;
        case gl.FLOAT_VEC3: gl.uniform3fv(u.loc, v); break;
        case gl.FLOAT_VEC4: gl.uniform4fv(u.loc, v); break;
        case gl.FLOAT_MAT2: gl.uniformMatrix2fv(u.loc, false, v); break;
        case gl.FLOAT_MAT3: gl.uniformMatrix3fv(u.loc, false, v); break;
        case gl.FLOAT_MAT4: gl.uniformMatrix4fv(u.loc, false, v); break;
        case gl.INT_VEC2: gl.uniform2iv(u.loc, v.map(Math.round)); break;
        case gl.INT_VEC3: gl.uniform3iv(u.loc, v.map(Math.round)); break;
        case gl.INT_VEC4: gl.uniform4iv(u.loc, v.map(Math.round)); break;
        // a sampler's unit, whatever it samples (the room's depth map from the key is a
        // sampler2DShadow: room_transport.frag)
        case gl.INT: case gl.BOOL: case gl.SAMPLER_2D: case gl.SAMPLER_2D_SHADOW: case gl.SAMPLER_3D:
        case gl.SAMPLER_CUBE: case gl.SAMPLER_2D_ARRAY: case gl.SAMPLER_2D_ARRAY_SHADOW:
        case gl.INT_SAMPLER_2D: case gl.UNSIGNED_INT_SAMPLER_2D: gl.uniform1iv(u.loc, v.map(Math.round)); break;
        default: throw new Error('uniform type ' + u.type + ' is not supported');
      }
    }
    // One frame of a scene: the recorded structure with the scene's values, our camera.
    render(scene, camera) {
      const gl = this.gl, structure = D.structures[scene.structure];
      this.resize();
      const [w, h] = this.size;
      const cam = cameraUniforms(camera, w / h);
      let screen = null;
      for (const c of structure) if (c.op === 'framebuffer') screen = c.framebuffer;
      let current = null, host = null;  // host: a host step the page ran itself (its recorded outputs skipped)
      for (const c of structure) {
        if (host !== null && c.op !== 'host_end') continue;
        switch (c.op) {
          case 'host':  // a host step (catalog/gl/host_step.py): run by host_steps.js where it knows it
            if (CatalogHost.run(c.name, c.inputs, this, scene)) { host = c.name; current = null; }
            break;
          case 'host_end': host = null; break;
          case 'texture_write': {  // texels a host step wrote this frame (record.py), on a spare unit
            const units = gl.getParameter(gl.MAX_COMBINED_TEXTURE_IMAGE_UNITS);
            gl.activeTexture(gl.TEXTURE0 + units - 1);
            gl.bindTexture(gl.TEXTURE_2D, this.targets[c.texture].tex);
            CatalogHost.writeTexture(gl, D.textures[c.texture], bin(D.blobs[value(scene, c.slot).blob]));
            break;
          }
          case 'framebuffer':  // moderngl's use(): the framebuffer's depth mask with it
            gl.bindFramebuffer(gl.FRAMEBUFFER, c.framebuffer === screen ? null : this.targets['fbo' + c.framebuffer].fbo);
            gl.depthMask(D.framebuffers[c.framebuffer].depth_mask !== false);
            break;
          case 'viewport':
            gl.viewport(...(c.canvas_level != null ? [0, 0, ...this.canvasAt(c.canvas_level)] : c.viewport)); break;
          case 'clear':
            gl.bindFramebuffer(gl.FRAMEBUFFER, c.framebuffer === screen ? null : this.targets['fbo' + c.framebuffer].fbo);
            gl.clearColor(...c.colour); gl.clearDepth(c.depth);
            gl.depthMask(D.framebuffers[c.framebuffer].depth_mask !== false);  // as moderngl's clear
            gl.clear(gl.COLOR_BUFFER_BIT | (D.framebuffers[c.framebuffer].depth != null ? gl.DEPTH_BUFFER_BIT : 0));
            break;
          case 'enable': for (const f of c.flags) gl.enable(gl[f]); break;
          case 'disable': for (const f of c.flags) gl.disable(gl[f]); break;
          case 'depth_func': gl.depthFunc(gl[DEPTH_FUNCS[c.func]]); break;
          case 'blend_equation': c.modes.length === 2 ? gl.blendEquationSeparate(...c.modes) : gl.blendEquation(c.modes[0]); break;
          case 'blend_func': c.factors.length === 4 ? gl.blendFuncSeparate(...c.factors) : gl.blendFunc(...c.factors); break;
          case 'texture':
            gl.activeTexture(gl.TEXTURE0 + c.unit); gl.bindTexture(gl.TEXTURE_2D, this.targets[c.texture].tex); break;
          case 'buffer_write': {  // bytes the frame wrote this frame (record.py)
            const b = this.buffer(c.buffer);
            gl.bindVertexArray(null); gl.bindBuffer(b.target, b);
            gl.bufferSubData(b.target, c.offset, bin(D.blobs[value(scene, c.slot).blob]));
            break;
          }
          case 'mipmaps': {  // a render target's mip chain built again (record.py), on a spare
            // unit (as moderngl does) so that no unit a later draw samples changes
            const units = gl.getParameter(gl.MAX_COMBINED_TEXTURE_IMAGE_UNITS);
            gl.activeTexture(gl.TEXTURE0 + units - 1);
            gl.bindTexture(gl.TEXTURE_2D, this.targets[c.texture].tex); gl.generateMipmap(gl.TEXTURE_2D); break;
          }
          case 'uniform': {
            const p = this.program(c.program);
            if (current !== p.program) { gl.useProgram(p.program); current = p.program; }
            const u = p.uniforms[c.name];
            if (!u) break;
            const which = c.camera ? D.camera_uniforms[c.name] : null;  // the frame's camera
            const canvas = c.canvas === 'texel' ? [1 / w, 1 / h] : c.canvas === 'size' ? [w, h] : null;
            this.setUniform(u, which ? cam[which] : canvas || value(scene, c.slot));
            break;
          }
          case 'draw': {
            const vao = this.vao(c.vertex_array), desc = D.vertex_arrays[c.vertex_array];
            const p = this.program(desc.program);
            if (current !== p.program) { gl.useProgram(p.program); current = p.program; }
            gl.bindVertexArray(vao);
            if (vao.indexed) {
              const count = c.vertices >= 0 ? c.vertices : (vao.indexBuffer.curtain ? this.curtainCount : vao.indexBuffer.bytes / 4);
              gl.drawElements(c.mode, count, gl.UNSIGNED_INT, 4 * (c.first || 0));
            } else {
              const count = c.vertices >= 0 ? c.vertices : vao.content[0].buffer.bytes / vao.content[0].stride - (c.first || 0);
              gl.drawArrays(c.mode, c.first || 0, count);
            }
            gl.bindVertexArray(null);
            break;
          }
          default: throw new Error('unknown recorded command ' + c.op);
        }
      }
    }
  }

  // ---------------------------------------------------------------- the app
  const $ = (id) => document.getElementById(id);
  const fabricByName = Object.fromEntries(D.fabrics.map((f) => [f.name, f]));
  const lamps = D.lights.filter((l) => l.kind === 'lamp');
  const suns = D.lights.filter((l) => l.kind === 'sun');
  const lim = D.camera.limits;
  const clamp = (x, r) => Math.min(r[1], Math.max(r[0], x));
  const state = {
    view: 'grid', fabric: D.fabrics[0].name, light: D.lights[0].id, fluorescence: 'on', compare: '',
    glare: 'on', lamp: 'none',  // `catalog snapshot`'s defaults: glare, no lamp
    yaw_deg: D.camera.yaw_deg, pitch_deg: D.camera.pitch_deg, distance_m: D.camera.distance_m,
    t: 0, playing: true, size: null,
  };
  const stats = { loadStartMs: performance.timeOrigin ? 0 : 0, firstFrameMs: null, frames: 0, errors: [],
                  panesDrawn: 0, contextsLost: 0 };
  let panes = null, dirty = true, lastTime = null, readyResolve, ready = new Promise((r) => (readyResolve = r));

  // export.scene_key: fabric, light and the three switches
  function sceneKey(fabric) { return [fabric, state.light, state.fluorescence, state.glare, state.lamp].join('|'); }
  function lightOf(id) { return D.lights.find((l) => l.id === id); }

  function buildGrid() {
    const ul = $('grid');
    for (const f of D.fabrics) {
      const li = document.createElement('li');
      li.className = 'card'; li.tabIndex = 0; li.dataset.fabric = f.name;
      li.setAttribute('role', 'button');
      li.innerHTML = '<img alt=""><h2></h2><p></p>';
      li.querySelector('img').src = 'data:image/png;base64,' + f.swatch;
      li.querySelector('img').alt = f.display_name + ' under D65, with a close-up of the cloth';
      li.querySelector('h2').textContent = f.display_name;
      li.querySelector('p').textContent = factsLine(f.facts);
      const open = () => set({ view: 'viewer', fabric: f.name });
      li.addEventListener('click', open);
      li.addEventListener('keydown', (e) => { if (e.key === 'Enter' || e.key === ' ') { e.preventDefault(); open(); } });
      ul.appendChild(li);
    }
  }
  // the desktop panel's words (catalog/presets/facts.py, exported by catalog/web/facts.py)
  function factsLine(x) { return x.line; }
  function buildControls() {
    const fab = $('fabric'), cmp = $('compare'), light = $('light');
    for (const f of D.fabrics) { fab.add(new Option(f.display_name, f.name)); cmp.add(new Option(f.display_name, f.name)); }
    for (const l of lamps) light.add(new Option(l.label, l.id));
    if (suns.length) light.add(new Option('Sun by hour', 'sun'));
    if (suns.length) { $('hour').min = suns[0].hour; $('hour').max = suns[suns.length - 1].hour; }
    fab.onchange = () => set({ fabric: fab.value });
    cmp.onchange = () => set({ compare: cmp.value });
    light.onchange = () => set({ light: light.value === 'sun' ? sunNearest(12).id : light.value });
    $('hour').oninput = () => set({ light: sunNearest(+$('hour').value).id });
    $('fluorescence').onchange = () => set({ fluorescence: $('fluorescence').checked ? 'on' : 'off' });
    $('glare').onchange = () => set({ glare: $('glare').checked ? 'on' : 'off' });
    for (const l of D.room_lamps) $('lamp').add(new Option(l.label || 'none', l.id));
    $('lamp').onchange = () => set({ lamp: $('lamp').value });
    $('play').onclick = () => set({ playing: !state.playing });
    $('back').onclick = () => set({ view: 'grid' });
    $('home').onclick = (e) => { e.preventDefault(); set({ view: 'grid' }); };
    $('reset-view').onclick = resetView;
  }
  function sunNearest(h) { return suns.reduce((a, b) => (Math.abs(b.hour - h) < Math.abs(a.hour - h) ? b : a)); }
  function resetView() { set({ yaw_deg: D.camera.yaw_deg, pitch_deg: D.camera.pitch_deg, distance_m: D.camera.distance_m }); }
  function cycleLight(step) {
    const ids = lamps.map((l) => l.id).concat(suns.length ? ['sun'] : []);
    const cur = lightOf(state.light).kind === 'sun' ? 'sun' : state.light;
    const next = ids[(ids.indexOf(cur) + step + ids.length) % ids.length];
    set({ light: next === 'sun' ? sunNearest(12).id : next });
  }
  function cycleFabric(step) {
    const i = D.fabrics.findIndex((f) => f.name === state.fabric);
    set({ fabric: D.fabrics[(i + step + D.fabrics.length) % D.fabrics.length].name });
  }

  function showFacts() {
    const f = fabricByName[state.fabric], dl = $('facts');
    const rows = [['Fabric', f.display_name + ' (' + f.name + ')'], ...f.facts.rows];
    const scene = D.scenes[sceneKey(state.fabric)];
    rows.push(['Light', lightOf(state.light).label + ' (' + Math.round(scene.illuminance_lx) + ' lx)']);
    rows.push(['Fluorescence', state.fluorescence === 'on' ? 'on (' + scene.fluorescence_variant + ')' : 'off']);
    dl.replaceChildren(...rows.flatMap(([k, v]) => { const dt = document.createElement('dt'), dd = document.createElement('dd'); dt.textContent = k; dd.textContent = v; return [dt, dd]; }));
  }

  function syncUI() {
    $('grid-view').hidden = state.view !== 'grid';
    $('viewer-view').hidden = state.view !== 'viewer';
    $('fabric').value = state.fabric;
    $('compare').value = state.compare;
    const l = lightOf(state.light);
    $('light').value = l.kind === 'sun' ? 'sun' : l.id;
    $('hour-label').hidden = l.kind !== 'sun';
    if (l.kind === 'sun') { $('hour').value = l.hour; $('hour-out').textContent = String(l.hour).padStart(2, '0') + ':00'; }
    $('fluorescence').checked = state.fluorescence === 'on';
    $('glare').checked = state.glare === 'on';
    $('lamp').value = state.lamp;
    $('play').textContent = state.playing ? 'Pause' : 'Play';
    $('pane-b').hidden = !state.compare;
    $('caption-a').textContent = fabricByName[state.fabric].display_name;
    $('caption-b').textContent = state.compare ? fabricByName[state.compare].display_name : '';
    showFacts();
  }
  let shownHash = null;  // the hash the page wrote last (its own writes are no change)
  function onHashChange() {
    if (location.hash === shownHash) return;
    const p = readHash();
    if (!('t' in p)) p.playing = true;
    set({ ...DEFAULTS, ...p });
  }
  function writeHash() {
    const h = new URLSearchParams({ view: state.view, fabric: state.fabric, light: state.light, fluorescence: state.fluorescence,
                                    glare: state.glare, lamp: state.lamp });
    if (state.compare) h.set('compare', state.compare);
    if (state.size) h.set('size', state.size[0] + 'x' + state.size[1]);
    const text = '#' + h.toString();
    if (text !== location.hash) history.replaceState(null, '', text);
    shownHash = location.hash;
  }
  const DEFAULTS = { view: 'grid', fabric: D.fabrics[0].name, light: D.lights[0].id, fluorescence: 'on',
                     glare: 'on', lamp: 'none', compare: '', size: null };
  function readHash() {
    const h = new URLSearchParams(location.hash.slice(1)), p = {};
    if (h.get('fabric') && fabricByName[h.get('fabric')]) p.fabric = h.get('fabric');
    if (h.get('light') && lightOf(h.get('light'))) p.light = h.get('light');
    if (h.get('fluorescence') === 'off') p.fluorescence = 'off';
    if (h.get('glare') === 'off') p.glare = 'off';
    if (h.get('lamp') && D.room_lamps.some((l) => l.id === h.get('lamp'))) p.lamp = h.get('lamp');
    if (h.get('compare') && fabricByName[h.get('compare')]) p.compare = h.get('compare');
    if (h.get('view') === 'viewer') p.view = 'viewer';
    if (h.get('frame') !== null) { p.t = +h.get('frame'); p.playing = false; }
    for (const k of ['yaw_deg', 'pitch_deg', 'distance_m']) if (h.get(k) !== null && isFinite(+h.get(k))) p[k] = +h.get(k);
    const size = /^(\d+)x(\d+)$/.exec(h.get('size') || '');
    if (size) p.size = [+size[1], +size[2]];
    return p;
  }

  function set(partial) {
    Object.assign(state, partial);
    state.yaw_deg = clamp(state.yaw_deg, lim.yaw_deg); state.pitch_deg = clamp(state.pitch_deg, lim.pitch_deg);
    state.distance_m = clamp(state.distance_m, lim.distance_m);
    if (state.compare === state.fabric) state.compare = '';
    syncUI(); writeHash(); dirty = true;
    if (state.view === 'viewer') ensurePanes();
  }

  // One replayer per canvas, made when the pane is first shown (again after a lost context);
  // input is installed once per canvas.
  const inputInstalled = new Set(), paneFailed = [false, false], paneLost = [false, false];
  function makePane(i) {
    const canvas = $(i === 0 ? 'canvas-a' : 'canvas-b');
    if (paneFailed[i] || paneLost[i]) return;
    try { panes[i] = new Replayer(canvas); } catch (e) { paneFailed[i] = true; fail(e); return; }
    if (!inputInstalled.has(canvas)) {
      inputInstalled.add(canvas); installInput(canvas);
      // a lost context (the GPU process reset, memory) shows black until it is made again
      canvas.addEventListener('webglcontextlost', (e) => { e.preventDefault(); panes[i] = null; paneLost[i] = true; stats.contextsLost++; });
      canvas.addEventListener('webglcontextrestored', () => { paneLost[i] = false; ensurePanes(); dirty = true; });
    }
  }
  function ensurePanes() {
    if (!panes) panes = [null, null];
    if (!panes[0]) makePane(0);
    if (state.compare && !panes[1]) makePane(1);
  }
  function fail(e) { stats.errors.push(String(e)); $('status').textContent = String(e.message || e); console.error(e); }

  // The canvas's size: the pane's width at 4:3, no taller than the window leaves below the
  // toolbar (with the caption under it), so the whole picture shows without scrolling.
  const ASPECT = 0.75, MIN_CANVAS_PX = 120;
  function canvasCssSize(canvas) {
    const pane = canvas.parentElement, caption = pane.querySelector('figcaption');
    const top = pane.getBoundingClientRect().top + window.scrollY;
    const room = window.innerHeight - top - (caption ? caption.offsetHeight : 0) - 8;
    const width = pane.clientWidth, height = Math.max(MIN_CANVAS_PX, Math.min(width * ASPECT, room));
    return [Math.floor(Math.min(width, height / ASPECT)), Math.floor(Math.min(width, height / ASPECT) * ASPECT)];
  }
  function sizeCanvas(canvas) {
    if (state.size) {
      canvas.width = state.size[0]; canvas.height = state.size[1];
      canvas.style.width = state.size[0] + 'px'; canvas.style.height = state.size[1] + 'px'; return;
    }
    const [cssW, cssH] = canvasCssSize(canvas), dpr = Math.min(window.devicePixelRatio || 1, 2);
    if (canvas.style.width !== cssW + 'px') canvas.style.width = cssW + 'px';
    if (canvas.style.height !== cssH + 'px') canvas.style.height = cssH + 'px';
    const w = Math.max(1, Math.round(cssW * dpr)), h = Math.max(1, Math.round(cssH * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  }

  // Every pane shown is drawn in the same frame or none is: each pane's cloth is asked for
  // before any is drawn, and a frame counts as drawn (settle, the first frame) only when every
  // shown pane has its replayer and its cloth; a pane still waiting keeps the page dirty.
  let pendingLoads = 0;
  function loadedAnimation(fabric) {
    const key = fabricByName[fabric].animation;
    if (!animations[key]) {
      pendingLoads++;
      animation(key).then((a) => { animations[key].done = true; animations[key].value = a; pendingLoads--; dirty = true; },
        (e) => { pendingLoads--; animations[key].failed = true; fail(e); });
    }
    return animations[key].done ? animations[key].value : null;
  }
  function drawPanes() {
    ensurePanes();
    const jobs = [[0, state.fabric]];
    if (state.compare) jobs.push([1, state.compare]);
    for (let k = jobs.length - 1; k >= 0; k--) if (paneFailed[jobs[k][0]]) jobs.splice(k, 1);  // said in the status line
    if (!jobs.length) return false;
    const loaded = jobs.map(([, fabric]) => loadedAnimation(fabric));
    if (loaded.some((a) => !a) || jobs.some(([i]) => !panes[i])) return false;
    jobs.forEach(([i, fabric], k) => {
      const pane = panes[i];
      sizeCanvas(pane.canvas);
      pane.setCurtain(loaded[k], state.t);
      pane.render(D.scenes[sceneKey(fabric)], state);
    });
    stats.panesDrawn = jobs.length;
    return true;
  }

  function frame(now) {
    requestAnimationFrame(frame);
    if (state.view !== 'viewer' || !panes) { lastTime = now; dirty = false; return; }
    const anim = animations[fabricByName[state.fabric].animation];
    if (state.playing && lastTime !== null && anim && anim.done) { state.t += (now - lastTime) / 1000 * anim.value.fps; dirty = true; }
    lastTime = now;
    if (!dirty) return;
    let drawn = false;
    try { drawn = drawPanes(); } catch (e) { fail(e); state.playing = false; }
    drawn.then ? drawn.then(done) : done(drawn);
  }
  function done(drawn) {
    if (!drawn) return;
    dirty = false; stats.frames++;
    if (stats.firstFrameMs === null) { stats.firstFrameMs = performance.now(); readyResolve(); }
    if (!state.playing) readyResolve();
  }

  // ---------------------------------------------------------------- input
  function installInput(canvas) {
    const pointers = new Map();
    let pinch = null;
    canvas.addEventListener('pointerdown', (e) => { canvas.setPointerCapture(e.pointerId); pointers.set(e.pointerId, [e.clientX, e.clientY]); canvas.focus(); });
    const up = (e) => { pointers.delete(e.pointerId); pinch = null; };
    canvas.addEventListener('pointerup', up); canvas.addEventListener('pointercancel', up);
    canvas.addEventListener('pointermove', (e) => {
      if (!pointers.has(e.pointerId)) return;
      const [x0, y0] = pointers.get(e.pointerId);
      pointers.set(e.pointerId, [e.clientX, e.clientY]);
      if (pointers.size === 1) {
        set({ yaw_deg: state.yaw_deg - (e.clientX - x0) * 0.3, pitch_deg: state.pitch_deg + (e.clientY - y0) * 0.3 });
      } else if (pointers.size === 2) {
        const [a, b] = [...pointers.values()], d = Math.hypot(a[0] - b[0], a[1] - b[1]);
        if (pinch) set({ distance_m: state.distance_m * pinch / d });
        pinch = d;
      }
    });
    canvas.addEventListener('wheel', (e) => { e.preventDefault(); set({ distance_m: state.distance_m * Math.exp(e.deltaY * 0.001) }); }, { passive: false });
  }
  function onKey(e) {
    if (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT') { if (e.key !== 'Escape') return; }
    if (state.view !== 'viewer') return;
    const k = e.key, hour = lightOf(state.light).hour;
    const actions = {
      ArrowLeft: () => set({ yaw_deg: state.yaw_deg - 5 }), ArrowRight: () => set({ yaw_deg: state.yaw_deg + 5 }),
      ArrowUp: () => set({ pitch_deg: state.pitch_deg + 5 }), ArrowDown: () => set({ pitch_deg: state.pitch_deg - 5 }),
      '+': () => set({ distance_m: state.distance_m / 1.1 }), '=': () => set({ distance_m: state.distance_m / 1.1 }),
      '-': () => set({ distance_m: state.distance_m * 1.1 }),
      l: () => cycleLight(1), L: () => cycleLight(-1),
      '[': () => suns.length && set({ light: sunNearest((hour ?? 13) - 1).id }), ']': () => suns.length && set({ light: sunNearest((hour ?? 11) + 1).id }),
      f: () => set({ fluorescence: state.fluorescence === 'on' ? 'off' : 'on' }),
      g: () => set({ glare: state.glare === 'on' ? 'off' : 'on' }),
      m: () => { const ids = D.room_lamps.map((l) => l.id); set({ lamp: ids[(ids.indexOf(state.lamp) + 1) % ids.length] }); },
      c: () => { const names = ['', ...D.fabrics.map((f) => f.name).filter((n) => n !== state.fabric)]; set({ compare: names[(names.indexOf(state.compare) + 1) % names.length] }); },
      n: () => cycleFabric(1), p: () => cycleFabric(-1), ' ': () => set({ playing: !state.playing }),
      r: resetView, Escape: () => set({ view: 'grid' }),
    };
    if (actions[k]) { e.preventDefault(); actions[k](); }
  }

  // ---------------------------------------------------------------- the room's transport pack
  // room_pack.js (catalog/room/web_pack.py), read after the grid is up and checked
  // (room_transport.js): a bad pack is refused in one line. The page does not apply it yet:
  // it draws the room under the constant light (docs/web.md, "The room").
  let roomPack = null;
  function loadRoomPack() {
    if (!D.room) return Promise.resolve(null);
    if (!roomPack) {
      roomPack = loadScript(D.room.pack)
        .then(() => CatalogRoom.load(window.CATALOG_ROOM_PACK, D.room.pack))
        .catch((e) => {
          const line = e instanceof CatalogRoom.PackError ? e.message : D.room.pack + ': ' + (e.message || e);
          stats.roomPackError = line; $('status').textContent = line; console.error(line);
          return null;
        });
    }
    return roomPack;
  }

  // ---------------------------------------------------------------- test and benchmark hooks
  // window.catalogApp: the browser tests and the benchmark drive the page through these.
  window.catalogApp = {
    state, stats, set,
    // the page's decoded data as float32 bytes in base64: a texture's texels, or a baked
    // frame's [positions, normals, tangents] (the tests compare them with the reference decoders)
    async decoded(kind, id, frame) {
      const b64 = (a) => {
        const u = new Uint8Array(a.buffer, a.byteOffset, a.byteLength);
        let s = '';
        for (let i = 0; i < u.length; i += 8192) s += String.fromCharCode.apply(null, u.subarray(i, i + 8192));
        return btoa(s);
      };
      if (kind === 'texels') return b64(decodeTexels(D.textures[id]));
      const a = await animation(id);
      return [a.positions[frame], a.normals[frame], a.tangents[frame]].map(b64);
    },
    // the room's pack (null: none, or refused: stats.roomPackError says why)
    roomPack: loadRoomPack,
    // resolves when the current state has been drawn (animations loaded)
    // (false at once when a frame failed since: a frame that throws is tried again each
    // animation frame and stays dirty, so waiting for it would wait for ever)
    settle() {
      const failed = stats.errors.length;
      return new Promise((resolve) => {
        const poll = () => (stats.errors.length > failed ? resolve(false)
          : !dirty && pendingLoads === 0 ? resolve(true) : setTimeout(poll, 20));
        dirty = true; poll();
      });
    },
    // median milliseconds of n frames drawn back to back (readPixels forces completion)
    benchmark(n) {
      // cpu_ms: until the frame's commands are issued (curtain interpolation and upload, the
      // replay); frame_ms: until its pixels can be read (readPixels waits for the rasteriser)
      const frame = [], cpu = [], px = new Uint8Array(4), gl = panes[0].gl;
      for (let i = 0; i < n; i++) {
        const t0 = performance.now();
        state.t += 1.0 / 3;  // a new interpolated curtain each frame, as when playing
        drawPanes();
        const t1 = performance.now();
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
        const t2 = performance.now();
        cpu.push(t1 - t0); frame.push(t2 - t0);
      }
      const median = (a) => { a.sort((x, y) => x - y); return a.length % 2 ? a[(a.length - 1) / 2] : (a[a.length / 2 - 1] + a[a.length / 2]) / 2; };
      return { frame_ms: median(frame.slice()), cpu_ms: median(cpu.slice()), frames: n,
               frame_samples_ms: frame, cpu_samples_ms: cpu,
               size: [panes[0].canvas.width, panes[0].canvas.height] };
    },
  };

  try {
    buildGrid(); buildControls();
    document.addEventListener('keydown', onKey);
    window.addEventListener('resize', () => (dirty = true));
    window.addEventListener('hashchange', onHashChange);
    set(readHash());
    stats.unpackMs = unpackMs; stats.gridReadyMs = performance.now();
    requestAnimationFrame(frame);
    loadRoomPack();
  } catch (e) { fail(e); }
  }
})();
