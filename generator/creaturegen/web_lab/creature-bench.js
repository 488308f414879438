// Creature runtime bench page (bench/runtime.py): loads a built creature package from /out/<slug>/, builds
// the forbidden baseline deform pre-pass beside the shipped one (creature-baseline.js, lab code only) and exposes
// window.__lab with the hooks the benchmark drives. Every number it returns is measured here: frame times
// to GPU completion, upload bytes from the population, draw calls from the WebGPU encoders, spawn times.
import * as THREE from 'three/webgpu';
import { Fn, instanceIndex, instancedArray, int } from 'three/tsl';
import { baselineFunctions, createBaselineKernel, createLbsKernel } from './creature-baseline.js';
import { countDraws } from './lab-common.js';

const params = new URLSearchParams(location.search);
const slug = params.get('pkg');
const width = Number(params.get('w') ?? 192);
const height = Number(params.get('h') ?? 144);
const capacity = Number(params.get('capacity') ?? 256);
const pageSize = Number(params.get('pageSize') ?? 64);
const spacing = Number(params.get('spacing') ?? 1.5);
// The camera and the shadow camera frame the grid of this many bodies, so no page is culled at any N.
const frameBodies = Number(params.get('frame') ?? capacity);
// Central-difference half step of the baseline, in units of the body scale.
const fdStep = Number(params.get('fdStep') ?? 1e-3);
// The sun's shadow map (a second pass through every body's vertex path); on by default, as in the lab.
const shadows = (params.get('shadows') ?? '1') !== '0';
// The pre-pass variants to build and compile (the crowd bench times the shipped one only).
const wanted = (params.get('variants') ?? 'shipped,baseline,lbs,ao').split(',');
const out = document.getElementById('out');

// Draw calls and render passes, counted at the WebGPU encoders (what was submitted, not what three meant to).
// Each draw is charged to the pass encoder it was recorded on (three may begin one pass while another is
// open on a different command encoder, e.g. the shadow map inside the main render).
const draws = countDraws();
const resetDraws = () => draws.reset();

// The smallest step performance.now() takes here (browsers coarsen it; spawn times are near it).
function timerResolution() {
  let best = Infinity;
  const until = performance.now() + 20;
  let last = performance.now();
  while (last < until) {
    const now = performance.now();
    if (now > last) { best = Math.min(best, now - last); last = now; }
  }
  return best;
}

const tick = () => new Promise((resolve) => requestAnimationFrame(resolve));
const sortedQuantile = (sorted, q) => sorted[Math.min(sorted.length - 1, Math.max(0, Math.ceil(q * sorted.length) - 1))];

