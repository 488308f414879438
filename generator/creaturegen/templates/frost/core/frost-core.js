// Pure JS, zero three imports: the frost effect's time policy, input intervals and tile scheduler.
// Line for line the same algorithm as generator/creaturegen/frost/{timeline,schedule}.py; the numbers
// (rates, radii, tolerance, policy) come from plan.js, which the compiler wrote from the same FrostParams.

/**
 * 'advance' | 'none' (equal instants) | 'catch-up' (a stalled frame: longer than maxInterval, at most
 * catchUp) | 'discontinuity' (reversed, non-finite or longer than that).
 */
export function classifyInterval(previous, current, maxInterval, catchUp) {
  if (!Number.isFinite(previous) || !Number.isFinite(current)) return 'discontinuity';
  if (current === previous) return 'none';
  if (current < previous) return 'discontinuity';
  const elapsed = current - previous;
  if (elapsed <= maxInterval) return 'advance';
  return elapsed <= catchUp ? 'catch-up' : 'discontinuity';
}

/**
 * Where the advances of a caught-up interval end: ceil(elapsed / maxInterval) equal pieces, the last ending
 * exactly at `current` (the same operations in the same order as the Python reference: bit-identical cuts).
 */
export function advanceInstants(previous, current, maxInterval) {
  const count = Math.ceil((current - previous) / maxInterval);
  const ends = [];
  for (let i = 1; i < count; i++) ends.push(previous + ((current - previous) * i) / count);
  ends.push(current);
  return ends;
}

/**
 * Why a segment is refused, or null: finite, and time-ordered and non-overlapping within its stream
 * (`lastEnd`: where that stream's previous segment ended, or null).
 */
export function validateSegment(segment, lastEnd) {
  const values = [segment.t0, segment.t1, ...segment.start, ...segment.end, segment.pressure0, segment.pressure1];
  if (segment.start.length !== 2 || segment.end.length !== 2) return 'start and end must be [u, v]';
  if (!values.every((v) => typeof v === 'number' && Number.isFinite(v))) return 'segment values must be finite';
  if (segment.t1 < segment.t0) return `segment ends (${segment.t1}) before it starts (${segment.t0})`;
  if (lastEnd !== null && segment.t0 < lastEnd) {
    return `segment starts at ${segment.t0}, before the previous one ended (${lastEnd})`;
  }
  if (!(segment.pressure0 >= 0 && segment.pressure0 <= 1 && segment.pressure1 >= 0 && segment.pressure1 <= 1)) {
    return 'pressures must lie in [0, 1]';
  }
  return null;
}

/**
 * Why a segment is refused for the streams it would overlap, or null: at most maxStreams - 1 other
 * streams' queued segments may overlap its span (a step holds at most one segment per stream).
 */
export function tooManyStreams(segment, pending, maxStreams) {
  const others = new Set();
  for (const g of pending) {
    if (g.stream !== segment.stream && g.t0 < segment.t1 && segment.t0 < g.t1) others.add(g.stream);
  }
  if (others.size >= maxStreams) {
    return `segment of stream ${segment.stream} would overlap ${others.size} other streams (at most ${maxStreams - 1})`;
  }
  return null;
}

/** A segment with defaults filled in: pressures 1, stream 0 (the pointer it came from). */
export function normalizeSegment({ t0, t1, start, end, pressure0 = 1, pressure1 = 1, stream = 0 }) {
  return { t0, t1, start: [start[0], start[1]], end: [end[0], end[1]], pressure0, pressure1, stream };
}

/** Pointer NDC in [-1, 1], y up, to history UV (origin top-left, v down). */
export function pointerUV(ndcX, ndcY) {
  return [0.5 * (ndcX + 1), 0.5 * (1 - ndcY)];
}

/** floor(x + 0.5), the rounding the Python side uses too (round() there rounds halves to even). */
export function scaledSize(width, height, scale) {
  return [Math.max(1, Math.floor(width * scale + 0.5)), Math.max(1, Math.floor(height * scale + 0.5))];
}

