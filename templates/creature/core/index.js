// Pure-JS entry (no three imports): creature data, LCG, the sway pose, the .glb reader, stateHash.
export { CREATURE } from './data.js';
export { lcgNext, instanceOffset } from './lcg.js';
export { createPoseScratch, rotate, swayTransforms, writePoseRows } from './pose.js';
export { hashBytes } from './hash.js';
export { parseGlb } from './glb.js';
// Locomotion: the fixed-step driver, providers (gravity, support surfaces, water) and the motion core.
export { createDriver, MAX_FRAME_S, MAX_ACCUMULATOR_S } from './motion/driver.js';
export {
  STANDARD_GRAVITY, SWIMMER_CHANNELS, builtinSupports, createAnalyticWater, createFlatGround, createGravity,
  createRotatingPlatform, createSlope, createTranslatingPlatform, toLocal, toWorld,
} from './motion/providers.js';
export { TierRefusedError, createMotion } from './motion/motion.js';
export { derive, ticksFromSeconds } from './motion/derived.js';
