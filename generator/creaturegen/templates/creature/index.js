export * from './core/index.js';
export { DEBUG_MODES, assertThreeRevision, createCreaturePopulation } from './tsl/index.js';
