// A population's CPU side of the pose pages: each body's rows written into its page's staging copy, the
// page's posed bounds, and the flush that uploads one coalesced range of changed rows per page, culls the
// page's bodies against the population's views (when it has any) and runs the deform pre-pass over exactly
// the drawn bodies whose rows changed since their last pre-pass (a body standing still, e.g. a hopper
// between hops or a frame with no step and the same interpolation, keeps its stored surface; a culled
// body is neither deformed nor drawn). All in place: the steady frame loop allocates nothing.
import { WebGLCoordinateSystem, WebGPUCoordinateSystem } from 'three/webgpu';
import { GENOME_LENGTH } from '../core/genome.js';
import { rootBounds, writePoseRows, writeRootRows } from '../core/pose.js';
import { dispatchDeform } from './deform.js';

/**
 * The page holding instance `id` of `state` and its index `j` there ({ page: null, j: -1 } for an id no
 * live body has); throws for an id out of range.
 */
export function locate(state, id) {
  const { capacity, pages, bodyPage, bodySlot } = state;
  if (!Number.isInteger(id) || id < 0 || id >= capacity) throw new Error(`id: ${id} is not an instance of this population (0..${capacity - 1})`);
  const p = bodyPage[id];
  return p < 0 ? { page: null, j: -1 } : { page: pages[p], j: bodySlot[id] };
}

/** The first free slot of `tier`'s pages: { page, j }, or null when the tier holds `tier.capacity` bodies. */
export function freeSlot(tier) {
  for (const page of tier.pages) for (let j = 0; j < page.size; j++) if (!page.alive[j]) return { page, j };
  return null;
}

/** Empty slot `j` of `page` (its rows zeroed and uploaded: the root row's alive flag with them). */
export function clearSlot(state, page, j) {
  const { data, floatsPerInstance } = state;
  page.alive[j] = 0;
  page.paused[j] = 0;
  page.motions[j] = null;
  page.ids[j] = -1;
  page.genomes.fill(0, GENOME_LENGTH * j, GENOME_LENGTH * (j + 1));
  page.colours.fill(0, 3 * data.slotCount * j, 3 * data.slotCount * (j + 1));
  page.staging.fill(0, j * floatsPerInstance, (j + 1) * floatsPerInstance);
  page.moved[j] = 0;
  page.dirtyLo = Math.min(page.dirtyLo, j);
  page.dirtyHi = Math.max(page.dirtyHi, j);
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

// Plane k of a view at planes[o + 4k ..]: (x, y, z, w) divided by |(x, y, z)|, as three's Plane
// setComponents(x, y, z, w).normalize() computes it.
function setPlane(planes, o, k, x, y, z, w) {
  const inverseLength = 1.0 / Math.sqrt(x * x + y * y + z * z);
  const p = o + 4 * k;
  planes[p] = x * inverseLength;
  planes[p + 1] = y * inverseLength;
  planes[p + 2] = z * inverseLength;
  planes[p + 3] = w * inverseLength;
}

/**
 * The six planes of the frustum of the view-projection matrix `me` (its elements) into planes[o .. o + 24):
 * three's Frustum.setFromProjectionMatrix, formula for formula, written into a Float64Array instead of
 * Plane objects (whose double fields V8 boxes anew on every store: 140 B per frame and view).
 */
function frustumPlanes(me, coordinateSystem, reversedDepth, planes, o) {
  setPlane(planes, o, 0, me[3] - me[0], me[7] - me[4], me[11] - me[8], me[15] - me[12]);
  setPlane(planes, o, 1, me[3] + me[0], me[7] + me[4], me[11] + me[8], me[15] + me[12]);
  setPlane(planes, o, 2, me[3] + me[1], me[7] + me[5], me[11] + me[9], me[15] + me[13]);
  setPlane(planes, o, 3, me[3] - me[1], me[7] - me[5], me[11] - me[9], me[15] - me[13]);
  if (reversedDepth) {
    setPlane(planes, o, 4, me[2], me[6], me[10], me[14]);
    setPlane(planes, o, 5, me[3] - me[2], me[7] - me[6], me[11] - me[10], me[15] - me[14]);
  } else {
    setPlane(planes, o, 4, me[3] - me[2], me[7] - me[6], me[11] - me[10], me[15] - me[14]);
    if (coordinateSystem === WebGLCoordinateSystem) setPlane(planes, o, 5, me[3] + me[2], me[7] + me[6], me[11] + me[10], me[15] + me[14]);
    else if (coordinateSystem === WebGPUCoordinateSystem) setPlane(planes, o, 5, me[2], me[6], me[10], me[14]);
    else throw new Error(`cullWith: a camera with an unknown coordinate system (${coordinateSystem})`);
  }
}

/**
 * The population's culling views for this flush: each camera's frustum (a shadow-casting light's shadow
 * camera, its matrices brought up to date first) as six planes in `state.planes`, and the group's world
 * matrix in `state.groupMatrix`, so that bounds in population space are tested in world space. Plain
 * Float64Arrays: the per-body test below stores no double into an object (which V8 may box), so the
 * steady loop allocates nothing.
 */
export function updateViews(state) {
  const { views, planes, groupMatrix, scratch } = state;
  state.group.updateWorldMatrix(true, false);
  groupMatrix.set(state.group.matrixWorld.elements);
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
    frustumPlanes(scratch.matrix.elements, camera.coordinateSystem, camera.reversedDepth, planes, 24 * i);
  }
}

