// The body path of one vertex, shared by the deform pre-pass (deform.js), the diagnostics kernels and
// the lab's baseline: skin by the joint's method, correct where the build said so, then one field
// evaluation at the final position for the normal, the distance and the albedo; or, for a vertex of a
// skin-represented tier (program SKIN_PROGRAM), no field at all: skinned position and normal,
// baked colour.
//
// An individual's size s (root row 1 .w, core/genome.js) is a similarity of the certified body: the rest
// vertex, its centre of rotation and its correction trust radius are scaled by s before skinning, the
// pose rows already hold the scaled slots (core/pose.js) and the field scales its blend widths (field.js),
// so the path below is the unit body's times s.
import { If, Loop, clamp, float, int, max, select, vec3 } from 'three/tsl';
import { POSE_ROWS } from '../core/pose.js';
import { createField } from './field.js';
import { createSkin } from './skin.js';

/** The candidate code of a vertex no candidate region covers: never corrected, it runs the full program
 * (creaturegen surface/correction_region.py NO_PROGRAM). */
export const NO_PROGRAM = 65535;
/** The candidate code of a vertex that evaluates no field (a skin-represented tier): skinned position and
 * normal, baked colour (creaturegen surface/correction_region.py SKIN_PROGRAM). */
export const SKIN_PROGRAM = 65534;

/** Layout constants every node graph of this creature shares (from CREATURE and this runtime's own). */
export function layoutOf(data) {
  return {
    rows: POSE_ROWS,
    maxParts: data.maxParts,
    slotCount: data.slotCount,
    registers: data.registers,
    fullProgram: data.fullProgram,
    noProgram: NO_PROGRAM,
    skinProgram: SKIN_PROGRAM,
    gradientFloor: data.gradientFloor,
    tiny: data.tiny,
    kFloor: data.kFloor,
    bodyScale: data.bodyScale,
    correction: data.correction,
    vertices: data.mesh.vertices,
  };
}

/**
 * The field's self-occlusion at `p` (creature-local) with gradient `g`: `look.aoTaps` taps of the full program
 * at δᵢ = r·i/R along n̂ = g/|g| (r = look.aoRadius·L·size, i = 1..R), each counting max(δᵢ − d, 0)/δᵢ with
 * weight 2⁻ⁱ, normalised; 1 − that, clamped to [0, 1]. 1 when aoTaps is 0. Only the body's own parts
 * occlude (intra-body; creature/reference.py self_occlusion is its numpy twin). Inline (call it in a Fn).
 */
export function selfOcclusion(layout, fns, p, g, base, look) {
  const n = g.div(max(g.length(), float(layout.tiny))).toVar();
  const reach = look.aoRadius.mul(layout.bodyScale).mul(fns.field.size(base)).toVar();
  const taps = look.aoTaps;
  const occlusion = float(0).toVar();
  const total = float(0).toVar();
  const w = float(0.5).toVar();
  Loop(taps, ({ i }) => {
    const delta = reach.mul(float(i.add(1))).div(float(taps)).toVar();
    const d = fns.field.runProgram(p.add(n.mul(delta)), base, int(layout.fullProgram)).x;
    occlusion.addAssign(w.mul(max(delta.sub(d), 0).div(delta)));
    total.addAssign(w);
    w.mulAssign(0.5);
  });
  return clamp(float(1).sub(occlusion.div(max(total, float(layout.tiny)))), 0, 1);
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
 * A vertex whose program is SKIN_PROGRAM (a skin-represented tier) evaluates no field at all: its
 * skinned position, its skinned rest normal (in the gradient slot) and, with `colour`, its baked colour;
 * distance and accepted are 0. Inputs are nodes so the vertex stage (attributes) and the diagnostics
 * kernels (storage) share it. `program` is the program the field runs (full for noProgram and
 * skinProgram), `code` the vertex's own candidate code as stored (skinProgram for a skin vertex).
 * `path` (deform.js PATHS) builds one branch alone for a kernel that runs only vertices taking it:
 * 'skin', 'field' (a vertex whose trust radius is 0, which the correction would leave as it is) or
 * 'corrected'; 'any' chooses per vertex.
 */
export function bodyVertex(layout, fns, {
  rest, slots, weights, skin, cor, normal, colourSlots, colourWeights, base, skinOnly, colour = false, path = 'any', look = null,
}) {
  const skinVertexOnly = skin.z.greaterThan(layout.skinProgram - 0.5).and(skin.z.lessThan(layout.skinProgram + 0.5)).toVar();
  const program = select(skin.z.greaterThan(layout.skinProgram - 0.5), int(layout.fullProgram), int(skin.z)).toVar();
  const s = fns.field.size(base).toVar();
  const skinned = vec3(0).toVar();
  const position = vec3(0).toVar();
  const accepted = float(0).toVar();
  const gradient = vec3(0).toVar();
  const distance = float(0).toVar();
  const albedo = colour ? vec3(0).toVar() : null;
  const skinPath = () => {
    // No field: the skinned position and rest normal (no correction: its trust radius is 0), baked colour.
    const body = fns.skin.skinVertexNormal(rest.mul(s), normal, base, slots, weights, skin.x, cor.mul(s));
    skinned.assign(body.position);
    position.assign(body.position);
    gradient.assign(body.normal);
    if (colour) albedo.assign(fns.field.bakedColour(base, colourSlots, colourWeights));
  };
  const fieldPath = (correct) => {
    skinned.assign(fns.skin.skinVertex(rest.mul(s), base, slots, weights, skin.x, cor.mul(s)));
    const corrected = skinOnly || !correct ? { position: skinned, accepted: float(0) } : fns.skin.correctVertex(skinned, base, program, skin.y.mul(s));
    // One evaluation at the final position: the normal's gradient, the distance and (display) the colour.
    const final = fns.field.evaluate(corrected.position, base, program, { colour, kFloor: layout.kFloor });
    position.assign(corrected.position);
    accepted.assign(corrected.accepted);
    gradient.assign(final.value.yzw);
    distance.assign(final.value.x);
    // The albedo darkened by the field's self-occlusion (look.aoTaps taps; none at 0, the default).
    if (colour) albedo.assign(look === null ? final.colour : final.colour.mul(selfOcclusion(layout, fns, corrected.position, final.value.yzw, base, look)));
  };
  if (path === 'skin') skinPath();
  else if (path === 'field') fieldPath(false);
  else if (path === 'corrected') fieldPath(true);
  else If(skinVertexOnly, skinPath).Else(() => fieldPath(true));
  const code = select(skinVertexOnly, float(layout.skinProgram), float(program));
  return { skinned, position, accepted, program, code, gradient, distance, colour: albedo };
}
