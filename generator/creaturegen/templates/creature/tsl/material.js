// The body material of one pose page. Instance i of the draw is body drawList[i] of the page (the live bodies
// the population did not cull, staging.js). The vertex stage only reads: the deformed vertex the page's deform
// pre-pass stored (deform.js: skinned, corrected, the analytic field gradient and the albedo), then the
// root transform (squash, yaw, position), applied once here (a plain Mesh with `count` instances: no
// instanceMatrix, so nothing is applied twice); the normal takes the transform's inverse transpose and goes
// to normalLocal, the local-space slot r185 expects. The shadow pass uses this positionNode too (three's
// default), so it casts the stored surface that is seen. A vertex of a skin-represented tier (program
// SKIN_PROGRAM, body.js) stores its skinned normal, baked colour and distance 0 there: every view reads it
// the same way (the 'distance' view shows it on the surface, 'candidates' gives it its own colour).
import * as THREE from 'three/webgpu';
import {
  Fn, attribute, clamp, float, fract, instanceIndex, int, mix, normalLocal, normalize, select, sin, uniform,
  varyingProperty, vec3, vertexIndex,
} from 'three/tsl';
import { DEFORM_STRIDE } from './deform.js';

/** The runtime's debug views (creaturegen creature/plan.py DEBUG_MODES); 'shell' is the diagnostic capsule shell. */
export const DEBUG_MODES = Object.freeze(['off', 'skin-only', 'distance', 'weights', 'normals', 'candidates', 'shell']);

/** Throws unless `mode` is one of DEBUG_MODES (every place a mode enters the runtime calls this). */
export function checkDebugMode(mode) {
  if (!DEBUG_MODES.includes(mode)) throw new Error(`debugMode: one of ${DEBUG_MODES.join(', ')} (got ${mode})`);
  return mode;
}

// A stable colour per integer (debug views): fract of a sine hash.
const hashColour = (n) => vec3(fract(sin(n.mul(12.9898)).mul(43758.5453)), fract(sin(n.mul(78.233)).mul(12543.37)), fract(sin(n.mul(3.7719)).mul(9821.13)));

/** Yaw about +y by the root row (cos, sin), as the JS core writes it. */
export const rootRotate = (root1, v) => vec3(root1.x.mul(v.x).add(root1.y.mul(v.z)), v.y, root1.y.negate().mul(v.x).add(root1.x.mul(v.z)));

/** A creature-local point under the root row's squash s (x, z by 1/√s, y by s: volume kept) and yaw. */
export const rootPoint = (root1, p) => {
  const k = root1.z.inverseSqrt();
  return rootRotate(root1, vec3(p.x.mul(k), p.y.mul(root1.z), p.z.mul(k)));
};

/** A creature-local normal under the same transform: the inverse transpose diag(√s, 1/s, √s), renormalised. */
export const rootNormal = (root1, n) => {
  const q = root1.z.sqrt();
  return rootRotate(root1, normalize(vec3(n.x.mul(q), n.y.div(root1.z), n.z.mul(q))));
};

/**
 * The shading controls as uniform nodes, one set per population and shared by every page and variant, so
 * setting one is a single uniform write (LookData: roughness, metalness, distanceRange, aoTaps, aoRadius).
 */
export function createLookUniforms(look) {
  return {
    roughness: uniform(look.roughness, 'float'),
    metalness: uniform(look.metalness, 'float'),
    distanceRange: uniform(look.distanceRange, 'float'),
    aoTaps: uniform(look.aoTaps, 'int'),
    aoRadius: uniform(look.aoRadius, 'float'),
  };
}

/** The shading controls setLook takes, each [lowest, highest] and whether the lowest is allowed (the spec's look). */
export const LOOK_RANGES = Object.freeze({ roughness: [0, 1, true], metalness: [0, 1, true], distanceRange: [0, 0.1, false], aoTaps: [0, 8, true], aoRadius: [0, 0.25, false] });
/** The controls that are whole numbers. */
export const LOOK_INTEGERS = Object.freeze(['aoTaps']);
/** The controls the deform pre-pass reads (setLook re-deforms every live body when one changes). */
export const LOOK_DEFORM = Object.freeze(['aoTaps', 'aoRadius']);

/** `changes` checked against LOOK_RANGES: throws a RangeError naming the control, else returns it. */
export function checkLook(changes) {
  if (changes === null || typeof changes !== 'object') throw new TypeError(`setLook: expected an object of controls (got ${changes})`);
  for (const [name, value] of Object.entries(changes)) {
    const range = LOOK_RANGES[name];
    if (!range) throw new RangeError(`setLook: unknown control ${JSON.stringify(name)}; controls: ${Object.keys(LOOK_RANGES).join(', ')}`);
    const [lo, hi, closed] = range;
    if (typeof value !== 'number' || !Number.isFinite(value) || value > hi || value < lo || (!closed && value === lo)
      || (LOOK_INTEGERS.includes(name) && !Number.isInteger(value))) {
      throw new RangeError(`setLook: ${name} must be ${LOOK_INTEGERS.includes(name) ? 'a whole number' : 'a number'} ${closed ? 'in' : 'above'} ${closed ? `[${lo}, ${hi}]` : `${lo}, at most ${hi}`} (got ${value})`);
    }
  }
  return changes;
}

/**
 * The display material of a page for one debug mode (a variant; cached by the population). `deform` is
 * the page's read-only deformed-vertex view (deform.js deformView), `drawList` the page's list of drawn
 * bodies (instance i draws body drawList[i]), `look` the population's shading uniforms
 * (createLookUniforms); 'skin-only' is the same material over the skin-only pre-pass.
 */
export function createBodyMaterial(layout, pose, deform, drawList, mode, look) {
  const material = new THREE.MeshStandardNodeMaterial();
  material.roughnessNode = look.roughness;
  material.metalnessNode = look.metalness;
  const vColour = varyingProperty('vec3', 'vCgColour');
  material.positionNode = Fn(() => {
    const j = drawList.element(int(instanceIndex)).toVar();
    const rootRow = j.mul(layout.maxParts * layout.rows).add(layout.slotCount * layout.rows);
    const root0 = pose.element(rootRow).toVar();
    const root1 = pose.element(rootRow.add(1)).toVar();
    const o = j.mul(layout.vertices).add(int(vertexIndex)).mul(DEFORM_STRIDE).toVar();
    const r0 = deform.element(o).toVar();
    const r1 = deform.element(o.add(1)).toVar();
    const r2 = deform.element(o.add(2)).toVar();
    const n = normalize(r1.xyz).toVar();
    let colour;
    if (mode === 'distance') {
      const t = clamp(r0.w.div(look.distanceRange.mul(layout.bodyScale)), -1, 1);
      colour = select(t.lessThan(0), mix(vec3(0.9), vec3(0.1, 0.3, 1.0), t.negate()), mix(vec3(0.9), vec3(1.0, 0.2, 0.1), t));
    } else if (mode === 'weights') {
      colour = hashColour(float(attribute('cgSlots', 'vec4').x).add(1)).mul(attribute('cgWeights', 'vec4').x);
    } else if (mode === 'normals') {
      colour = n.mul(0.5).add(0.5);
    } else if (mode === 'candidates') {
      colour = hashColour(r2.w.add(1));
    } else {
      colour = r2.xyz;
    }
    vColour.assign(colour);
    normalLocal.assign(rootNormal(root1, n));
    return select(root0.w.greaterThan(0.5), rootPoint(root1, r0.xyz).add(root0.xyz), vec3(0));
  })();
  material.colorNode = vColour;
  return material;
}
