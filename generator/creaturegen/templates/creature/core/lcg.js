// The seeded LCG (Numerical Recipes, modulo 2^32): the only source of variation in this package.
// Integer arithmetic, so Python's reference (model/lcg.py) reproduces every draw exactly.

/** The multiplier and increment of state' = (a·state + c) mod 2^32 (creaturegen model/lcg.py LCG_A, LCG_C). */
export const LCG_A = 1664525;
export const LCG_C = 1013904223;
/** The LCG every instance stream uses, as drawGenome, instanceYaw and createMotion take it. */
export const LCG = Object.freeze({ a: LCG_A, c: LCG_C });

/** Next state of the LCG; `state` is an unsigned 32-bit integer. */
export function lcgNext(state, a, c) {
  return (Math.imul(a, state >>> 0) + c) >>> 0;
}

/**
 * The first state of an instance's LCG stream: `seed` through murmur3's 32-bit finaliser. An LCG is affine,
 * so the k-th draws of consecutive seeds would form an arithmetic progression (spawn seeds 0, 1, 2, … on a
 * regular lattice of headings and genes); the finaliser decorrelates them.
 */
export function mixSeed(seed) {
  let h = seed >>> 0;
  h ^= h >>> 16;
  h = Math.imul(h, 0x85ebca6b) >>> 0;
  h ^= h >>> 13;
  h = Math.imul(h, 0xc2b2ae35) >>> 0;
  h ^= h >>> 16;
  return h >>> 0;
}

/** Yaw in [0, 2π) of an instance spawned from `seed`: the second draw of its stream (the first is reserved). */
export function instanceYaw(seed, lcg) {
  const second = lcgNext(lcgNext(mixSeed(seed), lcg.a, lcg.c), lcg.a, lcg.c);
  return (second / 4294967296) * 2 * Math.PI;
}
