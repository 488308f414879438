export { CREATURE, hashBytes, instanceOffset, lcgNext, parseGlb, swayTransforms, writePoseRows } from './core/index.js';
export { DEBUG_MODES, createCreaturePopulation, createDiagnostics } from './tsl/index.js';
