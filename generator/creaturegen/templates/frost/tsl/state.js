// The effect's state: one plain object holding everything the effect's pieces share, created once by
// createFrostEffect (frost-effect.js) and passed explicitly to each piece: history.js (the history's
// size, reallocation and clearing), kernels.js (the compute kernels), intake.js (pointer segments),
// frame.js (update), composite.js (the output pass), controls.js (tiers, controls, resize) and
// readback.js (diagnostics). Every GPU resource the per-frame path touches is allocated here: the two
// history textures, the uniforms the kernels read and the fixed-capacity storage buffers that carry
// each frame's steps, segments, bins and tile list. A frame writes into them; it never allocates them.
import { FloatType, HalfFloatType, NearestFilter, NoColorSpace, RGBAFormat, StorageTexture, Vector2 } from 'three/webgpu';
import { instancedArray, storageTexture, texture, uint, uniform } from 'three/tsl';
import { PLAN } from '../core/plan.js';
import { StepBins, TileScheduler, scaledSize } from '../core/frost-core.js';

/** Bytes per history texel, by history format. */
export const TEXEL = { rgba16float: 8, rgba32float: 16 };

function u32(x) {
  return x >>> 0;
}

/** One history texture: RGBA half or single float, nearest-filtered (the kernels load exact texels). */
export function historyTexture(width, height, format, name) {
  const tex = new StorageTexture(width, height);
  tex.type = format === 'rgba32float' ? FloatType : HalfFloatType;
  tex.format = RGBAFormat;
  tex.colorSpace = NoColorSpace;
  tex.magFilter = NearestFilter;
  tex.minFilter = NearestFilter;
  tex.generateMipmaps = false;
  tex.name = name;
  return tex;
}

/**
 * The state of one effect, sized from the renderer's drawing buffer and the tier's history scale.
 * A history texel holds R: the visible channel's state, G and B: the largest coverage the visible and tilt
 * channels received this frame, A: the tilt channel's state.
 */
export function createState(renderer, tierName, tier, binning) {
  const params = PLAN.params;
  const format = PLAN.tier.historyFormat;
  const size = new Vector2();
  renderer.getDrawingBufferSize(size);
  const [histW, histH] = scaledSize(size.x, size.y, tier.historyScale);
  const textures = [historyTexture(histW, histH, format, 'frost.history.0'), historyTexture(histW, histH, format, 'frost.history.1')];
  const scheduler = new TileScheduler(params, histW, histH);
  const state = {
    renderer, params, format, bytesPerTexel: TEXEL[format], tierName, tier, size, binning,
    // ---- the history: two ping-pong textures, `current` holds the latest ----------------------------
    histW, histH, textures, current: 0, scheduler,
    // ---- queued input ---------------------------------------------------------------------------------
    pending: [],
    freshFrom: 0, // pending[freshFrom..] were queued since the last update
    origin: null, // where the history's timeline starts: late segments deposit nothing before it
    lastEnd: new Map(), // stream -> where its latest segment ended
    bins: new StepBins(params),
    // ---- uniforms the kernels read --------------------------------------------------------------------
    uHistW: uniform(histW, 'int'),
    uHistH: uniform(histH, 'int'),
    uHistSize: uniform(new Vector2(histW, histH)),
    uStepCount: uniform(0, 'int'),
    uBinSize: uniform(params.tileSize, 'int'),
    uBinsX: uniform(1, 'int'),
    uDecayTotal: uniform(0), // seconds of ordinary (not catch-up) steps in the chunk
    uFirstChunk: uniform(1),
    uTileW: uniform(histW, 'int'),
    uTileH: uniform(histH, 'int'),
    uTilesX: uniform(1, 'int'),
    uTileCount: uniform(0, 'int'),
    uDiffusionRate: uniform(0),
    uOldSize: uniform(new Vector2(1, 1)),
    uOldW: uniform(1, 'int'),
    uOldH: uniform(1, 'int'),
    ...storageBuffers(params, scheduler),
    salts: PLAN.noiseSalts.map((s) => uint(u32(s))),
    // ---- the history as the kernels see it: texture loads and storage writes, re-pointed on resize ----
    read: [texture(textures[0]), texture(textures[1])],
    write: [storageTexture(textures[0]), storageTexture(textures[1])],
    // ---- bookkeeping ----------------------------------------------------------------------------------
    counters: {
      frames: 0, idleFrames: 0, discontinuities: 0, catchUps: 0, dispatches: 0, texelsDispatched: 0,
      lastFrame: null, segmentsQueued: 0, segmentsRejected: 0, resizes: 0, lateSteps: 0, pointerSeconds: 0,
    },
    // ---- the pieces built on this state, set once by createFrostEffect ---------------------------------
    kernels: null, // kernels.js
    composite: null, // composite.js
    readback: null, // readback.js
  };
  return state;
}

/**
 * The storage buffers of one dispatch, at fixed capacity (a storage buffer cannot grow in place), with
 * the typed arrays a frame writes into.
 */
function storageBuffers(params, scheduler) {
  // Per step: [dt, age, decayBefore, 0]: age >= 0 marks a catch-up step (the late part of a segment, see
  // lateSteps), -1 an ordinary one; decayBefore is the ordinary seconds of the chunk's earlier steps.
  const stepBuffer = instancedArray(params.maxSteps, 'vec4');
  // Per (step, segment) pair: [a.u, a.v, b.u, b.v] and [pressure, step, 0, 0].
  const pairBuffer = instancedArray(params.maxPairs * 2, 'vec4');
  // The chunk's pairs binned into tileSize tiles (StepBins, a CSR list): texels loop over their bin only.
  const binCapacity = Math.ceil(4096 / params.tileSize) ** 2 + 1;
  const binStartBuffer = instancedArray(new Uint32Array(binCapacity), 'uint');
  const binEntryBuffer = instancedArray(new Uint32Array(params.binCapacity), 'uint');
  // Every tile of a 4096² history.
  const tileCapacity = Math.max(scheduler.count, Math.ceil(4096 / params.tileSize) ** 2);
  const tileBuffer = instancedArray(new Uint32Array(tileCapacity), 'uint');
  return {
    stepBuffer, stepData: stepBuffer.value.array, pairBuffer, pairData: pairBuffer.value.array,
    binStartBuffer, binEntryBuffer, tileCapacity, tileBuffer,
  };
}
