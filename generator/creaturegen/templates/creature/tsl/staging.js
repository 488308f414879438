// A population's CPU side of the pose pages: each body's rows written into its page's staging copy, the
// page's posed bounds, and the flush that uploads one coalesced range of changed rows per page, culls the
// page's bodies against the population's views (when it has any) and runs the deform pre-pass over exactly
// the drawn bodies whose rows changed since their last pre-pass (a body standing still, e.g. a hopper
// between hops or a frame with no step and the same interpolation, keeps its stored surface; a culled
// body is neither deformed nor drawn). All in place: the steady frame loop allocates nothing.
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
      if (!page.alive[j] || page.paused[j]) continue;
      const m = page.motions[j];
      for (let k = 0; k < n; k++) m.step();
    }
  }
  state.tick += n;
  state.stats.ticks += n;
}

/**
 * The population's culling views for this flush: each camera's frustum (a shadow-casting light's shadow
 * camera, its matrices brought up to date first) and the group's world matrix, so that bounds in
 * population space can be tested in world space. Nothing is allocated (the frusta exist per view).
 */
export function updateViews(state) {
  const { views, frusta, scratch } = state;
  state.group.updateWorldMatrix(true, false);
  for (let i = 0; i < views.length; i++) {
    let camera = views[i];
    if (camera.isLight) {
      camera.updateMatrixWorld();
      camera.target?.updateMatrixWorld();
      camera.shadow.updateMatrices(camera);
      camera = camera.shadow.camera;
    } else {
      camera.updateMatrixWorld();
    }
    scratch.matrix.multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse);
    frusta[i].setFromProjectionMatrix(scratch.matrix, camera.coordinateSystem, camera.reversedDepth);
  }
}

// Whether body j's posed bounds meet one of the views (without views every body is seen).
function seen(state, page, j) {
  const { frusta, scratch } = state;
  if (frusta.length === 0) return true;
  const b = page.bounds;
  const box = scratch.bodyBox;
  box.min.set(b[6 * j], b[6 * j + 1], b[6 * j + 2]);
  box.max.set(b[6 * j + 3], b[6 * j + 4], b[6 * j + 5]);
  box.applyMatrix4(state.group.matrixWorld);
  for (let i = 0; i < frusta.length; i++) if (frusta[i].intersectsBox(box)) return true;
  return false;
}

/**
 * The page's drawn bodies: its live bodies that a view sees (every live body when the population does not
 * cull), in instance order, into its draw list (uploaded when it changed); the mesh draws that many
 * instances, and its bounding sphere covers them (three's own per-page culling).
 */
export function refreshDrawn(state, page) {
  const { box, corner } = state.scratch;
  box.makeEmpty();
  let n = 0;
  let culled = 0;
  let changed = false;
  const b = page.bounds;
  for (let j = 0; j < page.size; j++) {
    if (!page.alive[j]) continue;
    if (!seen(state, page, j)) { culled++; continue; }
    if (page.drawn[n] !== j) { page.drawn[n] = j; changed = true; }
    n++;
    box.expandByPoint(corner.set(b[6 * j], b[6 * j + 1], b[6 * j + 2]));
    box.expandByPoint(corner.set(b[6 * j + 3], b[6 * j + 4], b[6 * j + 5]));
  }
  if (changed) {
    page.drawList.value.addUpdateRange(0, n);
    page.drawList.value.needsUpdate = true;
  }
  page.culled = culled;
  page.mesh.count = n;
  if (page.shell) page.shell.count = page.mesh.count * state.data.slotCount;
  if (n === 0) page.mesh.boundingSphere.set(page.mesh.boundingSphere.center.set(0, 0, 0), 0);
  else box.getBoundingSphere(page.mesh.boundingSphere);
}

/**
 * The pre-pass over the page's drawn bodies that moved since their last pre-pass: their indices written
 * into the page's instance list (uploaded with the dispatch), one dispatch. A moved body that is culled
 * keeps its flag and is deformed when a view sees it again. Returns the vertices processed.
 */
export function deformMoved(state, page) {
  let n = 0;
  for (let i = 0; i < page.mesh.count; i++) {
    const j = page.drawn[i];
    if (!page.moved[j]) continue;
    page.moved[j] = 0;
    page.listed[n++] = j;
  }
  state.stats.lastFrameDeformedBodies += n;
  if (n === 0) return 0;
  page.list.value.addUpdateRange(0, n);
  page.list.value.needsUpdate = true;
  state.stats.deformDispatches += 1;
  return dispatchDeform(state.renderer, page.kernel, n);
}

/** Re-deform every live body of the page (a new pre-pass kernel: debug mode 'skin-only' and back). */
export function deformAll(state, page) {
  for (let j = 0; j < page.size; j++) page.moved[j] = page.alive[j];
  return deformMoved(state, page);
}

/**
 * One coalesced range per page: [first changed instance, last changed instance], uploaded once per
 * flush; the page's drawn bodies refreshed (every flush when the population culls: the views move); then
 * the drawn bodies that moved deformed once (the uploads ride on the dispatch's binding update).
 * Returns the bytes.
 */
export function flush(state) {
  const { floatsPerInstance, stats } = state;
  const culling = state.views.length > 0;
  if (culling) updateViews(state);
  let bytes = 0;
  let deformed = 0;
  let drawn = 0;
  let culled = 0;
  stats.lastFrameDeformedBodies = 0;
  for (const page of state.pages) {
    const dirty = page.dirtyHi >= 0;
    if (dirty) {
      const start = page.dirtyLo * floatsPerInstance;
      const count = (page.dirtyHi - page.dirtyLo + 1) * floatsPerInstance;
      page.pose.value.addUpdateRange(start, count);
      page.pose.value.needsUpdate = true;
      bytes += 4 * count;
    }
    if (dirty || culling || state.viewsChanged) refreshDrawn(state, page);
    deformed += deformMoved(state, page);
    drawn += page.mesh.count;
    culled += page.culled;
    page.dirtyLo = Infinity;
    page.dirtyHi = -1;
  }
  state.viewsChanged = false;
  stats.lastFrameDeformedVertices = deformed;
  stats.lastFrameDrawnBodies = drawn;
  stats.lastFrameCulledBodies = culled;
  stats.lastFrameBytes = bytes;
  stats.uploadBytes += bytes;
  if (bytes) stats.uploads += 1;
  return bytes;
}
