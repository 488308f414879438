// Pure-JS entry (no three imports): plan data, time policy, input intervals, tile scheduler.
export { PLAN } from './plan.js';
export {
  TileScheduler, chunkSteps, classifyInterval, diffusionSubsteps, normalizeSegment, pointerUV, scaledSize,
  splitInterval, validateSegment,
} from './frost-core.js';
