// The seeded LCG (Numerical Recipes, modulo 2^32): the only source of variation in this package.
// Integer arithmetic, so Python's reference reproduces every draw exactly.

/** Next state of the LCG; `state` is an unsigned 32-bit integer. */
export function lcgNext(state, a, c) {
  return (Math.imul(a, state >>> 0) + c) >>> 0;
}

/** (tick offset in [0, period), yaw in [0, 2π)) of an instance spawned from `seed`: two draws. */
export function instanceOffset(seed, lcg, period) {
  const first = lcgNext(seed >>> 0, lcg.a, lcg.c);
  const second = lcgNext(first, lcg.a, lcg.c);
  return { tickOffset: first % period, yaw: (second / 4294967296) * 2 * Math.PI };
}
