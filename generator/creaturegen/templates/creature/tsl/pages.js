// The pose pages of a population: fixed-capacity slices of bodies, each with its vec4 pose storage (and the
// CPU staging copy it uploads from), its deform storage, one mesh drawn once per pass, and the material
// and pre-pass kernel of the debug mode shown. Everything here is created before the first visible frame
// (createCreaturePopulation and warm()); a spawn only writes rows into a page that already exists.
import * as THREE from 'three/webgpu';
import { instancedArray } from 'three/tsl';
import { GENOME_LENGTH } from '../core/genome.js';
import { bodyFunctions } from './body.js';
import { createDeformKernel, deformStorage, deformView, instanceList } from './deform.js';
import { createBodyMaterial } from './material.js';
import { createShellMesh } from './shell.js';
import { uploadRange } from './staging.js';

/**
 * Allocate every page of one tier of `state` (`tier.capacity` bodies in pages of `tier.pageSize`, each
 * drawing `tier.geometry`) and add their meshes; `index` is the first page's place in state.pages.
 */
export function createPages(state, tier, index) {
  const { data, floatsPerInstance, group } = state;
  const { capacity, pageSize, geometry, vertices } = tier;
  const pages = [];
  for (let first = 0; first < capacity; first += pageSize) {
    const size = Math.min(pageSize, capacity - first);
    const pose = instancedArray(new Float32Array(size * floatsPerInstance), 'vec4').setName('cgPose'); // deformStorage
    const mesh = new THREE.Mesh(geometry, null);
    mesh.count = 0;
    mesh.castShadow = true;
    mesh.receiveShadow = true;
    mesh.boundingSphere = new THREE.Sphere(new THREE.Vector3(), 0);
    mesh.name = `${data.slug}.${tier.name}.page${pages.length}`;
    group.add(mesh);
    const deform = deformStorage(size, vertices);
    const list = instanceList(size, 'cgList');
    const drawList = instanceList(size, 'cgDrawList');
    pages.push({
      // The tier this page draws (its geometry, programs and layout), its place in state.pages, and the
      // population id of the body in each slot (-1: free; a body keeps its id when it changes tier).
      tier, index: index + pages.length, ids: new Int32Array(size).fill(-1),
      first, size, pose, mesh, staging: pose.value.array, deform, deformView: deformView(deform), kernels: new Map(), shell: null,
      // The bodies the next pre-pass runs (list, its CPU copy `listed`), and which bodies' rows changed
      // since their last pre-pass (`moved`): a body whose pose stood still is not deformed again.
      list, listed: list.value.array, moved: new Uint8Array(size),
      // The bodies the passes draw (drawList, its CPU copy `drawn`: live and, when the population culls,
      // seen by one of its views), in instance order; mesh.count is how many.
      drawList, drawn: drawList.value.array, culled: 0,
      // One reusable update range per uploaded attribute (staging.js uploadRange, markRange).
      ranges: { pose: uploadRange(pose.value), list: uploadRange(list.value), drawList: uploadRange(drawList.value) },
      alive: new Uint8Array(size), paused: new Uint8Array(size), seed: new Uint32Array(size), spawnTick: new Float64Array(size),
      motions: new Array(size).fill(null), bounds: new Float64Array(6 * size),
      genomes: new Float64Array(GENOME_LENGTH * size), colours: new Float64Array(3 * data.slotCount * size),
      dirtyLo: Infinity, dirtyHi: -1,
    });
  }
  return pages;
}

/** The pre-pass variant of a debug mode: 'skin-only' stores uncorrected positions, every other mode the body. */
export const kernelKind = (m) => (m === 'skin-only' ? 'skin-only' : 'body');

// One material per (signatures, tier, outline, mode, registers) and page: built on first use, kept for reuse.
// The look (roughness, metalness, the distance view's range) is not in the key: it is uniforms every variant
// shares (state.look), written by setLook. The outline term is 'none': no outline pass is built yet.
function materialFor(state, page, m) {
  const { variants } = state;
  const { data, layout } = page.tier;
  const shown = m === 'shell' ? 'off' : m;
  const key = `${[data.signatures.compilerSignature, data.signatures.topologySignature, data.tier, 'outline:none', shown, data.registers].join('|')}`
    + `|page${page.index}`;
  if (!variants.has(key)) variants.set(key, createBodyMaterial(layout, page.pose, page.deformView, page.drawList, shown, state.look));
  return variants.get(key);
}

function kernelFor(state, page, kind) {
  if (!page.kernels.has(kind)) {
    const { layout, programs, records, order, vertices } = page.tier;
    const fns = bodyFunctions(layout, page.pose, programs);
    page.kernels.set(kind, createDeformKernel(layout, fns, {
      pose: page.pose, records, order, deform: page.deform, list: page.list, size: page.size, vertices, skinOnly: kind === 'skin-only', look: state.look,
    }));
  }
  return page.kernels.get(kind);
}

/** Show debug mode `m` on `page`: its material, its pre-pass kernel, and the snapped shell for 'shell'. */
export function showMode(state, page, m) {
  const { data, group } = state;
  const { layout } = page.tier;
  page.mesh.material = materialFor(state, page, m);
  page.kernel = kernelFor(state, page, kernelKind(m));
  if (m === 'shell' && !page.shell) {
    const fns = bodyFunctions(layout, page.pose, page.tier.programs);
    page.shell = createShellMesh(layout, fns, page.pose, page.drawList, page.mesh.name, page.tier.data.tier);
    page.shell.boundingSphere = page.mesh.boundingSphere;
    group.add(page.shell);
  }
  page.mesh.visible = m !== 'shell';
  if (page.shell) {
    page.shell.visible = m === 'shell';
    page.shell.count = page.mesh.count * data.slotCount;
  }
}
