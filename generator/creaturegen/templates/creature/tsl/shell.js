// The diagnostic shell (debug mode 'shell'): each slot of each body as a capsule of the tier's preview
// counts (SHELL_RADIAL segments around, SHELL_CAP_RINGS rings per cap) placed on its pose row (segment
// a→b, radii ra→rb) and snapped onto the union field by SHELL_SNAP_STEPS Newton steps, shaded with the
// field's analytic normal and the slot's authored colour. It shows what the pose storage and the field
// hold, never what ships: the shells overlap at every blend and form no manifold skin; the shipped body
// is the skinned reference mesh. One draw per page (bodies × slots instances), built on first use.
import * as THREE from 'three/webgpu';
import {
  Fn, Loop, abs, attribute, cross, dot, float, instanceIndex, int, mix, normalLocal, normalize, select,
  varyingProperty, vec3,
} from 'three/tsl';
import { rootNormal, rootPoint } from './material.js';

/** The tiers the shell counts below are listed for, in this order. */
export const SHELL_TIERS = Object.freeze(['hero', 'repeated', 'distant']);
/** Segments around a slot's shell, per tier. */
export const SHELL_RADIAL = Object.freeze([12, 10, 8]);
/** Rings per hemispherical cap between its pole and its equator, per tier. */
export const SHELL_CAP_RINGS = Object.freeze([3, 2, 2]);
/** Newton steps that snap a shell vertex onto the union field, per tier (the correction's trials). */
export const SHELL_SNAP_STEPS = Object.freeze([2, 2, 1]);

/** The shell counts of `tier`: { radial, capRings, steps, vertices } with vertices = (2 + 2·capRings)·radial + 2. */
export function shellCounts(tier) {
  const t = SHELL_TIERS.indexOf(tier);
  if (t < 0) throw new Error(`shellCounts: unknown tier ${JSON.stringify(tier)}`);
  const radial = SHELL_RADIAL[t], capRings = SHELL_CAP_RINGS[t];
  return { radial, capRings, steps: SHELL_SNAP_STEPS[t], vertices: (2 + 2 * capRings) * radial + 2 };
}

/**
 * A unit shell in its slot frame: `position` holds each vertex's direction from its end's centre (y along
 * a→b), `cgEnd` its end (0 at a, 1 at b). Rings run from the pole at a through its cap and equator, then
 * b's equator, cap and pole; ring k of a cap sits at polar angle (π/2)·k/(capRings + 1).
 */
export function shellGeometry({ radial, capRings }) {
  const dirs = [];
  const ends = [];
  const ring = (end, polar) => {
    for (let j = 0; j < radial; j++) {
      const azimuth = (2 * Math.PI * j) / radial;
      const y = end === 0 ? -Math.cos(polar) : Math.cos(polar);
      dirs.push(Math.sin(polar) * Math.cos(azimuth), y, Math.sin(polar) * Math.sin(azimuth));
      ends.push(end);
    }
  };
  dirs.push(0, -1, 0); ends.push(0);
  for (let k = 1; k <= capRings + 1; k++) ring(0, (Math.PI / 2) * (k / (capRings + 1)));
  for (let k = capRings + 1; k >= 1; k--) ring(1, (Math.PI / 2) * (k / (capRings + 1)));
  dirs.push(0, 1, 0); ends.push(1);
  const rings = 2 * capRings + 2;
  const last = 1 + rings * radial;
  const index = [];
  const at = (r, j) => 1 + r * radial + (j % radial);
  for (let j = 0; j < radial; j++) index.push(0, at(0, j), at(0, j + 1));
  for (let r = 0; r + 1 < rings; r++) {
    for (let j = 0; j < radial; j++) index.push(at(r, j), at(r + 1, j), at(r + 1, j + 1), at(r, j), at(r + 1, j + 1), at(r, j + 1));
  }
  for (let j = 0; j < radial; j++) index.push(at(rings - 1, j), last, at(rings - 1, j + 1));
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(dirs), 3));
  // The unsnapped capsule's normal: the material replaces it with the field's (normalLocal), but three
  // builds its normal varying only for a geometry that has the attribute.
  geometry.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(dirs), 3));
  geometry.setAttribute('cgEnd', new THREE.BufferAttribute(new Float32Array(ends), 1));
  geometry.setIndex(index);
  return geometry;
}

