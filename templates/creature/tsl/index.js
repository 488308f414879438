// Three/TSL adapter: pose pages, field programs, skinning, materials, population, diagnostics.
export { OP, createField } from './field.js';
export { METHOD, createSkin, rotate } from './skin.js';
export { DEBUG_MODES, bodyFunctions, bodyVertex, createBodyMaterial, layoutOf } from './material.js';
export { assertWebGPU, createCreaturePopulation, programStorage, surfaceGeometry } from './population.js';
export { createDiagnostics } from './diagnostics.js';
