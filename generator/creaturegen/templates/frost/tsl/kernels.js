// The history's compute kernels, in TSL: the update (each channel's closed-form decay and saturating
// deposit under the pointer's capsules, with the exact catch-up of late segments and per-texel noise),
// the diffusion substep, the tile clear and the resize remap. Each kernel is built once per direction of
// the ping-pong (0 -> 1 and 1 -> 0), full-field and tiled, so a frame only changes uniforms and buffers
// and never builds a pipeline. The same law runs in creaturegen's numpy reference (creaturegen.frost.law),
// which the package's parity job compares GPU readbacks against.
import {
  Fn, If, Loop, clamp, dot, exp, float, globalId, instanceIndex, int, ivec2, length, max, min, mix, select,
  smoothstep, texture, textureStore, uint, vec2, vec4,
} from 'three/tsl';
import { WL, WX, WY } from './dispatch.js';
import { loadClamped } from './history.js';

/** PCG-RXS-M-XS on u32, the same hash as creaturegen.frost.brush.pcg_hash. */
const pcg = Fn(([v]) => {
  const state = v.mul(uint(747796405)).add(uint(2891336453));
  const word = state.shiftRight(state.shiftRight(uint(28)).add(uint(4))).bitXor(state).mul(uint(277803737));
  return word.shiftRight(uint(22)).bitXor(word);
}, { v: 'uint', return: 'uint' });

/** Closed-form decay + saturating deposit over dt with constant coverage b; a = 0 keeps x. */
const law = Fn(([x, b, dt, decay, fill]) => {
  const a = decay.add(fill.mul(b));
  const eq = fill.mul(b).div(max(a, float(1e-30)));
  return select(a.greaterThan(0), eq.add(x.sub(eq).mul(exp(a.negate().mul(dt)))), x);
}, { x: 'float', b: 'float', dt: 'float', decay: 'float', fill: 'float', return: 'float' });

/**
 * Catch-up of a late segment: x only decayed over the missed span tau and then `age` seconds; return the
 * state had it deposited under b over tau: e^(-r·b·tau)·x + e^(-λ·age)·xEq·(1 - e^(-a·tau)), exact.
 */
const catchUp = Fn(([x, b, tau, age, decay, fill]) => {
  const rb = fill.mul(b);
  const a = decay.add(rb);
  const gained = rb.div(max(a, float(1e-30))).mul(float(1).sub(exp(a.negate().mul(tau))));
  return exp(rb.negate().mul(tau)).mul(x).add(exp(decay.negate().mul(age)).mul(gained));
}, { x: 'float', b: 'float', tau: 'float', age: 'float', decay: 'float', fill: 'float', return: 'float' });

/** Per-texel noise in [0, 1): the top 24 bits of a double PCG hash of the texel and a salt. */
const texelNoise = (i, j, salt) => float(pcg(j.add(pcg(i.add(salt)))).shiftRight(uint(8))).mul(1 / 16777216);

