// three r185 WebGPU/TSL entry: the effect, its blur node, its asset URLs.
export { DEBUG_VIEWS, createFrostEffect } from './frost-effect.js';
export { SeparableBlurNode, gaussianWeights } from './separable-blur.js';
export { ASSET_FILES, assetUrl } from './assets.js';
