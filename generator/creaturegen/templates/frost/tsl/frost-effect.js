// The frost/thaw effect on WebGPU: StorageTexture history ping-pong updated by TSL compute, a
// reduced-resolution separable blur, static crystalline structure data textures and a two-scale
// normal-refraction composite feeding RenderPipeline.outputNode (one output transform owner).
import {
  DataTexture, FloatType, HalfFloatType, LinearFilter, MirroredRepeatWrapping, NearestFilter, NoColorSpace,
  REVISION, RGBAFormat, RenderPipeline, StorageTexture, UnsignedByteType, Vector2, Vector3,
} from 'three/webgpu';
import {
  Fn, If, Loop, clamp, dot, exp, float, globalId, instanceIndex, instancedArray, int, ivec2, length, max, min,
  mix, normalize, pass, pow, screenSize, screenUV, select, smoothstep, storageTexture, texture, textureStore,
  uint, uniform, vec2, vec3, vec4,
} from 'three/tsl';
import { PLAN } from '../core/plan.js';
import { checkThreeRevision } from '../core/revision.js';
import { FrostAssetError, decodeStructureFile } from '../core/structure-file.js';
import { assetUrl } from './assets.js';
import {
  StepBins, TileScheduler, chunkSteps, classifyInterval, diffusionSubsteps, lateSteps, normalizeSegment, scaledSize,
  splitInterval, tooManyStreams, validateSegment,
} from '../core/frost-core.js';
import { SeparableBlurNode } from './separable-blur.js';

/** Debug views, in uniform order; switching only changes a uniform, never a material. */
export const DEBUG_VIEWS = PLAN.debugViews;

const TEXEL = { rgba16float: 8, rgba32float: 16 };

function u32(x) {
  return x >>> 0;
}

/**
 * Fetch and decode the structure file: from beside the package, or from `assetBase` when given (for bundlers
 * that do not copy assets referenced relative to import.meta.url, such as esbuild, and for CDNs).
 */
async function loadStructure(assetBase) {
  const url = assetUrl('structure', assetBase);
  let response;
  try {
    response = await fetch(url);
  } catch (cause) {
    throw new FrostAssetError(`frost: cannot fetch ${url} (${cause}); pass options.assetBase if the assets live elsewhere`);
  }
  if (!response.ok) {
    throw new FrostAssetError(`frost: cannot load ${url} (HTTP ${response.status}); `
      + 'copy the package\'s assets/ folder where your bundle expects it, or pass options.assetBase');
  }
  try {
    return await decodeStructureFile(new Uint8Array(await response.arrayBuffer()), PLAN.assets.structure, String(url));
  } catch (error) {
    // Vite's dev-server dependency optimizer moves this module into node_modules/.vite/ without its assets,
    // and its fallback page then answers for the file: say how to fix that rather than only what failed.
    if (error instanceof FrostAssetError && String(url).includes('/.vite/')) {
      error.message += `; Vite's dependency optimizer moved ${PLAN.slug} away from its assets: add `
        + `optimizeDeps: { exclude: [${JSON.stringify(PLAN.slug)}] } to vite.config, or pass options.assetBase`;
    }
    throw error;
  }
}

function dataTexture(bytes, size, name) {
  const tex = new DataTexture(bytes, size, size, RGBAFormat, UnsignedByteType);
  tex.name = name;
  tex.colorSpace = NoColorSpace;
  tex.wrapS = MirroredRepeatWrapping;
  tex.wrapT = MirroredRepeatWrapping;
  tex.magFilter = LinearFilter;
  tex.minFilter = LinearFilter;
  tex.generateMipmaps = false;
  tex.flipY = false;
  tex.needsUpdate = true;
  return tex;
}

function historyTexture(width, height, format, name) {
  const tex = new StorageTexture(width, height);
  tex.type = format === 'rgba32float' ? FloatType : HalfFloatType;
  tex.format = RGBAFormat;
  tex.colorSpace = NoColorSpace;
  tex.magFilter = NearestFilter;
  tex.minFilter = NearestFilter;
  tex.generateMipmaps = false;
  tex.name = name;
  return tex;
}

/** PCG-RXS-M-XS on u32, the same hash as creaturegen.frost.brush.pcg_hash. */
const pcg = Fn(([v]) => {
  const state = v.mul(uint(747796405)).add(uint(2891336453));
  const word = state.shiftRight(state.shiftRight(uint(28)).add(uint(4))).bitXor(state).mul(uint(277803737));
  return word.shiftRight(uint(22)).bitXor(word);
}, { v: 'uint', return: 'uint' });

/** Closed-form decay + saturating deposit over dt with constant coverage b; a = 0 keeps x. */
const law = Fn(([x, b, dt, decay, fill]) => {
  const a = decay.add(fill.mul(b));
  const eq = fill.mul(b).div(max(a, float(1e-30)));
  return select(a.greaterThan(0), eq.add(x.sub(eq).mul(exp(a.negate().mul(dt)))), x);
}, { x: 'float', b: 'float', dt: 'float', decay: 'float', fill: 'float', return: 'float' });

/**
 * Catch-up of a late segment: x only decayed over the missed span tau and then `age` seconds; return the
 * state had it deposited under b over tau: e^(-r·b·tau)·x + e^(-λ·age)·xEq·(1 - e^(-a·tau)), exact.
 */
const catchUp = Fn(([x, b, tau, age, decay, fill]) => {
  const rb = fill.mul(b);
  const a = decay.add(rb);
  const gained = rb.div(max(a, float(1e-30))).mul(float(1).sub(exp(a.negate().mul(tau))));
  return exp(rb.negate().mul(tau)).mul(x).add(exp(decay.negate().mul(age)).mul(gained));
}, { x: 'float', b: 'float', tau: 'float', age: 'float', decay: 'float', fill: 'float', return: 'float' });

