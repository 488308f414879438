export * from './core/index.js';
export { DEBUG_MODES, assertThreeRevision, createCreaturePopulation, createDiagnostics } from './tsl/index.js';