/**
 * Cut [previous, current) at every segment boundary inside it: piecewise-constant input intervals, each
 * holding every segment active throughout it (one per stream at most; a texel takes the largest coverage).
 */
export function splitInterval(previous, current, segments) {
  const cuts = [previous, current];
  for (const g of segments) {
    for (const t of [g.t0, g.t1]) if (previous < t && t < current) cuts.push(t);
  }
  cuts.sort((a, b) => a - b);
  const ordered = cuts.filter((t, i) => i === 0 || t !== cuts[i - 1]);
  const steps = [];
  for (let i = 0; i + 1 < ordered.length; i++) {
    const s0 = ordered[i];
    const s1 = ordered[i + 1];
    const active = segments.filter((g) => g.t0 <= s0 && s1 <= g.t1 && g.t1 > g.t0);
    steps.push({ dt: s1 - s0, segments: active, age: null });
  }
  return steps;
}

/**
 * Catch-up steps for segments queued since the last update whose span began before `previous` (a pointer
 * segment is known only when its end sample arrives). The missed part [max(t0, origin), min(t1, previous)]
 * decayed in the history; the law's catch-up applies its deposit exactly, with `age` = the decay since.
 * Only segments[from..] are looked at (those queued since the last update).
 */
export function lateSteps(previous, segments, origin, from = 0) {
  const steps = [];
  for (let i = from; i < segments.length; i++) {
    const g = segments[i];
    const start = Math.max(g.t0, origin);
    const end = Math.min(g.t1, previous);
    if (end > start) steps.push({ dt: end - start, segments: [g], age: previous - end });
  }
  return steps;
}

/** Dispatch-sized groups: a group ends before it would hold more than maxSteps steps or maxPairs pairs. */
export function chunkSteps(steps, maxSteps, maxPairs) {
  const chunks = [];
  let pairs = 0;
  for (const step of steps) {
    const last = chunks[chunks.length - 1];
    if (last === undefined || last.length === maxSteps || pairs + step.segments.length > maxPairs) {
      chunks.push([step]);
      pairs = step.segments.length;
    } else {
      last.push(step);
      pairs += step.segments.length;
    }
  }
  return chunks;
}

/**
 * Inclusive texel box [x0, y0, x1, y1] a segment's capsule can reach over dt, or null when it deposits
 * nothing (no pressure, no time) or lies off the history.
 */
export function texelBox(g, dt, reach, width, height) {
  if (0.5 * (g.pressure0 + g.pressure1) <= 0 || dt <= 0) return null;
  const rx = (reach * height) / width;
  const x0 = Math.max(Math.floor((Math.min(g.start[0], g.end[0]) - rx) * width), 0);
  const x1 = Math.min(Math.floor((Math.max(g.start[0], g.end[0]) + rx) * width), width - 1);
  const y0 = Math.max(Math.floor((Math.min(g.start[1], g.end[1]) - reach) * height), 0);
  const y1 = Math.min(Math.floor((Math.max(g.start[1], g.end[1]) + reach) * height), height - 1);
  return x0 > x1 || y0 > y1 ? null : [x0, y0, x1, y1];
}

/**
 * The (step, segment) pairs of one chunk binned into square screen tiles of `size` texels, as a CSR list
 * (start[b]..start[b+1] index `entries`, pair indices in step order): the GPU loops each texel over its
 * bin's pairs only, so overlapping strokes cost sum over tiles of texels x entries, not every texel times
 * every pair. Past `capacity` entries the chunk is one bin holding every pair (the unbinned cost, never a
 * truncated list). Typed arrays are reused from frame to frame. Same counts as schedule.bin_steps.
 */
export class StepBins {
  constructor(params) {
    this.params = params;
    this.start = new Uint32Array(1);
    this.entries = new Uint32Array(0);
    this.boxes = [];
  }

