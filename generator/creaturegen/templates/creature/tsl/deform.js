// The deform pre-pass of a pose page: compute kernels (one per branch of the body path, vertexOrder) run
// every vertex of every listed body through the body path once (skin, bounded correction, one field
// evaluation at the final position) and store what the passes draw. The display pass and the shadow pass
// then read the same stored position, so the shadow is cast by the very surface that is seen, and no vertex is skinned or
// evaluated twice in a frame (a vertex stage would re-run the whole path per pass, and per re-shaded
// vertex on a rasteriser without a post-transform cache, such as SwiftShader).
import { Fn, If, instanceIndex, instancedArray, int, storage, vec4 } from 'three/tsl';
import { SKIN_PROGRAM, bodyVertex } from './body.js';

/** vec4 per drawn vertex: (position, distance), (gradient, accepted), (albedo, program); creaturegen's
 * DEFORM_STRIDE (creature/plan.py), which the build report's deformBytesPerBody uses. A SKIN_PROGRAM
 * vertex stores its skinned normal as the gradient, distance and accepted 0, and SKIN_PROGRAM as its
 * program. */
export const DEFORM_STRIDE = 3;
/** vec4 per rest vertex: (rest, 0), slots, weights, (centre of rotation, 0), (method, trust, program, 0),
 * (rest normal, 0), colour slots, colour weights (the last two zero unless the tier is skin-represented:
 * they colour the vertices whose program is SKIN_PROGRAM, which evaluate no field). */
export const RECORD_STRIDE = 8;

/** The rest-vertex records (one read-only storage node shared by every page and kernel). */
export function vertexRecords(geometry) {
  const a = geometry.attributes;
  const n = a.position.count;
  const out = new Float32Array(4 * RECORD_STRIDE * n);
  for (let v = 0; v < n; v++) {
    const o = 4 * RECORD_STRIDE * v;
    for (let c = 0; c < 3; c++) {
      out[o + c] = a.position.array[3 * v + c];
      out[o + 12 + c] = a.cgCor.array[3 * v + c];
      out[o + 20 + c] = a.normal.array[3 * v + c];
    }
    for (let c = 0; c < 4; c++) {
      out[o + 4 + c] = a.cgSlots.array[4 * v + c];
      out[o + 8 + c] = a.cgWeights.array[4 * v + c];
      out[o + 16 + c] = a.cgSkin.array[4 * v + c];
      out[o + 24 + c] = a.cgColourSlots.array[4 * v + c];
      out[o + 28 + c] = a.cgColourWeights.array[4 * v + c];
    }
  }
  return instancedArray(out, 'vec4').toReadOnly();
}

/**
 * The branch of the body path a vertex takes (bodyVertex `path`), in the order the pre-pass runs them:
 * no field at all (SKIN_PROGRAM), the field without correction (trust radius 0), corrected.
 */
export const PATHS = Object.freeze(['skin', 'field', 'corrected']);

/**
 * The order the pre-pass runs a body's vertices in and its segments, one per path (empty ones left
 * out): { order (one int per rest vertex, a permutation), segments: [{ path, start, count }] }. Within a
 * segment vertices are grouped by program and skinning method, rest order last. Each segment is its own
 * dispatch, compiled with only its path's code, and neighbouring invocations take the same branches: a
 * GPU lane group pays for every branch any of its lanes takes, and SwiftShader runs every branch of an
 * `if` under a mask, so in one kernel over the rest order a skin-only vertex paid for the field and the
 * correction, and every vertex for the longest tape beside it. The order changes no vertex's result:
 * each invocation writes its own vertex's slot of the deform storage.
 */
export function vertexOrder(geometry) {
  const skin = geometry.attributes.cgSkin.array;
  const n = geometry.attributes.position.count;
  const pathOf = (v) => {
    const program = skin[4 * v + 2];
    if (program > SKIN_PROGRAM - 0.5 && program < SKIN_PROGRAM + 0.5) return 0;
    return skin[4 * v + 1] > 0 ? 2 : 1;
  };
  const keys = Array.from({ length: n }, (_, v) => [pathOf(v), skin[4 * v + 2], skin[4 * v]]);
  const order = Int32Array.from({ length: n }, (_, v) => v);
  order.sort((a, b) => {
    for (let c = 0; c < 3; c++) if (keys[a][c] !== keys[b][c]) return keys[a][c] - keys[b][c];
    return a - b;
  });
  const segments = [];
  for (let k = 0; k < n; k++) {
    const path = PATHS[keys[order[k]][0]];
    if (segments.length === 0 || segments[segments.length - 1].path !== path) segments.push({ path, start: k, count: 0 });
    segments[segments.length - 1].count += 1;
  }
  return { order: instancedArray(order, 'int').toReadOnly(), segments };
}

