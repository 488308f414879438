// Three/TSL adapter: pose pages, field programs, skinning, the deform pre-pass, materials, population,
// the diagnostic shell (the readback diagnostics are their own entry, `<package>/diagnostics`).
export { OP, createField, rootSize } from './field.js';
export { METHOD, createSkin, rotate } from './skin.js';
export { NO_PROGRAM, SKIN_PROGRAM, bodyFunctions, bodyVertex, layoutOf, selfOcclusion } from './body.js';
export {
  DEFORM_STRIDE, RECORD_STRIDE, createDeformKernel, deformStorage, deformView, dispatchDeform, instanceList, recordInputs,
  PATHS, vertexOrder, vertexRecords,
} from './deform.js';
export {
  DEBUG_MODES, LOOK_DEFORM, LOOK_INTEGERS, LOOK_RANGES, checkDebugMode, checkLook, createBodyMaterial, createLookUniforms, rootNormal, rootPoint, rootRotate,
} from './material.js';
export {
  SHELL_CAP_RINGS, SHELL_RADIAL, SHELL_SNAP_STEPS, SHELL_TIERS, createShellMesh, shellCounts, shellGeometry, shellVertex,
} from './shell.js';
export {
  assertThreeRevision, assertWebGPU, createCreaturePopulation, programStorage, surfaceGeometry,
} from './population.js';
export { SURFACE_FILE, TIER_SURFACE_URLS, defaultSurfaceUrl } from './asset.js';
