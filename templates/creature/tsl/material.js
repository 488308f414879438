// The body material of one pose page: the reference mesh skinned from the page, corrected where the
// build said so, normals from the analytic field gradient (local space, as r185's normalLocal slot
// expects), root transform applied once here (a plain Mesh with `count` instances: no instanceMatrix,
// so positionNode sees creature-local geometry and nothing is applied twice).
import * as THREE from 'three/webgpu';
import {
  Fn, attribute, clamp, float, fract, instanceIndex, int, mix, normalLocal, normalize, positionGeometry, select,
  sin, varyingProperty, vec3,
} from 'three/tsl';
import { createField } from './field.js';
import { createSkin } from './skin.js';

export const DEBUG_MODES = Object.freeze(['off', 'skin-only', 'distance', 'weights', 'normals', 'candidates', 'shell']);

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
  };
}

/** The field and skin node builders over one pose storage node. */
export function bodyFunctions(layout, pose, programs) {
  const field = createField({
    pose, programs, rows: layout.rows, registers: layout.registers, gradientFloor: layout.gradientFloor, tiny: layout.tiny,
  });
  const skin = createSkin({ pose, rows: layout.rows, field, correction: layout.correction });
  return { field, skin };
}

// A stable colour per integer (debug views): fract of a sine hash.
const hashColour = (n) => vec3(fract(sin(n.mul(12.9898)).mul(43758.5453)), fract(sin(n.mul(78.233)).mul(12543.37)), fract(sin(n.mul(3.7719)).mul(9821.13)));

/**
 * One vertex through the whole body path, inline in a Fn: skin, correct (unless skin-only), then one
 * field evaluation at the final position for the normal, the distance and (with `colour`) the albedo.
 * Inputs are nodes so the vertex stage (attributes) and the diagnostics kernels (storage) share it.
 */
export function bodyVertex(layout, fns, { rest, slots, weights, skin, cor, base, skinOnly, colour = false }) {
  const program = select(skin.z.greaterThan(layout.noProgram - 0.5), int(layout.fullProgram), int(skin.z)).toVar();
  const skinned = fns.skin.skinVertex(rest, base, slots, weights, skin.x, cor).toVar();
  const corrected = skinOnly ? { position: skinned, accepted: float(0) } : fns.skin.correctVertex(skinned, base, program, skin.y);
  // One evaluation at the final position: the normal's gradient, the distance and (display) the colour.
  const final = fns.field.evaluate(corrected.position, base, program, { colour, kFloor: layout.kFloor });
  return {
    skinned, position: corrected.position, accepted: corrected.accepted, program,
    gradient: final.value.yzw, distance: final.value.x, colour: final.colour,
  };
}

/** The display material of a page for one debug mode (a variant; cached by the population). */
export function createBodyMaterial(layout, pose, programs, mode) {
  const fns = bodyFunctions(layout, pose, programs);
  const material = new THREE.MeshStandardNodeMaterial({ roughness: 0.55, metalness: 0.0 });
  const vColour = varyingProperty('vec3', 'vCgColour');
  material.positionNode = Fn(() => {
    const base = int(instanceIndex).mul(layout.maxParts * layout.rows).toVar();
    const rootRow = base.add(layout.slotCount * layout.rows);
    const root0 = pose.element(rootRow).toVar();
    const root1 = pose.element(rootRow.add(1)).toVar();
    const skinAttr = attribute('cgSkin', 'vec4');
    const weights = attribute('cgWeights', 'vec4');
    const body = bodyVertex(layout, fns, {
      rest: positionGeometry, slots: attribute('cgSlots', 'vec4'), weights, skin: skinAttr,
      cor: attribute('cgCor', 'vec3'), base, skinOnly: mode === 'skin-only', colour: mode === 'off' || mode === 'skin-only',
    });
    const p = body.position.toVar();
    const n = normalize(body.gradient).toVar();
    let colour;
    if (mode === 'distance') {
      const t = clamp(body.distance.div(layout.bodyScale * 0.005), -1, 1);
      colour = select(t.lessThan(0), mix(vec3(0.9), vec3(0.1, 0.3, 1.0), t.negate()), mix(vec3(0.9), vec3(1.0, 0.2, 0.1), t));
    } else if (mode === 'weights') {
      colour = hashColour(float(attribute('cgSlots', 'vec4').x).add(1)).mul(weights.x);
    } else if (mode === 'normals') {
      colour = n.mul(0.5).add(0.5);
    } else if (mode === 'candidates') {
      colour = hashColour(float(body.program).add(1));
    } else {
      colour = body.colour;
    }
    vColour.assign(colour);
    // Root transform (yaw about +y, then translation), applied exactly once, to position and normal.
    const rot = (v) => vec3(root1.x.mul(v.x).add(root1.y.mul(v.z)), v.y, root1.y.negate().mul(v.x).add(root1.x.mul(v.z)));
    normalLocal.assign(rot(n));
    return select(root0.w.greaterThan(0.5), rot(p).add(root0.xyz), vec3(0));
  })();
  material.colorNode = vColour;
  return material;
}
