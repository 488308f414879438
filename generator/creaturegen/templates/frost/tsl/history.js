// The history's lifetime: its size, the composite's binding to its two textures, clearing, reset, and
// reallocation when the drawing buffer or the tier changes size. Reallocation follows the plan's resize
// policy: 'clear' starts the new history empty, 'preserve-remap' resamples the old one into it (bilinear)
// and, since any tile may then hold frost, bounds every tile by the old history's largest values.
import { clamp, int, ivec2 } from 'three/tsl';
import { TileScheduler, scaledSize } from '../core/frost-core.js';
import { historyTexture } from './state.js';
import { dispatch2d, run, runLinear, uploadTiles } from './dispatch.js';

/** Load texel (x, y) of a history texture node, clamped to the history's extent. */
export function loadClamped(state, src, x, y) {
  const { uHistW, uHistH } = state;
  return src.load(ivec2(clamp(x, int(0), uHistW.sub(1)), clamp(y, int(0), uHistH.sub(1))));
}

/** Point the composite at the history before the latest update (prev) and after it (next). */
export function bindComposite(state) {
  const { composite, textures, current } = state;
  composite.histPrev.value = textures[1 - current];
  composite.histNext.value = textures[current];
}

export function setHistorySize(state, w, h) {
  state.histW = w;
  state.histH = h;
  state.uHistW.value = w;
  state.uHistH.value = h;
  state.uHistSize.value.set(w, h);
  state.scheduler = new TileScheduler(state.params, w, h);
  if (state.scheduler.count > state.tileCapacity) {
    throw new Error(`frost: a ${w}x${h} history needs ${state.scheduler.count} tiles, more than the ${state.tileCapacity} allocated`);
  }
}

/** Zero every tile of both history textures. */
export function clearAll(state) {
  const { scheduler } = state;
  uploadTiles(state, Uint32Array.from({ length: scheduler.count }, (_, i) => i), scheduler.count);
  runLinear(state, state.kernels.clear, scheduler.count);
}

/** Clear the history and drop queued input (the reset policy, on request). */
export function reset(state) {
  state.pending.length = 0;
  state.freshFrom = 0;
  state.origin = null;
  state.lastEnd.clear();
  state.scheduler = new TileScheduler(state.params, state.histW, state.histH);
  clearAll(state);
  state.current = 0;
  bindComposite(state);
}

/**
 * Resize the history for a drawing buffer of drawingWidth × drawingHeight pixels at the current tier's
 * history scale. Returns true if the old history was remapped into the new one, false if it was cleared
 * or the size did not change.
 */
export function reallocate(state, drawingWidth, drawingHeight) {
  const { textures, read, write, kernels, counters } = state;
  const [w, h] = scaledSize(drawingWidth, drawingHeight, state.tier.historyScale);
  if (w === state.histW && h === state.histH) return false;
  const old = textures[state.current];
  const [oldW, oldH] = [state.histW, state.histH];
  const [boundV, boundA] = state.scheduler.maxBounds();
  const fresh = [historyTexture(w, h, state.format, 'frost.history.0'), historyTexture(w, h, state.format, 'frost.history.1')];
  read[0].value = fresh[0];
  read[1].value = fresh[1];
  write[0].value = fresh[0];
  write[1].value = fresh[1];
  setHistorySize(state, w, h);
  const remap = state.params.resizePolicy === 'preserve-remap' && counters.frames > 0;
  if (remap) {
    kernels.oldRead.value = old;
    state.uOldSize.value.set(oldW, oldH);
    state.uOldW.value = oldW;
    state.uOldH.value = oldH;
    run(state, kernels.remap, dispatch2d(state));
    state.scheduler.markAll(boundV, boundA);
  } else {
    clearAll(state);
  }
  textures[0].dispose();
  textures[1].dispose();
  textures[0] = fresh[0];
  textures[1] = fresh[1];
  state.current = 0;
  bindComposite(state);
  counters.resizes += 1;
  return remap;
}