  /**
   * Bin `chunk` on a width x height history; returns this (fields valid until the next call). `unbinned`:
   * one bin holding every pair whatever the capacity (the baseline a benchmark compares with).
   */
  bin(chunk, width, height, unbinned = false) {
    const size = this.params.tileSize;
    const reach = Math.max(this.params.visible.radius, this.params.tilt.radius);
    const binsX = Math.ceil(width / size);
    const binsY = Math.ceil(height / size);
    const count = binsX * binsY;
    if (this.start.length < count + 1) this.start = new Uint32Array(count + 1);
    const start = this.start;
    start.fill(0, 0, count + 1);
    this.boxes.length = 0;
    let pairs = 0;
    let total = 0;
    for (const step of chunk) {
      for (const g of step.segments) {
        const box = texelBox(g, step.dt, reach, width, height);
        this.boxes.push(box);
        pairs += 1;
        if (box === null) continue;
        for (let by = Math.floor(box[1] / size); by <= Math.floor(box[3] / size); by++) {
          for (let bx = Math.floor(box[0] / size); bx <= Math.floor(box[2] / size); bx++) {
            start[by * binsX + bx + 1] += 1;
            total += 1;
          }
        }
      }
    }
    this.pairs = pairs;
    this.width = width;
    this.height = height;
    this.single = unbinned || total > this.params.binCapacity;
    if (this.single) {
      this.size = Math.max(width, height);
      this.binsX = 1;
      this.count = 1;
      this.total = pairs;
      if (this.entries.length < pairs) this.entries = new Uint32Array(Math.max(pairs, 2 * this.entries.length));
      start[0] = 0;
      start[1] = pairs;
      for (let i = 0; i < pairs; i++) this.entries[i] = i;
      return this;
    }
    this.size = size;
    this.binsX = binsX;
    this.count = count;
    this.total = total;
    for (let b = 0; b < count; b++) start[b + 1] += start[b];
    if (this.entries.length < total) this.entries = new Uint32Array(Math.max(total, 2 * this.entries.length));
    const cursor = this.scratch?.length >= count ? this.scratch : (this.scratch = new Uint32Array(count));
    cursor.set(start.subarray(0, count));
    for (let i = 0; i < pairs; i++) {
      const box = this.boxes[i];
      if (box === null) continue;
      for (let by = Math.floor(box[1] / size); by <= Math.floor(box[3] / size); by++) {
        for (let bx = Math.floor(box[0] / size); bx <= Math.floor(box[2] / size); bx++) {
          this.entries[cursor[by * binsX + bx]++] = i;
        }
      }
    }
    return this;
  }

  /**
   * Law evaluations the dispatch makes: sum over bins of updated texels x entries. `updated(b)` says
   * whether bin b's texels are dispatched (every bin under full-field; its tile under dirty tiles).
   */
  texelSteps(updated) {
    let sum = 0;
    for (let b = 0; b < this.count; b++) {
      const entries = this.start[b + 1] - this.start[b];
      if (entries === 0 || !updated(b)) continue;
      const bx = b % this.binsX;
      const by = Math.floor(b / this.binsX);
      const w = Math.min(this.size, this.width - bx * this.size);
      const h = Math.min(this.size, this.height - by * this.size);
      sum += w * h * entries;
    }
    return sum;
  }
}

/** Substeps keeping D·(dt/n)/dx² ≤ 1/4 with dx = 1/H; 0 without diffusion. */
export function diffusionSubsteps(diffusivity, dt, height, stability) {
  const number = diffusivity * dt * height * height;
  return number > 0 ? Math.ceil(number / stability) : 0;
}

/**
 * Per-tile analytic channel bounds decide what a frame dispatches: touched tiles get bound 1, diffusion
 * dilates bounds by its halo, the rest decay by exp(-λ·dt); a tile at or below the tolerance retires
 * (both ping-pong textures cleared to 0, the law's fixed point without input). Full-field is one tile.
 */
