// A population of one creature: fixed-capacity pose pages (vec4 storage, CPU Float32Array staging; pages.js),
// one deform pre-pass, one material and one draw per page, coalesced dirty-range uploads and posed bounds
// per page (staging.js). Every body is driven by its own locomotion core (core/motion/motion.js) on the population's
// support, gravity and water providers; the pose rows are what that core computed. Nothing GPU-side is
// created after warm(): pages, deform storage, materials and pipelines (compute, display, shadow) are
// built and warmed up front; a spawn validates, builds the body's CPU motion state and writes O(slots).
import * as THREE from 'three/webgpu';
import { instancedArray } from 'three/tsl';
import { CREATURE } from '../core/data.js';
import { hashBytes } from '../core/hash.js';
import { GENOME_LENGTH, drawGenome, genomeColours } from '../core/genome.js';
import { LCG } from '../core/lcg.js';
import { createDriver } from '../core/motion/driver.js';
import { assertWaterFor, createMotion } from '../core/motion/motion.js';
import { createFlatGround, createGravity } from '../core/motion/providers.js';
import { POSE_ROWS } from '../core/pose.js';
import { checkThreeRevision } from '../core/surface.js';
import { dispatchDeform } from './deform.js';
import { registerInternals } from './internals.js';
import { LOOK_DEFORM, checkDebugMode, checkLook, createLookUniforms } from './material.js';
import { createPages, kernelKind, showMode } from './pages.js';
import { advance, clearSlot, deformAll, flush, freeSlot, locate, writeCurrent, writeInstance } from './staging.js';
import { chooseTiers, loadTiers, moveBody, tierCount, tierNames } from './tiers.js';

const SHIPPED_VARIANTS = ['off'];

/** Throw unless `renderer` is an initialised WebGPURenderer on the WebGPU backend. */
export function assertWebGPU(renderer) {
  if (!renderer || !renderer.backend || renderer.backend.isWebGPUBackend !== true) {
    throw new Error(`${CREATURE.slug}: needs WebGPURenderer on a WebGPU backend (await renderer.init() first; `
      + 'the WebGL2 fallback is not supported)');
  }
}

/** BufferGeometry of the reference mesh with the skinning attributes this package's material reads. */
export function surfaceGeometry(surface) {
  const a = surface.attributes;
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(a.POSITION.array, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(a.NORMAL.array, 3));
  geometry.setAttribute('cgSlots', new THREE.BufferAttribute(a._SLOTS.array, 4));
  geometry.setAttribute('cgWeights', new THREE.BufferAttribute(a._WEIGHTS.array, 4));
  geometry.setAttribute('cgCor', new THREE.BufferAttribute(a._COR.array, 3));
  const n = a.POSITION.array.length / 3;
  const skin = new Float32Array(4 * n);
  for (let i = 0; i < n; i++) {
    skin[4 * i] = a._SKIN.array[2 * i];
    skin[4 * i + 1] = a._SKIN.array[2 * i + 1];
    skin[4 * i + 2] = a._CANDIDATE.array[i];
  }
  geometry.setAttribute('cgSkin', new THREE.BufferAttribute(skin, 4));
  // The baked colours of the vertices that evaluate no field (a skin-represented tier); zeros elsewhere,
  // where no vertex has SKIN_PROGRAM (body.js).
  geometry.setAttribute('cgColourSlots', new THREE.BufferAttribute(a._COLOUR_SLOTS?.array ?? new Float32Array(4 * n), 4));
  geometry.setAttribute('cgColourWeights', new THREE.BufferAttribute(a._COLOUR_WEIGHTS?.array ?? new Float32Array(4 * n), 4));
  geometry.setIndex(new THREE.BufferAttribute(surface.index.array, 1));
  return geometry;
}

/** The program tapes the .glb carries as a vec4 storage node (headers, then instructions), shared by every page. */
export function programStorage(surface) {
  return instancedArray(surface.program, 'vec4').toReadOnly();
}

/** Throws ThreeRevisionError unless the three.js in use is the release this package was built for. */
export function assertThreeRevision(revision = THREE.REVISION) {
  checkThreeRevision(revision);
}

