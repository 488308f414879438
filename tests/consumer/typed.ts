// A typed use of every public export of the two creature packages and the frost package, checked with
// `tsc --strict` by tests/test_consumer.py: an export without a declaration, or a declaration that does
// not match the README's use, fails the check.
import * as THREE from 'three/webgpu';
import {
  CREATURE,
  DEBUG_MODES,
  LCG,
  createAnalyticWater,
  createCreaturePopulation,
  createMotion,
} from 'hopper-squash-core';
import type { LookData } from 'hopper-squash-core';
import { createDiagnostics } from 'hopper-squash-core/diagnostics';
import { createCreaturePopulation as createQuadrupeds } from 'quadruped-rope-tail';
import { createFrostEffect } from 'frost-pane-balanced';

export async function typed(renderer: THREE.WebGPURenderer, scene: THREE.Scene, camera: THREE.Camera): Promise<number> {
  const hoppers = await createCreaturePopulation(renderer, { capacity: 4, water: createAnalyticWater() });
  const quadrupeds = await createQuadrupeds(renderer, { capacity: 2 });
  const id: number = hoppers.spawn({ seed: 7, position: [0, 0, 0] });
  quadrupeds.spawn({ seed: 1 });
  const sun = new THREE.DirectionalLight(0xffffff, 1);
  hoppers.cullWith(camera, sun);
  hoppers.pause(id);
  hoppers.resume(id);
  const steps: number = hoppers.update(1 / 60);
  const drawn: number = hoppers.stats.lastFrameDrawnBodies + hoppers.stats.lastFrameCulledBodies;
  hoppers.cullWith();
  const moved: number = hoppers.chooseTiers(camera, 720) + hoppers.tiers.length;
  const kept: boolean = hoppers.setBodyTier(id, hoppers.tiers[hoppers.tiers.length - 1].name);
  hoppers.setDebugMode(DEBUG_MODES[0]);
  const look: LookData = hoppers.setLook({ roughness: 0.4, aoTaps: 0 });
  console.assert(look.roughness === hoppers.look.roughness);
  const diagnostics = createDiagnostics(renderer, hoppers);
  const pose: Float32Array = await diagnostics.readPose(id);
  const staged: Float32Array = diagnostics.stagedPose(id);
  const slug: string = CREATURE.slug;
  const motion = createMotion(CREATURE.motion, LCG, { seed: 1 });
  const frost = await createFrostEffect(renderer, scene, camera);
  frost.update(0, 1 / 60);
  frost.render();
  return steps + drawn + moved + (kept ? 1 : 0) + pose.length + staged.length + slug.length + (motion ? 1 : 0);
}
