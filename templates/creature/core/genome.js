// Genomes: what makes one spawned individual differ from another, drawn from its seed by the LCG, the same
// scalar arithmetic in the same order as creaturegen's Python reference (creature/genome.py), so the two
// agree bit for bit. Genes are signed draws in [-1, 1) of the stream from mixSeed(seed): draw 1 is
// reserved, draw 2 is the heading (instanceYaw), draws 3, 4, 5 are hue, chroma and lightness, draws 6..
// the gait genes.
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
/** Floats in a genome array: hue, chroma, lightness, then MAX_GAIT_GENES gait genes. */
export const GENOME_LENGTH = 3 + MAX_GAIT_GENES;

/** Write the genome of the individual spawned from `seed` into `out` (GENOME_LENGTH floats). */
export function drawGenome(seed, lcg, out = new Float64Array(GENOME_LENGTH)) {
  let state = mixSeed(seed);
  for (let draw = 1; draw < GAIT_DRAW + MAX_GAIT_GENES; draw++) {
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
