// One frame of the history (effect.update): classify the interval since the last render instant (a stalled
// frame is caught up as several advances), turn the queued segments into piecewise-constant steps (late
// segments' missed spans first), let the tile scheduler pick the tiles that can still change, then run the
// update kernel over them chunk by chunk, the diffusion substeps, and the clear of tiles that have
// converged. Returns the frame's report, also kept as counters.lastFrame.
import {
  advanceInstants, chunkSteps, classifyInterval, diffusionSubsteps, lateSteps, splitInterval,
} from '../core/frost-core.js';
import { dispatch2d, run, runLinear, uploadTiles } from './dispatch.js';
import { bindComposite, reset } from './history.js';
import { writeChunk } from './intake.js';

export function update(state, previousInstant, currentInstant) {
  const { params, counters } = state;
  const decision = classifyInterval(previousInstant, currentInstant, params.maxInterval, params.catchUp);
  const report = {
    decision, steps: 0, dispatches: 0, texels: 0, updateTiles: 0, retiredTiles: 0, substeps: 0, advances: 0,
    lateSteps: 0, pointerSeconds: 0, binEntries: 0, texelSteps: 0,
  };
  if (decision === 'none') return report;
  counters.frames += 1;
  const before = counters.dispatches;
  if (decision === 'discontinuity') {
    jump(state, currentInstant);
    report.dispatches = counters.dispatches - before;
    counters.lastFrame = report;
    return report;
  }
  if (state.origin === null) state.origin = previousInstant;
  if (decision === 'advance') {
    advance(state, previousInstant, currentInstant, report, true);
  } else {
    // A stalled frame (longer than maxInterval, at most catchUp) runs as equal advances of at most
    // maxInterval: the pointer input queued during the stall deposits in full.
    counters.catchUps += 1;
    const ends = advanceInstants(previousInstant, currentInstant, params.maxInterval);
    let start = previousInstant;
    let fresh = true;
    for (let i = 0; i < ends.length; i++) {
      fresh = !advance(state, start, ends[i], report, fresh) && fresh;
      start = ends[i];
    }
  }
  if (report.updateTiles === 0 && report.retiredTiles === 0) counters.idleFrames += 1;
  counters.lateSteps += report.lateSteps;
  counters.pointerSeconds += report.pointerSeconds;
  bindComposite(state);
  report.dispatches = counters.dispatches - before;
  counters.texelsDispatched += report.texels;
  counters.lastFrame = report;
  return report;
}

// One advance over [previousInstant, currentInstant): a frame's whole interval or one piece of a catch-up.
// `fresh`: no advance of this frame has updated tiles yet (its first chunk restarts the deposit channels).
// Adds to the frame's report; returns whether it updated tiles.
function advance(state, previousInstant, currentInstant, report, fresh) {
  const { params, pending } = state;
  const frameDt = currentInstant - previousInstant;
  // Segments known only after the instant they overlap (a pointer segment arrives with its end sample)
  // first deposit their missed part exactly, then the interval itself runs.
  const late = lateSteps(previousInstant, pending, state.origin, state.freshFrom);
  const split = splitInterval(previousInstant, currentInstant, pending);
  const steps = late.length > 0 ? late.concat(split) : split;
  let pointerSeconds = 0;
  for (let i = 0; i < steps.length; i++) pointerSeconds += steps[i].dt * steps[i].segments.length;
  const substeps = diffusionSubsteps(params.diffusivity, frameDt, state.histH, params.diffusionStability);
  const { updateCount, retireCount } = state.scheduler.plan(steps, frameDt, substeps);
  const tileArea = state.scheduler.tileWidth * state.scheduler.tileHeight;
  report.steps += steps.length;
  report.updateTiles += updateCount;
  report.retiredTiles += retireCount;
  report.lateSteps += late.length;
  report.pointerSeconds += pointerSeconds;
  report.advances += 1;
  if (retireCount > 0) {
    uploadTiles(state, state.scheduler.retire, retireCount);
    runLinear(state, state.kernels.clear, retireCount);
    report.texels += retireCount * tileArea;
  }
  if (updateCount > 0) {
    runUpdate(state, steps, updateCount, tileArea, report, fresh);
    report.substeps += substeps;
    if (substeps > 0) runDiffusion(state, frameDt, substeps, updateCount, tileArea, report);
  }
  for (let i = pending.length - 1; i >= 0; i--) if (pending[i].t1 <= currentInstant) pending.splice(i, 1);
  state.freshFrom = pending.length;
  return updateCount > 0;
}

// Time jumped (a reversed or non-finite interval, or one past catchUp): drop the queued input, and reset the
// history when the plan's discontinuity policy says so.
function jump(state, currentInstant) {
  state.counters.discontinuities += 1;
  state.pending.length = 0;
  state.freshFrom = 0;
  state.lastEnd.clear(); // time jumped: the next segment may start anywhere
  if (state.params.discontinuity === 'reset') reset(state);
  state.origin = currentInstant; // after reset(): nothing queued later deposits before the jump's end
}

// The update kernel over the frame's steps, one dispatch per chunk (chunkSteps: at most maxSteps steps
// and maxPairs pairs each); every dispatch swaps the ping-pong.
function runUpdate(state, steps, updateCount, tileArea, report, fresh) {
  const { params, scheduler, bins, kernels } = state;
  const full = params.policy === 'full-field';
  if (!full) uploadTiles(state, scheduler.update, updateCount);
  const updated = full ? () => true : (b) => state.scheduler.live[b] === 1;
  chunkSteps(steps, params.maxSteps, params.maxPairs).forEach((chunk, index) => {
    writeChunk(state, chunk);
    report.binEntries += bins.total;
    report.texelSteps += bins.single
      ? bins.total * (full ? state.histW * state.histH : liveTexels(state, updateCount))
      : bins.texelSteps(updated);
    state.uFirstChunk.value = fresh && index === 0 ? 1 : 0;
    if (full) run(state, kernels.update2d[state.current], dispatch2d(state));
    else runLinear(state, kernels.updateTiles[state.current], updateCount);
    state.current = 1 - state.current;
    report.texels += updateCount * tileArea;
  });
}

// Explicit diffusion of the frost channels over the frame, in `substeps` stable substeps.
function runDiffusion(state, frameDt, substeps, updateCount, tileArea, report) {
  const { params, kernels } = state;
  const full = params.policy === 'full-field';
  state.uDiffusionRate.value = params.diffusivity * (frameDt / substeps) * state.histH * state.histH;
  for (let s = 0; s < substeps; s++) {
    if (full) run(state, kernels.diffuse2d[state.current], dispatch2d(state));
    else runLinear(state, kernels.diffuseTiles[state.current], updateCount);
    state.current = 1 - state.current;
    report.texels += updateCount * tileArea;
  }
}

// Texels of the first `count` update tiles, clipped to the history (what a single-bin chunk evaluates).
function liveTexels(state, count) {
  const { scheduler } = state;
  let sum = 0;
  for (let k = 0; k < count; k++) {
    const t = scheduler.update[k];
    const x0 = (t % scheduler.tilesX) * scheduler.tileWidth;
    const y0 = Math.floor(t / scheduler.tilesX) * scheduler.tileHeight;
    sum += Math.min(scheduler.tileWidth, state.histW - x0) * Math.min(scheduler.tileHeight, state.histH - y0);
  }
  return sum;
}
