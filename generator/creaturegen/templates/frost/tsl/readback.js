// Diagnostics only (effect.readHistory, effect.readStructure; the package's lab and parity job use them):
// copy the latest history, or the structure textures as the GPU loads them, into a storage buffer with a
// compute pass and read it back. Nothing here runs unless asked, and never on the per-frame path.
import { Fn, If, globalId, instanceIndex, instancedArray, int, ivec2, texture } from 'three/tsl';
import { WL, WX, WY } from './dispatch.js';

/** The readback's source node (pointed at the latest history on each read) and its buffer, grown on demand. */
export function createReadback(state) {
  return { source: texture(state.textures[0]), buffer: null, node: null, capacity: 0 };
}

/** The latest history, RGBA float per texel, row-major from the top-left texel. */
export async function readHistory(state) {
  const { readback, renderer, histW, histH, uHistW } = state;
  const count = histW * histH;
  if (count > readback.capacity) {
    readback.capacity = count;
    readback.buffer = instancedArray(count, 'vec4');
    const buffer = readback.buffer;
    const source = readback.source;
    readback.node = Fn(() => {
      const idx = int(instanceIndex);
      buffer.element(idx).assign(source.load(ivec2(idx.mod(uHistW), idx.div(uHistW))));
    })().compute(count, [WL, 1, 1]);
    readback.node.setName('frost.readback');
  }
  readback.source.value = state.textures[state.current];
  readback.node.count = count;
  renderer.compute(readback.node);
  const bytes = await renderer.getArrayBufferAsync(readback.buffer.value, null, 0, count * 16);
  return { width: histW, height: histH, data: new Float32Array(bytes) };
}

// The structure and normal textures as the GPU loads them, one textureLoad per texel (unorm8 → float,
// exact), copied to a buffer and read back, as 8-bit codes.
async function readTexels(renderer, tex) {
  const n = tex.image.width;
  const buffer = instancedArray(n * n, 'vec4');
  const source = texture(tex);
  const node = Fn(() => {
    const ix = int(globalId.x);
    const iy = int(globalId.y);
    If(ix.lessThan(n).and(iy.lessThan(n)), () => {
      buffer.element(iy.mul(n).add(ix)).assign(source.load(ivec2(ix, iy)));
    });
  })().compute([1, 1, 1], [WX, WY, 1]);
  node.setName('frost.readStructure');
  renderer.compute(node, [Math.ceil(n / WX), Math.ceil(n / WY), 1]);
  const floats = new Float32Array(await renderer.getArrayBufferAsync(buffer.value));
  const codes = new Uint8Array(floats.length);
  for (let i = 0; i < floats.length; i++) codes[i] = Math.round(floats[i] * 255);
  return codes;
}

/** The structure and normal textures (structure.js) as RGBA8 codes, N × N texels each. */
export async function readStructure(state, { structureTex, normalTex }) {
  return {
    resolution: structureTex.image.width,
    structure: await readTexels(state.renderer, structureTex),
    normals: await readTexels(state.renderer, normalTex),
  };
}
