// The fixed-step driver (creaturegen motion/driver.py): integer ticks are authoritative. Render frames
// feed wall-clock dt, clamped to [0, MAX_FRAME_S]; the accumulator is capped at MAX_ACCUMULATOR_S so a hitch
// never triggers a catch-up storm; `alpha` is how far the render pose lies between the previous and the
// current fixed step.

export const MAX_FRAME_S = 0.25;
export const MAX_ACCUMULATOR_S = 0.25;

export function createDriver(hz) {
  const step = 1 / hz;
  let accumulator = 0;
  let alpha = 0;
  return {
    hz, step,
    get accumulator() { return accumulator; },
    get alpha() { return alpha; },
    /** Whole fixed steps due after a frame of `dt` seconds (the caller runs them, then renders at alpha). */
    advance(dt) {
      const clamped = dt > 0 ? Math.min(dt, MAX_FRAME_S) : 0;
      accumulator = Math.min(accumulator + clamped, MAX_ACCUMULATOR_S);
      let steps = 0;
      while (accumulator >= step) { accumulator -= step; steps += 1; }
      alpha = accumulator / step;
      return steps;
    },
    reset() { accumulator = 0; alpha = 0; },
  };
}
