// Genomes: what makes one spawned individual differ from another, drawn from its seed by the LCG, the same
// scalar arithmetic in the same order as creaturegen's Python reference (model/genome.py, and
// motion/express.py for the motion data), so the two agree bit for bit. Genes are signed draws in [-1, 1) of
// the stream from mixSeed(seed): draw 1 is reserved, draw 2 is the heading (instanceYaw), draws 3, 4, 5 are
// hue, chroma and lightness, draws 6, 7, 8 the gait genes, draw 9 the size.
//
// Size is a similarity of the certified body (the only morphology a spawn carries): its rest geometry
// (pose.js writePoseRows, tsl/body.js) and every motion length (expressSize) scale by 1 + size·gene, so
// the same mesh stays valid; gravity is not scaled, so speeds scale by its square root (Froude
// similarity). Proportions are build-time identities.
//
// Colour genes act in OKLab on the authored sRGB colours (their OKLab coordinates are computed at build
// time, CREATURE.slotLab): one hue rotation, chroma scale and lightness shift per individual, converted
// back to linear rgb with cubes and 3×3 products (no cube root) and clamped to [0, 1].

import { lcgNext, mixSeed } from './lcg.js';
import { sincos } from './motion/trig.js';

export const HUE_DRAW = 3;
export const CHROMA_DRAW = 4;
export const LIGHTNESS_DRAW = 5;
export const GAIT_DRAW = 6;
export const MAX_GAIT_GENES = 3;
export const SIZE_DRAW = GAIT_DRAW + MAX_GAIT_GENES;
/** Floats in a genome array: hue, chroma, lightness, MAX_GAIT_GENES gait genes, then size. */
export const GENOME_LENGTH = 4 + MAX_GAIT_GENES;

/** Write the genome of the individual spawned from `seed` into `out` (GENOME_LENGTH floats). */
export function drawGenome(seed, lcg, out = new Float64Array(GENOME_LENGTH)) {
  let state = mixSeed(seed);
  for (let draw = 1; draw <= SIZE_DRAW; draw++) {
    state = lcgNext(state, lcg.a, lcg.c);
    if (draw >= HUE_DRAW) out[draw - HUE_DRAW] = state / 2147483648 - 1;
  }
  return out;
}

const clamp01 = (x) => Math.min(1, Math.max(0, x));
const scratch = new Float64Array(3); // angle, sin, cos

/**
 * Per-slot linear rgb of an individual into `out` at offset `o` (3 floats per slot), from the plan's
 * genetics bounds and per-slot OKLab (`data.genetics`, `data.slotLab`) and a genome from drawGenome.
 */
export function genomeColours(data, genome, out, o = 0) {
  const g = data.genetics;
  scratch[0] = g.hueRad * genome[0];
  sincos(scratch, 0, scratch, 1);
  const sin = scratch[1], cos = scratch[2];
  const scale = 1 + g.chroma * genome[1];
  const shift = g.lightness * genome[2];
  const lab = data.slotLab;
  for (let s = 0; s < lab.length; s++) {
    const L = clamp01(lab[s][0] + shift);
    const a = (cos * lab[s][1] - sin * lab[s][2]) * scale;
    const b = (sin * lab[s][1] + cos * lab[s][2]) * scale;
    const l_ = 1.0 * L + 0.3963377774 * a + 0.2158037573 * b;
    const m_ = 1.0 * L + -0.1055613458 * a + -0.0638541728 * b;
    const s_ = 1.0 * L + -0.0894841775 * a + -1.2914855480 * b;
    const lc = l_ * l_ * l_, mc = m_ * m_ * m_, sc3 = s_ * s_ * s_;
    out[o + 3 * s] = clamp01(4.0767416621 * lc + -3.3077115913 * mc + 0.2309699292 * sc3);
    out[o + 3 * s + 1] = clamp01(-1.2684380046 * lc + 2.6097574011 * mc + -0.3413193965 * sc3);
    out[o + 3 * s + 2] = clamp01(-0.0041960863 * lc + -0.7034186147 * mc + 1.7076147010 * sc3);
  }
  return out;
}

/**
 * The motion data of an individual: gait gene i scales every field of `motion.genes.fields[i]` by
 * 1 + jitter·gene (a walker's pace scales speed and stepLength together, capped at its reach limit,
 * motion.stepLimit). Returns a new object; `motion` is not modified.
 */
export function expressGait(motion, genome) {
  const genes = motion.genes;
  const expressed = { ...motion };
  genes.fields.forEach((group, i) => {
    let factor = 1 + genes.jitter * genome[3 + i];
    if (group.includes('stepLength') && motion.stepLength > 0) factor = Math.min(factor, motion.stepLimit / motion.stepLength);
    for (const name of group) expressed[name] = motion[name] * factor;
  });
  return expressed;
}

/** The size factor of an individual: 1 + motion.genes.size·gene (creaturegen's individual_size). */
export function individualSize(motion, genome) {
  return 1 + motion.genes.size * genome[SIZE_DRAW - HUE_DRAW];
}

const scaled = (value, factor) => (Array.isArray(value) ? value.map((v) => scaled(v, factor)) : value * factor);

/**
 * The motion data of an individual of `size`: every length `motion.lengths` names (top-level, and per leg,
 * rope and wing) times `size`, nested arrays element by element, and every speed times √size (Froude
 * similarity: gravity is not scaled, so every time scales by √size). Returns a new object; `motion` is not
 * modified.
 */
export function expressSize(motion, size) {
  const names = motion.lengths;
  const expressed = { ...motion };
  for (const name of names.speeds) expressed[name] = motion[name] * Math.sqrt(size);
  for (const name of names.top) expressed[name] = scaled(motion[name], size);
  for (const group of ['legs', 'ropes', 'wings']) {
    expressed[group] = motion[group].map((item) => {
      const out = { ...item };
      for (const name of names[group]) out[name] = scaled(item[name], size);
      return out;
    });
  }
  return expressed;
}

/**
 * The motion data of an individual: its size first, then its gait genes (creaturegen's express), as one
 * fresh copy built by JSON.parse. Copies made by spread-and-assign and Array.map left some legs' fields and
 * arrays in layouts whose loads box doubles in the hot step (tests/test_motion.py's allocation probe saw it
 * on the quadruped, hexapod and lizard); JSON.parse builds V8's fast packed layouts, and the step allocates
 * nothing again. The round trip is exact: CREATURE.motion holds only finite numbers and no -0 (creaturegen motion/rig.py),
 * and the size and gait factors are positive. Spawn-time only.
 */
export function express(motion, genome) {
  return JSON.parse(JSON.stringify(expressGait(expressSize(motion, individualSize(motion, genome)), genome)));
}
