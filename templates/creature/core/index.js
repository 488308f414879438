// Pure-JS entry (no three imports): creature data, LCG, the sway pose, the .glb reader, stateHash.
export { CREATURE } from './data.js';
export { lcgNext, instanceOffset } from './lcg.js';
export { createPoseScratch, rotate, swayTransforms, writePoseRows } from './pose.js';
export { hashBytes } from './hash.js';
export { parseGlb } from './glb.js';
