// The output pass: the scene rendered once (pass), blurred at reduced resolution (SeparableBlurNode), and
// composited through the frost mask with a two-scale normal refraction, tint and Fresnel, as the
// RenderPipeline's outputNode (the pipeline owns the one output colour transform). The history is
// sampled bilinearly in the shader, before and after the latest update. Every debug view is a branch on
// one uniform: switching views, like changing a control, never rebuilds the material.
import { RenderPipeline, Vector3 } from 'three/webgpu';
import {
  Fn, If, clamp, dot, float, int, length, max, min, mix, normalize, pass, pow, screenSize, screenUV, smoothstep,
  texture, uniform, vec2, vec3, vec4,
} from 'three/tsl';
import { PLAN } from '../core/plan.js';
import { SeparableBlurNode } from './separable-blur.js';
import { loadClamped } from './history.js';

/** Debug views, in uniform order; switching only changes a uniform, never a material. */
export const DEBUG_VIEWS = PLAN.debugViews;

/**
 * Build the output pass of `scene` seen by `camera` over the state's history and the structure textures
 * (structure.js). Returns the pipeline, its blur, the two history reads that bindComposite (history.js)
 * points at the latest textures, its uniforms, and `controls`: the uniforms setControl may change, by name.
 */
export function createComposite(state, scene, camera, { structureTex, normalTex }) {
  const { renderer, tier, textures } = state;
  const scenePass = pass(scene, camera);
  const sceneColor = scenePass.getTextureNode('output');
  const blur = new SeparableBlurNode(sceneColor, { sigma: PLAN.blur.sigma, resolutionScale: tier.blurScale, epsilon: PLAN.blur.epsilon });
  const k = {
    state, sceneColor, blur, blurred: blur.horizontalNode, structureTex, normalTex,
    histPrev: texture(textures[0]),
    histNext: texture(textures[1]),
    ...compositeUniforms(tier),
  };
  const output = outputNode(k);
  const pipeline = new RenderPipeline(renderer);
  pipeline.outputColorTransform = true;
  pipeline.outputNode = output();
  // Scalar controls are uniforms: changing one never rebuilds a material.
  const controls = {
    mainScreenPeriod: k.uMainPeriod, detailScreenPeriod: k.uDetailPeriod, mainStrength: k.uMainStrength,
    detailStrength: k.uDetailStrength, fresnelStrength: k.uFresnel, ior: k.uIor, thickness: k.uThickness,
    sourceInset: k.uInset, brightness: k.uBrightness, saturation: k.uSaturation, blurMix: k.uBlurMix,
    maskLow: k.uMaskLow, maskHigh: k.uMaskHigh, opacity: k.uOpacity, side: k.uSide, corner: k.uCorner,
  };
  return { ...k, pipeline, controls };
}

/** The composite's uniforms, at the plan's values; detail normals and Fresnel only where the tier has them. */
function compositeUniforms(tier) {
  const r = PLAN.refraction;
  const c = PLAN.composite;
  return {
    uDebugView: uniform(0, 'int'),
    uMainPeriod: uniform(r.mainScreenPeriod),
    uDetailPeriod: uniform(r.detailScreenPeriod),
    uMainStrength: uniform(r.mainStrength),
    uDetailStrength: uniform(tier.detail ? r.detailStrength : 0),
    uFresnel: uniform(tier.fresnel ? r.fresnelStrength : 0),
    uIor: uniform(r.ior),
    uThickness: uniform(r.thickness),
    uInset: uniform(r.sourceInset),
    tint: uniform(new Vector3(...c.tintLinear)),
    uBrightness: uniform(c.brightness),
    uSaturation: uniform(c.saturation),
    uBlurMix: uniform(c.blurMix),
    uMaskLow: uniform(c.maskLow),
    uMaskHigh: uniform(c.maskHigh),
    uOpacity: uniform(c.opacity),
    uSide: uniform(PLAN.fades.side),
    uCorner: uniform(PLAN.fades.corner),
  };
}

/** Bilinear sample of a history texture node at screen UV `coord` (the history is nearest-filtered). */
function sampleHistory(state, node, coord) {
  const p = coord.mul(state.uHistSize).sub(0.5);
  const p0 = p.floor();
  const f = p.sub(p0);
  const x0 = int(p0.x);
  const y0 = int(p0.y);
  const top = mix(loadClamped(state, node, x0, y0), loadClamped(state, node, x0.add(1), y0), f.x);
  const bottom = mix(loadClamped(state, node, x0, y0.add(1)), loadClamped(state, node, x0.add(1), y0.add(1)), f.x);
  return mix(top, bottom, f.y);
}

/** Edge fade: straight sides plus rounded corners, in screen-height units. */
function edgeFade(k, coord, aspect) {
  const edge = vec2(min(coord.x, float(1).sub(coord.x)).mul(aspect), min(coord.y, float(1).sub(coord.y)));
  const sideFade = smoothstep(0, max(k.uSide, 1e-6), min(edge.x, edge.y));
  const cornerGap = length(max(vec2(k.uCorner).sub(edge), vec2(0)));
  const cornerFade = float(1).sub(smoothstep(k.uCorner.mul(0.5), max(k.uCorner, 1e-6), cornerGap));
  return sideFade.mul(cornerFade);
}

