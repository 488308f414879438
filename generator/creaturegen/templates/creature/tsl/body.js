// The body path of one vertex, shared by the deform pre-pass (deform.js), the diagnostics kernels and
// the lab's baseline: skin by the joint's method, correct where the build said so, then one field
// evaluation at the final position for the normal, the distance and the albedo.
//
// An individual's size s (root row 1 .w, core/genome.js) is a similarity of the certified body: the rest
// vertex, its centre of rotation and its correction trust radius are scaled by s before skinning, the
// pose rows already hold the scaled slots (core/pose.js) and the field scales its blend widths (field.js),
// so the path below is the unit body's times s.
import { float, int, select } from 'three/tsl';
import { createField } from './field.js';
import { createSkin } from './skin.js';

/** Layout constants every node graph of this creature shares (from CREATURE). */
export function layoutOf(data) {
  return {
    rows: data.poseRows,
    maxParts: data.maxParts,
    slotCount: data.slotCount,
    registers: data.registers,
    fullProgram: data.fullProgram,
    noProgram: data.noProgram,
    gradientFloor: data.gradientFloor,
    tiny: data.tiny,
    kFloor: data.kFloor,
    bodyScale: data.bodyScale,
    correction: data.correction,
    vertices: data.mesh.vertices,
  };
}

/** The field and skin node builders over one pose storage node. */
export function bodyFunctions(layout, pose, programs) {
  const field = createField({
    pose, programs, rows: layout.rows, slotCount: layout.slotCount, registers: layout.registers,
    gradientFloor: layout.gradientFloor, tiny: layout.tiny,
  });
  const skin = createSkin({ pose, rows: layout.rows, field, correction: layout.correction });
  return { field, skin };
}

/**
 * One vertex through the whole body path, inline in a Fn: skin, correct (unless skin-only), then one
 * field evaluation at the final position for the normal, the distance and (with `colour`) the albedo.
 * Inputs are nodes so the vertex stage (attributes) and the diagnostics kernels (storage) share it.
 */
export function bodyVertex(layout, fns, { rest, slots, weights, skin, cor, base, skinOnly, colour = false }) {
  const program = select(skin.z.greaterThan(layout.noProgram - 0.5), int(layout.fullProgram), int(skin.z)).toVar();
  const s = fns.field.size(base).toVar();
  const skinned = fns.skin.skinVertex(rest.mul(s), base, slots, weights, skin.x, cor.mul(s)).toVar();
  const corrected = skinOnly ? { position: skinned, accepted: float(0) } : fns.skin.correctVertex(skinned, base, program, skin.y.mul(s));
  // One evaluation at the final position: the normal's gradient, the distance and (display) the colour.
  const final = fns.field.evaluate(corrected.position, base, program, { colour, kFloor: layout.kFloor });
  return {
    skinned, position: corrected.position, accepted: corrected.accepted, program,
    gradient: final.value.yzw, distance: final.value.x, colour: final.colour,
  };
}