/** The record of rest vertex `v` as the inputs bodyVertex takes. */
export function recordInputs(records, v) {
  const r = v.mul(RECORD_STRIDE);
  return {
    rest: records.element(r).xyz, slots: records.element(r.add(1)), weights: records.element(r.add(2)),
    cor: records.element(r.add(3)).xyz, skin: records.element(r.add(4)), normal: records.element(r.add(5)).xyz,
    colourSlots: records.element(r.add(6)), colourWeights: records.element(r.add(7)),
  };
}

/**
 * The deformed-vertex storage of a page of `size` bodies (written by compute, read by the passes).
 *
 * Every page's storage nodes carry the same names (cgDeform, cgDeformView, cgPose in pages.js, the lists'
 * own): three names an unnamed buffer after its node id, so each page's kernels and materials would be
 * different WGSL, compiled once per page. Named alike, the pages' shaders are one text and the device
 * compiles each pipeline once (measured on SwiftShader, hopper, 4 pages: warm-up 14.4 s -> 3.2 s).
 */
export function deformStorage(size, vertices) {
  return instancedArray(size * vertices * DEFORM_STRIDE, 'vec4').setName('cgDeform');
}

/** A read-only view of a page's deformed vertices for the vertex stage (same GPU buffer). */
export function deformView(deform) {
  return storage(deform.value, 'vec4', deform.value.count).toReadOnly().setName('cgDeformView');
}

/** A page's instance list (`name` for every page alike, see deformStorage): bodies, one int each. */
export function instanceList(size, name) {
  return instancedArray(new Int32Array(size), 'int').setName(name);
}

/**
 * The deform kernels of one page over `fns` (bodyFunctions, or a lab baseline's), one per segment of
 * `order` (vertexOrder). They run the bodies named by the first `count` entries of the page's instance
 * `list` (dispatchDeform), each into its own slice of the deform storage, so a body left out keeps what
 * it stored last: the population lists only the bodies whose pose rows changed since their last
 * pre-pass. Dead instances are skipped (the vertex stage draws them collapsed to the origin). `look` (the
 * population's shading uniforms, createLookUniforms) adds the field's self-occlusion to the stored albedo.
 */
export function createDeformKernel(layout, fns, { pose, records, order, deform, list, size, vertices, skinOnly = false, look = null }) {
  const rowsPerInstance = layout.maxParts * layout.rows;
  const kernels = order.segments.map(({ path, start, count }) => {
    const kernel = Fn(() => {
      const entry = int(instanceIndex).div(count).toVar();
      const v = order.order.element(int(instanceIndex).sub(entry.mul(count)).add(start)).toVar();
      const j = list.element(entry).toVar();
      const idx = j.mul(vertices).add(v).toVar();
      const base = j.mul(rowsPerInstance).toVar();
      const alive = pose.element(base.add(layout.slotCount * layout.rows)).w;
      If(alive.greaterThan(0.5), () => {
        const body = bodyVertex(layout, fns, { ...recordInputs(records, v), base, skinOnly, colour: true, path, look });
        const o = idx.mul(DEFORM_STRIDE).toVar();
        deform.element(o).assign(vec4(body.position, body.distance));
        deform.element(o.add(1)).assign(vec4(body.gradient, body.accepted));
        deform.element(o.add(2)).assign(vec4(body.colour, body.code));
      });
    })().compute(size * count);
    kernel.setName(`${skinOnly ? 'cgDeformSkinOnly' : 'cgDeform'}.${path}`);
    return { kernel, count };
  });
  return { kernels, list, vertices, size };
}

/**
 * Run `deform` (every segment's kernel) over the first `count` bodies of its page's instance list;
 * returns the vertices processed.
 */
export function dispatchDeform(renderer, deform, count) {
  if (count <= 0) return 0;
  let n = 0;
  for (const segment of deform.kernels) {
    segment.kernel.count = count * segment.count;
    renderer.compute(segment.kernel);
    n += segment.kernel.count;
  }
  return n;
}
