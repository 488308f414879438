export { FrostAssetError, FrostRevisionError, PLAN, pointerUV, TileScheduler } from './core/index.js';
export { DEBUG_VIEWS, createFrostEffect } from './tsl/index.js';