/**
 * Create the effect. Async because the structure textures are fetched from the package's assets.
 * The renderer must already be initialised on a WebGPU backend: there is no WebGL path. Throws
 * FrostRevisionError outside three r185 and FrostAssetError when the structure file cannot be loaded.
 */
export async function createFrostEffect(renderer, scene, camera, options = {}) {
  checkThreeRevision(REVISION);
  if (renderer.backend?.isWebGPUBackend !== true) {
    throw new Error('createFrostEffect: WebGPU is required (renderer.backend.isWebGPUBackend is not true); '
      + 'await renderer.init() on a WebGPU-capable browser. There is no WebGL fallback for this effect.');
  }
  const params = PLAN.params;
  let tierName = options.tier ?? PLAN.tier.name;
  let tier = PLAN.tiers[tierName];
  if (!tier) throw new Error(`createFrostEffect: unknown tier ${JSON.stringify(tierName)}`);
  const format = PLAN.tier.historyFormat;
  const bytesPerTexel = TEXEL[format];

  // ---- static structure (generated once at build time, shared by content hash) ----------------
  const { structure: structureBytes, normals: normalBytes } = await loadStructure(options.assetBase);
  const structureTex = dataTexture(structureBytes, PLAN.structure.resolution, 'frost.structure');
  const normalTex = dataTexture(normalBytes, PLAN.structure.resolution, 'frost.normals');

  // ---- history state ---------------------------------------------------------------------------
  const size = new Vector2();
  renderer.getDrawingBufferSize(size);
  let [histW, histH] = scaledSize(size.x, size.y, tier.historyScale);
  const textures = [historyTexture(histW, histH, format, 'frost.history.0'), historyTexture(histW, histH, format, 'frost.history.1')];
  let current = 0; // index of the texture holding the latest history
  let scheduler = new TileScheduler(params, histW, histH);
  const pending = [];
  let freshFrom = 0; // pending[freshFrom..] were queued since the last update
  let origin = null; // where the history's timeline starts: late segments deposit nothing before it
  const lastEnd = new Map(); // stream -> where its latest segment ended
  const bins = new StepBins(params);
  const binning = options.binning !== false;

  const uHistW = uniform(histW, 'int');
  const uHistH = uniform(histH, 'int');
  const uHistSize = uniform(new Vector2(histW, histH));
  const uStepCount = uniform(0, 'int');
  const uBinSize = uniform(params.tileSize, 'int');
  const uBinsX = uniform(1, 'int');
  const uDecayTotal = uniform(0); // seconds of ordinary (not catch-up) steps in the chunk
  const uFirstChunk = uniform(1);
  const uTileW = uniform(histW, 'int');
  const uTileH = uniform(histH, 'int');
  const uTilesX = uniform(1, 'int');
  const uTileCount = uniform(0, 'int');
  const uDiffusionRate = uniform(0);
  const uOldSize = uniform(new Vector2(1, 1));
  const uOldW = uniform(1, 'int');
  const uOldH = uniform(1, 'int');

  const maxSteps = params.maxSteps;
  // Per step: [dt, age, decayBefore, 0]: age >= 0 marks a catch-up step (the late part of a segment, see
  // lateSteps), -1 an ordinary one; decayBefore is the ordinary seconds of the chunk's earlier steps.
  const stepBuffer = instancedArray(maxSteps, 'vec4');
  const stepData = stepBuffer.value.array;
  // Per (step, segment) pair: [a.u, a.v, b.u, b.v] and [pressure, step, 0, 0].
  const pairBuffer = instancedArray(params.maxPairs * 2, 'vec4');
  const pairData = pairBuffer.value.array;
  // The chunk's pairs binned into tileSize tiles (StepBins, a CSR list): texels loop over their bin only.
  const binCapacity = Math.ceil(4096 / params.tileSize) ** 2 + 1;
  const binStartBuffer = instancedArray(new Uint32Array(binCapacity), 'uint');
  const binEntryBuffer = instancedArray(new Uint32Array(params.binCapacity), 'uint');
  // Fixed capacity (a storage buffer cannot grow in place): every tile of a 4096² history.
  const tileCapacity = Math.max(scheduler.count, Math.ceil(4096 / params.tileSize) ** 2);
  const tileBuffer = instancedArray(new Uint32Array(tileCapacity), 'uint');

  const salts = PLAN.noiseSalts.map((s) => uint(u32(s)));
  const vis = params.visible;
  const tilt = params.tilt;

  const read = [texture(textures[0]), texture(textures[1])];
  const write = [storageTexture(textures[0]), storageTexture(textures[1])];

  const texelNoise = (i, j, salt) => float(pcg(j.add(pcg(i.add(salt)))).shiftRight(uint(8))).mul(1 / 16777216);

  // One texel over its bin's pairs, in step order. A step with no pair in the bin covers no texel of it:
  // an ordinary one only decays (folded into one exp over the gap, from the chunk's decayBefore times), a
  // catch-up one is the identity. A step with pairs deposits the largest coverage among them (several
  // strokes at once). The sentinel iteration (i = last) applies the bin's final step.
  const updateTexel = (src, dst, ix, iy) => {
    const prev = src.load(ivec2(ix, iy));
    const xr = prev.x.toVar();
    const xa = prev.w.toVar();
    const dr = mix(prev.y, float(0), uFirstChunk).toVar();
    const da = mix(prev.z, float(0), uFirstChunk).toVar();
    const aspect = uHistSize.x.div(uHistSize.y);
    const p = vec2(float(ix).add(0.5).div(uHistSize.x).mul(aspect), float(iy).add(0.5).div(uHistSize.y));
    const n0 = texelNoise(uint(ix), uint(iy), salts[0]);
    const n1 = texelNoise(uint(ix), uint(iy), salts[1]);
    const bin = iy.div(uBinSize).mul(uBinsX).add(ix.div(uBinSize));
    const first = int(binStartBuffer.element(bin));
    const last = int(binStartBuffer.element(bin.add(1)));
    const elapsed = float(0).toVar(); // ordinary seconds of the chunk already applied
    const step = int(-1).toVar();
    const br = float(0).toVar();
    const ba = float(0).toVar();
    Loop({ start: first, end: last.add(1), type: 'int', condition: '<' }, ({ i }) => {
      const atEnd = i.greaterThanEqual(last);
      const pair = int(binEntryBuffer.element(min(i, max(last.sub(1), int(0)))));
      const info = pairBuffer.element(pair.mul(2).add(1));
      const next = select(atEnd, uStepCount, int(info.y));
      If(next.notEqual(step).and(step.greaterThanEqual(0)), () => {
        const s = stepBuffer.element(step);
        xr.mulAssign(exp(float(-vis.decay).mul(s.z.sub(elapsed))));
        xa.mulAssign(exp(float(-tilt.decay).mul(s.z.sub(elapsed))));
        dr.assign(max(dr, br));
        da.assign(max(da, ba));
        const late = s.y.greaterThanEqual(0);
        const age = max(s.y, float(0));
        xr.assign(select(late, catchUp(xr, br, s.x, age, float(vis.decay), float(vis.fill)),
          law(xr, br, s.x, float(vis.decay), float(vis.fill))));
        xa.assign(select(late, catchUp(xa, ba, s.x, age, float(tilt.decay), float(tilt.fill)),
          law(xa, ba, s.x, float(tilt.decay), float(tilt.fill))));
        elapsed.assign(s.z.add(select(late, float(0), s.x)));
      });
      If(next.notEqual(step), () => {
        step.assign(next);
        br.assign(0);
        ba.assign(0);
      });
      If(atEnd.not(), () => {
        const seg = pairBuffer.element(pair.mul(2));
        const a = vec2(seg.x.mul(aspect), seg.y);
        const d = vec2(seg.z.mul(aspect), seg.w).sub(a);
        const t = clamp(dot(p.sub(a), d).div(max(dot(d, d), float(1e-30))), 0, 1);
        const dist = length(p.sub(a).sub(d.mul(t)));
        br.assign(max(br, info.x.mul(float(1).sub(smoothstep(vis.radius * (1 - params.softness), vis.radius, dist)))
          .mul(float(1).sub(n0.mul(vis.noise)))));
        ba.assign(max(ba, info.x.mul(float(1).sub(smoothstep(tilt.radius * (1 - params.softness), tilt.radius, dist)))
          .mul(float(1).sub(n1.mul(tilt.noise)))));
      });
    });
    xr.mulAssign(exp(float(-vis.decay).mul(uDecayTotal.sub(elapsed))));
    xa.mulAssign(exp(float(-tilt.decay).mul(uDecayTotal.sub(elapsed))));
    textureStore(dst, ivec2(ix, iy), vec4(xr, dr, da, xa));
  };

  const loadClamped = (src, x, y) => src.load(ivec2(clamp(x, int(0), uHistW.sub(1)), clamp(y, int(0), uHistH.sub(1))));

  const diffuseTexel = (src, dst, ix, iy) => {
    const c = src.load(ivec2(ix, iy));
    const sum = loadClamped(src, ix.sub(1), iy).add(loadClamped(src, ix.add(1), iy))
      .add(loadClamped(src, ix, iy.sub(1))).add(loadClamped(src, ix, iy.add(1)));
    const lap = sum.sub(c.mul(4));
    textureStore(dst, ivec2(ix, iy), vec4(c.x.add(lap.x.mul(uDiffusionRate)), c.y, c.z, c.w.add(lap.w.mul(uDiffusionRate))));
  };

  // Declared dispatch shapes: full-field is 2-D [ceil(W/8), ceil(H/8), 1] workgroups of [8, 8, 1] with an
  // extent guard; tiles are linear, 64 threads per workgroup, tile-list indirection and extent guard.
  const [wx, wy] = params.workgroup2d;
  const wl = params.workgroupLinear;
  const kernel2d = (body, src, dst, name) => {
    const node = Fn(() => {
      const ix = int(globalId.x);
      const iy = int(globalId.y);
      If(ix.lessThan(uHistW).and(iy.lessThan(uHistH)), () => body(src, dst, ix, iy));
    })().compute([1, 1, 1], [wx, wy, 1]);
    node.setName(name);
    return node;
  };
  const tileCoords = (fn) => Fn(() => {
    const area = uTileW.mul(uTileH);
    const idx = int(instanceIndex);
    const slot = idx.div(area);
    const local = idx.mod(area);
    If(slot.lessThan(uTileCount), () => {
      const tile = int(tileBuffer.element(slot));
      const ix = tile.mod(uTilesX).mul(uTileW).add(local.mod(uTileW));
      const iy = tile.div(uTilesX).mul(uTileH).add(local.div(uTileW));
      If(ix.lessThan(uHistW).and(iy.lessThan(uHistH)), () => fn(ix, iy));
    });
  });
  const kernelTiles = (body, src, dst, name) => {
    const node = tileCoords((ix, iy) => body(src, dst, ix, iy))().compute(1, [wl, 1, 1]);
    node.setName(name);
    return node;
  };
  const clearKernel = () => {
    const node = tileCoords((ix, iy) => {
      textureStore(write[0], ivec2(ix, iy), vec4(0));
      textureStore(write[1], ivec2(ix, iy), vec4(0));
    })().compute(1, [wl, 1, 1]);
    node.setName('frost.clear');
    return node;
  };

  // The remap kernel reads the old history (bilinear by UV, clamp-to-edge, texel loads in float32) and
  // writes both new textures, so untouched tiles agree in both ping-pong slots.
  const oldRead = texture(textures[0]);
  const remapNode = Fn(() => {
    const ix = int(globalId.x);
    const iy = int(globalId.y);
    If(ix.lessThan(uHistW).and(iy.lessThan(uHistH)), () => {
      const x = clamp(float(ix).add(0.5).div(uHistSize.x).mul(uOldSize.x).sub(0.5), 0, uOldSize.x.sub(1));
      const y = clamp(float(iy).add(0.5).div(uHistSize.y).mul(uOldSize.y).sub(0.5), 0, uOldSize.y.sub(1));
      const x0 = int(x.floor());
      const y0 = int(y.floor());
      const x1 = min(x0.add(1), uOldW.sub(1));
      const y1 = min(y0.add(1), uOldH.sub(1));
      const fx = x.sub(float(x0));
      const fy = y.sub(float(y0));
      const top = mix(oldRead.load(ivec2(x0, y0)), oldRead.load(ivec2(x1, y0)), fx);
      const bottom = mix(oldRead.load(ivec2(x0, y1)), oldRead.load(ivec2(x1, y1)), fx);
      const value = mix(top, bottom, fy);
      textureStore(write[0], ivec2(ix, iy), value);
      textureStore(write[1], ivec2(ix, iy), value);
    });
  })().compute([1, 1, 1], [wx, wy, 1]);
  remapNode.setName('frost.remap');

  const kernels = {
    update2d: [kernel2d(updateTexel, read[0], write[1], 'frost.update.0to1'), kernel2d(updateTexel, read[1], write[0], 'frost.update.1to0')],
    updateTiles: [kernelTiles(updateTexel, read[0], write[1], 'frost.updateTiles.0to1'), kernelTiles(updateTexel, read[1], write[0], 'frost.updateTiles.1to0')],
    diffuse2d: [kernel2d(diffuseTexel, read[0], write[1], 'frost.diffuse.0to1'), kernel2d(diffuseTexel, read[1], write[0], 'frost.diffuse.1to0')],
    diffuseTiles: [kernelTiles(diffuseTexel, read[0], write[1], 'frost.diffuseTiles.0to1'), kernelTiles(diffuseTexel, read[1], write[0], 'frost.diffuseTiles.1to0')],
    clear: clearKernel(),
  };

  // ---- composite -------------------------------------------------------------------------------
  const scenePass = pass(scene, camera);
  const sceneColor = scenePass.getTextureNode('output');
  const blur = new SeparableBlurNode(sceneColor, { sigma: PLAN.blur.sigma, resolutionScale: tier.blurScale, epsilon: PLAN.blur.epsilon });
  const blurred = blur.horizontalNode;
  const histPrev = texture(textures[0]);
  const histNext = texture(textures[1]);
  const r = PLAN.refraction;
  const c = PLAN.composite;
  const uDebugView = uniform(0, 'int');
  const uMainPeriod = uniform(r.mainScreenPeriod);
  const uDetailPeriod = uniform(r.detailScreenPeriod);
  const uMainStrength = uniform(r.mainStrength);
  const uDetailStrength = uniform(tier.detail ? r.detailStrength : 0);
  const uFresnel = uniform(tier.fresnel ? r.fresnelStrength : 0);
  const uIor = uniform(r.ior);
  const uThickness = uniform(r.thickness);
  const uInset = uniform(r.sourceInset);
  const tint = uniform(new Vector3(...c.tintLinear));
  const uBrightness = uniform(c.brightness);
  const uSaturation = uniform(c.saturation);
  const uBlurMix = uniform(c.blurMix);
  const uMaskLow = uniform(c.maskLow);
  const uMaskHigh = uniform(c.maskHigh);
  const uOpacity = uniform(c.opacity);
  const uSide = uniform(PLAN.fades.side);
  const uCorner = uniform(PLAN.fades.corner);

  const sampleHistory = (node, coord) => {
    const p = coord.mul(uHistSize).sub(0.5);
    const p0 = p.floor();
    const f = p.sub(p0);
    const x0 = int(p0.x);
    const y0 = int(p0.y);
    const top = mix(loadClamped(node, x0, y0), loadClamped(node, x0.add(1), y0), f.x);
    const bottom = mix(loadClamped(node, x0, y0.add(1)), loadClamped(node, x0.add(1), y0.add(1)), f.x);
    return mix(top, bottom, f.y);
  };

  const output = Fn(() => {
    const coord = screenUV;
    const aspect = screenSize.x.div(screenSize.y);
    const mainUV = coord.mul(screenSize).div(uMainPeriod);
    const detailUV = coord.mul(screenSize).div(uDetailPeriod);
    const st = texture(structureTex, mainUV);
    const nMain = texture(normalTex, mainUV).xy.mul(2).sub(1);
    const nDetail = texture(normalTex, detailUV).zw.mul(2).sub(1);
    const before = sampleHistory(histPrev, coord);
    const after = sampleHistory(histNext, coord);
    // Edge fade: straight sides plus rounded corners, in screen-height units.
    const edge = vec2(min(coord.x, float(1).sub(coord.x)).mul(aspect), min(coord.y, float(1).sub(coord.y)));
    const sideFade = smoothstep(0, max(uSide, 1e-6), min(edge.x, edge.y));
    const cornerGap = length(max(vec2(uCorner).sub(edge), vec2(0)));
    const cornerFade = float(1).sub(smoothstep(uCorner.mul(0.5), max(uCorner, 1e-6), cornerGap));
    const fade = sideFade.mul(cornerFade);
    const crystal = mix(float(PLAN.composite.haze), float(1), st.x);
    const maskOf = (h) => smoothstep(uMaskLow, uMaskHigh, float(1).sub(h.x)).mul(fade).mul(crystal);
    const maskBefore = maskOf(before);
    const frost = maskOf(after);
    const tiltResponse = clamp(float(1).sub(after.w), 0, 1);
    const gain = uThickness.mul(float(1).sub(float(1).div(uIor))).mul(tiltResponse).mul(frost);
    const offMain = nMain.mul(uMainStrength).mul(gain);
    const offDetail = nDetail.mul(uDetailStrength).mul(st.y).mul(gain);
    const inset = vec2(uInset);
    const refracted = clamp(coord.add(offMain).add(offDetail), inset, vec2(1).sub(inset));
    const n3 = normalize(vec3(nMain.mul(uMainStrength).add(nDetail.mul(uDetailStrength)).mul(8), 1));
    const f0 = pow(uIor.sub(1).div(uIor.add(1)), 2);
    const fresnel = f0.add(float(1).sub(f0).mul(pow(float(1).sub(n3.z), 5)));
    const look = (at) => {
      const sharp = sceneColor.sample(at).rgb;
      const soft = blurred.sample(at).rgb;
      const mixed = mix(sharp, soft, uBlurMix.mul(frost));
      const luma = dot(mixed, vec3(0.2126, 0.7152, 0.0722));
      const frosted = mix(vec3(luma), mixed, uSaturation).mul(tint).mul(uBrightness)
        .add(tint.mul(fresnel.mul(uFresnel)));
      return { mixed, final: mix(sharp, frosted, frost.mul(uOpacity)) };
    };
    const refractedLook = look(refracted);
    const plainLook = look(coord);
    const grey = (x) => vec3(x);
    const views = {
      final: refractedLook.final,
      scene: sceneColor.sample(coord).rgb,
      blurVertical: blur.verticalNode.sample(coord).rgb,
      blurHorizontal: blurred.sample(coord).rgb,
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
    // Branch on the view uniform (uniform control flow): a frame pays for the final image plus the one
    // view shown, not for all of them, and switching views never rebuilds the material.
    const result = views.final.toVar();
    let chain = null;
    DEBUG_VIEWS.forEach((name, index) => {
      if (name === 'final') return;
      const assign = () => { result.assign(views[name]); };
      chain = chain === null ? If(uDebugView.equal(index), assign) : chain.ElseIf(uDebugView.equal(index), assign);
    });
    return vec4(result, 1);
  });

  const pipeline = new RenderPipeline(renderer);
  pipeline.outputColorTransform = true;
  pipeline.outputNode = output();

  // ---- bookkeeping -----------------------------------------------------------------------------
  const counters = {
    frames: 0, idleFrames: 0, discontinuities: 0, dispatches: 0, texelsDispatched: 0, lastFrame: null,
    segmentsQueued: 0, segmentsRejected: 0, resizes: 0, lateSteps: 0, pointerSeconds: 0,
  };

  function bindComposite() {
    histPrev.value = textures[1 - current];
    histNext.value = textures[current];
  }

  function setHistorySize(w, h) {
    histW = w;
    histH = h;
    uHistW.value = w;
    uHistH.value = h;
    uHistSize.value.set(w, h);
    scheduler = new TileScheduler(params, w, h);
    if (scheduler.count > tileCapacity) {
      throw new Error(`frost: a ${w}x${h} history needs ${scheduler.count} tiles, more than the ${tileCapacity} allocated`);
    }
  }

  function uploadTiles(list, count) {
    const array = tileBuffer.value.array;
    array.set(list.subarray(0, count));
    tileBuffer.value.addUpdateRange(0, count);
    tileBuffer.value.needsUpdate = true;
    uTileW.value = scheduler.tileWidth;
    uTileH.value = scheduler.tileHeight;
    uTilesX.value = scheduler.tilesX;
    uTileCount.value = count;
  }

  // Linear kernels: `count` threads (tiles × tile area). Three guards instanceIndex < node.count, so the
  // count is set per dispatch as well as the workgroup grid (split into y past 65535 groups).
  function runLinear(node, tiles) {
    const threads = tiles * scheduler.tileWidth * scheduler.tileHeight;
    const groups = Math.ceil(threads / wl);
    node.count = threads;
    run(node, groups <= 65535 ? [groups, 1, 1] : [65535, Math.ceil(groups / 65535), 1]);
  }

  const dispatch2d = () => [Math.ceil(histW / wx), Math.ceil(histH / wy), 1];

  function run(node, size) {
    renderer.compute(node, size);
    counters.dispatches += 1;
  }

  function clearAll() {
    uploadTiles(Uint32Array.from({ length: scheduler.count }, (_, i) => i), scheduler.count);
    runLinear(kernels.clear, scheduler.count);
  }

  // Element writes into reused typed arrays, no temporaries beyond StepBins' own: this runs every frame.
  function writeChunk(chunk) {
    let decay = 0;
    let pair = 0;
    for (let i = 0; i < chunk.length; i++) {
      const step = chunk[i];
      const late = step.age !== null && step.age !== undefined;
      stepData[i * 4] = step.dt;
      stepData[i * 4 + 1] = late ? step.age : -1;
      stepData[i * 4 + 2] = decay;
      stepData[i * 4 + 3] = 0;
      if (!late) decay += step.dt;
      for (const g of step.segments) {
        const o = pair * 8;
        pairData[o] = g.start[0];
        pairData[o + 1] = g.start[1];
        pairData[o + 2] = g.end[0];
        pairData[o + 3] = g.end[1];
        pairData[o + 4] = 0.5 * (g.pressure0 + g.pressure1);
        pairData[o + 5] = i;
        pairData[o + 6] = 0;
        pairData[o + 7] = 0;
        pair += 1;
      }
    }
    stepBuffer.value.addUpdateRange(0, Math.max(chunk.length, 1) * 4);
    stepBuffer.value.needsUpdate = true;
    if (pair > 0) {
      pairBuffer.value.addUpdateRange(0, pair * 8);
      pairBuffer.value.needsUpdate = true;
    }
    bins.bin(chunk, histW, histH, !binning);
    const starts = binStartBuffer.value.array;
    starts.set(bins.start.subarray(0, bins.count + 1));
    binStartBuffer.value.addUpdateRange(0, bins.count + 1);
    binStartBuffer.value.needsUpdate = true;
    if (bins.total > 0) {
      binEntryBuffer.value.array.set(bins.entries.subarray(0, bins.total));
      binEntryBuffer.value.addUpdateRange(0, bins.total);
      binEntryBuffer.value.needsUpdate = true;
    }
    uBinSize.value = bins.size;
    uBinsX.value = bins.binsX;
    uStepCount.value = chunk.length;
    uDecayTotal.value = decay;
  }

  function update(previousInstant, currentInstant) {
    const decision = classifyInterval(previousInstant, currentInstant, params.maxInterval);
    const report = {
      decision, steps: 0, dispatches: 0, texels: 0, updateTiles: 0, retiredTiles: 0, substeps: 0, lateSteps: 0,
      pointerSeconds: 0, binEntries: 0, texelSteps: 0,
    };
    if (decision === 'none') return report;
    counters.frames += 1;
    const before = counters.dispatches;
    if (decision === 'discontinuity') {
      counters.discontinuities += 1;
      pending.length = 0;
      freshFrom = 0;
      lastEnd.clear(); // time jumped: the next segment may start anywhere
      if (params.discontinuity === 'reset') reset();
      origin = currentInstant; // after reset(): nothing queued later deposits before the jump's end
      report.dispatches = counters.dispatches - before;
      counters.lastFrame = report;
      return report;
    }
    const frameDt = currentInstant - previousInstant;
    if (origin === null) origin = previousInstant;
    // Segments known only after the instant they overlap (a pointer segment arrives with its end sample)
    // first deposit their missed part exactly, then the frame's own interval runs.
    const late = lateSteps(previousInstant, pending, origin, freshFrom);
    const split = splitInterval(previousInstant, currentInstant, pending);
    const steps = late.length > 0 ? late.concat(split) : split;
    let pointerSeconds = 0;
    for (let i = 0; i < steps.length; i++) pointerSeconds += steps[i].dt * steps[i].segments.length;
    const substeps = diffusionSubsteps(params.diffusivity, frameDt, histH, params.diffusionStability);
    const { updateCount, retireCount } = scheduler.plan(steps, frameDt, substeps);
    const tileArea = scheduler.tileWidth * scheduler.tileHeight;
    Object.assign(report, {
      steps: steps.length, updateTiles: updateCount, retiredTiles: retireCount, lateSteps: late.length, pointerSeconds,
    });
    counters.lateSteps += late.length;
    counters.pointerSeconds += pointerSeconds;
    if (retireCount > 0) {
      uploadTiles(scheduler.retire, retireCount);
      runLinear(kernels.clear, retireCount);
      report.texels += retireCount * tileArea;
    }
    if (updateCount > 0) {
      const full = params.policy === 'full-field';
      if (!full) uploadTiles(scheduler.update, updateCount);
      const updated = full ? () => true : (b) => scheduler.live[b] === 1;
      chunkSteps(steps, maxSteps, params.maxPairs).forEach((chunk, index) => {
        writeChunk(chunk);
        report.binEntries += bins.total;
        report.texelSteps += bins.single
          ? bins.total * (full ? histW * histH : liveTexels(updateCount))
          : bins.texelSteps(updated);
        uFirstChunk.value = index === 0 ? 1 : 0;
        if (full) run(kernels.update2d[current], dispatch2d());
        else runLinear(kernels.updateTiles[current], updateCount);
        current = 1 - current;
        report.texels += updateCount * tileArea;
      });
      report.substeps = substeps;
      if (substeps > 0) {
        uDiffusionRate.value = params.diffusivity * (frameDt / substeps) * histH * histH;
        for (let s = 0; s < substeps; s++) {
          if (full) run(kernels.diffuse2d[current], dispatch2d());
          else runLinear(kernels.diffuseTiles[current], updateCount);
          current = 1 - current;
          report.texels += updateCount * tileArea;
        }
      }
    } else if (retireCount === 0) {
      counters.idleFrames += 1;
    }
    for (let i = pending.length - 1; i >= 0; i--) if (pending[i].t1 <= currentInstant) pending.splice(i, 1);
    freshFrom = pending.length;
    bindComposite();
    report.dispatches = counters.dispatches - before;
    counters.texelsDispatched += report.texels;
    counters.lastFrame = report;
    return report;
  }

  // Texels of the first `count` update tiles, clipped to the history (what a single-bin chunk evaluates).
  function liveTexels(count) {
    let sum = 0;
    for (let k = 0; k < count; k++) {
      const t = scheduler.update[k];
      const x0 = (t % scheduler.tilesX) * scheduler.tileWidth;
      const y0 = Math.floor(t / scheduler.tilesX) * scheduler.tileHeight;
      sum += Math.min(scheduler.tileWidth, histW - x0) * Math.min(scheduler.tileHeight, histH - y0);
    }
    return sum;
  }

  function pointer(segment) {
    const g = normalizeSegment(segment);
    const problem = validateSegment(g, lastEnd.get(g.stream) ?? null) ?? tooManyStreams(g, pending, params.maxStreams);
    if (problem !== null) {
      counters.segmentsRejected += 1;
      throw new Error(`frost.pointer: ${problem}`);
    }
    pending.push(g);
    lastEnd.set(g.stream, g.t1);
    counters.segmentsQueued += 1;
  }

  /**
   * Wire real pointers: one segment between successive samples of a press (coalesced events included),
   * captured on pointerdown, ending on pointerup/cancel. Every pointer that is down is its own stream
   * (stream = event.pointerId), so two fingers or a pen and a mouse wipe at once. Instants are
   * `clock(event.timeStamp)`, by default event.timeStamp / 1000: seconds on the same clock as
   * requestAnimationFrame's timestamp / 1000, which is what the frame loop must pass to
   * update(previous, current). Positions map to history UV through the element's bounding rect (origin
   * top-left). Pressure: pen and touch report it; a mouse is 1 while its primary button is down; the
   * release sample keeps the last pressure (contact lasted until then).
   */
  function attachPointer(element, attachOptions = {}) {
    const clock = attachOptions.clock ?? ((timeStampMs) => timeStampMs / 1000);
    const onSegment = attachOptions.onSegment ?? null;
    const presses = new Map(); // pointerId -> { t, uv, p } of the latest sample of that press
    const sampleOf = (event, pressure) => {
      const rect = element.getBoundingClientRect();
      const u = (event.clientX - rect.left) / Math.max(rect.width, 1e-9);
      const v = (event.clientY - rect.top) / Math.max(rect.height, 1e-9);
      return { t: clock(event.timeStamp), uv: [u, v], p: Math.min(Math.max(pressure, 0), 1) };
    };
    const pressureOf = (event) => (event.pointerType === 'mouse' ? 1 : event.pressure);
    const extend = (id, next) => {
      const last = presses.get(id);
      if (!(next.t > last.t)) {
        if (next.t === last.t) presses.set(id, { t: last.t, uv: next.uv, p: next.p });
        return;
      }
      const segment = {
        t0: last.t, t1: next.t, start: last.uv, end: next.uv, pressure0: last.p, pressure1: next.p, stream: id,
      };
      presses.set(id, next);
      try {
        pointer(segment);
      } catch {
        return; // refused (counted in counters.segmentsRejected); the stroke goes on from this sample
      }
      if (onSegment !== null) onSegment(normalizeSegment(segment));
    };
    const down = (event) => {
      if (presses.has(event.pointerId) || (event.pointerType === 'mouse' && event.button !== 0)) return;
      presses.set(event.pointerId, sampleOf(event, pressureOf(event)));
      try { element.setPointerCapture(event.pointerId); } catch { /* element not connected: no capture */ }
    };
    const move = (event) => {
      if (!presses.has(event.pointerId)) return;
      const coalesced = typeof event.getCoalescedEvents === 'function' ? event.getCoalescedEvents() : [];
      const samples = coalesced.length > 0 ? coalesced : [event];
      for (const e of samples) extend(event.pointerId, sampleOf(e, pressureOf(e)));
    };
    const up = (event) => {
      if (!presses.has(event.pointerId)) return;
      extend(event.pointerId, sampleOf(event, presses.get(event.pointerId).p));
      presses.delete(event.pointerId);
    };
    const previousTouchAction = element.style.touchAction;
    element.style.touchAction = 'none'; // touch drags reach us as pointer events instead of scrolling
    element.addEventListener('pointerdown', down);
    element.addEventListener('pointermove', move);
    element.addEventListener('pointerup', up);
    element.addEventListener('pointercancel', up);
    return function detach() {
      element.removeEventListener('pointerdown', down);
      element.removeEventListener('pointermove', move);
      element.removeEventListener('pointerup', up);
      element.removeEventListener('pointercancel', up);
      element.style.touchAction = previousTouchAction;
      for (const id of presses.keys()) {
        try { element.releasePointerCapture(id); } catch { /* already released */ }
      }
      presses.clear();
    };
  }

  function reallocate(drawingWidth, drawingHeight) {
    const [w, h] = scaledSize(drawingWidth, drawingHeight, tier.historyScale);
    if (w === histW && h === histH) return false;
    const old = textures[current];
    const [oldW, oldH] = [histW, histH];
    const [boundV, boundA] = scheduler.maxBounds();
    const fresh = [historyTexture(w, h, format, 'frost.history.0'), historyTexture(w, h, format, 'frost.history.1')];
    read[0].value = fresh[0];
    read[1].value = fresh[1];
    write[0].value = fresh[0];
    write[1].value = fresh[1];
    setHistorySize(w, h);
    const remap = params.resizePolicy === 'preserve-remap' && counters.frames > 0;
    if (remap) {
      oldRead.value = old;
      uOldSize.value.set(oldW, oldH);
      uOldW.value = oldW;
      uOldH.value = oldH;
      run(remapNode, dispatch2d());
      scheduler.markAll(boundV, boundA);
    } else {
      clearAll();
    }
    textures[0].dispose();
    textures[1].dispose();
    textures[0] = fresh[0];
    textures[1] = fresh[1];
    current = 0;
    bindComposite();
    counters.resizes += 1;
    return remap;
  }

  function resize(width, height, dpr = 1) {
    const [drawingWidth, drawingHeight] = scaledSize(width, height, dpr);
    return reallocate(drawingWidth, drawingHeight);
  }

  function setTier(name) {
    const next = PLAN.tiers[name];
    if (!next) throw new Error(`frost.setTier: unknown tier ${JSON.stringify(name)} (known: ${Object.keys(PLAN.tiers).join(', ')})`);
    tierName = name;
    tier = next;
    blur.resolutionScale = tier.blurScale;
    uDetailStrength.value = tier.detail ? r.detailStrength : 0;
    uFresnel.value = tier.fresnel ? r.fresnelStrength : 0;
    renderer.getDrawingBufferSize(size);
    reallocate(size.x, size.y);
  }

  // Scalar controls are uniforms: changing one never rebuilds a material.
  const controls = {
    mainScreenPeriod: uMainPeriod, detailScreenPeriod: uDetailPeriod, mainStrength: uMainStrength,
    detailStrength: uDetailStrength, fresnelStrength: uFresnel, ior: uIor, thickness: uThickness,
    sourceInset: uInset, brightness: uBrightness, saturation: uSaturation, blurMix: uBlurMix,
    maskLow: uMaskLow, maskHigh: uMaskHigh, opacity: uOpacity, side: uSide, corner: uCorner,
  };
  function setControl(name, value) {
    if (!(name in controls)) throw new Error(`frost.setControl: unknown control ${JSON.stringify(name)} (known: ${Object.keys(controls).join(', ')})`);
    if (typeof value !== 'number' || !Number.isFinite(value)) throw new Error(`frost.setControl: ${name} must be a finite number`);
    controls[name].value = value;
  }

  /** Clear the history and drop queued input (the reset policy, on request). */
  function reset() {
    pending.length = 0;
    freshFrom = 0;
    origin = null;
    lastEnd.clear();
    scheduler = new TileScheduler(params, histW, histH);
    clearAll();
    current = 0;
    bindComposite();
  }

  function setDebugView(name) {
    const index = DEBUG_VIEWS.indexOf(name);
    if (index < 0) throw new Error(`frost.setDebugView: unknown view ${JSON.stringify(name)} (known: ${DEBUG_VIEWS.join(', ')})`);
    uDebugView.value = index;
  }
  const debugView = () => DEBUG_VIEWS[uDebugView.value];

  // Diagnostics only (the lab and tests): copies the latest history into a buffer and reads it back.
  let readbackBuffer = null;
  let readbackNode = null;
  let readbackCapacity = 0;
  const readbackSource = texture(textures[0]);
  async function readHistory() {
    const count = histW * histH;
    if (count > readbackCapacity) {
      readbackCapacity = count;
      readbackBuffer = instancedArray(count, 'vec4');
      readbackNode = Fn(() => {
        const idx = int(instanceIndex);
        readbackBuffer.element(idx).assign(readbackSource.load(ivec2(idx.mod(uHistW), idx.div(uHistW))));
      })().compute(count, [wl, 1, 1]);
      readbackNode.setName('frost.readback');
    }
    readbackSource.value = textures[current];
    readbackNode.count = count;
    renderer.compute(readbackNode);
    const bytes = await renderer.getArrayBufferAsync(readbackBuffer.value, null, 0, count * 16);
    return { width: histW, height: histH, data: new Float32Array(bytes) };
  }

  // Diagnostics only (the parity job): the structure and normal textures as the GPU loads them, one
  // textureLoad per texel (unorm8 → float, exact), copied to a buffer and read back, as 8-bit codes.
  async function readTexels(tex) {
    const n = tex.image.width;
    const buffer = instancedArray(n * n, 'vec4');
    const source = texture(tex);
    const node = Fn(() => {
      const ix = int(globalId.x);
      const iy = int(globalId.y);
      If(ix.lessThan(n).and(iy.lessThan(n)), () => {
        buffer.element(iy.mul(n).add(ix)).assign(source.load(ivec2(ix, iy)));
      });
    })().compute([1, 1, 1], [wx, wy, 1]);
    node.setName('frost.readStructure');
    renderer.compute(node, [Math.ceil(n / wx), Math.ceil(n / wy), 1]);
    const floats = new Float32Array(await renderer.getArrayBufferAsync(buffer.value));
    const codes = new Uint8Array(floats.length);
    for (let i = 0; i < floats.length; i++) codes[i] = Math.round(floats[i] * 255);
    return codes;
  }
  async function readStructure() {
    return {
      resolution: structureTex.image.width,
      structure: await readTexels(structureTex),
      normals: await readTexels(normalTex),
    };
  }

  bindComposite();
  clearAll();

  return {
    get tier() { return tierName; },
    get historySize() { return [histW, histH]; },
    get format() { return format; },
    get debugView() { return debugView(); },
    get counters() { return counters; },
    pointer,
    attachPointer,
    update,
    render() { pipeline.render(); },
    resize,
    setTier,
    setDebugView,
    setControl,
    reset,
    readHistory,
    readStructure,
    memory() {
      return {
        historyBytesDerived: 2 * histW * histH * bytesPerTexel,
        historyTextures: textures.map((t) => [t.image.width, t.image.height]),
        bytesPerTexel,
        structureBytes: structureBytes.byteLength + normalBytes.byteLength,
      };
    },
    pipeline,
    dispose() {
      textures.forEach((t) => t.dispose());
      structureTex.dispose();
      normalTex.dispose();
      blur.dispose();
      pipeline.dispose();
    },
  };
}
