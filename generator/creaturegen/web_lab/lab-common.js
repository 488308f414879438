// Helpers every lab page shares: counters wrapped around the WebGPU API (so "nothing created after reveal"
// and "one draw per page" are measured at the device, not assumed) and base64 for binary readbacks.

/** Count GPUDevice object creations; returns the live counts object (wraps the prototype once). */
export function countDeviceCalls() {
  if (globalThis.__labDeviceCounts) return globalThis.__labDeviceCounts;
  const counts = {};
  for (const name of ['createBuffer', 'createTexture', 'createBindGroup', 'createComputePipeline',
    'createComputePipelineAsync', 'createRenderPipeline', 'createRenderPipelineAsync', 'createShaderModule']) {
    counts[name] = 0;
    const original = GPUDevice.prototype[name];
    GPUDevice.prototype[name] = function counted(...args) {
      counts[name] += 1;
      return original.apply(this, args);
    };
  }
  globalThis.__labDeviceCounts = counts;
  return counts;
}

/**
 * Count render passes and the indexed draws of one mesh (matched by its index count), each charged to the
 * pass encoder it was recorded on (three may begin one pass while another is open on a different command
 * encoder, e.g. the shadow map inside the main render). Returns { passes, perPass, instances, reset() };
 * set `bodyIndexCount` before drawing.
 */
export function countDraws() {
  if (globalThis.__labDraws) return globalThis.__labDraws;
  const draws = {
    passes: 0, perPass: [], instances: 0, passOf: new WeakMap(), bodyIndexCount: -1,
    reset() { this.passes = 0; this.perPass = []; this.instances = 0; this.passOf = new WeakMap(); },
  };
  const beginRenderPass = GPUCommandEncoder.prototype.beginRenderPass;
  GPUCommandEncoder.prototype.beginRenderPass = function counted(...args) {
    const pass = beginRenderPass.apply(this, args);
    draws.passOf.set(pass, draws.perPass.length);
    draws.passes += 1;
    draws.perPass.push(0);
    return pass;
  };
  const drawIndexed = GPURenderPassEncoder.prototype.drawIndexed;
  GPURenderPassEncoder.prototype.drawIndexed = function counted(indexCount, instanceCount = 1, ...rest) {
    const index = draws.passOf.get(this);
    if (indexCount === draws.bodyIndexCount && index !== undefined && index < draws.perPass.length) {
      draws.perPass[index] += 1;
      draws.instances += instanceCount;
    }
    return drawIndexed.call(this, indexCount, instanceCount, ...rest);
  };
  globalThis.__labDraws = draws;
  return draws;
}

export function toBase64(bytes) {
  let text = '';
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(text);
}

export function fromBase64(text) {
  const bin = atob(text);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return bytes;
}

/** Calls `callback` whenever the device-pixel ratio changes (a window moved to another screen, zoom):
 * a media query on the current ratio fires once, so it is re-armed on every change. */
export function watchPixelRatio(callback) {
  let query = null;
  const arm = () => {
    query?.removeEventListener('change', changed);
    query = window.matchMedia(`(resolution: ${window.devicePixelRatio}dppx)`);
    query.addEventListener('change', changed);
  };
  function changed() { arm(); callback(); }
  arm();
}

/**
 * The demos' animation loop: `draw(ms)` once per animation frame with at most two frames queued on the GPU
 * (a slow adapter, a software one or a busy laptop, skips a vsync rather than fall further behind; the
 * next draw covers the longer interval), `window.__lab.ready` once `readyAfter` frames have finished on
 * the GPU, and a throw stops the loop and goes to `onError`. Returns the frame counter.
 */
export function runPacedLoop(renderer, draw, onError, readyAfter = 3) {
  const device = renderer.backend.device;
  let inFlight = 0;
  let frames = 0;
  let marked = false;
  renderer.setAnimationLoop((ms) => {
    if (inFlight >= 2) return;
    inFlight += 1;
    try {
      draw(ms);
    } catch (error) {
      renderer.setAnimationLoop(null);
      onError(error);
      return;
    }
    frames += 1;
    const done = device.queue.onSubmittedWorkDone().then(() => { inFlight -= 1; });
    if (frames >= readyAfter && !marked) {
      marked = true;
      done.then(() => { window.__lab.ready = true; });
    }
  });
  return { frames: () => frames };
}