// Whether body j's posed bounds meet one of the views (without views every body is seen): the box's centre
// and half extents carried into world space by the group's affine matrix (|M| for the extents), then for
// each frustum the plane test of its farthest corner along the plane's normal (three's Frustum.intersectsBox).
function seen(state, page, j) {
  const views = state.views.length;
  if (views === 0) return true;
  const b = page.bounds;
  const m = state.groupMatrix;
  const planes = state.planes;
  const o = 6 * j;
  const cx = 0.5 * (b[o] + b[o + 3]), cy = 0.5 * (b[o + 1] + b[o + 4]), cz = 0.5 * (b[o + 2] + b[o + 5]);
  const ex = 0.5 * (b[o + 3] - b[o]), ey = 0.5 * (b[o + 4] - b[o + 1]), ez = 0.5 * (b[o + 5] - b[o + 2]);
  const wx = m[0] * cx + m[4] * cy + m[8] * cz + m[12];
  const wy = m[1] * cx + m[5] * cy + m[9] * cz + m[13];
  const wz = m[2] * cx + m[6] * cy + m[10] * cz + m[14];
  const hx = Math.abs(m[0]) * ex + Math.abs(m[4]) * ey + Math.abs(m[8]) * ez;
  const hy = Math.abs(m[1]) * ex + Math.abs(m[5]) * ey + Math.abs(m[9]) * ez;
  const hz = Math.abs(m[2]) * ex + Math.abs(m[6]) * ey + Math.abs(m[10]) * ez;
  for (let v = 0; v < views; v++) {
    let inside = true;
    for (let k = 0; k < 6 && inside; k++) {
      const p = 24 * v + 4 * k;
      const nx = planes[p], ny = planes[p + 1], nz = planes[p + 2];
      const reach = Math.abs(nx) * hx + Math.abs(ny) * hy + Math.abs(nz) * hz;
      inside = nx * wx + ny * wy + nz * wz + planes[p + 3] + reach >= 0;
    }
    if (inside) return true;
  }
  return false;
}

/**
 * The one update range of a storage attribute the population uploads (pose rows, instance and draw lists),
 * reused for the attribute's life: its `updateRanges` become a fixed one-entry list that three's backend
 * reads as it reads the array (length, then [i]) and its `clearUpdateRanges` only sets the length back to
 * 0. three's own pair allocates every frame: addUpdateRange a range object per call, and clearUpdateRanges
 * sets the array's length to 0, on which V8 drops the array's backing store, so the next push allocates
 * another (1.5 kB per frame for 16 pages). Returns the range object.
 */
export function uploadRange(attribute) {
  const range = { start: 0, count: 0 };
  const list = { length: 0, 0: range };
  attribute.updateRanges = list;
  attribute.clearUpdateRanges = () => { list.length = 0; };
  return range;
}

/**
 * Mark `count` elements from `start` of an attribute set up by uploadRange for the next upload: its one
 * range, merged with a pending upload (the span of both).
 */
function markRange(attribute, range, start, count) {
  const ranges = attribute.updateRanges;
  if (ranges.length === 0) {
    range.start = start;
    range.count = count;
    ranges.length = 1;
  } else {
    const end = Math.max(range.start + range.count, start + count);
    range.start = Math.min(range.start, start);
    range.count = end - range.start;
  }
  attribute.needsUpdate = true;
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
  if (changed) markRange(page.drawList.value, page.ranges.drawList, 0, n);
  page.culled = culled;
  page.mesh.count = n;
  if (page.shell) page.shell.count = page.mesh.count * state.data.slotCount;
  if (n === 0) page.mesh.boundingSphere.set(page.mesh.boundingSphere.center.set(0, 0, 0), 0);
  else box.getBoundingSphere(page.mesh.boundingSphere);
}

/**
 * The pre-pass over the page's drawn bodies that moved since their last pre-pass: their indices written
 * into the page's instance list (uploaded with the dispatch), one dispatch per path (deform.js vertexOrder). A moved body that is culled
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
  markRange(page.list.value, page.ranges.list, 0, n);
  state.stats.deformDispatches += page.kernel.kernels.length;
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
      markRange(page.pose.value, page.ranges.pose, start, count);
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
