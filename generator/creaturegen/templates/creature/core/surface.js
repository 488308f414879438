// Loading the reference surface this package ships, and the checks that make a wrong file or a wrong
// three.js fail loudly instead of drawing something else. Pure JS, no three: the tsl/ adapter passes in
// three's REVISION and the default asset URL (tsl/asset.js, where the one static URL literal lives).
import { CREATURE } from './data.js';
import { parseGlb } from './glb.js';

/**
 * The signatures a .glb must carry to be this package's surface (surface/asset.py writes them;
 * programDigest is the sha256 of the program tapes the file carries, surface/glb.py).
 */
export const SURFACE_KEYS = Object.freeze(['geometryDigest', 'topologySignature', 'compilerSignature', 'tier', 'programDigest']);

/**
 * The fetched .glb is not this package's surface (another package's file under a shared name, a stale
 * copy, or no creaturegen asset at all). Drawing it would skin a foreign mesh with this creature's rig.
 */
export class SurfaceMismatchError extends Error {
  constructor(packageName, url, expected, found, file = CREATURE.surfaceFile) {
    const differing = SURFACE_KEYS.filter((k) => expected[k] !== found[k]);
    super(`${packageName}: ${url} is not this package's surface: geometryDigest ${found.geometryDigest ?? '(none)'}, `
      + `expected ${expected.geometryDigest} (differing: ${differing.join(', ')}); `
      + `serve ${file} of ${packageName}@${CREATURE.version} there, or fix surfaceUrl/assetBase`);
    this.name = 'SurfaceMismatchError';
    this.packageName = packageName;
    this.url = url;
    this.expected = expected;
    this.found = found;
  }
}

/** three.js is not the release the package's TSL was written and tested against. */
export class ThreeRevisionError extends Error {
  constructor(packageName, expected, found) {
    super(`${packageName}: built for three r${expected} (three@0.${expected}.x); found r${found}. `
      + `Install it: npm install three@0.${expected}`);
    this.name = 'ThreeRevisionError';
    this.packageName = packageName;
    this.expected = expected;
    this.found = found;
  }
}

/** Throws ThreeRevisionError unless `revision` (three's REVISION) is the one this package targets. */
export function checkThreeRevision(revision) {
  if (String(revision) !== CREATURE.threeRevision) {
    throw new ThreeRevisionError(CREATURE.slug, CREATURE.threeRevision, String(revision));
  }
}

/** The signatures this package expects of a tier's surface (`tier`: one of CREATURE.tiers; default the first). */
export function expectedSurface(tier = CREATURE) {
  return { ...tier.signatures, tier: tier.tier, programDigest: tier.programDigest };
}

/** Throws SurfaceMismatchError unless the .glb's asset.extras carry the signatures of this package's `tier`. */
export function checkSurface(extras, url, tier = CREATURE) {
  const expected = expectedSurface(tier);
  const found = {};
  for (const key of SURFACE_KEYS) found[key] = typeof extras?.[key] === 'string' ? extras[key] : null;
  if (SURFACE_KEYS.some((k) => found[k] !== expected[k])) {
    throw new SurfaceMismatchError(CREATURE.slug, String(url), expected, found, tier.surfaceFile);
  }
}

// A relative base means "relative to the page", as it would in an <img src>; outside a document it has
// nothing to be relative to.
function absoluteBase(base) {
  const page = globalThis.document?.baseURI ?? globalThis.location?.href;
  try {
    return page === undefined ? new URL(base) : new URL(base, page);
  } catch {
    throw new TypeError(`${CREATURE.slug}: assetBase ${String(base)} is not a URL (outside a page it must be absolute)`);
  }
}

/**
 * Where to fetch the surface from: `surfaceUrl` (the .glb itself), else `new URL(file, assetBase)` (`file`:
 * the tier's surfaceFile, default CREATURE's), else `fallback()` (the package's own copy, resolved by
 * tsl/asset.js or a bundler). Returns a string.
 */
export function resolveSurfaceUrl({ surfaceUrl, assetBase } = {}, fallback, file = CREATURE.surfaceFile) {
  if (surfaceUrl != null && assetBase != null) {
    throw new TypeError(`${CREATURE.slug}: give surfaceUrl (the .glb's own URL) or assetBase (its folder), not both`);
  }
  if (surfaceUrl != null) return String(surfaceUrl);
  if (assetBase != null) return new URL(file, absoluteBase(assetBase)).href;
  return String(fallback());
}

/** Fetch, parse and check the surface of `tier` (default CREATURE's own) at `url`: the parsed .glb (parseGlb), or a named error. */
export async function loadSurface(url, tier = CREATURE) {
  const response = await fetch(url);
  if (!response.ok) {
    throw new Error(`${CREATURE.slug}: cannot load its surface ${url} (HTTP ${response.status}); `
      + `serve ${tier.surfaceFile} there, or point assetBase at the folder that holds it`);
  }
  const surface = parseGlb(await response.arrayBuffer(), url);
  checkSurface(surface.extras, url, tier);
  if (surface.program?.length !== 4 * tier.programRows) {
    throw new SurfaceMismatchError(CREATURE.slug, String(url), expectedSurface(tier), { ...surface.extras, programDigest: null }, tier.surfaceFile);
  }
  return surface;
}
