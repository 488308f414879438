// Creature lab page: loads a built creature package from /out/<slug>/ and exposes window.__lab for the
// Playwright harness. Paused and deterministic by default: the pose moves only through seekTick/stepTicks.
// Every GPU number it reports is read back from the device (buffers or render targets).
import * as THREE from 'three/webgpu';
import { countDeviceCalls, countDraws, fromBase64, toBase64 } from './lab-common.js';

const params = new URLSearchParams(location.search);
const slug = params.get('pkg');
const width = Number(params.get('w') ?? 192);
const height = Number(params.get('h') ?? 144);
const capacity = Number(params.get('capacity') ?? 64);
const pageSize = Number(params.get('pageSize') ?? 64);
const out = document.getElementById('out');

// Count what the device creates, so "nothing created after reveal" is measured, not assumed.
const deviceCounts = countDeviceCalls();
// Body draw calls per render pass, counted at the encoders: "one draw per page" is measured.
const draws = countDraws();

async function main() {
  if (!slug) throw new Error('creature lab: add ?pkg=<slug> (a folder of out/)');
  const errors = [];
  const canvas = document.getElementById('canvas');
  const renderer = new THREE.WebGPURenderer({ canvas, antialias: false });
  renderer.onError = (info) => errors.push(`${info.api} ${info.type}: ${info.message}`);
  renderer.setPixelRatio(1);
  renderer.setSize(width, height, true);
  renderer.shadowMap.enabled = true;
  await renderer.init();
  if (renderer.backend.isWebGPUBackend !== true) throw new Error('creature lab: three fell back to WebGL2; WebGPU is required');
  const device = renderer.backend.device;
  const pkg = await import(`/out/${slug}/index.js`);
  const data = pkg.CREATURE;
  const L = data.bodyScale;
  draws.bodyIndexCount = 3 * data.mesh.triangles;

  // Scene: a ground plane that receives shadows, a shadow-casting sun straight above, a soft fill.
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1d2430);
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(40 * L, 40 * L), new THREE.MeshStandardNodeMaterial({ color: 0x9aa3ad, roughness: 0.9 }));
  ground.rotation.x = -Math.PI / 2;
  ground.receiveShadow = true;
  scene.add(ground);
  scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x404040, 1.2));
  const sun = new THREE.DirectionalLight(0xffffff, 2.0);
  sun.position.set(0, 4 * L, 0);
  sun.castShadow = true;
  sun.shadow.mapSize.set(256, 256);
  const half = 1.5 * L;
  Object.assign(sun.shadow.camera, { left: -half, right: half, top: half, bottom: -half, near: 0.1 * L, far: 8 * L });
  sun.shadow.camera.updateProjectionMatrix();
  scene.add(sun);
  scene.add(sun.target);
  const camera = new THREE.PerspectiveCamera(35, width / height, 0.05 * L, 100 * L);
  camera.position.set(1.6 * L, 1.1 * L, 2.2 * L);
  camera.lookAt(0, 0.3 * L, 0);

  const pop = await pkg.createCreaturePopulation(renderer, { capacity, pageSize });
  scene.add(pop.object3d);
  const diag = pkg.createDiagnostics(renderer, pop);
  // Lift the body so its lowest posed point rests on the ground.
  const restMinY = Math.min(...data.slots.map((r) => Math.min(r[1] - r[3], r[5] - r[7])));
  const lift = -restMinY;
  pop.spawn({ seed: Number(params.get('seed') ?? 1), position: [0, lift, 0] });
  pop.flush();

  function render() { renderer.render(scene, camera); }

  const t0 = performance.now();
  await pop.warm(scene, camera);
  render();
  await device.queue.onSubmittedWorkDone();
  const bootMs = performance.now() - t0;
  const revealCounts = { ...deviceCounts };

  // Capture targets, reused: a fresh RenderTarget per capture would build fresh textures.
  const targets = new Map();
  function targetFor(w, h) {
    const key = `${w}x${h}`;
    if (!targets.has(key)) targets.set(key, new THREE.RenderTarget(w, h, { depthBuffer: true }));
    return targets.get(key);
  }
  async function readTarget(target, w, h) {
    const padded = await renderer.readRenderTargetPixelsAsync(target, 0, 0, w, h);
    const rowBytes = Math.ceil((w * 4) / 256) * 256;
    const rgba = new Uint8Array(w * h * 4);
    for (let y = 0; y < h; y++) rgba.set(padded.subarray(y * rowBytes, y * rowBytes + w * 4), y * w * 4);
    return rgba;
  }
  async function renderTo(cam, w, h) {
    const target = targetFor(w, h);
    renderer.setRenderTarget(target);
    renderer.render(scene, cam);
    renderer.setRenderTarget(null);
    return readTarget(target, w, h);
  }

  // Silhouette vs shadow footprint, both seen from the sun's own orthographic camera:
  // (1) the body alone, flat white on black: its silhouette from the light;
  // (2) the body hidden from the camera (layer 1, which only the shadow camera sees), the ground lit:
  //     the dark footprint on the ground is the shadow map's coverage of the same position function.
  const silhouetteMaterial = new THREE.MeshBasicNodeMaterial({ color: 0xffffff });
  async function shadowParity(size = 128) {
    const cam = sun.shadow.camera.clone();
    cam.position.copy(sun.position);
    cam.lookAt(sun.target.position);
    cam.updateMatrixWorld();
    const savedBackground = scene.background;
    // (1) silhouette: only the body, unlit white, background black.
    scene.background = new THREE.Color(0x000000);
    ground.visible = false;
    const materials = pop.pages.map((p) => p.mesh.material);
    // The silhouette must use the same positionNode: reuse each page material, colour forced white.
    const savedColour = materials.map((m) => m.colorNode);
    const savedEmissive = materials.map((m) => m.emissiveNode);
    materials.forEach((m) => { m.emissiveNode = THREE.TSL.vec3(1, 1, 1); m.colorNode = THREE.TSL.vec3(0, 0, 0); m.needsUpdate = true; });
    const lightsVisible = [sun.intensity];
    sun.intensity = 0;
    const hemi = scene.children.find((c) => c.isHemisphereLight);
    const hemiIntensity = hemi.intensity;
    hemi.intensity = 0;
    const silhouette = await renderTo(cam, size, size);
    materials.forEach((m, i) => { m.emissiveNode = savedEmissive[i]; m.colorNode = savedColour[i]; m.needsUpdate = true; });
    sun.intensity = lightsVisible[0];
    hemi.intensity = hemiIntensity;
    // (2) footprint: ground only for the camera, body only in the shadow pass (layer 1).
    ground.visible = true;
    scene.background = savedBackground;
    for (const p of pop.pages) p.mesh.layers.set(1);
    sun.shadow.camera.layers.enable(1);
    hemi.intensity = 0;
    const lit = await renderTo(cam, size, size);
    hemi.intensity = hemiIntensity;
    for (const p of pop.pages) p.mesh.layers.set(0);
    sun.shadow.camera.layers.disable(1);
    return { size, silhouette: toBase64(silhouette), footprint: toBase64(lit) };
  }

  async function capturePixels(view = 'front') {
    if (view === 'front') return { view, width, height, rgba: toBase64(await renderTo(camera, width, height)) };
    if (view === 'portrait') {
      // Three-quarter view framing body 0's posed bounds (the package README's picture).
      const b = pop.instance(0).bounds;
      const centre = new THREE.Vector3((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2);
      const radius = 0.5 * Math.hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]);
      const cam = camera.clone();
      const distance = 1.15 * radius / Math.sin(THREE.MathUtils.degToRad(cam.fov / 2));
      cam.position.copy(centre).add(new THREE.Vector3(0.62, 0.42, 0.66).normalize().multiplyScalar(distance));
      cam.near = 0.01 * distance;
      cam.far = 10 * distance;
      cam.lookAt(centre);
      cam.updateProjectionMatrix();
      cam.updateMatrixWorld();
      return { view, width, height, rgba: toBase64(await renderTo(cam, width, height)) };
    }
    if (view === 'top') {
      const cam = sun.shadow.camera.clone();
      cam.position.copy(sun.position); cam.lookAt(0, 0, 0); cam.updateMatrixWorld();
      return { view, width: 128, height: 128, rgba: toBase64(await renderTo(cam, 128, 128)) };
    }
    throw new Error(`capturePixels: view is front, portrait or top (got ${view})`);
  }

  const spawnTimes = [];
  const lab = {
    ready: true,
    error: null,
    package: slug,
    errors,
    bootMs,
    info() {
      const info = device.adapterInfo ?? {};
      return {
        isWebGPUBackend: renderer.backend.isWebGPUBackend === true,
        adapter: { architecture: info.architecture ?? null, vendor: info.vendor ?? null, description: info.description ?? null },
        limits: { maxStorageBuffersPerShaderStage: device.limits.maxStorageBuffersPerShaderStage, maxStorageBufferBindingSize: device.limits.maxStorageBufferBindingSize },
        features: [...device.features].sort(),
        tier: data.tier, slots: data.slotCount, registers: data.registers, programs: data.programCount,
        vertices: data.mesh.vertices, triangles: data.mesh.triangles, capacity, pageSize: pop.pageSize, pages: pop.pages.length,
        signatures: data.signatures, bodyScale: L, canvas: [width, height], lift,
      };
    },
    async load(next) { location.search = `?pkg=${encodeURIComponent(next)}`; },
    seekTick(n) { const bytes = pop.seekTick(n); render(); return bytes; },
    stepTicks(n = 1) { let bytes = 0; for (let k = 0; k < n; k++) bytes += pop.stepTicks(1); render(); return bytes; },
    stateHash() { return pop.stateHash(); },
    telemetry() {
      return {
        tick: pop.tick, count: pop.count, debugMode: pop.debugMode, stats: { ...pop.stats },
        pagesInUse: pop.pages.filter((p) => p.mesh.count > 0).length, pages: pop.pages.length,
        instances: Array.from({ length: pop.count }, (_, i) => pop.instance(i)),
        variantKeys: pop.variantKeys(), errors: errors.length,
      };
    },
    setTier(t) { pop.setTier(t); return t; },
    setDebugMode(m) { pop.setDebugMode(m); render(); return m; },
    spawn(seed, count = 1, spacing = 1.5, draw = true) {
      const ids = [];
      const side = Math.ceil(Math.sqrt(count));
      for (let i = 0; i < count; i++) {
        const position = [((i % side) - (side - 1) / 2) * spacing * L, lift, (Math.floor(i / side) - (side - 1) / 2) * spacing * L];
        const start = performance.now();
        ids.push(pop.spawn({ seed: (seed + i) >>> 0, position }));
        spawnTimes.push(performance.now() - start);
      }
      pop.flush();
      if (draw) render();
      return ids;
    },
    despawnAll(keep = []) {
      for (let i = 0; i < pop.capacity; i++) if (pop.instance(i).alive && !keep.includes(i)) pop.despawn(i);
      pop.flush();
      render();
    },
    async probeField(points, id = 0, program = data.fullProgram) {
      const r = await diag.probeField(id, Float32Array.from(points), program);
      return Array.from(r);
    },
    async readPose(i = 0) { return Array.from(await diag.readPose(i)); },
    stagedPose(i = 0) { return Array.from(pop.stagedPose(i)); },
    async readSkinned(i = 0) {
      const r = await diag.readSkinned(i);
      return { skinned: toBase64(new Uint8Array(r.skinned.buffer)), corrected: toBase64(new Uint8Array(r.corrected.buffer)),
        accepted: toBase64(new Uint8Array(r.accepted.buffer)), gradient: toBase64(new Uint8Array(r.gradient.buffer)),
        distance: toBase64(new Uint8Array(r.distance.buffer)) };
    },
    /** What the display and shadow passes draw (the page's deform storage), read back. */
    async readDeformed(i = 0) {
      const r = await diag.readDeformed(i);
      return { position: toBase64(new Uint8Array(r.position.buffer)), gradient: toBase64(new Uint8Array(r.gradient.buffer)),
        distance: toBase64(new Uint8Array(r.distance.buffer)), accepted: toBase64(new Uint8Array(r.accepted.buffer)) };
    },
    capturePixels,
    shadowParity,
    render,
    async finish() { await device.queue.onSubmittedWorkDone(); return errors.length; },
    counters() {
      const after = {};
      for (const [k, v] of Object.entries(deviceCounts)) after[k] = v - revealCounts[k];
      return { device: { ...deviceCounts }, sinceReveal: after };
    },
    resetCounters() { Object.assign(revealCounts, deviceCounts); draws.reset(); },
    /** Render passes and body draw calls per pass since the last resetCounters(), counted at the encoders. */
    draws() { return { passes: draws.passes, perPass: [...draws.perPass], instances: draws.instances }; },
    spawnCost() {
      const sorted = [...spawnTimes].sort((a, b) => a - b);
      return { samples: sorted.length, medianMs: sorted.length ? sorted[Math.floor(sorted.length / 2)] : null, maxMs: sorted.at(-1) ?? null };
    },
    fromBase64,
  };
  window.__lab = lab;
  wireControls(lab, pkg.DEBUG_MODES);
  out.textContent = JSON.stringify(lab.info(), null, 2);
}

function wireControls(lab, modes) {
  const select = document.getElementById('mode');
  for (const m of modes) select.add(new Option(m, m));
  const note = document.getElementById('mode-note');
  select.onchange = () => {
    try {
      lab.setDebugMode(select.value);
      note.textContent = select.value === 'shell' ? 'diagnostic capsule shell (pose storage), not the shipping body' : '';
    } catch (e) { out.textContent = String(e); }
  };
  document.getElementById('step').onclick = () => lab.stepTicks(1);
  document.getElementById('grid').onclick = () => lab.spawn(100, 63);
  let playing = false;
  const loop = () => { if (!playing) return; lab.stepTicks(1); requestAnimationFrame(loop); };
  document.getElementById('play').onclick = () => { playing = !playing; if (playing) requestAnimationFrame(loop); };
}

main().catch((error) => {
  window.__lab = { ready: true, error: `${error?.stack ?? error}` };
  out.textContent = window.__lab.error;
});
