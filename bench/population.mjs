// The Node side of bench/population.py: the CPU side of a creature population (issue 27, item 5) at scale.
//
//   node --expose-gc --no-concurrent-recompilation bench/population.mjs <copy of a package> '<json options>'
//
// The package's own createCreaturePopulation runs against a stand-in renderer that records compute
// dispatches and, after each frame, clears the attributes' update ranges as three's backend does when it
// uploads them; nothing GPU-side runs. What is timed is what a frame costs the CPU: update(dt) (the fixed
// steps due, each body's render pose written into its page's staging copy, the change test, culling, the
// instance lists and the dispatch calls). Prints one JSON object: µs per body per frame (p50/p95 of frames),
// per scenario, and steady-state allocation (V8 heap growth and garbage collections over a window of frames
// after a full collection, as bench/motion.mjs probes the locomotion core). Bench code: it may use clocks.
import { readFileSync } from 'node:fs';
import { performance } from 'node:perf_hooks';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { allocationWindows } from './alloc.mjs';

const [packageDir, optionsText] = process.argv.slice(2);
if (!packageDir) throw new Error('usage: node --expose-gc bench/population.mjs <package copy> [json options]');
if (typeof globalThis.gc !== 'function') throw new Error('run node with --expose-gc');
const options = {
  bodies: 1024, pageSize: 64, spacing: 2, warmFrames: 120, frames: 120, allocWarm: 2000, allocFrames: 300, allocRounds: 5,
  inView: 0.1, ...JSON.parse(optionsText ?? '{}'),
};

// The package's surface is fetched by URL: read it from disk.
globalThis.fetch = async (url) => {
  const bytes = readFileSync(fileURLToPath(String(url)));
  return { ok: true, status: 200, arrayBuffer: async () => bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength) };
};
const base = pathToFileURL(`${packageDir}/`).href;
const pkg = await import(new URL('index.js', base).href);
// three as the package resolves it (the copy's folder holds node_modules/three).
const THREE = await import(new URL('../node_modules/three/build/three.webgpu.js', base).href);
const data = pkg.CREATURE;
const L = data.bodyScale;

let dispatches = 0;
const renderer = {
  backend: { isWebGPUBackend: true, device: { limits: { maxStorageBufferBindingSize: 1 << 30 } } },
  compute() { dispatches++; },
};
const pop = await pkg.createCreaturePopulation(renderer, { capacity: options.bodies, pageSize: options.pageSize, water: pkg.createAnalyticWater() });
const side = Math.ceil(Math.sqrt(options.bodies));
for (let i = 0; i < options.bodies; i++) {
  pop.spawn({ seed: i + 1, position: [((i % side) - (side - 1) / 2) * options.spacing * L, 0, (Math.floor(i / side) - (side - 1) / 2) * options.spacing * L] });
}
pop.flush();

// What three's backend does once it uploaded an attribute: its update ranges are consumed.
function uploaded() {
  for (const page of pop.pages) {
    page.pose.value.clearUpdateRanges();
    page.list.value.clearUpdateRanges();
    page.drawList.value.clearUpdateRanges();
  }
}

// A camera looking straight down on the middle of the grid, its square sized to hold `inView` of the bodies.
function topCamera(fraction) {
  const half = 0.5 * Math.sqrt(fraction) * side * options.spacing * L;
  const camera = new THREE.OrthographicCamera(-half, half, half, -half, 0.1 * L, 40 * L);
  camera.position.set(0, 20 * L, 0);
  camera.lookAt(0, 0, 0);
  camera.updateProjectionMatrix();
  return camera;
}

// A package shipping several tiers: a perspective camera dollying over the grid, every frame asking
// chooseTiers before update() (what a crowd with levels of detail runs), so bodies keep moving between tiers.
let perFrame = null;
const walkCamera = new THREE.PerspectiveCamera(35, 16 / 9, 0.05 * L, 1000 * L);
let walkFrame = 0;
function walk() {
  const t = (walkFrame++ % 240) / 240;
  walkCamera.position.set(0, 2 * L, (4 + 60 * (0.5 - 0.5 * Math.cos(2 * Math.PI * t))) * L);
  pop.chooseTiers(walkCamera, 720);
}

