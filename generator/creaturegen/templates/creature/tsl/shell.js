// The diagnostic capsule shell (debug mode 'shell'): each slot of each body drawn as a capsule snapped to
// its pose row (segment a→b, radii ra→rb, the slot's authored colour), with no blending, no skin and no
// field. It shows what the pose storage holds, never what ships: the shipped body is the skinned
// reference mesh. One draw per page (bodies × slots instances), built on first use.
import * as THREE from 'three/webgpu';
import {
  Fn, abs, attribute, cross, float, instanceIndex, int, mix, normalLocal, normalize, select, varyingProperty,
  vec3,
} from 'three/tsl';
import { rootNormal, rootPoint } from './material.js';

/** A unit capsule along +y (hemispheres at y = ±0.5) with per-vertex end (0 at a, 1 at b). */
function shellGeometry() {
  const geometry = new THREE.CapsuleGeometry(1, 1, 4, 12);
  const y = geometry.attributes.position.array;
  const end = new Float32Array(geometry.attributes.position.count);
  for (let v = 0; v < end.length; v++) end[v] = y[3 * v + 1] > 0 ? 1 : 0;
  geometry.setAttribute('cgEnd', new THREE.BufferAttribute(end, 1));
  return geometry;
}

/** The shell mesh of one page (drawn in place of the body while the debug mode is 'shell'): instance i is
 * slot i % slotCount of body drawList[i / slotCount]. */
export function createShellMesh(layout, pose, drawList, name) {
  const material = new THREE.MeshStandardNodeMaterial({ roughness: 0.7, metalness: 0.0 });
  const vColour = varyingProperty('vec3', 'vCgShellColour');
  material.positionNode = Fn(() => {
    const i = int(instanceIndex);
    const k = i.div(layout.slotCount);
    const s = i.sub(k.mul(layout.slotCount));
    const j = drawList.element(k).toVar();
    const base = j.mul(layout.maxParts * layout.rows).toVar();
    const o = base.add(s.mul(layout.rows)).toVar();
    const rowA = pose.element(o).toVar();
    const rowB = pose.element(o.add(1)).toVar();
    const root0 = pose.element(base.add(layout.slotCount * layout.rows)).toVar();
    const root1 = pose.element(base.add(layout.slotCount * layout.rows + 1)).toVar();
    const end = attribute('cgEnd', 'float');
    const unit = attribute('position', 'vec3');
    const dir = vec3(unit.x, unit.y.sub(end.sub(0.5)), unit.z);
    const ba = rowB.xyz.sub(rowA.xyz);
    const len = ba.length();
    const axis = select(len.greaterThan(float(layout.tiny)), ba.div(len), vec3(0, 1, 0)).toVar();
    const helper = select(abs(axis.x).lessThan(0.9), vec3(1, 0, 0), vec3(0, 0, 1));
    const u = normalize(cross(axis, helper)).toVar();
    const w = cross(axis, u);
    const n = u.mul(dir.x).add(axis.mul(dir.y)).add(w.mul(dir.z)).toVar();
    const centre = mix(rowA.xyz, rowB.xyz, end);
    const radius = mix(rowA.w, rowB.w, end);
    vColour.assign(pose.element(o.add(2)).yzw);
    normalLocal.assign(rootNormal(root1, n));
    const p = centre.add(n.mul(radius));
    return select(root0.w.greaterThan(0.5), rootPoint(root1, p).add(root0.xyz), vec3(0));
  })();
  material.colorNode = vColour;
  const mesh = new THREE.Mesh(shellGeometry(), material);
  mesh.name = `${name}.shell`;
  mesh.count = 0;
  mesh.visible = false;
  return mesh;
}
