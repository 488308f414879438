// Pure-JS entry (no three imports): plan data, time policy, input intervals, tile scheduler, the structure
// file decoder and the three.js release check.
export { PLAN } from './plan.js';
export {
  StepBins, TileScheduler, advanceInstants, chunkSteps, classifyInterval, diffusionSubsteps, lateSteps,
  normalizeSegment, pointerUV, scaledSize, splitInterval, texelBox, tooManyStreams, validateSegment,
} from './frost-core.js';
export { FrostRevisionError, THREE_REVISION, checkThreeRevision } from './revision.js';
export { FrostAssetError, decodeStructureFile } from './structure-file.js';