const scenarios = {
  moving: () => { perFrame = null; pop.cullWith(); for (let i = 0; i < options.bodies; i++) pop.resume(i); },
  'half-paused': () => { perFrame = null; pop.cullWith(); for (let i = 0; i < options.bodies; i++) (i % 2 ? pop.resume(i) : pop.pause(i)); },
  'culled-moving': () => { perFrame = null; pop.cullWith(topCamera(options.inView)); for (let i = 0; i < options.bodies; i++) pop.resume(i); },
  'culled-half-paused': () => { perFrame = null; pop.cullWith(topCamera(options.inView)); for (let i = 0; i < options.bodies; i++) (i % 2 ? pop.resume(i) : pop.pause(i)); },
};
if (data.tiers.length > 1) {
  scenarios['tier-walk'] = () => { perFrame = walk; pop.cullWith(); for (let i = 0; i < options.bodies; i++) pop.resume(i); };
}

const dt = 1 / data.tickRate;
/** `n` frames of one tick each: the measured loop, its own function so V8 optimises it in the warm-up. */
function frames(n, times) {
  for (let f = 0; f < n; f++) {
    const t0 = times ? performance.now() : 0;
    if (perFrame !== null) perFrame();
    pop.update(dt);
    if (times) times.push(performance.now() - t0);
    uploaded();
  }
}

const quantile = (sorted, q) => sorted[Math.min(sorted.length - 1, Math.max(0, Math.ceil(q * sorted.length) - 1))];

function cost(name) {
  scenarios[name]();
  frames(options.warmFrames, null);
  const times = [];
  const before = dispatches;
  frames(options.frames, times);
  times.sort((a, b) => a - b);
  const perBody = (ms) => (1000 * ms) / options.bodies;
  return {
    frames: times.length, msPerFrame: { p50: quantile(times, 0.5), p95: quantile(times, 0.95) },
    usPerBodyPerFrame: { p50: perBody(quantile(times, 0.5)), p95: perBody(quantile(times, 0.95)) },
    drawnBodies: pop.stats.lastFrameDrawnBodies, deformedBodies: pop.stats.lastFrameDeformedBodies,
    dispatchesPerFrame: (dispatches - before) / options.frames,
    tierMoves: pop.stats.tierMoves, bodiesPerTier: Object.fromEntries(pop.tiers.map((t) => [t.name, t.count])),
  };
}

// Windows of N and of 3N frames: what the frames allocate grows with N, what the probe itself costs a
// window (its closures, the memory reading) does not, so the difference of the cleanest windows over 2N
// frames is the steady loop's own rate.
async function allocation(name) {
  scenarios[name]();
  const n = options.allocFrames;
  const run = (k) => frames(k, null);
  const best = await allocationWindows(run, { warm: options.allocWarm, window: n, rounds: options.allocRounds });
  const long = await allocationWindows(run, { warm: 0, window: 3 * n, rounds: options.allocRounds });
  return {
    scenario: name, frames: n, bytesPerFrame: (long.heapGrowthBytes - best.heapGrowthBytes) / (2 * n), ...best,
    long: { frames: 3 * n, ...long },
  };
}

async function allocations(names) {
  const out = [];
  for (const name of names) out.push(await allocation(name));
  return out;
}

const result = {
  package: data.slug, type: data.motion.type, tickRate: data.tickRate, slots: data.slotCount, bodies: options.bodies,
  pageSize: pop.pageSize, pages: pop.pages.length,
  // One dispatch per vertex path of the body (tsl/deform.js vertexOrder) per page whose bodies moved.
  deformKernelsPerPage: pop.pages[0].kernel.kernels.length, node: process.version, v8Flags: process.execArgv, options,
  scenarios: Object.fromEntries(Object.keys(scenarios).map((name) => [name, cost(name)])),
  tiers: pop.tiers.map((t) => ({ name: t.name, vertices: t.vertices, ceiling: t.ceiling })),
  allocation: await allocations(options.allocScenarios
    ?? ['moving', 'culled-half-paused', ...(data.tiers.length > 1 ? ['tier-walk'] : [])]),
};
console.log(JSON.stringify(result));