/**
 * Create a population. Options: capacity (bodies, default 64), tiers (the shipped tiers to load, default
 * every one: CREATURE.tiers), tier (the tier spawn() puts a body in, default the finest loaded),
 * tierCapacity ({ tier: bodies } at most in that tier, default capacity each), pageSize (bodies per page
 * and draw, at most what one storage binding of the device holds: DEFORM_STRIDE·16 bytes per vertex per
 * body, default 64), debugMode, look (shading controls over CREATURE.look, see setLook), surfaceUrl (the .glb's URL; { tier: URL } for several tiers) or assetBase
 * (the folder holding the tiers' surfaceFile; default: this package's own assets/), support (a
 * SupportSurfaceProvider, default flat ground at y = 0), gravity (a gravity provider, default standard
 * gravity), water (a WaterSurfaceProvider: required for a swimmer, which is refused without one).
 */
export async function createCreaturePopulation(renderer, options = {}) {
  assertThreeRevision();
  assertWebGPU(renderer);
  const data = CREATURE;
  const capacity = options.capacity ?? 64;
  const requestedPageSize = options.pageSize ?? 64;
  if (!Number.isInteger(capacity) || capacity < 1) throw new Error(`capacity: must be a positive integer (got ${capacity})`);
  if (!Number.isInteger(requestedPageSize) || requestedPageSize < 1) {
    throw new Error(`pageSize: must be a positive integer (got ${requestedPageSize})`);
  }
  const support = options.support ?? createFlatGround();
  const gravity = options.gravity ?? createGravity();
  const water = options.water ?? null;
  assertWaterFor(data.motion.type, water, `${data.slug}: options.water`);
  const names = tierNames(data, options.tiers);
  const spawnTier = options.tier ?? names[0];
  if (!names.includes(spawnTier)) {
    throw new Error(`tier: spawns go to one of the loaded tiers ${names.join(', ')} (got ${spawnTier}); `
      + (data.tiers.some((t) => t.tier === spawnTier) ? 'add it to options.tiers' : `rebuild with --tier ${[...data.tiers.map((t) => t.tier), spawnTier].join(',')}`));
  }
  const floatsPerInstance = data.maxParts * POSE_ROWS * 4;
  const group = new THREE.Group();
  group.name = data.slug;
  const state = {
    renderer, data, capacity, floatsPerInstance, group,
    variants: new Map(),
    stats: {
      uploads: 0, uploadBytes: 0, lastFrameBytes: 0, spawns: 0, ticks: 0, deformDispatches: 0, lastFrameDeformedVertices: 0,
      lastFrameDeformedBodies: 0, lastFrameDrawnBodies: 0, lastFrameCulledBodies: 0, tierMoves: 0, tierMovesRefused: 0,
    },
    pages: null,
    // Where each body lives (its page in state.pages and slot there; -1: no live body has this id), its
    // last size on screen (chooseTiers) and the call of chooseTiers that last asked for it.
    bodyPage: new Int32Array(capacity).fill(-1), bodySlot: new Int32Array(capacity), sizePx: new Float64Array(capacity),
    chosen: new Uint32Array(capacity), chooseEpoch: 0,
    rootRow: data.slotCount * POSE_ROWS * 4,
    // Scratch for writing rows and bounds, reused by every body every frame.
    scratch: {
      tmp: new Float64Array(3), localBox: new Float64Array(6), corner: new THREE.Vector3(), box: new THREE.Box3(),
      previous: new Float32Array(floatsPerInstance), matrix: new THREE.Matrix4(),
    },
    // The views the population culls against (cullWith) and their frustum planes, refreshed at every flush.
    views: [], planes: new Float64Array(0), groupMatrix: new Float64Array(16), viewsChanged: false,
    tick: 0,
    mode: checkDebugMode(options.debugMode ?? 'off'),
    // The shading controls, one set of uniforms for every page and variant (setLook writes them).
    look: createLookUniforms({ ...data.look, ...checkLook(options.look ?? {}) }),
  };
  const tiers = await loadTiers(state, names, options, (surface) => ({ geometry: surfaceGeometry(surface), programs: programStorage(surface) }));
  state.tiers = tiers;
  state.tierByName = Object.fromEntries(tiers.map((t) => [t.name, t]));
  // { tier: subpixel size } of the loaded tiers, as chooseTier reads them.
  state.ceilings = Object.fromEntries(tiers.map((t) => [t.name, t.ceiling]));
  const pages = [];
  for (const tier of tiers) {
    tier.pages = createPages(state, tier, pages.length);
    pages.push(...tier.pages);
  }
  const first = tiers[0];
  const { geometry, layout, programs, records, order, pageSize, deformBytesPerBody } = first;

  state.pages = pages;
  const { stats, variants } = state;
  const home = state.tierByName[spawnTier];
  // The render pose of one body (update() interpolates every body into these, then writes its rows).
  const render = {
    quats: new Float64Array(4 * data.slotCount), trans: new Float64Array(3 * data.slotCount), root: new Float64Array(6),
  };
  const driver = createDriver(data.tickRate);
  for (const page of pages) showMode(state, page, state.mode);

  const population = {
    object3d: group,
    pages,
    get tick() { return state.tick; },
    get debugMode() { return state.mode; },
    get capacity() { return capacity; },
    /** Bodies per page (one draw each) of the finest loaded tier: the requested size, clamped to what one storage binding holds. */
    get pageSize() { return pageSize; },
    /** GPU bytes of deform storage per body of the finest loaded tier (DEFORM_STRIDE vec4 per vertex). */
    deformBytesPerBody,
    /** The loaded tiers, finest first: name, bodies held (count) and at most (capacity), subpixel size (ceiling), pages. */
    tiers: tiers.map((t) => ({
      name: t.name, capacity: t.capacity, ceiling: t.ceiling, vertices: t.vertices, pageSize: t.pageSize, pages: t.pages,
      get count() { return tierCount(t); },
    })),
    get count() { return pages.reduce((n, p) => n + p.alive.reduce((a, b) => a + b, 0), 0); },
    stats,
    /** The support, gravity and water providers every body of this population stands, falls and swims on. */
    support, gravity, water,
    /**
     * Validate and add one body at `position` (its path starts there; the locomotion core puts it on the
     * support, on the water or at the flyer's altitude). Its seed is its genome (core/genome.js): heading,
     * colour genes (hue, chroma, lightness in OKLab), gait genes and its size, within the package's genetics
     * bounds.
     * Builds its CPU motion state and writes O(slots) rows: no geometry, material, buffer or pipeline is
     * created. Its motion starts at its own tick 0.
     */
    spawn({ seed = 0, position = [0, 0, 0], tier = home.name } = {}) {
      if (!Number.isInteger(seed) || seed < 0 || seed > 0xffffffff) throw new Error(`spawn.seed: an integer in [0, 2^32) (got ${seed})`);
      if (!Array.isArray(position) || position.length !== 3 || !position.every(Number.isFinite)) {
        throw new Error('spawn.position: three finite numbers');
      }
      const into = state.tierByName[tier];
      if (!into) throw new Error(`spawn.tier: one of the loaded tiers ${names.join(', ')} (got ${JSON.stringify(tier)})`);
      const id = state.bodyPage.indexOf(-1);
      if (id < 0) throw new Error(`spawn: the population is full (capacity ${capacity}); create it with a larger capacity`);
      const slot = freeSlot(into);
      if (slot === null) {
        throw new Error(`spawn: tier ${into.name} is full (tierCapacity ${into.capacity}); spawn into another tier or raise it`);
      }
      const { page, j } = slot;
      const genome = drawGenome(seed, LCG, page.genomes.subarray(GENOME_LENGTH * j, GENOME_LENGTH * (j + 1)));
      page.motions[j] = createMotion(data.motion, LCG, { support, gravity, water, seed, position, genome });
      genomeColours(data, genome, page.colours, 3 * data.slotCount * j);
      page.alive[j] = 1;
      page.paused[j] = 0;
      page.seed[j] = seed;
      page.spawnTick[j] = state.tick;
      page.ids[j] = id;
      state.bodyPage[id] = page.index;
      state.bodySlot[id] = j;
      writeCurrent(state, page, j);
      stats.spawns += 1;
      return id;
    },
    /** Remove a body (its id is free for the next spawn); a dead id is left as it is. */
    despawn(id) {
      const { page, j } = locate(state, id);
      if (page === null) return;
      clearSlot(state, page, j);
      state.bodyPage[id] = -1;
    },
    /**
     * Move live body `id` into loaded tier `tier`, keeping its id, motion and genome: the next flush draws
     * it with that tier's surface. No GPU object is created. Returns false when the tier is full.
     */
    setBodyTier(id, tier) {
      const into = state.tierByName[tier];
      if (!into) throw new Error(`setBodyTier: one of the loaded tiers ${names.join(', ')} (got ${JSON.stringify(tier)})`);
      return moveBody(state, id, into);
    },
    /**
     * Give every live body the tier its size on screen asks for (core/lod.js chooseTier over the loaded
     * tiers' CREATURE.tiers[].projectedSizeMaxPx, with hysteresis), seen from `camera` in a viewport
     * `viewportHeight` pixels tall (the drawing buffer's height). Call it before update() or flush(); it
     * allocates nothing and creates no GPU object. Returns how many bodies changed tier.
     */
    chooseTiers(camera, viewportHeight) {
      return chooseTiers(state, camera, viewportHeight);
    },
    /** Advance every body `n` whole fixed steps and upload the current step's pose (no interpolation). */
    stepTicks(n = 1) {
      if (!Number.isInteger(n) || n < 0) throw new Error(`stepTicks: a non-negative integer (got ${n})`);
      advance(state, n);
      for (const page of pages) for (let j = 0; j < page.size; j++) if (page.alive[j] && !page.paused[j]) writeCurrent(state, page, j);
      return flush(state);
    },
    /**
     * Put the population at tick `n`: each body re-simulated from its spawn to its own tick
     * n − spawnTick (0 if it was spawned later), so the state equals stepping there tick by tick. A seek
     * re-simulates paused bodies too (the timeline knows no pauses; they stay paused at the sought pose).
     */
    seekTick(n) {
      if (!Number.isInteger(n) || n < 0) throw new Error(`seekTick: a non-negative integer (got ${n})`);
      for (const page of pages) {
        for (let j = 0; j < page.size; j++) {
          if (!page.alive[j]) continue;
          page.motions[j].seekTick(Math.max(0, n - page.spawnTick[j]));
          writeCurrent(state, page, j);
        }
      }
      state.tick = n;
      driver.reset();
      return flush(state);
    },
    /**
     * One render frame of `dt` seconds: the fixed-step driver (dt clamped to [0, 0.25] s, accumulator
     * capped at 0.25 s) runs the whole steps due, then every body is drawn at the render pose interpolated
     * between its previous and current step. Returns the number of steps run.
     */
    update(dt) {
      const steps = driver.advance(dt);
      advance(state, steps);
      for (const page of pages) {
        for (let j = 0; j < page.size; j++) {
          if (!page.alive[j] || page.paused[j]) continue;
          page.motions[j].renderPose(driver.alpha, render.quats, render.trans, render.root);
          writeInstance(state, page, j, render.quats, render.trans, render.root);
        }
      }
      flush(state);
      return steps;
    },
    /**
     * Hold a live body still: it is neither stepped nor rewritten by update() and stepTicks(), so its pose
     * rows do not change and the pre-pass does not run it again; it is still drawn (an idle creature of a
     * crowd costs its draw, not its deformation). resume() steps it on from its own tick.
     */
    pause(id) {
      const { page, j } = locate(state, id);
      if (page === null) throw new Error(`pause: instance ${id} is not alive`);
      page.paused[j] = 1;
    },
    resume(id) {
      const { page, j } = locate(state, id);
      if (page === null) throw new Error(`resume: instance ${id} is not alive`);
      page.paused[j] = 0;
    },
    /** The fixed-step driver (hz, alpha, accumulator) update() uses. */
    driver,
    /** Upload whatever spawn/despawn left dirty (called by the owner before rendering). */
    flush: () => flush(state),
    instance(id) {
      const { page, j } = locate(state, id);
      if (page === null) {
        return { index: -1, alive: false, paused: false, seed: 0, spawnTick: 0, tick: null, root: null, bounds: [0, 0, 0, 0, 0, 0],
          genome: null, tier: null, sizePx: null };
      }
      const m = page.motions[j];
      return { index: j, alive: true, paused: page.paused[j] === 1, seed: page.seed[j], spawnTick: page.spawnTick[j],
        tick: m.tick, root: Array.from(m.root), bounds: Array.from(page.bounds.subarray(6 * j, 6 * j + 6)),
        genome: Array.from(page.genomes.subarray(GENOME_LENGTH * j, GENOME_LENGTH * (j + 1))),
        tier: page.tier.name, sizePx: state.chosen[id] === 0 ? null : state.sizePx[id] };
    },
    /** The locomotion core of a live instance (createMotion: state, gates, renderPose), or null. */
    motion(id) {
      const { page, j } = locate(state, id);
      return page === null ? null : page.motions[j];
    },
    stateHash() {
      return hashBytes(pages.map((p) => new Uint8Array(p.staging.buffer, p.staging.byteOffset, p.staging.byteLength)), state.tick);
    },
    /** The shading controls now: { roughness, metalness, distanceRange } (CREATURE.look at creation). */
    get look() {
      return Object.fromEntries(Object.entries(state.look).map(([name, node]) => [name, node.value]));
    },
    /**
     * Change shading controls ({ roughness?, metalness?, distanceRange? }, each in the spec's range): uniform
     * writes seen from the next render, shared by every page and debug view; no material, pipeline or buffer
     * is created. Throws a RangeError naming the control for an unknown one or a value out of range.
     */
    setLook(changes) {
      checkLook(changes);
      for (const [name, value] of Object.entries(changes)) state.look[name].value = value;
      // The occlusion is stored by the pre-pass: every live body is deformed again now.
      if (Object.keys(changes).some((name) => LOOK_DEFORM.includes(name))) for (const page of pages) deformAll(state, page);
      return population.look;
    },
    /** Switch every page to debug mode `m` (a variant built on first use; 'off' is the shipped one). */
    setDebugMode(m) {
      checkDebugMode(m);
      const rerun = kernelKind(m) !== kernelKind(state.mode);
      for (const page of pages) {
        showMode(state, page, m);
        if (rerun) deformAll(state, page);
      }
      state.mode = m;
    },
    /**
     * Cull bodies by their posed bounds against `views`: cameras, or shadow-casting lights (their shadow
     * cameras). From the next flush on, only the live bodies one of the views sees are deformed and drawn,
     * in every pass (a body that casts a shadow into the picture is seen by the light's view); a body that
     * moved while culled is deformed when it comes back into view. No views (the default): no culling.
     * Creates no GPU object (the draw lists exist per page).
     */
    cullWith(...views) {
      for (const view of views) {
        const usable = view?.isCamera === true || (view?.isLight === true && view.shadow?.camera?.isCamera === true);
        if (!usable) throw new Error(`cullWith: cameras or shadow-casting lights (got ${view?.type ?? view})`);
      }
      state.views = views;
      state.planes = new Float64Array(24 * views.length);
      state.viewsChanged = true;
    },
    /** Move every live body into loaded tier `t` (setBodyTier for each); throws when it cannot hold them all. */
    setTier(t) {
      const into = state.tierByName[t];
      if (!into) {
        throw new Error(`tier: this population loaded ${names.join(', ')} (got ${t}); `
          + (data.tiers.some((x) => x.tier === t) ? 'create it with that tier in options.tiers' : `rebuild with --tier ${[...data.tiers.map((x) => x.tier), t].join(',')}`));
      }
      for (let id = 0; id < capacity; id++) {
        if (state.bodyPage[id] >= 0 && !moveBody(state, id, into)) throw new Error(`setTier: tier ${t} is full (tierCapacity ${into.capacity})`);
      }
    },
    /**
     * Build every shipped variant's pipelines (deform compute, display and shadow) and every page's deform
     * storage before the first visible frame.
     */
    async warm(scene, camera) {
      const saved = pages.map((p) => p.mesh.count);
      for (const page of pages) page.mesh.count = Math.max(1, page.mesh.count);
      for (const m of SHIPPED_VARIANTS) {
        for (const page of pages) {
          showMode(state, page, m);
          dispatchDeform(renderer, page.kernel, 1);
        }
        await renderer.compileAsync(scene, camera);
      }
      pages.forEach((p, i) => { p.mesh.count = saved[i]; showMode(state, p, state.mode); });
      // Each variant's warm-up dispatch wrote its own surface for a listed body: the shown one redraws them.
      for (const page of pages) deformAll(state, page);
    },
    dispose() {
      for (const tier of tiers) tier.geometry.dispose();
      for (const material of variants.values()) material.dispose();
      for (const page of pages) if (page.shell) { page.shell.geometry.dispose(); page.shell.material.dispose(); }
      group.removeFromParent();
    },
  };
  return registerInternals(population, {
    data, layout, programs, geometry,
    /** The rest-vertex records (deform.js) every page's pre-pass reads. */
    records,
    /** The order every page's pre-pass runs a body's vertices in (deform.js vertexOrder). */
    order,
    /** The loaded tiers (tiers.js): the diagnostics read bodies of the first. */
    tiers,
    /** The page holding live instance `id`, its index there and its tier's name. */
    locate(id) {
      const { page, j } = locate(state, id);
      if (page === null) throw new Error(`instance ${id} is not alive`);
      return { page, index: j, tier: page.tier.name };
    },
    /** Pose rows of one instance from the CPU staging copy (what the next upload sends; zeros when dead). */
    stagedPose(id) {
      const { page, j } = locate(state, id);
      if (page === null) return new Float32Array(floatsPerInstance);
      return page.staging.slice(j * floatsPerInstance, (j + 1) * floatsPerInstance);
    },
    /** The debug-mode variants built so far ('off' is the shipped one). */
    variantKeys() { return [...variants.keys()]; },
  });
}