// One texel over its bin's pairs, in step order. A step with no pair in the bin covers no texel of it:
// an ordinary one only decays (folded into one exp over the gap, from the chunk's decayBefore times), a
// catch-up one is the identity. A step with pairs deposits the largest coverage among them (several
// strokes at once). The sentinel iteration (i = last) applies the bin's final step.
function updateTexel(state, src, dst, ix, iy) {
  const { params, uFirstChunk, uHistSize, uBinSize, uBinsX, uStepCount, uDecayTotal, salts } = state;
  const { binStartBuffer, binEntryBuffer, pairBuffer, stepBuffer } = state;
  const vis = params.visible;
  const tilt = params.tilt;
  const prev = src.load(ivec2(ix, iy));
  const xr = prev.x.toVar();
  const xa = prev.w.toVar();
  const dr = mix(prev.y, float(0), uFirstChunk).toVar();
  const da = mix(prev.z, float(0), uFirstChunk).toVar();
  const aspect = uHistSize.x.div(uHistSize.y);
  const p = vec2(float(ix).add(0.5).div(uHistSize.x).mul(aspect), float(iy).add(0.5).div(uHistSize.y));
  const n0 = texelNoise(uint(ix), uint(iy), salts[0]);
  const n1 = texelNoise(uint(ix), uint(iy), salts[1]);
  const bin = iy.div(uBinSize).mul(uBinsX).add(ix.div(uBinSize));
  const first = int(binStartBuffer.element(bin));
  const last = int(binStartBuffer.element(bin.add(1)));
  const elapsed = float(0).toVar(); // ordinary seconds of the chunk already applied
  const step = int(-1).toVar();
  const br = float(0).toVar();
  const ba = float(0).toVar();
  Loop({ start: first, end: last.add(1), type: 'int', condition: '<' }, ({ i }) => {
    const atEnd = i.greaterThanEqual(last);
    const pair = int(binEntryBuffer.element(min(i, max(last.sub(1), int(0)))));
    const info = pairBuffer.element(pair.mul(2).add(1));
    const next = select(atEnd, uStepCount, int(info.y));
    If(next.notEqual(step).and(step.greaterThanEqual(0)), () => {
      const s = stepBuffer.element(step);
      xr.mulAssign(exp(float(-vis.decay).mul(s.z.sub(elapsed))));
      xa.mulAssign(exp(float(-tilt.decay).mul(s.z.sub(elapsed))));
      dr.assign(max(dr, br));
      da.assign(max(da, ba));
      const late = s.y.greaterThanEqual(0);
      const age = max(s.y, float(0));
      xr.assign(select(late, catchUp(xr, br, s.x, age, float(vis.decay), float(vis.fill)),
        law(xr, br, s.x, float(vis.decay), float(vis.fill))));
      xa.assign(select(late, catchUp(xa, ba, s.x, age, float(tilt.decay), float(tilt.fill)),
        law(xa, ba, s.x, float(tilt.decay), float(tilt.fill))));
      elapsed.assign(s.z.add(select(late, float(0), s.x)));
    });
    If(next.notEqual(step), () => {
      step.assign(next);
      br.assign(0);
      ba.assign(0);
    });
    If(atEnd.not(), () => {
      const seg = pairBuffer.element(pair.mul(2));
      const a = vec2(seg.x.mul(aspect), seg.y);
      const d = vec2(seg.z.mul(aspect), seg.w).sub(a);
      const t = clamp(dot(p.sub(a), d).div(max(dot(d, d), float(1e-30))), 0, 1);
      const dist = length(p.sub(a).sub(d.mul(t)));
      br.assign(max(br, info.x.mul(float(1).sub(smoothstep(vis.radius * (1 - params.softness), vis.radius, dist)))
        .mul(float(1).sub(n0.mul(vis.noise)))));
      ba.assign(max(ba, info.x.mul(float(1).sub(smoothstep(tilt.radius * (1 - params.softness), tilt.radius, dist)))
        .mul(float(1).sub(n1.mul(tilt.noise)))));
    });
  });
  xr.mulAssign(exp(float(-vis.decay).mul(uDecayTotal.sub(elapsed))));
  xa.mulAssign(exp(float(-tilt.decay).mul(uDecayTotal.sub(elapsed))));
  textureStore(dst, ivec2(ix, iy), vec4(xr, dr, da, xa));
}

/** One explicit diffusion substep of the frost channels (R and A): a 5-point Laplacian, clamped at the edges. */
function diffuseTexel(state, src, dst, ix, iy) {
  const { uDiffusionRate } = state;
  const c = src.load(ivec2(ix, iy));
  const sum = loadClamped(state, src, ix.sub(1), iy).add(loadClamped(state, src, ix.add(1), iy))
    .add(loadClamped(state, src, ix, iy.sub(1))).add(loadClamped(state, src, ix, iy.add(1)));
  const lap = sum.sub(c.mul(4));
  textureStore(dst, ivec2(ix, iy), vec4(c.x.add(lap.x.mul(uDiffusionRate)), c.y, c.z, c.w.add(lap.w.mul(uDiffusionRate))));
}

/** A full-field kernel: one thread per history texel on a 2-D grid. */
function kernel2d(state, body, src, dst, name) {
  const { uHistW, uHistH } = state;
  const node = Fn(() => {
    const ix = int(globalId.x);
    const iy = int(globalId.y);
    If(ix.lessThan(uHistW).and(iy.lessThan(uHistH)), () => body(state, src, dst, ix, iy));
  })().compute([1, 1, 1], [WX, WY, 1]);
  node.setName(name);
  return node;
}

