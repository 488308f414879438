// A population's CPU side of the pose pages: each body's rows written into its page's staging copy, the
// page's posed bounds, and the flush that uploads one coalesced dirty range per page and runs the deform
// pre-pass over exactly that range. All in place: the steady frame loop allocates nothing.
import { rootBounds, writePoseRows, writeRootRows } from '../core/pose.js';
import { dispatchDeform } from './deform.js';

/** The page holding instance `id` of `state` and its index `j` there; throws for an id out of range. */
export function locate(state, id) {
  const { capacity, pages, pageSize } = state;
  if (!Number.isInteger(id) || id < 0 || id >= capacity) throw new Error(`id: ${id} is not an instance of this population (0..${capacity - 1})`);
  const page = pages[Math.floor(id / pageSize)];
  return { page, j: id - page.first };
}

/**
 * One body's rows from per-slot transforms and a root (the motion's current step, or its render pose),
 * and its world bounds; marks the instance dirty for the next flush.
 */
export function writeInstance(state, page, j, quats, trans, root) {
  const { data, floatsPerInstance, rootRow, scratch } = state;
  const base = j * floatsPerInstance;
  const size = page.motions[j].size;
  writePoseRows(data, quats, trans, page.colours, 3 * data.slotCount * j, scratch.tmp, page.staging, base, scratch.localBox, size);
  writeRootRows(root, page.alive[j], page.staging, base + rootRow, size);
  rootBounds(scratch.localBox, root, page.bounds, 6 * j);
  page.dirtyLo = Math.min(page.dirtyLo, j);
  page.dirtyHi = Math.max(page.dirtyHi, j);
}

/** Write body `j` of `page` at its motion's current step. */
export function writeCurrent(state, page, j) {
  const m = page.motions[j];
  writeInstance(state, page, j, m.quats, m.trans, m.root);
}

/** Every live body `n` fixed steps on (stepTicks and update share it: same ticks, same state). */
export function advance(state, n) {
  for (const page of state.pages) {
    for (let j = 0; j < page.size; j++) {
      if (!page.alive[j]) continue;
      const m = page.motions[j];
      for (let k = 0; k < n; k++) m.step();
    }
  }
  state.tick += n;
  state.stats.ticks += n;
}

// The page's drawn count (up to its last live body) and bounding sphere over its live bodies' bounds.
function refreshBounds(state, page) {
  const { box, corner } = state.scratch;
  box.makeEmpty();
  let last = -1;
  for (let j = 0; j < page.size; j++) {
    if (!page.alive[j]) continue;
    last = j;
    const b = page.bounds;
    box.expandByPoint(corner.set(b[6 * j], b[6 * j + 1], b[6 * j + 2]));
    box.expandByPoint(corner.set(b[6 * j + 3], b[6 * j + 4], b[6 * j + 5]));
  }
  page.mesh.count = last + 1;
  if (page.shell) page.shell.count = page.mesh.count * state.data.slotCount;
  if (last < 0) page.mesh.boundingSphere.set(page.mesh.boundingSphere.center.set(0, 0, 0), 0);
  else box.getBoundingSphere(page.mesh.boundingSphere);
}

/** The pre-pass over instances lo..hi of a page, clipped to the drawn range (dead ones are skipped). */
export function deformRange(state, page, lo, hi) {
  const top = Math.min(hi, page.mesh.count - 1);
  if (top < lo) return 0;
  state.stats.deformDispatches += 1;
  return dispatchDeform(state.renderer, page.kernel, lo, top);
}

/**
 * One coalesced range per page: [first dirty instance, last dirty instance], uploaded once per flush,
 * then that range deformed once (the upload rides on the dispatch's binding update). Returns the bytes.
 */
export function flush(state) {
  const { floatsPerInstance, stats } = state;
  let bytes = 0;
  let deformed = 0;
  for (const page of state.pages) {
    if (page.dirtyHi < 0) continue;
    const start = page.dirtyLo * floatsPerInstance;
    const count = (page.dirtyHi - page.dirtyLo + 1) * floatsPerInstance;
    page.pose.value.addUpdateRange(start, count);
    page.pose.value.needsUpdate = true;
    bytes += 4 * count;
    refreshBounds(state, page);
    deformed += deformRange(state, page, page.dirtyLo, page.dirtyHi);
    page.dirtyLo = Infinity;
    page.dirtyHi = -1;
  }
  stats.lastFrameDeformedVertices = deformed;
  stats.lastFrameBytes = bytes;
  stats.uploadBytes += bytes;
  if (bytes) stats.uploads += 1;
  return bytes;
}
