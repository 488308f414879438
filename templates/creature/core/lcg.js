// The seeded LCG (Numerical Recipes, modulo 2^32): the only source of variation in this package.
// Integer arithmetic, so Python's reference (creature/pose.py) reproduces every draw exactly.

/** Next state of the LCG; `state` is an unsigned 32-bit integer. */
export function lcgNext(state, a, c) {
  return (Math.imul(a, state >>> 0) + c) >>> 0;
}

/** Yaw in [0, 2π) of an instance spawned from `seed`: the second draw (the first is reserved). */
export function instanceYaw(seed, lcg) {
  const second = lcgNext(lcgNext(seed >>> 0, lcg.a, lcg.c), lcg.a, lcg.c);
  return (second / 4294967296) * 2 * Math.PI;
}
