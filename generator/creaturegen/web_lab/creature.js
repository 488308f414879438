// Creature lab page: loads a built creature package from /out/<slug>/ and exposes window.__lab for the
// Playwright harness. Paused and deterministic by default: the pose moves only through seekTick/stepTicks
// (the package's locomotion core on flat ground, analytic water for swimmers). Every GPU number it reports
// is read back from the device (buffers or render targets). The cameras and the sun follow body 0.
import * as THREE from 'three/webgpu';
import { normalWorld, positionWorld, vec4 } from 'three/tsl';
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
  // A swimmer swims in the analytic water (surface at y = 0): its ground is a seabed below it.
  if (data.motion.type === 'swimmer') ground.position.y = -2 * L;
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

  // Water is passed to every package (only a swimmer reads it); the ground plane is the flat support y = 0.
  const pop = await pkg.createCreaturePopulation(renderer, { capacity, pageSize, water: pkg.createAnalyticWater() });
  scene.add(pop.object3d);
  const { createDiagnostics } = await import(`/out/${slug}/tsl/diagnostics.js`);
  const diag = createDiagnostics(renderer, pop);
  pop.spawn({ seed: Number(params.get('seed') ?? 1), position: [0, 0, 0] });
  pop.flush();

  // Foot-drift markers: one small sphere per leg of body 0 at its plant point (hidden while in swing),
  // green when the foot the GPU pose buffer draws sits on it, red otherwise (footDrift() colours them).
  const legs = data.motion.legs;
  const feet = new Float64Array(4 * Math.max(1, legs.length));
  const markerMaterial = new THREE.MeshBasicNodeMaterial();
  const markers = new THREE.InstancedMesh(new THREE.SphereGeometry(0.025 * L, 8, 6), markerMaterial, Math.max(1, legs.length));
  markers.count = legs.length;
  markers.castShadow = false;
  markers.name = 'foot-drift markers';
  const markerColour = new THREE.Color();
  for (let i = 0; i < legs.length; i++) markers.setColorAt(i, markerColour.set(0x30d050));
  scene.add(markers);
  const markerMatrix = new THREE.Matrix4();
  function placeMarkers() {
    const motion = pop.motion(0);
    if (!motion || !legs.length) { markers.visible = false; return; }
    markers.visible = true;
    motion.feet(feet);
    for (let i = 0; i < legs.length; i++) {
      const scale = feet[4 * i + 3] ? 1 : 0;
      markerMatrix.makeScale(scale, scale, scale).setPosition(feet[4 * i], feet[4 * i + 1], feet[4 * i + 2]);
      markers.setMatrixAt(i, markerMatrix);
    }
    markers.instanceMatrix.needsUpdate = true;
    markers.computeBoundingSphere();
  }

  // Frame body 0: the camera keeps its offset and the sun stays straight above; the shadow camera covers
  // the body's posed bounds with a margin, so thin parts (a tail on the ground) span several texels.
  const cameraOffset = new THREE.Vector3(1.6 * L, 0.8 * L, 2.2 * L);
  const focus = new THREE.Vector3();
  function follow() {
    const info = pop.instance(0);
    if (!info.alive) return;
    const b = info.bounds;
    focus.set((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2);
    camera.position.copy(focus).add(cameraOffset);
    camera.lookAt(focus);
    sun.position.set(focus.x, focus.y + 4 * L, focus.z);
    sun.target.position.set(focus.x, 0, focus.z);
    sun.target.updateMatrixWorld();
    const reach = 0.6 * Math.max(b[3] - b[0], b[5] - b[2], 0.5 * L);
    Object.assign(sun.shadow.camera, { left: -reach, right: reach, top: reach, bottom: -reach, near: 0.1 * L, far: focus.y + 8 * L });
    sun.shadow.camera.updateProjectionMatrix();
  }

  function render() { follow(); placeMarkers(); renderer.render(scene, camera); }

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
  // Device create* calls made by `run` (awaited, then the queue drained), added into `created`.
  async function countCreated(created, run) {
    const start = { ...deviceCounts };
    const result = await run();
    await device.queue.onSubmittedWorkDone();
    for (const [k, v] of Object.entries(deviceCounts)) created[k] = (created[k] ?? 0) + v - start[k];
    return result;
  }
  // Body i's deform storage read back, every array as base64 of its float32 bytes.
  async function deformedBase64(i) {
    const r = await diag.readDeformed(i);
    return Object.fromEntries(Object.entries(r).map(([k, a]) => [k, toBase64(new Uint8Array(a.buffer))]));
  }

  // A readback's rows are padded to 256 bytes (WebGPU's bytesPerRow); `texel` is bytes per pixel (4 for
  // RGBA8, 16 for RGBA32F), and the result is the tightly packed array of the target's own type.
  async function readTarget(target, w, h, texel = 4) {
    const padded = await renderer.readRenderTargetPixelsAsync(target, 0, 0, w, h);
    const row = (Math.ceil((w * texel) / 256) * 256) / padded.BYTES_PER_ELEMENT;
    const width = (w * texel) / padded.BYTES_PER_ELEMENT;
    const out = new padded.constructor(width * h);
    for (let y = 0; y < h; y++) out.set(padded.subarray(y * row, y * row + width), y * width);
    return out;
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
    follow();
    const markersVisible = markers.visible;
    markers.visible = false;
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
    // (2) footprint: ground only for the camera, body only in the shadow pass (layer 1). The receiver is
    // lowered by 0.1 L for this pass: where the body rests on the support (feet, a tail on the ground) a
    // shadow map cannot resolve the contact, and the straight-down projection is the same at any depth.
    ground.visible = true;
    const groundY = ground.position.y;
    ground.position.y = groundY - 0.1 * L;
    ground.updateMatrixWorld();
    scene.background = savedBackground;
    for (const p of pop.pages) p.mesh.layers.set(1);
    sun.shadow.camera.layers.enable(1);
    hemi.intensity = 0;
    const lit = await renderTo(cam, size, size);
    hemi.intensity = hemiIntensity;
    for (const p of pop.pages) p.mesh.layers.set(0);
    sun.shadow.camera.layers.disable(1);
    ground.position.y = groundY;
    ground.updateMatrixWorld();
    markers.visible = markersVisible;
    return { size, silhouette: toBase64(silhouette), footprint: toBase64(lit) };
  }

  // Three-quarter view framing body 0's posed bounds (the package README's picture, the display readback).
  function portraitCamera() {
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
    return cam;
  }

  async function capturePixels(view = 'front') {
    if (view === 'front') return { view, width, height, rgba: toBase64(await renderTo(camera, width, height)) };
    if (view === 'portrait') return { view, width, height, rgba: toBase64(await renderTo(portraitCamera(), width, height)) };
    if (view === 'grid') return captureGrid();
    if (view === 'top') {
      const cam = sun.shadow.camera.clone();
      cam.position.copy(sun.position); cam.lookAt(sun.target.position); cam.updateMatrixWorld();
      return { view, width: 128, height: 128, rgba: toBase64(await renderTo(cam, 128, 128)) };
    }
    throw new Error(`capturePixels: view is front, portrait or top (got ${view})`);
  }

  // The whole population from above at three-quarters (the genetics grid): the camera frames the union of
  // every live body's posed bounds and the shadow camera covers it, for this capture only.
  const gridBox = new THREE.Box3();
  const gridPoint = new THREE.Vector3();
  async function captureGrid(w = 480, h = 320) {
    gridBox.makeEmpty();
    for (let i = 0; i < pop.capacity; i++) {
      const info = pop.instance(i);
      if (!info.alive) continue;
      const b = info.bounds;
      gridBox.expandByPoint(gridPoint.set(b[0], b[1], b[2]));
      gridBox.expandByPoint(gridPoint.set(b[3], b[4], b[5]));
    }
    const centre = gridBox.getCenter(new THREE.Vector3());
    const radius = 0.5 * gridBox.getSize(new THREE.Vector3()).length();
    const cam = new THREE.PerspectiveCamera(30, w / h, 0.01 * radius, 20 * radius);
    // The grid is flat: framing its bounding sphere leaves most of the picture empty.
    const distance = 0.72 * radius / Math.sin(THREE.MathUtils.degToRad(15));
    cam.position.copy(centre).add(new THREE.Vector3(0, 0.75, 1).normalize().multiplyScalar(distance));
    cam.lookAt(centre);
    cam.updateMatrixWorld();
    sun.position.set(centre.x, centre.y + 4 * L, centre.z);
    sun.target.position.set(centre.x, 0, centre.z);
    sun.target.updateMatrixWorld();
    Object.assign(sun.shadow.camera, { left: -radius, right: radius, top: radius, bottom: -radius, near: 0.1 * L, far: centre.y + 8 * L });
    sun.shadow.camera.updateProjectionMatrix();
    const rgba = await renderTo(cam, w, h);
    follow();
    return { view: 'grid', width: w, height: h, rgba: toBase64(rgba) };
  }

  // Tier walk: `bodies` bodies in a row across the view of a camera looking down −z, which dollies from
  // `near` to `far` body lengths and back over `frames` frames. Every frame: chooseTiers from that camera
  // (what moves bodies between tiers), one tick, one flush and one render (from the lab camera). Recorded per frame, before the
  // tick, what the choice read (the camera's view matrix and fov, every body's posed-bounds centre and
  // size gene) and what it gave (each body's tier and size on screen), for the Python reference
  // (creature/lod.py) to recompute.
  const tierCamera = new THREE.PerspectiveCamera(35, width / height, 0.05 * L, 400 * L);
  function tierWalk(frames = 48, bodies = 6, near = 1.5, far = 24, seed = 5000) {
    for (let i = 0; i < pop.capacity; i++) if (pop.instance(i).alive) pop.despawn(i);
    const ids = [];
    for (let i = 0; i < bodies; i++) ids.push(pop.spawn({ seed: seed + i, position: [(i - (bodies - 1) / 2) * 1.5 * L, 0, 0] }));
    // Every other body idles (paused): a moved body whose pose stands still must still be deformed by its new tier.
    for (let i = 1; i < bodies; i += 2) pop.pause(ids[i]);
    pop.flush();
    const records = [];
    for (let f = 0; f < frames; f++) {
      const t = frames === 1 ? 0 : f / (frames - 1);
      const depth = near * Math.pow(far / near, 1 - Math.abs(2 * t - 1));  // near → far → near, geometric
      tierCamera.position.set(0, 0.5 * L, depth * L);
      tierCamera.rotation.set(0, 0, 0);
      const seen = ids.map((id) => {
        const b = pop.instance(id).bounds;
        return { id, centre: [(b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2], size: pop.motion(id).size };
      });
      const moved = pop.chooseTiers(tierCamera, height);
      const view = Array.from(tierCamera.matrixWorldInverse.elements);
      for (const body of seen) {
        const info = pop.instance(body.id);
        body.tier = info.tier;
        body.sizePx = info.sizePx;
      }
      pop.stepTicks(1);
      render();  // the lab's own camera: the gate counts what the moves create, not a new camera's bindings
      records.push({ view, fov: tierCamera.fov, zoom: tierCamera.zoom, height, moved, bodies: seen });
    }
    return { frames: records, stats: { tierMoves: pop.stats.tierMoves, tierMovesRefused: pop.stats.tierMovesRefused } };
  }

  // The same body drawn by two tiers, as masks: body `id` (the only live one) framed three-quarters in a
  // `size`² target, white on black, through each tier's own page material (its positionNode: the drawn
  // surface of that tier's deform storage), and its length on screen in pixels in that view.
  const maskScene = new THREE.Scene();
  const maskMaterial = new THREE.MeshBasicNodeMaterial();
  async function tierSilhouettes(tiers, size = 256, id = 0) {
    const masks = {};
    const cam = portraitCamera();
    cam.aspect = 1;
    cam.updateProjectionMatrix();
    const savedBackground = scene.background;
    for (const tier of tiers) {
      pop.setBodyTier(id, tier);
      pop.flush();
      const page = pop.tiers.find((t) => t.name === tier).pages.find((p) => p.mesh.count > 0);
      const mesh = new THREE.Mesh(page.mesh.geometry, maskMaterial);
      maskMaterial.positionNode = page.mesh.material.positionNode;
      maskMaterial.colorNode = vec4(1, 1, 1, 1);
      maskMaterial.needsUpdate = true;
      mesh.count = page.mesh.count;
      mesh.boundingSphere = page.mesh.boundingSphere;
      maskScene.add(mesh);
      maskScene.background = new THREE.Color(0x000000);
      const target = targetFor(size, size);
      renderer.setRenderTarget(target);
      renderer.render(maskScene, cam);
      renderer.setRenderTarget(null);
      masks[tier] = toBase64(await readTarget(target, size, size));
      maskScene.remove(mesh);
    }
    scene.background = savedBackground;
    cam.updateMatrixWorld();
    const b = pop.instance(id).bounds;
    const centre = new THREE.Vector3((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2).applyMatrix4(cam.matrixWorldInverse);
    const sizePx = pkg.projectedSizePx(L * pop.motion(id).size, -centre.z, size, cam);
    return { size, masks, sizePx };
  }

  // The display path itself: body 0 of page 0 drawn with the shipped material's own positionNode (the
  // same node object, so the same root squash/yaw/position and normal transform the draw runs), writing
  // world position and world normal into float targets from the front camera. The parity job compares
  // them with numpy's root transform of the drawn vertices (issue 25: every other readback is taken before
  // the root transform).
  const DISPLAY_OFFSET = 64;
  const displayScene = new THREE.Scene();
  const displayProbe = { position: null, normal: null, mesh: null };
  async function displayPath() {
    const body = pop.pages[0].mesh;
    if (displayProbe.mesh === null || displayProbe.mesh.geometry !== body.geometry) {
      for (const [key, value] of [['position', positionWorld], ['normal', normalWorld]]) {
        const probe = new THREE.MeshBasicNodeMaterial();
        probe.positionNode = body.material.positionNode;
        // Colour outputs are clamped at 0 on the way to the target: the readback adds an offset.
        probe.colorNode = vec4(value.add(DISPLAY_OFFSET), 1);
        displayProbe[key] = probe;
      }
      displayProbe.mesh = new THREE.Mesh(body.geometry, displayProbe.position);
      displayProbe.mesh.count = 1;
      displayScene.add(displayProbe.mesh);
    }
    const target = new THREE.RenderTarget(width, height, { type: THREE.FloatType, depthBuffer: true });
    const framing = portraitCamera();  // body 0 wherever it flies or swims
    const result = { width, height, offset: DISPLAY_OFFSET };
    const clearColour = renderer.getClearColor(new THREE.Color());
    const clearAlpha = renderer.getClearAlpha();
    renderer.setClearColor(0x000000, 0);  // alpha 0 marks pixels the body does not cover
    for (const key of ['position', 'normal']) {
      displayProbe.mesh.material = displayProbe[key];
      renderer.setRenderTarget(target);
      renderer.render(displayScene, framing);
      renderer.setRenderTarget(null);
      result[key] = toBase64(new Uint8Array((await readTarget(target, width, height, 16)).buffer));
    }
    renderer.setClearColor(clearColour, clearAlpha);
    target.dispose();
    return result;
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
        signatures: data.signatures, bodyScale: L, canvas: [width, height], locomotion: data.motion.type, tickRate: data.tickRate,
      };
    },
    async load(next) { location.search = `?pkg=${encodeURIComponent(next)}`; },
    seekTick(n) { const bytes = pop.seekTick(n); render(); return bytes; },
    /** n fixed steps of every body, one upload and one deform pre-pass of the result, one frame. */
    stepTicks(n = 1) { const bytes = pop.stepTicks(n); render(); return bytes; },
    /** One render frame of dt seconds through the population's fixed-step driver (interpolated pose). */
    update(dt) { const steps = pop.update(dt); render(); return { steps, alpha: pop.driver.alpha }; },
    stateHash() { return pop.stateHash(); },
    telemetry() {
      return {
        tick: pop.tick, count: pop.count, debugMode: pop.debugMode, stats: { ...pop.stats },
        pagesInUse: pop.pages.filter((p) => p.mesh.count > 0).length, pages: pop.pages.length,
        instances: Array.from({ length: pop.count }, (_, i) => pop.instance(i)),
        variantKeys: diag.variantKeys(), errors: errors.length,
      };
    },
    setTier(t) { pop.setTier(t); return t; },
    /** The population's loaded tiers (finest first): name, subpixel size, capacity, bodies held, vertices. */
    tierInfo() {
      return pop.tiers.map((t) => ({ name: t.name, ceiling: t.ceiling, capacity: t.capacity, count: t.count, vertices: t.vertices }));
    },
    tierWalk,
    tierSilhouettes,
    /** Hold these instances still (population.pause), or step them on again. */
    pause(ids = [0]) { for (const id of ids) pop.pause(id); return ids; },
    resume(ids = [0]) { for (const id of ids) pop.resume(id); return ids; },
    /** Pause every live body but `keep`; returns the ids paused. */
    pauseAllBut(keep = [0]) {
      const held = [];
      for (let i = 0; i < pop.capacity; i++) if (pop.instance(i).alive && !keep.includes(i)) { pop.pause(i); held.push(i); }
      return held;
    },
    /** Flush (whatever changed since the last upload, culling included) and draw one frame. */
    redraw() { const bytes = pop.flush(); render(); return bytes; },
    /** Cull against body 0's portrait view as it stands now ('portrait'), the lab camera ('camera'), or nothing. */
    cullWith(which = 'none') {
      const views = { portrait: () => [portraitCamera()], camera: () => [camera], none: () => [] }[which];
      if (!views) throw new Error(`cullWith: portrait, camera or none (got ${which})`);
      pop.cullWith(...views());
      return which;
    },
    setDebugMode(m) { pop.setDebugMode(m); render(); return m; },
    spawn(seed, count = 1, spacing = 1.5, draw = true) {
      const ids = [];
      const side = Math.ceil(Math.sqrt(count));
      for (let i = 0; i < count; i++) {
        const position = [((i % side) - (side - 1) / 2) * spacing * L, 0, (Math.floor(i / side) - (side - 1) / 2) * spacing * L];
        const start = performance.now();
        ids.push(pop.spawn({ seed: (seed + i) >>> 0, position }));
        spawnTimes.push(performance.now() - start);
      }
      // Without drawing, the new bodies stay dirty until the next flush (the next tick's one upload).
      if (draw) { pop.flush(); render(); }
      return ids;
    },
    /**
     * The genetics grid: every body replaced by n×n individuals with seeds seed, seed+1, … in rows
     * `spacing` body lengths apart, drawn at once unless `draw` is false (then they wait for the next
     * tick's one upload and deform). Returns [{ id, seed, position }] (the Python reference re-simulates
     * each from its seed and position).
     */
    grid(n = 8, seed = 0, spacing = 2, draw = true) {
      if (n * n > pop.capacity) throw new Error(`grid: ${n}×${n} needs capacity ${n * n} (this lab has ${pop.capacity}; add ?capacity=)`);
      for (let i = 0; i < pop.capacity; i++) if (pop.instance(i).alive) pop.despawn(i);
      const bodies = [];
      for (let i = 0; i < n * n; i++) {
        const position = [((i % n) - (n - 1) / 2) * spacing * L, 0, (Math.floor(i / n) - (n - 1) / 2) * spacing * L];
        const s = (seed + i) >>> 0;
        bodies.push({ id: pop.spawn({ seed: s, position }), seed: s, position });
      }
      if (draw) { pop.flush(); render(); }
      return bodies;
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
    /**
     * The shading controls as uniforms: the front view under the current look, under `changes` and under
     * the current look again, with the device objects created from the first setLook to the last capture.
     */
    async lookCheck(changes) {
      const before = { ...pop.look };
      const target = targetFor(width, height);
      const frame = () => { renderer.setRenderTarget(target); renderer.render(scene, camera); renderer.setRenderTarget(null); };
      // A readback makes its own staging buffer: only setLook and the renders are inside the counted window.
      frame();
      const a = await readTarget(target, width, height);
      const created = {};
      const count = (change) => countCreated(created, () => { const now = pop.setLook(change); frame(); return now; });
      const during = await count(changes);
      const b = await readTarget(target, width, height);
      await count(before);
      const c = await readTarget(target, width, height);
      return { before, during, restored: { ...pop.look }, created, width, height, rgba: [a, b, c].map(toBase64) };
    },
    /**
     * Body i's debug shell through the package's shellVertex (creature-local), and the vertex count of the
     * shell mesh the 'shell' view draws (the view is built, not drawn, and the mode put back).
     */
    async readShell(i = 0) {
      const r = await diag.readShell(i);
      const mode = pop.debugMode;
      pop.setDebugMode('shell');
      // The shells of the pages of the tier the diagnostics read (the finest loaded): one count, or -1.
      const counts = new Set(pop.pages.filter((p) => p.shell && p.tier.name === pop.tiers[0].name).map((p) => p.shell.geometry.attributes.position.count));
      const drawnVertices = counts.size === 1 ? [...counts][0] : -1;
      pop.setDebugMode(mode);
      return { counts: r.counts, placed: Array.from(r.placed), position: Array.from(r.position), distance: Array.from(r.distance), drawnVertices };
    },
    /** The locomotion gates of body i (worst values since its reset, measured by the JS core every tick). */
    motionGates(i = 0) { return pop.motion(i).gates; },
    /** Body i's locomotion state as the JS core in this page holds it (root, slots, ropes) and its tick. */
    motionState(i = 0) { const m = pop.motion(i); return { tick: m.tick, state: m.stateVector() }; },
    /**
     * Foot drift measured on the GPU pose buffer: for each planted leg of body i, its foot as the GPU rows
     * place it (lower slot's quaternion and translation read back, then the root rows: squash, yaw,
     * position) against the plant point of the JS core in world space, over the leg length. Colours the
     * markers: green within `tolerance` leg lengths, red beyond.
     */
    async footDrift(i = 0, tolerance = 1e-5) {
      const rows = await diag.readPose(i);
      const motion = pop.motion(i);
      motion.feet(feet);
      const r = data.slotCount * pkg.POSE_ROWS * 4;
      const root = [rows[r], rows[r + 1], rows[r + 2], rows[r + 4], rows[r + 5], rows[r + 6]];
      const k = 1 / Math.sqrt(root[5]);
      const out = [];
      for (let l = 0; l < legs.length; l++) {
        const leg = motion.data.legs[l]; // the individual's leg: its size scales the rest foot the rows draw
        const o = leg.lower * pkg.POSE_ROWS * 4;
        const q = new Float64Array([rows[o + 12], rows[o + 13], rows[o + 14], rows[o + 15]]);
        const p = new Float64Array(3);
        pkg.rotate(q, 0, leg.foot, 0, p, 0);
        const x = (p[0] + rows[o + 16]) * k, y = (p[1] + rows[o + 17]) * root[5], z = (p[2] + rows[o + 18]) * k;
        const world = [root[3] * x + root[4] * z + root[0], y + root[1], -root[4] * x + root[3] * z + root[2]];
        const planted = feet[4 * l + 3] === 1;
        const drift = Math.hypot(world[0] - feet[4 * l], world[1] - feet[4 * l + 1], world[2] - feet[4 * l + 2]) / (leg.a + leg.b);
        if (planted) markers.setColorAt(l, markerColour.set(drift <= tolerance ? 0x30d050 : 0xe03030));
        out.push({ leg: leg.part, planted, drift });
      }
      if (markers.instanceColor) markers.instanceColor.needsUpdate = true;
      return out;
    },
    stagedPose(i = 0) { return Array.from(diag.stagedPose(i)); },
    /**
     * The largest distance between body i's drawn vertices (its deform storage) and the GPU body path run
     * at its current pose by the diagnostics kernel: both read back here, only the number goes out.
     */
    async drawnGap(i = 0) {
      const drawn = (await diag.readDeformed(i)).position;
      const path = (await diag.readSkinned(i)).corrected;
      let gap = 0;
      for (let k = 0; k < drawn.length; k += 3) {
        gap = Math.max(gap, Math.hypot(drawn[k] - path[k], drawn[k + 1] - path[k + 1], drawn[k + 2] - path[k + 2]));
      }
      return gap;
    },
    async readSkinned(i = 0) {
      const r = await diag.readSkinned(i);
      return { skinned: toBase64(new Uint8Array(r.skinned.buffer)), corrected: toBase64(new Uint8Array(r.corrected.buffer)),
        accepted: toBase64(new Uint8Array(r.accepted.buffer)), gradient: toBase64(new Uint8Array(r.gradient.buffer)),
        distance: toBase64(new Uint8Array(r.distance.buffer)) };
    },
    /**
     * The field's self-occlusion: body i's deform storage under the current look, then under `changes`
     * (occlusion taps: setLook re-deforms every live body), then the look put back, with the device objects
     * created and the pre-pass dispatches run across both changes.
     */
    async aoCheck(changes, i = 0) {
      const before = { ...pop.look };
      const off = await deformedBase64(i);
      const created = {};
      const change = (c) => countCreated(created, () => {
        const deformed = pop.stats.deformDispatches;
        pop.setLook(c);
        pop.flush();
        render();
        return pop.stats.deformDispatches - deformed;
      });
      const dispatches = await change(changes);
      const on = await deformedBase64(i);
      await change(before);
      const back = await deformedBase64(i);
      return { look: { ...changes }, dispatches, created, off, on, back };
    },
    /** What the display and shadow passes draw (the page's deform storage), read back. */
    readDeformed: (i = 0) => deformedBase64(i),
    capturePixels,
    displayPath,
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
  document.getElementById('grid').onclick = () => lab.grid(8);
  let playing = false;
  // Play at a fixed 1/60 s per animation frame: deterministic whatever the display rate.
  const loop = () => { if (!playing) return; lab.update(1 / 60); requestAnimationFrame(loop); };
  document.getElementById('play').onclick = () => { playing = !playing; if (playing) requestAnimationFrame(loop); };
}

main().catch((error) => {
  window.__lab = { ready: true, error: `${error?.stack ?? error}` };
  out.textContent = window.__lab.error;
});
