// The package's diagnostics entry (`<package>/diagnostics`), for labs and parity jobs, not for an app's
// frame loop: compute kernels that call the very same TSL functions as the material (field programs,
// skinning, correction), with results read back from the GPU, and the CPU staging of a body's pose. Kernels
// and their buffers are created on first use, never by spawn or render. An app that never imports this
// entry ships none of it.
import { Fn, instanceIndex, instancedArray, int, uniform, vec4 } from 'three/tsl';
import { bodyFunctions, bodyVertex } from './body.js';
import { DEFORM_STRIDE, recordInputs } from './deform.js';
import { populationInternals } from './internals.js';
import { shellCounts, shellGeometry, shellVertex } from './shell.js';

export { populationInternals };

/** Readbacks of `population` (created by this package's createCreaturePopulation) through its own kernels. */
export function createDiagnostics(renderer, population, { maxPoints = 8192 } = {}) {
  const internals = populationInternals(population);
  const { layout, programs, geometry, records } = internals;
  // The kernels run the first loaded tier's programs over its pages: a body in another tier is refused.
  const { pages } = internals.tiers[0];
  const where = (id) => {
    const found = internals.locate(id);
    if (found.page.tier !== internals.tiers[0]) {
      throw new Error(`diagnostics: instance ${id} is in tier ${found.tier}; these readbacks serve tier ${internals.tiers[0].name} (setBodyTier it back)`);
    }
    return found;
  };
  const n = geometry.attributes.position.count;
  const rowsPerInstance = layout.maxParts * layout.rows;
  let skinState = null;
  let probeState = null;

  function skinKernels() {
    if (skinState) return skinState;
    const out = instancedArray(3 * n, 'vec4');
    const instance = uniform(0, 'int');
    const kernels = pages.map((page) => {
      const fns = bodyFunctions(layout, page.pose, programs);
      return Fn(() => {
        const i = int(instanceIndex);
        const base = instance.mul(rowsPerInstance).toVar();
        const body = bodyVertex(layout, fns, { ...recordInputs(records, i), base, skinOnly: false });
        out.element(i.mul(3)).assign(vec4(body.skinned, 0));
        out.element(i.mul(3).add(1)).assign(vec4(body.position, body.accepted));
        out.element(i.mul(3).add(2)).assign(vec4(body.gradient, body.distance));
      })().compute(n);
    });
    skinState = { out, instance, kernels };
    return skinState;
  }

  function probeKernels() {
    if (probeState) return probeState;
    const points = instancedArray(new Float32Array(4 * maxPoints), 'vec4');
    const out = instancedArray(maxPoints, 'vec4');
    const instance = uniform(0, 'int');
    const program = uniform(layout.fullProgram, 'int');
    const count = uniform(0, 'int');
    const kernels = pages.map((page) => {
      const fns = bodyFunctions(layout, page.pose, programs);
      return Fn(() => {
        const i = int(instanceIndex);
        const base = instance.mul(rowsPerInstance).toVar();
        out.element(i).assign(fns.field.runProgram(points.element(i).xyz, base, program));
      })().compute(maxPoints);
    });
    probeState = { points, out, instance, program, count, kernels };
    return probeState;
  }

  let shellState = null;
  function shellKernels() {
    if (shellState) return shellState;
    const counts = shellCounts(internals.tiers[0].data.tier);
    const unit = shellGeometry(counts);
    const m = counts.vertices * layout.slotCount;
    const dirs = new Float32Array(4 * m);
    for (let i = 0; i < m; i++) {
      const v = i % counts.vertices;
      for (let c = 0; c < 3; c++) dirs[4 * i + c] = unit.attributes.position.array[3 * v + c];
      dirs[4 * i + 3] = unit.attributes.cgEnd.array[v];
    }
    unit.dispose();
    const input = instancedArray(dirs, 'vec4').toReadOnly();
    const out = instancedArray(2 * m, 'vec4');
    const instance = uniform(0, 'int');
    const kernels = pages.map((page) => {
      const fns = bodyFunctions(layout, page.pose, programs);
      return Fn(() => {
        const i = int(instanceIndex);
        const slot = i.div(counts.vertices);
        const d = input.element(i).toVar();
        const base = instance.mul(rowsPerInstance).toVar();
        const shell = shellVertex(layout, fns, page.pose, { base, slot, dir: d.xyz, end: d.w, steps: counts.steps });
        out.element(i.mul(2)).assign(vec4(shell.placed, 0));
        out.element(i.mul(2).add(1)).assign(vec4(shell.position, shell.value.x));
      })().compute(m);
    });
    shellState = { out, instance, kernels, counts, m };
    return shellState;
  }

  return {
    /**
     * The debug shell of instance `id` as shell.js draws it (creature-local, before the root transform), slot
     * after slot: { counts, placed (on the pose rows), position (snapped), distance (d there) }.
     */
    async readShell(id) {
      const { page, index } = where(id);
      const s = shellKernels();
      s.instance.value = index;
      renderer.compute(s.kernels[pages.indexOf(page)]);
      const raw = new Float32Array(await renderer.getArrayBufferAsync(s.out.value));
      const placed = new Float32Array(3 * s.m), position = new Float32Array(3 * s.m), distance = new Float32Array(s.m);
      for (let i = 0; i < s.m; i++) {
        for (let c = 0; c < 3; c++) {
          placed[3 * i + c] = raw[8 * i + c];
          position[3 * i + c] = raw[8 * i + 4 + c];
        }
        distance[i] = raw[8 * i + 7];
      }
      return { counts: s.counts, placed, position, distance };
    },
    /** Pose rows of instance `id` from the CPU staging copy (what the next upload sends). */
    stagedPose: internals.stagedPose,
    /** The debug-mode variants built so far ('off' is the shipped one). */
    variantKeys: internals.variantKeys,
    /**
     * Skinned, corrected and gradient data of instance `id` (creature-local, before the root
     * transform): { skinned, corrected, accepted, gradient, distance } as Float32Arrays.
     */
    async readSkinned(id) {
      const { page, index } = where(id);
      const s = skinKernels();
      s.instance.value = index;
      renderer.compute(s.kernels[pages.indexOf(page)]);
      const raw = new Float32Array(await renderer.getArrayBufferAsync(s.out.value));
      const skinned = new Float32Array(3 * n), corrected = new Float32Array(3 * n), gradient = new Float32Array(3 * n);
      const accepted = new Float32Array(n), distance = new Float32Array(n);
      for (let v = 0; v < n; v++) {
        for (let c = 0; c < 3; c++) {
          skinned[3 * v + c] = raw[12 * v + c];
          corrected[3 * v + c] = raw[12 * v + 4 + c];
          gradient[3 * v + c] = raw[12 * v + 8 + c];
        }
        accepted[v] = raw[12 * v + 7];
        distance[v] = raw[12 * v + 11];
      }
      return { skinned, corrected, accepted, gradient, distance };
    },
    /** The body field of instance `id` at creature-local points (Float32Array xyz): vec4 (d, ∇d) each. */
    async probeField(id, xyz, program = layout.fullProgram) {
      const count = xyz.length / 3;
      if (count > maxPoints) throw new Error(`probeField: at most ${maxPoints} points per call (got ${count})`);
      const { page, index } = where(id);
      const s = probeKernels();
      const arr = s.points.value.array;
      arr.fill(0);
      for (let i = 0; i < count; i++) { arr[4 * i] = xyz[3 * i]; arr[4 * i + 1] = xyz[3 * i + 1]; arr[4 * i + 2] = xyz[3 * i + 2]; }
      s.points.value.needsUpdate = true;
      s.instance.value = index;
      s.program.value = program;
      renderer.compute(s.kernels[pages.indexOf(page)]);
      const raw = new Float32Array(await renderer.getArrayBufferAsync(s.out.value));
      return raw.slice(0, 4 * count);
    },
    /**
     * What the passes draw for instance `id`: its page's deform storage read back (creature-local, before
     * the root transform): { position, gradient, distance, accepted, colour, program } as Float32Arrays.
     */
    async readDeformed(id) {
      const { page, index } = where(id);
      const floats = 4 * DEFORM_STRIDE * n;
      const raw = new Float32Array(await renderer.getArrayBufferAsync(page.deform.value, null, 4 * floats * index, 4 * floats));
      const position = new Float32Array(3 * n), gradient = new Float32Array(3 * n), colour = new Float32Array(3 * n);
      const distance = new Float32Array(n), accepted = new Float32Array(n), program = new Float32Array(n);
      for (let v = 0; v < n; v++) {
        const o = 4 * DEFORM_STRIDE * v;
        for (let c = 0; c < 3; c++) {
          position[3 * v + c] = raw[o + c];
          gradient[3 * v + c] = raw[o + 4 + c];
          colour[3 * v + c] = raw[o + 8 + c];
        }
        distance[v] = raw[o + 3];
        accepted[v] = raw[o + 7];
        program[v] = raw[o + 11];
      }
      return { position, gradient, distance, accepted, colour, program };
    },
    /** The pose rows of instance `id` as the GPU holds them (readback). */
    async readPose(id) {
      const { page, index } = where(id);
      const floats = rowsPerInstance * 4;
      const buffer = await renderer.getArrayBufferAsync(page.pose.value, null, 4 * floats * index, 4 * floats);
      return new Float32Array(buffer);
    },
  };
}