/** The texel (ix, iy) of each linear thread over the uploaded tile list, passed to fn inside the guards. */
function tileCoords(state, fn) {
  const { uTileW, uTileH, uTileCount, uTilesX, uHistW, uHistH, tileBuffer } = state;
  return Fn(() => {
    const area = uTileW.mul(uTileH);
    const idx = int(instanceIndex);
    const slot = idx.div(area);
    const local = idx.mod(area);
    If(slot.lessThan(uTileCount), () => {
      const tile = int(tileBuffer.element(slot));
      const ix = tile.mod(uTilesX).mul(uTileW).add(local.mod(uTileW));
      const iy = tile.div(uTilesX).mul(uTileH).add(local.div(uTileW));
      If(ix.lessThan(uHistW).and(iy.lessThan(uHistH)), () => fn(ix, iy));
    });
  });
}

/** A tiled kernel: one linear thread per texel of the listed tiles. */
function kernelTiles(state, body, src, dst, name) {
  const node = tileCoords(state, (ix, iy) => body(state, src, dst, ix, iy))().compute(1, [WL, 1, 1]);
  node.setName(name);
  return node;
}

/** Zero the listed tiles in both history textures. */
function clearKernel(state) {
  const { write } = state;
  const node = tileCoords(state, (ix, iy) => {
    textureStore(write[0], ivec2(ix, iy), vec4(0));
    textureStore(write[1], ivec2(ix, iy), vec4(0));
  })().compute(1, [WL, 1, 1]);
  node.setName('frost.clear');
  return node;
}

// The remap kernel reads the old history (bilinear by UV, clamp-to-edge, texel loads in float32) and
// writes both new textures, so untouched tiles agree in both ping-pong slots.
function remapKernel(state, oldRead) {
  const { uHistW, uHistH, uHistSize, uOldSize, uOldW, uOldH, write } = state;
  const node = Fn(() => {
    const ix = int(globalId.x);
    const iy = int(globalId.y);
    If(ix.lessThan(uHistW).and(iy.lessThan(uHistH)), () => {
      const x = clamp(float(ix).add(0.5).div(uHistSize.x).mul(uOldSize.x).sub(0.5), 0, uOldSize.x.sub(1));
      const y = clamp(float(iy).add(0.5).div(uHistSize.y).mul(uOldSize.y).sub(0.5), 0, uOldSize.y.sub(1));
      const x0 = int(x.floor());
      const y0 = int(y.floor());
      const x1 = min(x0.add(1), uOldW.sub(1));
      const y1 = min(y0.add(1), uOldH.sub(1));
      const fx = x.sub(float(x0));
      const fy = y.sub(float(y0));
      const top = mix(oldRead.load(ivec2(x0, y0)), oldRead.load(ivec2(x1, y0)), fx);
      const bottom = mix(oldRead.load(ivec2(x0, y1)), oldRead.load(ivec2(x1, y1)), fx);
      const value = mix(top, bottom, fy);
      textureStore(write[0], ivec2(ix, iy), value);
      textureStore(write[1], ivec2(ix, iy), value);
    });
  })().compute([1, 1, 1], [WX, WY, 1]);
  node.setName('frost.remap');
  return node;
}

/**
 * Every kernel of the effect, built once. `update*[k]` and `diffuse*[k]` read history k and write history
 * 1 - k; `remap` reads `oldRead` (pointed at the old history on resize) and writes both.
 */
export function createKernels(state) {
  const { read, write } = state;
  const oldRead = texture(state.textures[0]);
  const remap = remapKernel(state, oldRead);
  return {
    oldRead,
    remap,
    update2d: [kernel2d(state, updateTexel, read[0], write[1], 'frost.update.0to1'), kernel2d(state, updateTexel, read[1], write[0], 'frost.update.1to0')],
    updateTiles: [kernelTiles(state, updateTexel, read[0], write[1], 'frost.updateTiles.0to1'), kernelTiles(state, updateTexel, read[1], write[0], 'frost.updateTiles.1to0')],
    diffuse2d: [kernel2d(state, diffuseTexel, read[0], write[1], 'frost.diffuse.0to1'), kernel2d(state, diffuseTexel, read[1], write[0], 'frost.diffuse.1to0')],
    diffuseTiles: [kernelTiles(state, diffuseTexel, read[0], write[1], 'frost.diffuseTiles.0to1'), kernelTiles(state, diffuseTexel, read[1], write[0], 'frost.diffuseTiles.1to0')],
    clear: clearKernel(state),
  };
}
