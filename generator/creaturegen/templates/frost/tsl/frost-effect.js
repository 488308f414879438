// The frost/thaw effect on WebGPU: StorageTexture history ping-pong updated by TSL compute, a
// reduced-resolution separable blur, static crystalline structure data textures and a two-scale
// normal-refraction composite feeding RenderPipeline.outputNode (one output transform owner).
// createFrostEffect composes the pieces around one state object (state.js): the structure textures
// (structure.js), the compute kernels (kernels.js), the output pass (composite.js), the history's
// lifetime (history.js), pointer input (intake.js), the frame step (frame.js), the user's controls
// (controls.js) and the diagnostics readbacks (readback.js).
import { REVISION } from 'three/webgpu';
import { PLAN } from '../core/plan.js';
import { checkThreeRevision } from '../core/revision.js';
import { loadStructureTextures } from './structure.js';
import { createState } from './state.js';
// composite.js (with the blur it imports) loads before kernels.js: module-level TSL nodes are created in the
// order the effect has always created them.
import { createComposite } from './composite.js';
import { createKernels } from './kernels.js';
import { bindComposite, clearAll, reset } from './history.js';
import { attachPointer, pointer } from './intake.js';
import { update } from './frame.js';
import { debugView, resize, setControl, setDebugView, setTier } from './controls.js';
import { createReadback, readHistory, readStructure } from './readback.js';

export { DEBUG_VIEWS } from './composite.js';

/**
 * Create the effect. Async because the structure textures are fetched from the package's assets.
 * The renderer must already be initialised on a WebGPU backend: there is no WebGL path. Throws
 * FrostRevisionError outside three r185 and FrostAssetError when the structure file cannot be loaded.
 */
export async function createFrostEffect(renderer, scene, camera, options = {}) {
  checkThreeRevision(REVISION);
  if (renderer.backend?.isWebGPUBackend !== true) {
    throw new Error('createFrostEffect: WebGPU is required (renderer.backend.isWebGPUBackend is not true); '
      + 'await renderer.init() on a WebGPU-capable browser. There is no WebGL fallback for this effect.');
  }
  const tierName = options.tier ?? PLAN.tier.name;
  const tier = PLAN.tiers[tierName];
  if (!tier) throw new Error(`createFrostEffect: unknown tier ${JSON.stringify(tierName)}`);
  const structure = await loadStructureTextures(options.assetBase);
  const state = createState(renderer, tierName, tier, options.binning !== false);
  state.kernels = createKernels(state);
  state.composite = createComposite(state, scene, camera, structure);
  state.readback = createReadback(state);
  bindComposite(state);
  clearAll(state);
  return publicEffect(state, structure);
}

/** The effect object the user holds: every method is one of the pieces above, applied to the state. */
function publicEffect(state, structure) {
  const { counters, format, bytesPerTexel } = state;
  const { pipeline, blur } = state.composite;
  return {
    get tier() { return state.tierName; },
    get historySize() { return [state.histW, state.histH]; },
    get format() { return format; },
    get debugView() { return debugView(state); },
    get counters() { return counters; },
    pointer: (segment) => pointer(state, segment),
    attachPointer: (element, attachOptions = {}) => attachPointer(state, element, attachOptions),
    update: (previousInstant, currentInstant) => update(state, previousInstant, currentInstant),
    render() { pipeline.render(); },
    resize: (width, height, dpr = 1) => resize(state, width, height, dpr),
    setTier: (name) => setTier(state, name),
    setDebugView: (name) => setDebugView(state, name),
    setControl: (name, value) => setControl(state, name, value),
    reset: () => reset(state),
    readHistory: () => readHistory(state),
    readStructure: () => readStructure(state, structure),
    memory() {
      return {
        historyBytesDerived: 2 * state.histW * state.histH * bytesPerTexel,
        historyTextures: state.textures.map((t) => [t.image.width, t.image.height]),
        bytesPerTexel,
        structureBytes: structure.structureBytes.byteLength + structure.normalBytes.byteLength,
      };
    },
    pipeline,
    dispose() {
      state.textures.forEach((t) => t.dispose());
      structure.structureTex.dispose();
      structure.normalTex.dispose();
      blur.dispose();
      pipeline.dispose();
    },
  };
}