export class TileScheduler {
  constructor(params, width, height) {
    this.params = params;
    const full = params.policy === 'full-field';
    this.tileWidth = full ? width : params.tileSize;
    this.tileHeight = full ? height : params.tileSize;
    this.tilesX = Math.ceil(width / this.tileWidth);
    this.tilesY = Math.ceil(height / this.tileHeight);
    this.width = width;
    this.height = height;
    this.count = this.tilesX * this.tilesY;
    this.bounds = [new Float64Array(this.count), new Float64Array(this.count)];
    this.live = new Uint8Array(this.count);
    this.update = new Uint32Array(this.count);
    this.retire = new Uint32Array(this.count);
    this.scratch = new Float64Array(this.count);
    this.touchedMask = new Uint8Array(this.count);
  }

  touched(steps) {
    const touched = this.touchedMask;
    touched.fill(0);
    const reach = Math.max(this.params.visible.radius, this.params.tilt.radius);
    for (const step of steps) {
      for (const g of step.segments) {
        const box = texelBox(g, step.dt, reach, this.width, this.height);
        if (box === null) continue;
        for (let ty = Math.floor(box[1] / this.tileHeight); ty <= Math.floor(box[3] / this.tileHeight); ty++) {
          for (let tx = Math.floor(box[0] / this.tileWidth); tx <= Math.floor(box[2] / this.tileWidth); tx++) {
            touched[ty * this.tilesX + tx] = 1;
          }
        }
      }
    }
    return touched;
  }

  dilate(halo) {
    for (const bound of this.bounds) {
      const out = this.scratch;
      for (let ty = 0; ty < this.tilesY; ty++) {
        for (let tx = 0; tx < this.tilesX; tx++) {
          let m = 0;
          for (let dy = -halo; dy <= halo; dy++) {
            const y = Math.min(Math.max(ty + dy, 0), this.tilesY - 1);
            for (let dx = -halo; dx <= halo; dx++) {
              const x = Math.min(Math.max(tx + dx, 0), this.tilesX - 1);
              m = Math.max(m, bound[y * this.tilesX + x]);
            }
          }
          out[ty * this.tilesX + tx] = m;
        }
      }
      bound.set(out);
    }
  }

  /** Returns { updateCount, retireCount } and fills this.update / this.retire (row-major tile ids). */
  plan(steps, frameDt, substeps) {
    if (substeps > 0) this.dilate(Math.ceil(substeps / Math.min(this.tileWidth, this.tileHeight)));
    const decays = [this.params.visible.decay, this.params.tilt.decay];
    for (let c = 0; c < 2; c++) {
      const factor = Math.exp(-decays[c] * frameDt);
      const bound = this.bounds[c];
      for (let t = 0; t < this.count; t++) bound[t] *= factor;
    }
    const touched = this.touched(steps);
    const always = this.params.policy === 'full-field' && !this.params.idleWhenConverged;
    let updateCount = 0;
    let retireCount = 0;
    for (let t = 0; t < this.count; t++) {
      if (touched[t]) {
        this.bounds[0][t] = 1;
        this.bounds[1][t] = 1;
      }
      const live = always || this.bounds[0][t] > this.params.tolerance || this.bounds[1][t] > this.params.tolerance;
      if (live) this.update[updateCount++] = t;
      else {
        if (this.live[t]) this.retire[retireCount++] = t;
        this.bounds[0][t] = 0;
        this.bounds[1][t] = 0;
      }
      this.live[t] = live ? 1 : 0;
    }
    return { updateCount, retireCount };
  }

  /** After a remapping resize every tile may hold content up to the old bounds. */
  markAll(boundVisible, boundTilt) {
    this.bounds[0].fill(boundVisible);
    this.bounds[1].fill(boundTilt);
    const live = boundVisible > this.params.tolerance || boundTilt > this.params.tolerance;
    this.live.fill(live ? 1 : 0);
  }

  maxBounds() {
    let v = 0;
    let a = 0;
    for (let t = 0; t < this.count; t++) {
      v = Math.max(v, this.bounds[0][t]);
      a = Math.max(a, this.bounds[1][t]);
    }
    return [v, a];
  }
}
