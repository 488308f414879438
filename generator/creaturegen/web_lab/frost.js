// Frost lab page: loads a built frost package from /out/<slug>/ and exposes window.__lab for the
// Playwright harness. Paused and deterministic by default: time only moves through step()/advance(),
// whose instants the caller chooses. play() runs the rAF loop (instants: the rAF timestamp / 1000, the
// clock of the package's attachPointer, which wires the canvas); tests/test_frost_pointer.py drags a real
// mouse over it with uneven frame times (play({ stallMs })) and replays the recorded log in numpy.
import * as THREE from 'three/webgpu';
import { Fn, float, floor, mix, mod, uv, vec3 } from 'three/tsl';
import { countDeviceCalls, toBase64 } from './lab-common.js';

const params = new URLSearchParams(location.search);
const slug = params.get('pkg');
const width = Number(params.get('w') ?? 256);
const height = Number(params.get('h') ?? 160);
// Where the package's assets are fetched from when not beside it (the package's assetBase option).
const assetBase = params.get('assetBase') ?? undefined;
// binning=0: the effect's unbinned baseline (bench/frost_strokes.py times both).
const binning = params.get('binning') !== '0';
const out = document.getElementById('out');

// Count what the device creates, so "nothing created after reveal" is measured, not assumed.
const deviceCounts = countDeviceCalls();

function labScene() {
  // A deterministic, high-contrast backdrop so blur and refraction are visible in a readback.
  const scene = new THREE.Scene();
  const material = new THREE.MeshBasicNodeMaterial();
  material.colorNode = Fn(() => {
    const p = uv();
    const cell = mod(floor(p.x.mul(10)).add(floor(p.y.mul(6))), 2);
    const warm = vec3(0.9, 0.35, 0.08);
    const cool = vec3(0.05, 0.25, 0.7);
    return mix(mix(warm, cool, p.x), vec3(0.95), cell.mul(float(0.6)));
  })();
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material);
  scene.add(plane);
  const disc = new THREE.Mesh(new THREE.CircleGeometry(0.35, 48), new THREE.MeshBasicNodeMaterial({ color: 0x20c040 }));
  disc.position.set(0.3, -0.1, 0.1);
  scene.add(disc);
  const camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0.1, 10);
  camera.position.z = 2;
  return { scene, camera };
}

