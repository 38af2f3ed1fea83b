// The page's host steps (catalog/gl/host_step.py): CPU work the desktop frame does between GL
// commands (read its views back, compute, upload), which replaying the recorded commands alone
// cannot do. The recording marks each with a 'host' command (its name, its inputs: the GL
// objects by recorded id, constants) and a 'host_end'; the commands between are the step's
// outputs as the desktop computed them for the recorded scene. CatalogHost.run(name, inputs,
// renderer, scene) runs a step the page knows and returns true (app.js then skips the recorded
// outputs); a step it does not know returns false and the desktop's outputs are replayed.
// Also the GL pieces of what host steps read and write: depth textures, in-frame texel writes.
(function () {
  const steps = {};
  // a step: fn(inputs, renderer, scene) -> true when it wrote the step's outputs itself
  function register(name, fn) { steps[name] = fn; }
  function run(name, inputs, renderer, scene) {
    const fn = steps[name];
    return fn ? fn(inputs, renderer, scene) === true : false;
  }
  // the texture bound at TEXTURE_2D made a depth texture of record.py's entry (size s)
  function depthTexture(gl, t, s, depthFuncs) {
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT24, s[0], s[1], 0, gl.DEPTH_COMPONENT, gl.UNSIGNED_INT, null);
    const filter = t.filter || [gl.NEAREST, gl.NEAREST];
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, filter[0]);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, filter[1]);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, t.repeat_x === false ? gl.CLAMP_TO_EDGE : gl.REPEAT);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, t.repeat_y === false ? gl.CLAMP_TO_EDGE : gl.REPEAT);
    if (t.compare_func) {  // sampled by a shadow sampler (moderngl's compare_func)
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, gl[depthFuncs[t.compare_func]]);
    }
  }
  // the whole of level 0 of the texture bound at TEXTURE_2D (record.py's entry t) from bytes
  function writeTexture(gl, t, bytes) {
    const formats = [gl.RED, gl.RG, gl.RGB, gl.RGBA], c = t.components - 1;
    if (t.dtype !== 'f4' && t.dtype !== 'f1') throw new Error('in-frame texels of dtype ' + t.dtype + ': not replayed');
    const own = bytes.byteOffset % 4 ? bytes.slice() : bytes;
    const texels = t.dtype === 'f4' ? new Float32Array(own.buffer, own.byteOffset, own.byteLength / 4) : bytes;
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, t.size[0], t.size[1], formats[c], t.dtype === 'f4' ? gl.FLOAT : gl.UNSIGNED_BYTE, texels);
  }
  window.CatalogHost = { register, run, depthTexture, writeTexture };
})();
