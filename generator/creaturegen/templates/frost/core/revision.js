// Pure JS, zero three imports: the three.js release check. The runtime passes three's REVISION in, so this
// module stays free of three and testable on its own.
import { PLAN } from './plan.js';

/** The installed three.js is not the release this package was written for. */
export class FrostRevisionError extends Error {
  constructor(message) {
    super(message);
    this.name = 'FrostRevisionError';
  }
}

/** The three.js revision this package requires, e.g. '185'. */
export const THREE_REVISION = PLAN.three.revision;

/**
 * Throw FrostRevisionError unless `revision` (three's REVISION, e.g. '185' or '185dev') is this package's.
 * TSL and the WebGPU renderer change between releases, so another release fails loudly here instead of
 * compiling wrong shaders.
 */
export function checkThreeRevision(revision) {
  const found = /^\d+/.exec(String(revision))?.[0] ?? String(revision);
  if (found !== THREE_REVISION) {
    throw new FrostRevisionError(`frost: this package is built for three r${THREE_REVISION} `
      + `(three@0.${THREE_REVISION}.x); found r${found}`);
  }
}