async function main() {
  if (!slug) throw new Error('frost lab: add ?pkg=<slug> (a folder of out/)');
  const errors = [];
  const canvas = document.getElementById('canvas');
  const renderer = new THREE.WebGPURenderer({ canvas, antialias: false });
  renderer.onError = (info) => errors.push(`${info.api} ${info.type}: ${info.message}`);
  renderer.setPixelRatio(1);
  renderer.setSize(width, height, true);
  await renderer.init();
  if (renderer.backend.isWebGPUBackend !== true) throw new Error('frost lab: three fell back to WebGL2; WebGPU is required');
  const pkg = await import(`/out/${slug}/index.js`);
  const { scene, camera } = labScene();
  const effect = await pkg.createFrostEffect(renderer, scene, camera, { assetBase, binning });
  const device = renderer.backend.device;

  let clock = 0;
  let playing = false;
  let lastInstant = null;
  let recording = false;
  let pointerLog = [];
  let stalls = []; // ms of busy work per played frame, cycled: uneven frame times on purpose
  let frameIndex = 0;

  function update(previous, current) {
    const report = effect.update(previous, current);
    if (recording) pointerLog.push({ kind: 'update', previous, current, report });
    return report;
  }

  function render() {
    effect.render();
  }

  // Render once and warm every pipeline (all views share one material: the view is a uniform).
  render();
  await device.queue.onSubmittedWorkDone();
  const revealCounts = { ...deviceCounts };

  // One capture target, reused: a fresh RenderTarget per capture would build fresh pipelines.
  let captureTarget = null;
  async function capturePixels(view = 'final') {
    const previous = effect.debugView;
    effect.setDebugView(view);
    const size = new THREE.Vector2();
    renderer.getDrawingBufferSize(size);
    if (!captureTarget || captureTarget.width !== size.x || captureTarget.height !== size.y) {
      captureTarget?.dispose();
      captureTarget = new THREE.RenderTarget(size.x, size.y, { depthBuffer: false });
    }
    renderer.setRenderTarget(captureTarget);
    render();
    renderer.setRenderTarget(null);
    const padded = await renderer.readRenderTargetPixelsAsync(captureTarget, 0, 0, size.x, size.y);
    effect.setDebugView(previous);
    const rowBytes = Math.ceil((size.x * 4) / 256) * 256;
    const rgba = new Uint8Array(size.x * size.y * 4);
    for (let y = 0; y < size.y; y++) rgba.set(padded.subarray(y * rowBytes, y * rowBytes + size.x * 4), y * size.x * 4);
    return { width: size.x, height: size.y, view, rgba: toBase64(rgba) };
  }

  const lab = {
    ready: true,
    error: null,
    package: slug,
    plan: pkg.PLAN,
    errors,
    info() {
      const info = device.adapterInfo ?? {};
      return {
        isWebGPUBackend: renderer.backend.isWebGPUBackend === true,
        adapter: { architecture: info.architecture ?? null, vendor: info.vendor ?? null, description: info.description ?? null },
        limits: { maxStorageTexturesPerShaderStage: device.limits.maxStorageTexturesPerShaderStage, maxStorageBuffersPerShaderStage: device.limits.maxStorageBuffersPerShaderStage, maxTextureDimension2D: device.limits.maxTextureDimension2D },
        features: [...device.features].sort(),
        tier: effect.tier,
        format: effect.format,
        historySize: effect.historySize,
        canvas: [width, height],
        debugViews: pkg.DEBUG_VIEWS,
        refraction: pkg.PLAN.refraction ?? null,
        memory: effect.memory(),
        effectKeys: Object.keys(effect).sort(),
      };
    },
    queuePointerSegment(segment) { effect.pointer(segment); },
    queuePointerSegments(segments) { segments.forEach((s) => effect.pointer(s)); return segments.length; },
    update(previous, current) { return update(previous, current); },
    step(dt, { render: draw = true } = {}) {
      const report = update(clock, clock + dt);
      clock += dt;
      if (draw) render();
      return report;
    },
    advance(instants) {
      const reports = [];
      for (let i = 0; i + 1 < instants.length; i++) reports.push(update(instants[i], instants[i + 1]));
      clock = instants[instants.length - 1] ?? clock;
      return reports;
    },
    resetHistory() { effect.reset(); clock = 0; },
    async readStructure() {
      const s = await effect.readStructure();
      return { resolution: s.resolution, structure: toBase64(s.structure), normals: toBase64(s.normals) };
    },
    async readHistory() {
      const h = await effect.readHistory();
      return { width: h.width, height: h.height, data: Array.from(h.data) };
    },
    setDebugView(name) { effect.setDebugView(name); },
    setControl(name, value) { effect.setControl(name, value); },
    setTier(name) { effect.setTier(name); return effect.historySize; },
    resize(w, h, dpr = 1) {
      renderer.setPixelRatio(dpr);
      renderer.setSize(w, h, true);
      const remapped = effect.resize(w, h, dpr);
      return { remapped, historySize: effect.historySize };
    },
    capturePixels,
    render,
    async finish() { await device.queue.onSubmittedWorkDone(); return errors.length; },
    counters() {
      const after = {};
      for (const [k, v] of Object.entries(deviceCounts)) after[k] = v - revealCounts[k];
      return { effect: structuredClone(effect.counters), device: { ...deviceCounts }, sinceReveal: after };
    },
    memory() { return effect.memory(); },
    async timeFrames(instants, { draw = false } = {}) {
      // Bench helper: wall time of GPU-complete frames (lab code, not shipped runtime).
      await device.queue.onSubmittedWorkDone();
      const start = performance.now();
      for (let i = 0; i + 1 < instants.length; i++) {
        effect.update(instants[i], instants[i + 1]);
        if (draw) render();
      }
      await device.queue.onSubmittedWorkDone();
      return performance.now() - start;
    },
    // Bench helper: each frame's update to GPU completion, in ms (p50/p95 need the frames one by one).
    async timeFramesEach(instants) {
      const ms = [];
      for (let i = 0; i + 1 < instants.length; i++) {
        await device.queue.onSubmittedWorkDone();
        const start = performance.now();
        effect.update(instants[i], instants[i + 1]);
        await device.queue.onSubmittedWorkDone();
        ms.push(performance.now() - start);
      }
      return ms;
    },
    // bench helpers. three advances its node frame once per requestAnimationFrame tick, and the scene pass
    // and the blur run once per node frame, so renders back to back in one task (timeFrames) redo only the
    // composite. timeAnimationFrames runs one frame per tick, as an app's loop does, and sums each frame's
    // ms from its update to its GPU completion (the wait for the tick is not counted).
    async timeAnimationFrames(instants, { draw = true } = {}) {
      let total = 0;
      for (let i = 0; i + 1 < instants.length; i++) {
        await new Promise((resolve) => requestAnimationFrame(resolve));
        const start = performance.now();
        effect.update(instants[i], instants[i + 1]);
        if (draw) render();
        await device.queue.onSubmittedWorkDone();
        total += performance.now() - start;
      }
      return total;
    },
    // The effect's blur node, found by wrapping its class's updateBefore for one render (lab code; the
    // package is not modified); sets only that node's resolution scale, as setTier does (setTier puts the
    // tier's scale back). The second render, a tick later, resizes the blur's two targets.
    async setBlurScale(scale) {
      const { SeparableBlurNode } = await import(`/out/${slug}/tsl/separable-blur.js`);
      const proto = SeparableBlurNode.prototype;
      const original = proto.updateBefore;
      let node = null;
      proto.updateBefore = function captured(frame) { node = this; return original.call(this, frame); };
      await new Promise((resolve) => requestAnimationFrame(resolve));
      try { render(); } finally { proto.updateBefore = original; }
      if (node === null) throw new Error('frost lab: the blur node did not run during render()');
      const previous = node.resolutionScale;
      node.resolutionScale = scale;
      await new Promise((resolve) => requestAnimationFrame(resolve));
      render();
      await device.queue.onSubmittedWorkDone();
      return { previous, scale, size: [...node.size] };
    },
    play({ stallMs = [] } = {}) { stalls = stallMs; frameIndex = 0; playing = true; lastInstant = null; requestAnimationFrame(loop); },
    pause() { playing = false; },
    get playing() { return playing; },
    get playedFrames() { return frameIndex; },
    // The pointer log: segments attachPointer queued, updates (instants and reports) and press instants.
    startRecording() { pointerLog = []; recording = true; },
    stopRecording() { recording = false; return pointerLog; },
  };

  function loop(ms) {
    if (!playing) return;
    const now = ms / 1000;
    if (lastInstant !== null) update(lastInstant, now);
    lastInstant = now;
    render();
    const stall = stalls.length > 0 ? stalls[frameIndex % stalls.length] : 0;
    frameIndex += 1;
    if (stall > 0) { const until = performance.now() + stall; while (performance.now() < until) { /* lab: uneven frames */ } }
    requestAnimationFrame(loop);
  }

  // Real pointer input through the package's own attachPointer (instants: event.timeStamp / 1000, the
  // clock of the rAF loop above). While recording, every accepted segment and every update is logged in
  // order, with the pointerdown/pointerup instants, so numpy can replay exactly what the effect received.
  effect.attachPointer(canvas, {
    onSegment(segment) { if (recording) pointerLog.push({ kind: 'segment', segment }); },
  });
  const pressInstants = (event) => { if (recording) pointerLog.push({ kind: event.type, t: event.timeStamp / 1000 }); };
  canvas.addEventListener('pointerdown', pressInstants);
  canvas.addEventListener('pointerup', pressInstants);
  document.getElementById('play').onclick = () => (playing ? lab.pause() : lab.play());
  document.getElementById('step').onclick = () => lab.step(1 / 60);
  document.getElementById('reset').onclick = () => { lab.resetHistory(); render(); };
  const viewSelect = document.getElementById('view');
  for (const v of pkg.DEBUG_VIEWS) viewSelect.add(new Option(v, v));
  viewSelect.onchange = () => { lab.setDebugView(viewSelect.value); render(); };
  const tierSelect = document.getElementById('tier');
  for (const t of Object.keys(pkg.PLAN.tiers)) tierSelect.add(new Option(t, t, false, t === effect.tier));
  tierSelect.onchange = () => { lab.setTier(tierSelect.value); render(); };
  return lab;
}

main().then(
  (lab) => {
    window.__lab = lab;
    out.textContent = JSON.stringify(lab.info(), null, 2);
  },
  (err) => {
    const message = err && err.stack ? String(err.stack) : String(err);
    window.__lab = { ready: true, error: message };
    out.textContent = `error: ${message}`;
  },
);
