// The consumer page: what a three.js user's app does with creaturegen packages installed from npm
// tarballs, bundled (esbuild, Vite) or not (an import map into node_modules). tests/test_consumer.py
// writes the entry module that imports the packages by name and calls runConsumer with them.
//
// Two creature packages share one page and one renderer; each is drawn alone into a render target at two
// ticks, so the test can compare each body's silhouette with the same package's unbundled render (its own
// mesh, not the other package's) and see that it moves. A frost effect renders one frame. Everything is
// reported on window.__lab (ready, errors, masks as base64 bitmaps).
import * as THREE from 'three/webgpu';

const SIZE = 160;
const TICKS = [37, 49];

function toBase64(bytes) {
  let text = '';
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(text);
}

async function readTarget(renderer, target) {
  const padded = await renderer.readRenderTargetPixelsAsync(target, 0, 0, SIZE, SIZE);
  const rowBytes = Math.ceil((SIZE * 4) / 256) * 256;
  const rgba = new Uint8Array(SIZE * SIZE * 4);
  for (let y = 0; y < SIZE; y++) rgba.set(padded.subarray(y * rowBytes, y * rowBytes + SIZE * 4), y * SIZE * 4);
  return rgba;
}

/** 1 where the lit body covers the pixel (the background is black), one byte per pixel. */
function mask(rgba) {
  const out = new Uint8Array(SIZE * SIZE);
  for (let i = 0; i < out.length; i++) out[i] = rgba[4 * i] + rgba[4 * i + 1] + rgba[4 * i + 2] > 12 ? 1 : 0;
  return out;
}

/** A camera framing a body's posed bounds from three-quarters, as the package README picture does. */
function framing(bounds) {
  const centre = new THREE.Vector3((bounds[0] + bounds[3]) / 2, (bounds[1] + bounds[4]) / 2, (bounds[2] + bounds[5]) / 2);
  const radius = 0.5 * Math.hypot(bounds[3] - bounds[0], bounds[4] - bounds[1], bounds[5] - bounds[2]);
  const camera = new THREE.PerspectiveCamera(35, 1, 0.01 * radius, 40 * radius);
  const distance = 1.15 * radius / Math.sin(THREE.MathUtils.degToRad(17.5));
  camera.position.copy(centre).add(new THREE.Vector3(0.62, 0.42, 0.66).normalize().multiplyScalar(distance));
  camera.lookAt(centre);
  camera.updateMatrixWorld();
  return camera;
}

async function creatureMasks(renderer, pkg, target) {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x000000);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 1.5));
  const sun = new THREE.DirectionalLight(0xffffff, 2.0);
  sun.position.set(1, 3, 2);
  scene.add(sun);
  const population = await pkg.createCreaturePopulation(renderer, { capacity: 1, pageSize: 1, water: pkg.createAnalyticWater() });
  scene.add(population.object3d);
  population.spawn({ seed: 1, position: [0, 0, 0] });
  population.seekTick(TICKS[0]);
  const camera = framing(population.instance(0).bounds);
  // Culled as an app culls (the camera and the sun's shadow camera): a body in view draws as before.
  population.cullWith(camera, sun);
  await population.warm(scene, camera);
  const masks = [];
  for (const tick of TICKS) {
    population.seekTick(tick);
    population.flush();
    renderer.setRenderTarget(target);
    renderer.render(scene, camera);
    renderer.setRenderTarget(null);
    masks.push(toBase64(mask(await readTarget(renderer, target))));
  }
  // A package shipping several tiers: the same body moved into each coarser tier (its own .glb, which the
  // bundle must have fetched) and drawn again at the last tick.
  const tierMasks = {};
  for (const tier of population.tiers.slice(1)) {
    population.setBodyTier(0, tier.name);
    population.flush();
    renderer.setRenderTarget(target);
    renderer.render(scene, camera);
    renderer.setRenderTarget(null);
    tierMasks[tier.name] = toBase64(mask(await readTarget(renderer, target)));
  }
  const result = { slug: pkg.CREATURE.slug, vertices: pkg.CREATURE.mesh.vertices, masks, tierMasks };
  population.dispose();
  return result;
}

async function frostFrame(renderer, frost, target) {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x3060a0);
  const camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0.1, 10);
  camera.position.z = 2;
  const effect = await frost.createFrostEffect(renderer, scene, camera);
  effect.update(0, 1 / 60);
  renderer.setRenderTarget(target);
  effect.render();
  renderer.setRenderTarget(null);
  const rgba = await readTarget(renderer, target);
  let lit = 0;
  for (let i = 0; i < SIZE * SIZE; i++) lit += rgba[4 * i] + rgba[4 * i + 1] + rgba[4 * i + 2] > 0 ? 1 : 0;
  effect.dispose();
  return { slug: frost.PLAN.slug ?? null, litPixels: lit };
}

export async function runConsumer({ creatures, frost }) {
  const errors = [];
  const renderer = new THREE.WebGPURenderer({ antialias: false });
  renderer.onError = (info) => errors.push(`${info.api} ${info.type}: ${info.message}`);
  renderer.setPixelRatio(1);
  renderer.setSize(SIZE, SIZE);
  document.body.appendChild(renderer.domElement);
  await renderer.init();
  if (renderer.backend.isWebGPUBackend !== true) throw new Error('consumer page: three fell back to WebGL2');
  const target = new THREE.RenderTarget(SIZE, SIZE, { depthBuffer: true });
  const bodies = [];
  for (const pkg of creatures) bodies.push(await creatureMasks(renderer, pkg, target));
  const frame = frost ? await frostFrame(renderer, frost, target) : null;
  await renderer.backend.device.queue.onSubmittedWorkDone();
  return { size: SIZE, ticks: TICKS, bodies, frost: frame, errors, revision: THREE.REVISION };
}

export function report(promise) {
  promise.then(
    (result) => { window.__lab = { ready: true, error: null, ...result }; },
    (error) => { window.__lab = { ready: true, error: `${error?.name ?? 'Error'}: ${error?.message ?? error}`, stack: String(error?.stack ?? '') }; },
  );
}
