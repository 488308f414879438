// What the user may change while the effect runs: the tier (history and blur resolution, detail normals,
// Fresnel), the scalar controls and the debug view (uniforms only, so no material is rebuilt), and the
// canvas size (the history is reallocated under the plan's resize policy, see history.js).
import { PLAN } from '../core/plan.js';
import { scaledSize } from '../core/frost-core.js';
import { DEBUG_VIEWS } from './composite.js';
import { reallocate } from './history.js';

/** CSS size and device-pixel ratio of the canvas; returns true if the history was remapped. */
export function resize(state, width, height, dpr = 1) {
  const [drawingWidth, drawingHeight] = scaledSize(width, height, dpr);
  return reallocate(state, drawingWidth, drawingHeight);
}

export function setTier(state, name) {
  const next = PLAN.tiers[name];
  if (!next) throw new Error(`frost.setTier: unknown tier ${JSON.stringify(name)} (known: ${Object.keys(PLAN.tiers).join(', ')})`);
  const r = PLAN.refraction;
  const { composite, renderer, size } = state;
  state.tierName = name;
  state.tier = next;
  composite.blur.resolutionScale = next.blurScale;
  composite.uDetailStrength.value = next.detail ? r.detailStrength : 0;
  composite.uFresnel.value = next.fresnel ? r.fresnelStrength : 0;
  renderer.getDrawingBufferSize(size);
  reallocate(state, size.x, size.y);
}

export function setControl(state, name, value) {
  const { controls } = state.composite;
  if (!(name in controls)) throw new Error(`frost.setControl: unknown control ${JSON.stringify(name)} (known: ${Object.keys(controls).join(', ')})`);
  if (typeof value !== 'number' || !Number.isFinite(value)) throw new Error(`frost.setControl: ${name} must be a finite number`);
  controls[name].value = value;
}

export function setDebugView(state, name) {
  const index = DEBUG_VIEWS.indexOf(name);
  if (index < 0) throw new Error(`frost.setDebugView: unknown view ${JSON.stringify(name)} (known: ${DEBUG_VIEWS.join(', ')})`);
  state.composite.uDebugView.value = index;
}

/** The debug view shown now. */
export function debugView(state) {
  return DEBUG_VIEWS[state.composite.uDebugView.value];
}
