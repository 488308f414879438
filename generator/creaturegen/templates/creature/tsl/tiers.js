// The tiers of a population: each shipped tier it was asked for (CREATURE.tiers) with its own surface,
// geometry, program tapes and pose pages, all loaded and allocated before the first frame. A body lives
// in one tier's pages at a time and keeps its population id when it moves: moveBody copies its CPU state
// (locomotion core, genome, colours, pose rows) into a free slot of the other tier, which the next flush
// uploads, deforms and draws. A move creates no GPU object (pages, materials and pipelines exist up
// front), so a crowd can move its bodies by their size on screen every frame (chooseTiers, core/lod.js).
import { GENOME_LENGTH } from '../core/genome.js';
import { chooseTier, projectedSizePx } from '../core/lod.js';
import { loadSurface, resolveSurfaceUrl } from '../core/surface.js';
import { TIER_SURFACE_URLS } from './asset.js';
import { layoutOf } from './body.js';
import { DEFORM_STRIDE, vertexOrder, vertexRecords } from './deform.js';
import { clearSlot, locate } from './staging.js';

/**
 * The shipped tiers named by `names` (default: every tier the package ships), checked, in CREATURE.tiers
 * order (finest first).
 */
export function tierNames(data, names) {
  const shipped = data.tiers.map((t) => t.tier);
  const asked = names ?? shipped;
  if (!Array.isArray(asked) || asked.length === 0) throw new Error(`tiers: a non-empty array of tier names (shipped: ${shipped.join(', ')})`);
  for (const name of asked) {
    if (!shipped.includes(name)) {
      throw new Error(`tiers: this package ships ${shipped.join(', ')} (got ${JSON.stringify(name)}); `
        + `rebuild with --tier ${[...shipped, name].join(',')}`);
    }
  }
  return shipped.filter((name) => asked.includes(name));
}

// The URL of one tier's .glb: `surfaceUrl` (a URL for a one-tier population, or { tier: URL }), else
// the tier's file under `assetBase`, else the package's own copy.
function tierUrl(options, tier) {
  const { surfaceUrl, assetBase } = options;
  const own = surfaceUrl != null && typeof surfaceUrl === 'object' && !(surfaceUrl instanceof URL) ? surfaceUrl[tier.tier] : surfaceUrl;
  return resolveSurfaceUrl({ surfaceUrl: own, assetBase }, TIER_SURFACE_URLS[tier.tier], tier.surfaceFile);
}

/**
 * Load every tier in `names`: its surface (fetched and checked against its signatures), its geometry and
 * program storage, the rest-vertex records and path order of its pre-pass, and the page size one storage
 * binding of the device holds. `build` turns a parsed surface into { geometry, programs } (the population's
 * three.js adapters).
 */
export async function loadTiers(state, names, options, build) {
  const { data, renderer, capacity } = state;
  if (typeof options.surfaceUrl === 'string' || options.surfaceUrl instanceof URL) {
    if (names.length > 1) {
      throw new Error('surfaceUrl: one URL serves one tier; give { tier: URL } for each of '
        + `${names.join(', ')}, or assetBase`);
    }
  }
  const limits = options.tierCapacity ?? {};
  const bindingLimit = renderer.backend.device.limits.maxStorageBufferBindingSize;
  const requestedPageSize = options.pageSize ?? 64;
  return Promise.all(names.map(async (name, index) => {
    const tierData = data.tiers.find((t) => t.tier === name);
    const tierCapacity = limits[name] ?? capacity;
    if (!Number.isInteger(tierCapacity) || tierCapacity < 1 || tierCapacity > capacity) {
      throw new Error(`tierCapacity.${name}: an integer in [1, capacity ${capacity}] (got ${tierCapacity})`);
    }
    const surface = await loadSurface(tierUrl(options, tierData), tierData);
    const { geometry, programs } = build(surface);
    const layout = layoutOf({ ...data, ...tierData });
    // A page's deform storage is one binding: it must fit the device's maxStorageBufferBindingSize.
    const deformBytesPerBody = layout.vertices * DEFORM_STRIDE * 16;
    const fitting = Math.floor(bindingLimit / deformBytesPerBody);
    if (fitting < 1) {
      throw new Error(`${data.slug}: one ${name} body's deform storage (${deformBytesPerBody} bytes) exceeds this `
        + `device's maxStorageBufferBindingSize (${bindingLimit}); build a lighter tier`);
    }
    return {
      name, index, data: tierData, layout, geometry, programs, surface,
      records: vertexRecords(geometry), order: vertexOrder(geometry), vertices: layout.vertices,
      capacity: tierCapacity, pageSize: Math.min(requestedPageSize, tierCapacity, fitting), deformBytesPerBody,
      ceiling: tierData.projectedSizeMaxPx, pages: null,
    };
  }));
}

/** The live bodies `tier` holds. */
export function tierCount(tier) {
  let n = 0;
  for (const page of tier.pages) for (let j = 0; j < page.size; j++) n += page.alive[j];
  return n;
}

