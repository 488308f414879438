// Steady-state allocation of a loop in Node, shared by bench/motion.mjs and bench/population.mjs. Needs
// node --expose-gc (and --no-concurrent-recompilation, so optimised code lands at a fixed point).
import { PerformanceObserver, performance } from 'node:perf_hooks';

/**
 * Heap growth and garbage collections over `rounds` windows of `run(window)`, each after a full
 * collection, after `run(warm)` in four parts (V8 needs thousands of iterations to settle its optimised
 * code: until then unoptimised code boxes every double, and compiling allocates too). The cleanest window
 * is the steady state (a window can still catch a late compilation): the fewest collections, then the
 * least growth (a collection inside a window frees memory, so growth alone understates what it
 * allocated). Returns it with every window.
 */
export async function allocationWindows(run, { warm, window, rounds }) {
  for (let k = 0; k < 4; k++) run(warm / 4);
  const gcTimes = [];
  const observer = new PerformanceObserver((list) => { for (const e of list.getEntries()) gcTimes.push(e.startTime); });
  observer.observe({ entryTypes: ['gc'] });
  const settle = () => new Promise((resolve) => setTimeout(resolve, 20)); // let gc entries arrive
  const windows = [];
  for (let r = 0; r < rounds; r++) {
    globalThis.gc();
    await settle();
    const start = performance.now();
    const before = process.memoryUsage().heapUsed;
    run(window);
    const after = process.memoryUsage().heapUsed;
    const end = performance.now();
    await settle();
    // Collections that started inside the window (the forced one before it is not counted).
    windows.push({ heapGrowthBytes: after - before, collections: gcTimes.filter((t) => t >= start && t <= end).length });
  }
  observer.disconnect();
  const cleaner = (w, a) => w.collections < a.collections || (w.collections === a.collections && w.heapGrowthBytes < a.heapGrowthBytes);
  const best = windows.reduce((a, w) => (cleaner(w, a) ? w : a));
  return { heapGrowthBytes: best.heapGrowthBytes, collections: best.collections, windows };
}
