// The fixed-step driver (creaturegen motion/driver.py): integer ticks are authoritative. Render frames
// feed wall-clock dt, clamped to [0, MAX_FRAME_S]; the accumulator is capped at MAX_ACCUMULATOR_S so a hitch
// never triggers a catch-up storm; `alpha` is how far the render pose lies between the previous and the
// current fixed step.

export const MAX_FRAME_S = 0.25;
export const MAX_ACCUMULATOR_S = 0.25;

export function createDriver(hz) {
  const step = 1 / hz;
  // (accumulator, alpha) in a Float64Array: a double stored into a closure variable is boxed anew on
  // every store, and the driver runs once per frame.
  const s = new Float64Array(2);
  return {
    hz, step,
    get accumulator() { return s[0]; },
    get alpha() { return s[1]; },
    /** Whole fixed steps due after a frame of `dt` seconds (the caller runs them, then renders at alpha). */
    advance(dt) {
      const clamped = dt > 0 ? Math.min(dt, MAX_FRAME_S) : 0;
      s[0] = Math.min(s[0] + clamped, MAX_ACCUMULATOR_S);
      let steps = 0;
      while (s[0] >= step) { s[0] -= step; steps += 1; }
      s[1] = s[0] / step;
      return steps;
    },
    reset() { s[0] = 0; s[1] = 0; },
  };
}