/**
 * Move live body `id` into `tier` (a tier state of state.tiers): its CPU state copied into the tier's
 * first free slot, its old slot emptied; both pages' rows are uploaded by the next flush, which deforms
 * and draws it with the new tier. Returns false (and moves nothing) when the tier is full.
 */
export function moveBody(state, id, tier) {
  // No object per call (no locate() or subarray views): chooseTiers moves bodies inside the frame loop.
  if (!Number.isInteger(id) || id < 0 || id >= state.capacity) locate(state, id);  // throws, naming the range
  if (state.bodyPage[id] < 0) throw new Error(`setBodyTier: instance ${id} is not alive`);
  const from = state.pages[state.bodyPage[id]];
  const i = state.bodySlot[id];
  if (from.tier === tier) return true;
  let to = null;
  let j = -1;
  for (let p = 0; p < tier.pages.length && to === null; p++) {
    const page = tier.pages[p];
    for (let k = 0; k < page.size; k++) if (!page.alive[k]) { to = page; j = k; break; }
  }
  if (to === null) { state.stats.tierMovesRefused += 1; return false; }
  const { data, floatsPerInstance } = state;
  const colours = 3 * data.slotCount;
  copyRun(from.genomes, GENOME_LENGTH * i, to.genomes, GENOME_LENGTH * j, GENOME_LENGTH);
  copyRun(from.colours, colours * i, to.colours, colours * j, colours);
  copyRun(from.staging, floatsPerInstance * i, to.staging, floatsPerInstance * j, floatsPerInstance);
  copyRun(from.bounds, 6 * i, to.bounds, 6 * j, 6);
  to.motions[j] = from.motions[i];
  to.alive[j] = 1;
  to.paused[j] = from.paused[i];
  to.seed[j] = from.seed[i];
  to.spawnTick[j] = from.spawnTick[i];
  to.ids[j] = id;
  // Its surface in this tier's deform storage is not written yet: the next pre-pass deforms it.
  to.moved[j] = 1;
  to.dirtyLo = Math.min(to.dirtyLo, j);
  to.dirtyHi = Math.max(to.dirtyHi, j);
  clearSlot(state, from, i);
  state.bodyPage[id] = to.index;
  state.bodySlot[id] = j;
  state.stats.tierMoves += 1;
  return true;
}

function copyRun(source, from, target, to, count) {
  for (let k = 0; k < count; k++) target[to + k] = source[from + k];
}

/**
 * Each live body's length on screen (CREATURE.bodyScale × its size gene, at the view depth of its posed
 * bounds' centre) from `camera` in a viewport `viewportHeight` pixels tall, and the tier chooseTier gives
 * it (hysteresis from the tier it is in), moved there when that differs. The sizes are kept per body
 * (state.sizePx) for instance(). Allocates nothing. Returns the bodies moved.
 */
export function chooseTiers(state, camera, viewportHeight) {
  const { tiers, ceilings, sizePx, chosen, data } = state;
  if (!(viewportHeight > 0)) throw new Error(`chooseTiers: viewportHeight in pixels, > 0 (got ${viewportHeight})`);
  camera.updateMatrixWorld();
  state.group.updateWorldMatrix(true, false);
  const g = state.group.matrixWorld.elements;
  const v = camera.matrixWorldInverse.elements;
  // The group's scale carries L with it (its largest axis scale, as three's getMaxScaleOnAxis).
  const scale = Math.sqrt(Math.max(g[0] * g[0] + g[1] * g[1] + g[2] * g[2], g[4] * g[4] + g[5] * g[5] + g[6] * g[6],
    g[8] * g[8] + g[9] * g[9] + g[10] * g[10]));
  let moved = 0;
  // A body moved into a tier not yet visited is not asked again this call.
  const epoch = (state.chooseEpoch = (state.chooseEpoch + 1) >>> 0);
  for (let t = 0; t < tiers.length; t++) {
    const pages = tiers[t].pages;
    for (let p = 0; p < pages.length; p++) {
      const page = pages[p];
      for (let j = 0; j < page.size; j++) {
        if (!page.alive[j]) continue;
        const id = page.ids[j];
        if (chosen[id] === epoch) continue;
        chosen[id] = epoch;
        const b = page.bounds;
        const o = 6 * j;
        const cx = 0.5 * (b[o] + b[o + 3]), cy = 0.5 * (b[o + 1] + b[o + 4]), cz = 0.5 * (b[o + 2] + b[o + 5]);
        const wx = g[0] * cx + g[4] * cy + g[8] * cz + g[12];
        const wy = g[1] * cx + g[5] * cy + g[9] * cz + g[13];
        const wz = g[2] * cx + g[6] * cy + g[10] * cz + g[14];
        const depth = -(v[2] * wx + v[6] * wy + v[10] * wz + v[14]);
        const size = projectedSizePx(data.bodyScale * page.motions[j].size * scale, depth, viewportHeight, camera);
        sizePx[id] = size;
        const next = chooseTier(size, page.tier.name, ceilings);
        if (next !== page.tier.name && moveBody(state, id, state.tierByName[next])) moved++;
      }
    }
  }
  return moved;
}
