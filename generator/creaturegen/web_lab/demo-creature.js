// Creature demo: a built creature package (/out/<slug>/, ?pkg=<slug>) used through its public API only, as an app
// would: a population of bodies with different seeds walking on a lit ground plane with shadows, an orbiting
// camera the user can take over (OrbitControls), the canvas sized to the window (devicePixelRatio included).
// Query: ?pkg=<slug>&count=12&seed=1 (the first seed; body i has seed + i).
//
// A body that walks out of the arena re-enters on the opposite side with the same seed (despawn + spawn:
// validation and an O(slots) write, no compiles). window.__lab (for the headless test) is ready once the
// first frames have rendered.
import * as THREE from 'three/webgpu';
import { checker, color, mix, positionWorld, screenUV, smoothstep } from 'three/tsl';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { runPacedLoop, toBase64, watchPixelRatio } from './lab-common.js';

const params = new URLSearchParams(location.search);
const slug = params.get('pkg');
const count = Math.max(1, Math.min(64, Number(params.get('count') ?? 12) | 0));
const firstSeed = Math.max(0, Number(params.get('seed') ?? 1) | 0);
const statusLine = document.getElementById('status');
const problem = document.getElementById('problem');
const READY_AFTER_FRAMES = 3;

/** Calls back whenever devicePixelRatio changes (browser zoom, a window dragged to another screen). */
async function main() {
  if (!slug) throw new Error('creature demo: add ?pkg=<slug> (a creature package folder of out/); the index at / lists them');
  document.getElementById('package').textContent = slug;
  document.title = `creaturegen demo: ${slug}`;
  const errors = window.__lab.errors;

  const renderer = new THREE.WebGPURenderer({ antialias: true });
  renderer.onError = (info) => errors.push(`${info.api} ${info.type}: ${info.message}`);
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = THREE.PCFSoftShadowMap;
  document.body.prepend(renderer.domElement);
  await renderer.init();
  if (renderer.backend.isWebGPUBackend !== true) throw new Error('creature demo: this browser has no WebGPU (three fell back to WebGL2)');

  const pkg = await import(`/out/${encodeURIComponent(slug)}/index.js`);
  const data = pkg.CREATURE;
  const L = data.bodyScale; // the creature's size in metres: every distance below is in bodies
  const swimmer = data.motion.type === 'swimmer';
  const arena = 7 * L; // bodies farther than this from the centre re-enter on the other side

  // Scene: a gradient sky, a chequered ground (one-body squares, so the walking reads), sun and sky light.
  const scene = new THREE.Scene();
  scene.backgroundNode = mix(color(0x2b5fa8), color(0xdfe9f2), smoothstep(0.0, 0.8, screenUV.y));
  const groundY = swimmer ? -2 * L : 0; // a swimmer's ground is the seabed below the water (surface at y = 0)
  const groundMaterial = new THREE.MeshStandardNodeMaterial({ roughness: 0.92 });
  groundMaterial.colorNode = mix(color(0x8a9a7b), color(0xa5b394), checker(positionWorld.xz.div(L)));
  const ground = new THREE.Mesh(new THREE.CircleGeometry(3 * arena, 96), groundMaterial);
  ground.rotation.x = -Math.PI / 2;
  ground.position.y = groundY;
  ground.receiveShadow = true;
  scene.add(ground);
  if (swimmer) {
    const water = new THREE.Mesh(new THREE.CircleGeometry(3 * arena, 96),
      new THREE.MeshStandardNodeMaterial({ color: 0x3a8fc0, transparent: true, opacity: 0.25, roughness: 0.1, depthWrite: false }));
    water.rotation.x = -Math.PI / 2;
    scene.add(water);
  }
  scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x4a4038, 1.1));
  const sun = new THREE.DirectionalLight(0xfff3e0, 2.4);
  sun.position.set(3 * L, 10 * L, 4 * L);
  sun.castShadow = true;
  sun.shadow.mapSize.set(2048, 2048);
  const reach = arena + 2 * L;
  Object.assign(sun.shadow.camera, { left: -reach, right: reach, top: reach, bottom: -reach, near: 0.1 * L, far: 30 * L });
  sun.shadow.camera.updateProjectionMatrix();
  sun.shadow.bias = -0.0005;
  scene.add(sun);

  const camera = new THREE.PerspectiveCamera(45, window.innerWidth / window.innerHeight, 0.05 * L, 200 * L);
  camera.position.set(6 * L, 4.5 * L, 9 * L);

  // The population: water is passed to every package (only a swimmer reads it); the default support is flat
  // ground at y = 0.
  const population = await pkg.createCreaturePopulation(renderer, { capacity: Math.max(16, count), water: pkg.createAnalyticWater() });
  scene.add(population.object3d);
  // Bodies start on a sunflower spiral inside the arena; each walks off along its own genome's heading.
  const bodies = [];
  for (let i = 0; i < count; i++) {
    const radius = 0.8 * arena * Math.sqrt((i + 0.5) / count);
    const angle = i * 2.399963;
    const seed = firstSeed + i;
    bodies.push({ seed, id: population.spawn({ seed, position: [radius * Math.cos(angle), 0, radius * Math.sin(angle)] }) });
  }
  population.flush();
  // Orbit around the population's mean height (flyers and swimmers are not at ground level).
  const heights = bodies.map((b) => population.instance(b.id).root?.[1] ?? 0);
  const focusY = heights.reduce((a, b) => a + b, 0) / heights.length + 0.3 * L;

  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.set(0, focusY, 0);
  controls.enableDamping = true;
  controls.autoRotate = true;
  controls.autoRotateSpeed = 0.5;
  controls.minDistance = 1.5 * L;
  controls.maxDistance = 40 * L;
  controls.maxPolarAngle = 0.49 * Math.PI;
  controls.addEventListener('start', () => { controls.autoRotate = false; }); // the user has the camera now
  controls.update();

  await population.warm(scene, camera); // every pipeline before the first visible frame

  let respawns = 0;
  function keepInArena() {
    for (const body of bodies) {
      const root = population.motion(body.id)?.root;
      if (!root || Math.hypot(root[0], root[2]) <= arena) continue;
      population.despawn(body.id);
      // Re-enter on the far side with the same seed (same colours and gait): it walks across again.
      body.id = population.spawn({ seed: body.seed, position: [-0.95 * root[0], 0, -0.95 * root[2]] });
      respawns += 1;
    }
  }

  function resize() {
    renderer.setPixelRatio(window.devicePixelRatio);
    renderer.setSize(window.innerWidth, window.innerHeight);
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
  }
  window.addEventListener('resize', resize);
  watchPixelRatio(resize);

  let last = null; // the previous frame's requestAnimationFrame timestamp (ms)
  let shownAt = -1;
  let fps = 0;
  function showStatus(now) {
    const size = renderer.getDrawingBufferSize(new THREE.Vector2());
    statusLine.textContent = [
      `clock      t = ${now.toFixed(2)} s, tick ${population.tick} (60 Hz fixed steps)`,
      `bodies     ${population.count} × ${data.motion.type}, seeds ${firstSeed}..${firstSeed + count - 1}; ${respawns} re-entries`,
      `mesh       ${data.mesh.vertices} vertices, tier ${data.tier ?? '?'}`,
      `canvas     ${size.x}×${size.y} px (dpr ${renderer.getPixelRatio()}), ${fps.toFixed(0)} fps`,
    ].join('\n');
    problem.textContent = errors.slice(-3).join('\n');
  }

  function frame(ms) {
    // A skipped vsync makes the next update() cover the longer interval (the driver clamps a frame to 0.25 s).
    const dt = last === null ? 0 : (ms - last) / 1000;
    if (dt > 0) fps = 0.9 * fps + 0.1 / Math.max(dt, 1e-3);
    last = ms;
    keepInArena();
    population.update(dt); // fixed 60 Hz steps, interpolated render pose
    controls.update(dt);
    renderer.render(scene, camera);
    const now = ms / 1000;
    if (now - shownAt > 0.25) { showStatus(now); shownAt = now; }
  }
  const loop = runPacedLoop(renderer, frame, fail, READY_AFTER_FRAMES);

  Object.assign(window.__lab, {
    package: slug,
    count,
    bodyScale: L,
    motionType: data.motion.type,
    frames: loop.frames,
    tick: () => population.tick,
    respawns: () => respawns,
    /** The frame rendered off-screen and read back: base64 RGBA8 rows (first row first), for a test's picture. */
    async snapshot() {
      const size = renderer.getDrawingBufferSize(new THREE.Vector2());
      const target = new THREE.RenderTarget(size.x, size.y);
      renderer.setRenderTarget(target);
      renderer.render(scene, camera);
      renderer.setRenderTarget(null);
      const padded = await renderer.readRenderTargetPixelsAsync(target, 0, 0, size.x, size.y);
      target.dispose();
      const rowBytes = Math.ceil((size.x * 4) / 256) * 256;
      const rgba = new Uint8Array(size.x * size.y * 4);
      for (let y = 0; y < size.y; y++) rgba.set(padded.subarray(y * rowBytes, y * rowBytes + size.x * 4), y * size.x * 4);
      return { width: size.x, height: size.y, rgba: toBase64(rgba) };
    },
    /** Every body's root: x, y, z, cos yaw, sin yaw, squash (null for a dead one), and its seed. */
    roots: () => bodies.map((b) => ({ seed: b.seed, root: population.motion(b.id)?.root ? Array.from(population.motion(b.id).root) : null })),
  });
}

function fail(error) {
  console.error(error);
  problem.textContent = String(error?.message ?? error);
  statusLine.textContent = '';
  window.__lab.error = String(error?.stack ?? error);
  window.__lab.ready = true;
}

main().catch(fail);
