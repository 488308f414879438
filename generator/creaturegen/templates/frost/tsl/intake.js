// Pointer input: segments queued by effect.pointer (validated, one queue for every stream), real pointers
// wired by effect.attachPointer (pointer events -> segments), and the upload of one chunk of a frame's
// steps and segments into the kernels' storage buffers (writeChunk, called by update in frame.js).
import { normalizeSegment, tooManyStreams, validateSegment } from '../core/frost-core.js';

/** Queue one segment; throws (and counts it in counters.segmentsRejected) when it is refused. */
export function pointer(state, segment) {
  const { pending, lastEnd, counters } = state;
  const g = normalizeSegment(segment);
  const problem = validateSegment(g, lastEnd.get(g.stream) ?? null) ?? tooManyStreams(g, pending, state.params.maxStreams);
  if (problem !== null) {
    counters.segmentsRejected += 1;
    throw new Error(`frost.pointer: ${problem}`);
  }
  pending.push(g);
  lastEnd.set(g.stream, g.t1);
  counters.segmentsQueued += 1;
}

/**
 * Wire real pointers: one segment between successive samples of a press (coalesced events included),
 * captured on pointerdown, ending on pointerup/cancel. Every pointer that is down is its own stream
 * (stream = event.pointerId), so two fingers or a pen and a mouse wipe at once. Instants are
 * `clock(event.timeStamp)`, by default event.timeStamp / 1000: seconds on the same clock as
 * requestAnimationFrame's timestamp / 1000, which is what the frame loop must pass to
 * update(previous, current). Positions map to history UV through the element's bounding rect (origin
 * top-left). Pressure: pen and touch report it; a mouse is 1 while its primary button is down; the
 * release sample keeps the last pressure (contact lasted until then).
 */
export function attachPointer(state, element, attachOptions = {}) {
  const clock = attachOptions.clock ?? ((timeStampMs) => timeStampMs / 1000);
  const onSegment = attachOptions.onSegment ?? null;
  const presses = new Map(); // pointerId -> { t, uv, p } of the latest sample of that press
  const sampleOf = (event, pressure) => {
    const rect = element.getBoundingClientRect();
    const u = (event.clientX - rect.left) / Math.max(rect.width, 1e-9);
    const v = (event.clientY - rect.top) / Math.max(rect.height, 1e-9);
    return { t: clock(event.timeStamp), uv: [u, v], p: Math.min(Math.max(pressure, 0), 1) };
  };
  const pressureOf = (event) => (event.pointerType === 'mouse' ? 1 : event.pressure);
  const extend = (id, next) => {
    const last = presses.get(id);
    if (!(next.t > last.t)) {
      if (next.t === last.t) presses.set(id, { t: last.t, uv: next.uv, p: next.p });
      return;
    }
    const segment = {
      t0: last.t, t1: next.t, start: last.uv, end: next.uv, pressure0: last.p, pressure1: next.p, stream: id,
    };
    presses.set(id, next);
    try {
      pointer(state, segment);
    } catch {
      return; // refused (counted in counters.segmentsRejected); the stroke goes on from this sample
    }
    if (onSegment !== null) onSegment(normalizeSegment(segment));
  };
  const down = (event) => {
    if (presses.has(event.pointerId) || (event.pointerType === 'mouse' && event.button !== 0)) return;
    presses.set(event.pointerId, sampleOf(event, pressureOf(event)));
    try { element.setPointerCapture(event.pointerId); } catch { /* element not connected: no capture */ }
  };
  const move = (event) => {
    if (!presses.has(event.pointerId)) return;
    const coalesced = typeof event.getCoalescedEvents === 'function' ? event.getCoalescedEvents() : [];
    const samples = coalesced.length > 0 ? coalesced : [event];
    for (const e of samples) extend(event.pointerId, sampleOf(e, pressureOf(e)));
  };
  const up = (event) => {
    if (!presses.has(event.pointerId)) return;
    extend(event.pointerId, sampleOf(event, presses.get(event.pointerId).p));
    presses.delete(event.pointerId);
  };
  return listen(element, { down, move, up }, presses);
}

/** Add the pointer listeners to element; return the function that removes them and releases captures. */
function listen(element, { down, move, up }, presses) {
  const previousTouchAction = element.style.touchAction;
  element.style.touchAction = 'none'; // touch drags reach us as pointer events instead of scrolling
  element.addEventListener('pointerdown', down);
  element.addEventListener('pointermove', move);
  element.addEventListener('pointerup', up);
  element.addEventListener('pointercancel', up);
  return function detach() {
    element.removeEventListener('pointerdown', down);
    element.removeEventListener('pointermove', move);
    element.removeEventListener('pointerup', up);
    element.removeEventListener('pointercancel', up);
    element.style.touchAction = previousTouchAction;
    for (const id of presses.keys()) {
      try { element.releasePointerCapture(id); } catch { /* already released */ }
    }
    presses.clear();
  };
}

// Upload one chunk of steps: the step and pair buffers, the chunk's bins, and the uniforms that describe
// it. Element writes into reused typed arrays, no temporaries beyond StepBins' own: this runs every frame.
export function writeChunk(state, chunk) {
  const { stepData, pairData, stepBuffer, pairBuffer, bins } = state;
  let decay = 0;
  let pair = 0;
  for (let i = 0; i < chunk.length; i++) {
    const step = chunk[i];
    const late = step.age !== null && step.age !== undefined;
    stepData[i * 4] = step.dt;
    stepData[i * 4 + 1] = late ? step.age : -1;
    stepData[i * 4 + 2] = decay;
    stepData[i * 4 + 3] = 0;
    if (!late) decay += step.dt;
    for (const g of step.segments) {
      const o = pair * 8;
      pairData[o] = g.start[0];
      pairData[o + 1] = g.start[1];
      pairData[o + 2] = g.end[0];
      pairData[o + 3] = g.end[1];
      pairData[o + 4] = 0.5 * (g.pressure0 + g.pressure1);
      pairData[o + 5] = i;
      pairData[o + 6] = 0;
      pairData[o + 7] = 0;
      pair += 1;
    }
  }
  stepBuffer.value.addUpdateRange(0, Math.max(chunk.length, 1) * 4);
  stepBuffer.value.needsUpdate = true;
  if (pair > 0) {
    pairBuffer.value.addUpdateRange(0, pair * 8);
    pairBuffer.value.needsUpdate = true;
  }
  writeBins(state, chunk);
  state.uStepCount.value = chunk.length;
  state.uDecayTotal.value = decay;
}

/** Bin the chunk's pairs into screen tiles and upload the CSR lists (starts per bin, then entries). */
function writeBins(state, chunk) {
  const { bins, binStartBuffer, binEntryBuffer } = state;
  bins.bin(chunk, state.histW, state.histH, !state.binning);
  const starts = binStartBuffer.value.array;
  starts.set(bins.start.subarray(0, bins.count + 1));
  binStartBuffer.value.addUpdateRange(0, bins.count + 1);
  binStartBuffer.value.needsUpdate = true;
  if (bins.total > 0) {
    binEntryBuffer.value.array.set(bins.entries.subarray(0, bins.total));
    binEntryBuffer.value.addUpdateRange(0, bins.total);
    binEntryBuffer.value.needsUpdate = true;
  }
  state.uBinSize.value = bins.size;
  state.uBinsX.value = bins.binsX;
}
