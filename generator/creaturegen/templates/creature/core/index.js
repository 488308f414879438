// Pure-JS entry (no three imports): creature data, LCG, pose rows, the .glb reader, stateHash, and the
// locomotion core (driver, providers, motion) that poses every body.
export { CREATURE } from './data.js';
export { LCG, LCG_A, LCG_C, lcgNext, instanceYaw, mixSeed } from './lcg.js';
export {
  GENOME_LENGTH, SIZE_DRAW, drawGenome, express, expressGait, expressSize, genomeColours, individualSize,
} from './genome.js';
export { POSE_ROWS, rootBounds, rotate, writePoseRows, writeRootRows } from './pose.js';
export { hashBytes } from './hash.js';
export { parseGlb } from './glb.js';
// The surface loader's checks: the .glb's signatures and three's REVISION, each with a named error.
export {
  SURFACE_KEYS, SurfaceMismatchError, ThreeRevisionError, checkSurface, checkThreeRevision, expectedSurface, loadSurface,
  resolveSurfaceUrl,
} from './surface.js';
// Locomotion: the fixed-step driver, providers (gravity, support surfaces, water) and the motion core.
export { createDriver, MAX_FRAME_S, MAX_ACCUMULATOR_S } from './motion/driver.js';
export {
  STANDARD_GRAVITY, SWIMMER_CHANNELS, builtinSupports, createAnalyticWater, createFlatGround, createGravity,
  createRotatingPlatform, createSlope, createTranslatingPlatform, toLocal, toWorld,
} from './motion/providers.js';
export { TierRefusedError, assertWaterFor, createMotion } from './motion/motion.js';
export { derive, ticksFromSeconds } from './motion/derived.js';
// The projected-size contract a body's tier is chosen by (CREATURE.projectedSizeMaxPx per built tier).
export { TIER_HYSTERESIS, TIER_ORDER, chooseTier, projectedSizePx } from './lod.js';