/** The frosted look of the scene seen at `at`: sharp/blurred mix, desaturated, tinted, with Fresnel. */
function look(k, at, frost, fresnel) {
  const sharp = k.sceneColor.sample(at).rgb;
  const soft = k.blurred.sample(at).rgb;
  const mixed = mix(sharp, soft, k.uBlurMix.mul(frost));
  const luma = dot(mixed, vec3(0.2126, 0.7152, 0.0722));
  const frosted = mix(vec3(luma), mixed, k.uSaturation).mul(k.tint).mul(k.uBrightness)
    .add(k.tint.mul(fresnel.mul(k.uFresnel)));
  return { mixed, final: mix(sharp, frosted, frost.mul(k.uOpacity)) };
}

/** The composite's output node: the final image, or the debug view the view uniform selects. */
function outputNode(k) {
  return Fn(() => {
    const coord = screenUV;
    const aspect = screenSize.x.div(screenSize.y);
    const mainUV = coord.mul(screenSize).div(k.uMainPeriod);
    const detailUV = coord.mul(screenSize).div(k.uDetailPeriod);
    const st = texture(k.structureTex, mainUV);
    const nMain = texture(k.normalTex, mainUV).xy.mul(2).sub(1);
    const nDetail = texture(k.normalTex, detailUV).zw.mul(2).sub(1);
    const before = sampleHistory(k.state, k.histPrev, coord);
    const after = sampleHistory(k.state, k.histNext, coord);
    const fade = edgeFade(k, coord, aspect);
    const crystal = mix(float(PLAN.composite.haze), float(1), st.x);
    const maskOf = (h) => smoothstep(k.uMaskLow, k.uMaskHigh, float(1).sub(h.x)).mul(fade).mul(crystal);
    const maskBefore = maskOf(before);
    const frost = maskOf(after);
    const tiltResponse = clamp(float(1).sub(after.w), 0, 1);
    const gain = k.uThickness.mul(float(1).sub(float(1).div(k.uIor))).mul(tiltResponse).mul(frost);
    const offMain = nMain.mul(k.uMainStrength).mul(gain);
    const offDetail = nDetail.mul(k.uDetailStrength).mul(st.y).mul(gain);
    const inset = vec2(k.uInset);
    const refracted = clamp(coord.add(offMain).add(offDetail), inset, vec2(1).sub(inset));
    const n3 = normalize(vec3(nMain.mul(k.uMainStrength).add(nDetail.mul(k.uDetailStrength)).mul(8), 1));
    const f0 = pow(k.uIor.sub(1).div(k.uIor.add(1)), 2);
    const fresnel = f0.add(float(1).sub(f0).mul(pow(float(1).sub(n3.z), 5)));
    const refractedLook = look(k, refracted, frost, fresnel);
    const plainLook = look(k, coord, frost, fresnel);
    const views = debugViews(k, coord, {
      st, nMain, nDetail, before, after, maskBefore, frost, offMain, offDetail, refractedLook, plainLook,
    });
    return vec4(chooseView(k, views), 1);
  });
}

/** Every debug view's colour, by name (DEBUG_VIEWS). */
function debugViews(k, coord, values) {
  const { st, nMain, nDetail, before, after, maskBefore, frost, offMain, offDetail, refractedLook, plainLook } = values;
  const r = PLAN.refraction;
  const grey = (x) => vec3(x);
  return {
    final: refractedLook.final,
    scene: k.sceneColor.sample(coord).rgb,
    blurVertical: k.blur.verticalNode.sample(coord).rgb,
    blurHorizontal: k.blurred.sample(coord).rgb,
    structure: grey(st.x),
    structureHeight: grey(st.y),
    mainNormal: vec3(nMain.mul(0.5).add(0.5), 1),
    detailNormal: vec3(nDetail.mul(0.5).add(0.5), 1),
    historyPrevR: grey(before.x),
    historyPrevA: grey(before.w),
    depositR: grey(after.y),
    depositA: grey(after.z),
    historyNextR: grey(after.x),
    historyNextA: grey(after.w),
    maskBefore: grey(maskBefore),
    maskAfter: grey(frost),
    sharpBlurMix: refractedLook.mixed,
    refractMain: vec3(offMain.mul(0.5 / Math.max(r.mainStrength, 1e-6)).add(0.5), 0.5),
    refractDetail: vec3(offDetail.mul(0.5 / Math.max(r.detailStrength, 1e-6)).add(0.5), 0.5),
    finalNoRefraction: plainLook.final,
  };
}

// Branch on the view uniform (uniform control flow): a frame pays for the final image plus the one
// view shown, not for all of them, and switching views never rebuilds the material.
function chooseView(k, views) {
  const result = views.final.toVar();
  let chain = null;
  DEBUG_VIEWS.forEach((name, index) => {
    if (name === 'final') return;
    const assign = () => { result.assign(views[name]); };
    chain = chain === null ? If(k.uDebugView.equal(index), assign) : chain.ElseIf(k.uDebugView.equal(index), assign);
  });
  return result;
}
