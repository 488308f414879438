// A population's CPU side of the pose pages: each body's rows written into its page's staging copy, the
// page's posed bounds, and the flush that uploads one coalesced range of changed rows per page and runs the
// deform pre-pass over exactly the bodies whose rows changed since their last pre-pass (a body standing
// still, e.g. a hopper between hops or a frame with no step and the same interpolation, keeps its stored
// surface). All in place: the steady frame loop allocates nothing.
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
 * and its world bounds. When any row differs from what the staging copy held, the body is marked moved
 * (its next pre-pass re-deforms it) and its rows join the page's upload range.
 */
export function writeInstance(state, page, j, quats, trans, root) {
  const { data, floatsPerInstance, rootRow, scratch } = state;
  const base = j * floatsPerInstance;
  const size = page.motions[j].size;
  const rows = page.staging;
  const previous = scratch.previous;
  for (let i = 0; i < floatsPerInstance; i++) previous[i] = rows[base + i];
  writePoseRows(data, quats, trans, page.colours, 3 * data.slotCount * j, scratch.tmp, rows, base, scratch.localBox, size);
  writeRootRows(root, page.alive[j], rows, base + rootRow, size);
  rootBounds(scratch.localBox, root, page.bounds, 6 * j);
  let changed = false;
  for (let i = 0; i < floatsPerInstance && !changed; i++) changed = rows[base + i] !== previous[i];
  if (!changed) return;
  page.moved[j] = 1;
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

/**
 * The pre-pass over the page's moved live bodies in its drawn range: their indices written into the
 * page's instance list (uploaded with the dispatch), one dispatch; every moved flag cleared. Returns the
 * vertices processed.
 */
export function deformMoved(state, page) {
  const top = page.mesh.count;
  let n = 0;
  for (let j = 0; j < top; j++) {
    if (page.moved[j] && page.alive[j]) page.listed[n++] = j;
  }
  page.moved.fill(0);
  state.stats.lastFrameDeformedBodies += n;
  if (n === 0) return 0;
  page.list.value.addUpdateRange(0, n);
  page.list.value.needsUpdate = true;
  state.stats.deformDispatches += 1;
  return dispatchDeform(state.renderer, page.kernel, n);
}

/** Re-deform every live body of the page (a new pre-pass kernel: debug mode 'skin-only' and back). */
export function deformAll(state, page) {
  page.moved.fill(1);
  return deformMoved(state, page);
}

/**
 * One coalesced range per page: [first changed instance, last changed instance], uploaded once per
 * flush, then the moved bodies deformed once (the upload rides on the dispatch's binding update).
 * Returns the bytes.
 */
export function flush(state) {
  const { floatsPerInstance, stats } = state;
  let bytes = 0;
  let deformed = 0;
  stats.lastFrameDeformedBodies = 0;
  for (const page of state.pages) {
    if (page.dirtyHi < 0) continue;
    const start = page.dirtyLo * floatsPerInstance;
    const count = (page.dirtyHi - page.dirtyLo + 1) * floatsPerInstance;
    page.pose.value.addUpdateRange(start, count);
    page.pose.value.needsUpdate = true;
    bytes += 4 * count;
    refreshBounds(state, page);
    deformed += deformMoved(state, page);
    page.dirtyLo = Infinity;
    page.dirtyHi = -1;
  }
  stats.lastFrameDeformedVertices = deformed;
  stats.lastFrameBytes = bytes;
  stats.uploadBytes += bytes;
  if (bytes) stats.uploads += 1;
  return bytes;
}