/**
 * One shell vertex of slot `slot` of the body whose pose rows start at `base`, creature-local: the unit
 * direction `dir` of end `end` placed on the slot's row, then `steps` Newton steps p ← p − d·∇d/|∇d|² of
 * the full program (none where |∇d|² is under the correction's gradient floor). Inline (call it in a Fn):
 * returns { placed, position, value } with value = vec4(d, ∇d) at the snapped position.
 */
export function shellVertex(layout, fns, pose, { base, slot, dir, end, steps }) {
  const o = base.add(slot.mul(layout.rows)).toVar();
  const rowA = pose.element(o).toVar();
  const rowB = pose.element(o.add(1)).toVar();
  const ba = rowB.xyz.sub(rowA.xyz);
  const len = ba.length();
  const axis = select(len.greaterThan(float(layout.tiny)), ba.div(len), vec3(0, 1, 0)).toVar();
  const helper = select(abs(axis.x).lessThan(0.9), vec3(1, 0, 0), vec3(0, 0, 1));
  const u = normalize(cross(axis, helper)).toVar();
  const w = cross(axis, u);
  const n = u.mul(dir.x).add(axis.mul(dir.y)).add(w.mul(dir.z));
  const placed = mix(rowA.xyz, rowB.xyz, end).add(n.mul(mix(rowA.w, rowB.w, end))).toVar();
  const p = placed.toVar();
  const program = int(layout.fullProgram);
  Loop(steps, () => {
    const r = fns.field.runProgram(p, base, program).toVar();
    const gg = dot(r.yzw, r.yzw);
    p.assign(select(gg.greaterThanEqual(layout.correction.gradientFloor), p.sub(r.yzw.mul(r.x.div(gg))), p));
  });
  const value = fns.field.runProgram(p, base, program).toVar();
  return { placed, position: p, value };
}

/** The shell mesh of one page of tier `tier` (drawn in place of the body while the debug mode is 'shell'):
 * instance i is slot i % slotCount of body drawList[i / slotCount]. */
export function createShellMesh(layout, fns, pose, drawList, name, tier) {
  const counts = shellCounts(tier);
  const material = new THREE.MeshStandardNodeMaterial({ roughness: 0.7, metalness: 0.0 });
  const vColour = varyingProperty('vec3', 'vCgShellColour');
  material.positionNode = Fn(() => {
    const i = int(instanceIndex);
    const k = i.div(layout.slotCount);
    const slot = i.sub(k.mul(layout.slotCount)).toVar();
    const j = drawList.element(k).toVar();
    const base = j.mul(layout.maxParts * layout.rows).toVar();
    const root0 = pose.element(base.add(layout.slotCount * layout.rows)).toVar();
    const root1 = pose.element(base.add(layout.slotCount * layout.rows + 1)).toVar();
    const dir = attribute('position', 'vec3');
    const end = attribute('cgEnd', 'float');
    const shell = shellVertex(layout, fns, pose, { base, slot, dir, end, steps: counts.steps });
    vColour.assign(pose.element(base.add(slot.mul(layout.rows)).add(2)).yzw);
    normalLocal.assign(rootNormal(root1, normalize(shell.value.yzw)));
    return select(root0.w.greaterThan(0.5), rootPoint(root1, shell.position).add(root0.xyz), vec3(0));
  })();
  material.colorNode = vColour;
  const mesh = new THREE.Mesh(shellGeometry(counts), material);
  mesh.name = `${name}.shell`;
  mesh.count = 0;
  mesh.visible = false;
  return mesh;
}
