export * from './core/index.js';
export { DEBUG_MODES, createCreaturePopulation, createDiagnostics } from './tsl/index.js';