async function main() {
  if (!slug) throw new Error('creature bench: add ?pkg=<slug> (a folder of out/)');
  const errors = [];
  const canvas = document.getElementById('canvas');
  const renderer = new THREE.WebGPURenderer({ canvas, antialias: false });
  renderer.onError = (info) => errors.push(`${info.api} ${info.type}: ${info.message}`);
  renderer.setPixelRatio(1);
  renderer.setSize(width, height, true);
  renderer.shadowMap.enabled = shadows;
  await renderer.init();
  if (renderer.backend.isWebGPUBackend !== true) throw new Error('creature bench: three fell back to WebGL2; WebGPU is required');
  const device = renderer.backend.device;
  const pkg = await import(`/out/${slug}/index.js`);
  const tsl = await import(`/out/${slug}/tsl/index.js`);
  const { populationInternals } = await import(`/out/${slug}/tsl/diagnostics.js`);
  const data = pkg.CREATURE;
  const L = data.bodyScale;
  draws.bodyIndexCount = 3 * data.mesh.triangles;

  // The lab's scene (ground receiving shadows, hemisphere fill, one shadow-casting sun), framed to the grid.
  const side = Math.ceil(Math.sqrt(frameBodies));
  const extent = (side - 1) * spacing * L + 2 * L;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1d2430);
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(extent + 4 * L, extent + 4 * L), new THREE.MeshStandardNodeMaterial({ color: 0x9aa3ad, roughness: 0.9 }));
  ground.rotation.x = -Math.PI / 2;
  ground.receiveShadow = true;
  scene.add(ground);
  scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x404040, 1.2));
  const sun = new THREE.DirectionalLight(0xffffff, 2.0);
  sun.position.set(0, 4 * L, 0);
  sun.castShadow = shadows;
  sun.shadow.mapSize.set(256, 256);
  scene.add(sun);
  scene.add(sun.target);
  const camera = new THREE.PerspectiveCamera(35, width / height, 0.05 * L, 100 * L + 4 * extent);
  // The camera and the shadow camera frame the middle of the grid: a square of n bodies around the origin.
  function frameGrid(n) {
    const s = Math.ceil(Math.sqrt(n));
    const e = (s - 1) * spacing * L + 2 * L;
    const half = 0.5 * e + L;
    Object.assign(sun.shadow.camera, { left: -half, right: half, top: half, bottom: -half, near: 0.1 * L, far: 8 * L });
    sun.shadow.camera.updateProjectionMatrix();
    const reach = Math.max(2.2 * L, 0.5 * e / Math.tan(THREE.MathUtils.degToRad(17.5)) * 1.1);
    camera.position.set(0.55 * reach, 0.6 * reach, 0.75 * reach);
    camera.lookAt(0, 0.3 * L, 0);
    camera.updateMatrixWorld();
    return n;
  }
  frameGrid(frameBodies);

  // Water for every package (only a swimmer reads it); bodies walk on the default flat ground.
  const pop = await tsl.createCreaturePopulation(renderer, { capacity, pageSize, water: pkg.createAnalyticWater() });
  scene.add(pop.object3d);
  const internals = populationInternals(pop);
  const { layout } = internals;
  const step = fdStep * L;

  // Both variants' deform pre-passes, one per page, built before anything is timed. The material, the
  // storage and the draws are the package's own in both: only the field path in the pre-pass differs.
  const builders = {
    shipped: () => pop.pages.map((p) => p.kernel),
    baseline: () => pop.pages.map((p) => createBaselineKernel(tsl, layout, p, internals.records, internals.order, internals.programs, step)),
    // What a SkinnedMesh does: linear blend skinning alone, no correction, no field (lab code too).
    lbs: () => pop.pages.map((p) => createLbsKernel(tsl, layout, p, internals.records, internals.programs)),
    // The shipped pre-pass with the field's self-occlusion on (look.aoTaps; the same kernels: the taps
    // are a uniform loop bound).
    ao: () => pop.pages.map((p) => p.kernel),
  };
  const AO_LOOK = { aoTaps: 4, aoRadius: 0.08 };
  const kernels = Object.fromEntries(wanted.map((v) => [v, builders[v]()]));
  let variant = 'shipped';
  function setVariant(v) {
    if (!(v in kernels)) throw new Error(`variant: ${Object.keys(kernels).join(', ')} (got ${v})`);
    pop.pages.forEach((p, i) => { p.kernel = kernels[v][i]; });
    if ((v === 'ao') !== (variant === 'ao')) pop.setLook(v === 'ao' ? AO_LOOK : { aoTaps: 0 });
    variant = v;
  }
  function render() { renderer.render(scene, camera); }

  const spawnTimes = [];
  let lastSpawnBatchMs = null;
  function spawn(seed, count, gridSide = Math.ceil(Math.sqrt(count))) {
    const ids = [];
    const batchStart = performance.now();
    for (let i = 0; i < count; i++) {
      const position = [((i % gridSide) - (gridSide - 1) / 2) * spacing * L, 0, (Math.floor(i / gridSide) - (gridSide - 1) / 2) * spacing * L];
      const start = performance.now();
      ids.push(pop.spawn({ seed: (seed + i) >>> 0, position }));
      spawnTimes.push(performance.now() - start);
    }
    lastSpawnBatchMs = performance.now() - batchStart;
    pop.flush();
    return ids;
  }
  function despawnAll() {
    for (let i = 0; i < pop.capacity; i++) if (pop.instance(i).alive) pop.despawn(i);
    pop.flush();
  }

  // Build both variants' deform pipelines (one dispatch of every page's kernel) and the shared display and
  // shadow pipelines, with one body, before the first timed frame.
  const t0 = performance.now();
  spawn(1, 1);
  const compileMs = {};
  for (const v of wanted) {
    const start = performance.now();
    setVariant(v);
    console.log(`creature bench: compiling ${v}`);
    for (const p of pop.pages) tsl.dispatchDeform(renderer, p.kernel, 1);
    await device.queue.onSubmittedWorkDone();
    compileMs[v] = performance.now() - start;
    console.log(`creature bench: compiled ${v} in ${compileMs[v].toFixed(0)} ms`);
  }
  {
    const start = performance.now();
    const saved = pop.pages.map((p) => p.mesh.count);
    for (const p of pop.pages) p.mesh.count = Math.max(1, p.mesh.count);
    await renderer.compileAsync(scene, camera);
    pop.pages.forEach((p, i) => { p.mesh.count = saved[i]; });
    await tick();
    render();
    await device.queue.onSubmittedWorkDone();
    compileMs.display = performance.now() - start;
  }
  setVariant('shipped');
  despawnAll();
  const bootMs = performance.now() - t0;

  // Field queries, outside any frame: the shipped query (one K-instruction tape, distance and analytic
  // gradient together) and the baseline query (every slot's distance, seven times: the value and six
  // central-difference taps), each in its own compute kernel over the rest vertices of body 0 (page 0)
  // that query the field, repeated `copies` times, each vertex through its own candidate program (the full
  // program for noProgram). A skinProgram vertex queries no field in either variant, so it is left out;
  // when no vertex queries the field (a skin-represented tier) every rest vertex runs the full program, so
  // the two field paths can still be compared (fieldVertices says which). Built on first use.
  let fieldState = null;
  function fieldKernels(copies) {
    if (fieldState && fieldState.copies === copies) return fieldState;
    const g = internals.geometry.attributes;
    const code = (v) => g.cgSkin.array[4 * v + 2];
    const isSkin = (c) => Math.abs(c - layout.skinProgram) < 0.5;
    const all = Array.from({ length: g.position.count }, (_, v) => v);
    const querying = all.filter((v) => !isSkin(code(v)));
    const rest = querying.length ? querying : all;
    const nv = rest.length;
    const n = nv * copies;
    const pts = new Float32Array(4 * n);
    for (let i = 0; i < n; i++) {
      const v = rest[i % nv];
      pts[4 * i] = g.position.array[3 * v];
      pts[4 * i + 1] = g.position.array[3 * v + 1];
      pts[4 * i + 2] = g.position.array[3 * v + 2];
      const c = code(v);
      pts[4 * i + 3] = c > layout.skinProgram - 0.5 ? layout.fullProgram : c;
    }
    const points = instancedArray(pts, 'vec4').toReadOnly();
    const fns = baselineFunctions(tsl, layout, pop.pages[0].pose, internals.programs, step);
    const kernel = (query) => {
      const result = instancedArray(n, 'vec4');
      const node = Fn(() => {
        const i = int(instanceIndex);
        const q = points.element(i).toVar();
        const base = int(0).toVar(); // instance 0 of page 0
        result.element(i).assign(query(q.xyz, base, int(q.w)));
      })().compute(n);
      return { node, result };
    };
    fieldState = {
      copies, n, vertices: nv, fieldVertices: querying.length,
      shipped: kernel(fns.shipped.field.runProgram),
      baseline: kernel(fns.field.runProgram),
    };
    return fieldState;
  }

  async function dispatch(kernel) {
    const start = performance.now();
    renderer.compute(kernel.node);
    await device.queue.onSubmittedWorkDone();
    return performance.now() - start;
  }

  // The baseline's field against the shipped one at the same points, read back from the GPU.
  async function fieldCheck() {
    if (!pop.instance(0).alive) throw new Error('fieldCheck: spawn a body first');
    const k = fieldKernels(1);
    await dispatch(k.shipped);
    await dispatch(k.baseline);
    const a = new Float32Array(await renderer.getArrayBufferAsync(k.shipped.result.value));
    const b = new Float32Array(await renderer.getArrayBufferAsync(k.baseline.result.value));
    let maxAbsD = 0, maxGradNormErr = 0;
    const angles = [];
    for (let i = 0; i < k.n; i++) {
      maxAbsD = Math.max(maxAbsD, Math.abs(a[4 * i] - b[4 * i]));
      const ga = [a[4 * i + 1], a[4 * i + 2], a[4 * i + 3]], gb = [b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]];
      const na = Math.hypot(...ga), nb = Math.hypot(...gb);
      if (na < 0.5 || nb < 0.5) continue; // kinks and degenerate points, where a difference is no gradient
      const cos = (ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2]) / (na * nb);
      angles.push(Math.acos(Math.min(1, Math.max(-1, cos))) * 180 / Math.PI);
      maxGradNormErr = Math.max(maxGradNormErr, Math.abs(na - nb));
    }
    angles.sort((x, y) => x - y);
    return {
      points: k.n, fieldVertices: k.fieldVertices, gradientsCompared: angles.length, maxAbsDistance: maxAbsD, maxAbsDistanceOverBodyScale: maxAbsD / L,
      gradientAngleDeg: angles.length ? { median: sortedQuantile(angles, 0.5), p99: sortedQuantile(angles, 0.99), max: angles.at(-1) } : null,
      maxGradientNormDifference: maxGradNormErr, step,
    };
  }

  // ms per dispatch of each query kernel, to GPU completion, alternating (order flips every repetition),
  // after one untimed dispatch of each (pipeline creation).
  async function timeFieldQueries(reps, copies = 4) {
    const k = fieldKernels(copies);
    await dispatch(k.shipped);
    await dispatch(k.baseline);
    const ms = { shipped: [], baseline: [] };
    for (let r = 0; r < reps; r++) {
      for (const v of r % 2 ? ['baseline', 'shipped'] : ['shipped', 'baseline']) ms[v].push(await dispatch(k[v]));
    }
    return { points: k.n, vertices: k.vertices, fieldVertices: k.fieldVertices, copies, ms };
  }

  // One frame per animation-frame tick (three advances its node frame once per tick), each timed from
  // stepTicks to GPU completion; the wait for the tick is not counted. cpuMs: stepTicks + render() only.
  async function timeFrames(frames) {
    const ms = [], cpuMs = [], bytes = [], deformed = [], bodyDraws = [], passDraws = [], instances = [], passes = [];
    const drawnBodies = [], deformedBodies = [];
    for (let f = 0; f < frames; f++) {
      await tick();
      resetDraws();
      const start = performance.now();
      bytes.push(pop.stepTicks(1));
      render();
      const submitted = performance.now();
      await device.queue.onSubmittedWorkDone();
      const end = performance.now();
      ms.push(end - start);
      cpuMs.push(submitted - start);
      if (pop.stats.lastFrameBytes !== bytes.at(-1)) throw new Error('stepTicks bytes differ from stats.lastFrameBytes');
      deformed.push(pop.stats.lastFrameDeformedVertices);
      passes.push(draws.passes);
      bodyDraws.push(draws.perPass.reduce((s, x) => s + x, 0));
      passDraws.push(draws.perPass.filter((x) => x > 0));
      instances.push(draws.instances);
      drawnBodies.push(pop.stats.lastFrameDrawnBodies);
      deformedBodies.push(pop.stats.lastFrameDeformedBodies);
    }
    return { variant, ms, cpuMs, bytes, deformed, bodyDraws, passDraws, instances, passes, drawnBodies, deformedBodies };
  }

  const lab = {
    ready: true,
    error: null,
    package: slug,
    errors,
    bootMs,
    compileMs,
    info() {
      const info = device.adapterInfo ?? {};
      return {
        isWebGPUBackend: renderer.backend.isWebGPUBackend === true,
        adapter: {
          architecture: info.architecture ?? null, vendor: info.vendor ?? null, device: info.device ?? null,
          description: info.description ?? null, isFallbackAdapter: info.isFallbackAdapter ?? null,
        },
        limits: { maxStorageBuffersPerShaderStage: device.limits.maxStorageBuffersPerShaderStage, maxStorageBufferBindingSize: device.limits.maxStorageBufferBindingSize },
        features: [...device.features].sort(),
        userAgent: navigator.userAgent,
        slug: data.slug, tier: data.tier, slots: data.slotCount, registers: data.registers, programs: data.programCount,
        vertices: data.mesh.vertices, triangles: data.mesh.triangles, capacity, pageSize: pop.pageSize, pages: pop.pages.length,
        floatsPerInstance: data.maxParts * pkg.POSE_ROWS * 4, bodyScale: L, canvas: [width, height],
        drawingBuffer: [canvas.width, canvas.height], spacing, frameBodies, fdStep: step,
        shadows, shadowMapSize: shadows ? [sun.shadow.mapSize.x, sun.shadow.mapSize.y] : null, signatures: data.signatures,
        // MSAA samples of the frames the bench times (three's renderer.samples; 0: no multisampling).
        sampleCount: renderer.samples,
      };
    },
    setVariant(v) { setVariant(v); return v; },
    spawn(seed, count) { return spawn(seed, count); },
    despawnAll,
    population(n, seed = 1) {
      despawnAll();
      spawn(seed, n);
      return { count: pop.count, pagesInUse: pop.pages.filter((p) => p.mesh.count > 0).length, meshCounts: pop.pages.map((p) => p.mesh.count) };
    },
    timeFrames,
    fieldCheck,
    timeFieldQueries,
    clearSpawnTimes() { spawnTimes.length = 0; },
    spawnCost() {
      const sorted = [...spawnTimes].sort((a, b) => a - b);
      return {
        samples: sorted.length, medianMs: sorted.length ? sorted[Math.floor(sorted.length / 2)] : null, maxMs: sorted.at(-1) ?? null,
        ms: [...spawnTimes], lastBatchMs: lastSpawnBatchMs, timerResolutionMs: timerResolution(),
      };
    },
    stats() { return { ...pop.stats, tick: pop.tick, count: pop.count }; },
    frameGrid,
    /**
     * A crowd scenario on the live bodies: the views frame the middle `framed` bodies of the grid, the
     * population culls against the camera (and the sun when it casts shadows; or not at all, `cull` false),
     * and every `pauseEvery`-th live body is paused (0: none). Flushes, and returns live, paused and the
     * bodies the flush left drawn.
     */
    crowd({ framed = pop.capacity, cull = true, pauseEvery = 0 } = {}) {
      frameGrid(framed);
      // The sun's view counts only when it casts shadows (its shadow pass draws the bodies it sees).
      if (cull) pop.cullWith(...(shadows ? [camera, sun] : [camera])); else pop.cullWith();
      let live = 0, paused = 0;
      for (let i = 0; i < pop.capacity; i++) {
        if (!pop.instance(i).alive) continue;
        const hold = pauseEvery > 0 && live % pauseEvery === 0;
        if (hold) { pop.pause(i); paused++; } else pop.resume(i);
        live++;
      }
      pop.flush();
      return { live, paused, framed, cull, drawn: pop.stats.lastFrameDrawnBodies };
    },
    async finish() { await device.queue.onSubmittedWorkDone(); return errors.length; },
  };
  window.__lab = lab;
  out.textContent = JSON.stringify(lab.info(), null, 2);
}

main().catch((error) => {
  window.__lab = { ready: true, error: `${error?.stack ?? error}` };
  out.textContent = window.__lab.error;
});
