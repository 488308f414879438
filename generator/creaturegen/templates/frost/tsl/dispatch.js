// Running the history's compute kernels: the dispatch shapes the plan declares, the tile list the tiled
// kernels read, and the dispatch counter (counters.dispatches) every run adds to. Full-field kernels are
// 2-D, [ceil(W/8), ceil(H/8), 1] workgroups of [8, 8, 1] with an extent guard; tiled kernels are linear,
// 64 threads per workgroup, one thread per texel of the listed tiles, with the same guard.
import { PLAN } from '../core/plan.js';

/** Workgroup size of the 2-D kernels. */
export const [WX, WY] = PLAN.params.workgroup2d;
/** Workgroup size of the linear (tiled) kernels. */
export const WL = PLAN.params.workgroupLinear;

export function run(state, node, size) {
  state.renderer.compute(node, size);
  state.counters.dispatches += 1;
}

/** The workgroup grid of a 2-D kernel over the whole history. */
export function dispatch2d(state) {
  return [Math.ceil(state.histW / WX), Math.ceil(state.histH / WY), 1];
}

// Linear kernels: `count` threads (tiles × tile area). Three guards instanceIndex < node.count, so the
// count is set per dispatch as well as the workgroup grid (split into y past 65535 groups).
export function runLinear(state, node, tiles) {
  const threads = tiles * state.scheduler.tileWidth * state.scheduler.tileHeight;
  const groups = Math.ceil(threads / WL);
  node.count = threads;
  run(state, node, groups <= 65535 ? [groups, 1, 1] : [65535, Math.ceil(groups / 65535), 1]);
}

/** Upload the first `count` tile indices of `list` for the next tiled dispatches. */
export function uploadTiles(state, list, count) {
  const { tileBuffer, scheduler } = state;
  const array = tileBuffer.value.array;
  array.set(list.subarray(0, count));
  tileBuffer.value.addUpdateRange(0, count);
  tileBuffer.value.needsUpdate = true;
  state.uTileW.value = scheduler.tileWidth;
  state.uTileH.value = scheduler.tileHeight;
  state.uTilesX.value = scheduler.tilesX;
  state.uTileCount.value = count;
}
