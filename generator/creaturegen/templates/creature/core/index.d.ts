// Types of the pure-JS core (no three imports): the plan as data, the LCG, pose rows, the .glb reader,
// stateHash, and the locomotion core with its providers. Vectors are plain arrays or Float64Arrays.

type Vec = ArrayLike<number> & { [index: number]: number };

export type DebugMode = 'off' | 'skin-only' | 'distance' | 'weights' | 'normals' | 'candidates' | 'shell';
export type TierName = 'hero' | 'repeated' | 'distant';
export type LocomotionType = 'none' | 'biped' | 'quadruped' | 'hexapod' | 'octopod' | 'walker' | 'hopper' | 'flyer' | 'swimmer';
export type Vec3 = [number, number, number];

/** The LCG every instance stream uses: state' = (a·state + c) mod 2^32. */
export interface Lcg { readonly a: number; readonly c: number }

/** Cache identities of the build: the .glb carries the same three (checked when it loads). */
export interface CreatureSignatures {
  readonly compilerSignature: string;
  readonly topologySignature: string;
  readonly geometryDigest: string;
}

/** One leg of a walker or hopper (two slots: upper and lower), rest geometry in creature-local metres. */
export interface LegData {
  readonly part: string; readonly upper: number; readonly lower: number;
  readonly hip: Vec3; readonly knee: Vec3; readonly foot: Vec3; readonly hint: Vec3; readonly hinge: Vec3;
  readonly a: number; readonly b: number; readonly group: number; readonly reachMin: number; readonly reachMax: number;
  readonly tuck: number; readonly crouch: number;
}

/** A rope part: a chain of slots simulated follow-the-leader. */
export interface RopeData {
  readonly part: string; readonly slots: readonly number[]; readonly parent: number;
  readonly rest: readonly Vec3[]; readonly before: Vec3; readonly radius: readonly number[];
  readonly segment: number; readonly bendMin: number; readonly bendCos: number; readonly bendSin: number;
}

export interface WingData {
  readonly part: string; readonly slot: number; readonly sign: number; readonly amplitude: number; readonly length: number;
}

/** CREATURE.motion: what createMotion runs (creaturegen's motion/rig.py build_motion, as JSON). */
export interface MotionData {
  readonly type: LocomotionType;
  /** Fixed steps per second. */
  readonly hz: number;
  readonly speed: number; readonly bodyScale: number; readonly groundY: number; readonly centreY: number;
  readonly pathRadius: number; readonly stepLength: number; readonly stepLengthSpec: number; readonly stepLimit: number;
  readonly stepHeight: number; readonly hopLength: number; readonly hopHeight: number; readonly altitude: number;
  readonly undulation: number; readonly buoyancy: number; readonly groups: number;
  readonly legs: readonly LegData[];
  readonly ropes: readonly RopeData[];
  readonly wings: readonly WingData[];
  readonly roots: readonly number[];
  readonly parent: readonly number[];
  readonly order: readonly number[];
  readonly pivot: readonly Vec3[];
  readonly constants: Readonly<Record<string, number>>;
  readonly ropeGround: boolean;
  /** Gait genes: `fields[i]` lists the motion fields gene i scales by 1 + jitter·gene; `size` bounds the size gene. */
  readonly genes: { readonly jitter: number; readonly fields: readonly (readonly string[])[]; readonly size: number };
  /** Motion fields scaled with an individual's size, by group. */
  readonly lengths: Readonly<Record<string, readonly string[]>>;
}

/** CREATURE: the build plan of this creature, as data (core/data.js). */
export interface CreatureData {
  readonly name: string;
  /** The npm package name. */
  readonly slug: string;
  /** creaturegen version that built the package. */
  readonly version: string;
  readonly specSha256: string;
  readonly signatures: CreatureSignatures;
  readonly tier: TierName;
  /** The reference surface's file name in assets/ (`new URL(surfaceFile, assetBase)` when assetBase is given). */
  readonly surfaceFile: string;
  /** three.js REVISION the package was built for ('185'). */
  readonly threeRevision: string;
  readonly bodyScale: number;
  readonly slotCount: number;
  readonly maxParts: number;
  readonly poseRows: number;
  /** Rest slot table, one row of 12 numbers per slot. */
  readonly slots: readonly (readonly number[])[];
  readonly slotNames: readonly string[];
  readonly roundCone: readonly number[];
  readonly lcg: Lcg;
  readonly genetics: { readonly hueRad: number; readonly chroma: number; readonly lightness: number };
  readonly slotLab: readonly Vec3[];
  readonly motion: MotionData;
  readonly tickRate: number;
  readonly programData: readonly number[];
  readonly programCount: number;
  readonly fullProgram: number;
  readonly noProgram: number;
  /** The candidate code of a vertex that evaluates no field (a skin-represented tier): skinned position
   * and normal, baked colour. */
  readonly skinProgram: number;
  readonly registers: number;
  readonly candidateNote: string;
  readonly gradientFloor: number;
  readonly tiny: number;
  readonly kFloor: number;
  readonly correction: { readonly budget: number; readonly earlyOut: number; readonly gradientFloor: number };
  readonly mesh: { readonly vertices: number; readonly triangles: number };
  readonly debugModes: readonly DebugMode[];
  readonly deformStride: number;
}

export const CREATURE: CreatureData;
export function lcgNext(state: number, a: number, c: number): number;
/** The first state of an instance's LCG stream (murmur3's 32-bit finaliser of the seed). */
export function mixSeed(seed: number): number;
export function instanceYaw(seed: number, lcg: Lcg): number;
/** R(q)·v with q at q[qo..qo+3] (xyzw) and v at v[vo..vo+2]; vectors travel as (array, offset) so no call boxes a double. */
export function rotate(q: ArrayLike<number>, qo: number, v: ArrayLike<number>, vo: number, out: Vec, o: number): void;
/** An instance's slot rows; `size` (the motion's) scales the rest ends, radii and blend widths. */
export function writePoseRows(data: CreatureData, quats: ArrayLike<number>, trans: ArrayLike<number>, colours: ArrayLike<number> | null, co: number, tmp: Float64Array, target: Float32Array, base: number, bounds: Float64Array, size?: number): void;
/** Floats in a genome: hue, chroma, lightness, the gait genes, then size (each signed, in [-1, 1)). */
export const GENOME_LENGTH: number;
/** LCG draw (1-based) of the size gene. */
export const SIZE_DRAW: number;
/** The genome of the individual spawned from `seed` (LCG draws 3 onwards). */
export function drawGenome(seed: number, lcg: Lcg, out?: Float64Array): Float64Array;
/** Per-slot linear rgb of an individual (its colour genes applied in OKLab to the authored colours). */
export function genomeColours(data: CreatureData, genome: ArrayLike<number>, out: Float64Array, o?: number): Float64Array;
/** The motion data of an individual: gene-listed gait parameters scaled by 1 + jitter·gene. */
export function expressGait<T extends MotionData>(motion: T, genome: ArrayLike<number>): T;
/** An individual's size factor, 1 + genes.size·gene: a similarity of the whole body (gravity unscaled). */
export function individualSize(motion: MotionData, genome: ArrayLike<number>): number;
/** The motion data with every field `motion.lengths` names scaled by `size`. */
export function expressSize<T extends MotionData>(motion: T, size: number): T;
/** The motion data of an individual: expressSize, then expressGait. */
export function express<T extends MotionData>(motion: T, genome: ArrayLike<number>): T;
/** The root rows (x, y, z, alive), (cos yaw, sin yaw, squash, size). */
export function writeRootRows(root: ArrayLike<number>, alive: number, target: Float32Array, at: number, size?: number): void;
export function rootBounds(local: ArrayLike<number>, root: ArrayLike<number>, out: Float64Array, at: number): void;
export function hashBytes(bytes: Uint8Array | Uint8Array[], tick: number): string;
export interface ParsedSurface {
  attributes: Record<string, { array: Float32Array | Uint16Array | Uint32Array; itemSize: number }>;
  index: { array: Uint16Array | Uint32Array };
  /** The glTF asset.extras: the build's signatures (geometryDigest, topologySignature, compilerSignature, tier). */
  extras: Record<string, unknown>;
}
/** `source` names the file in errors. */
export function parseGlb(buffer: ArrayBuffer, source?: string): ParsedSurface;

/** The signatures a surface .glb must carry to be this package's, compared when it loads. */
export type SurfaceKey = 'geometryDigest' | 'topologySignature' | 'compilerSignature' | 'tier';
export type SurfaceSignatures = Record<SurfaceKey, string | null>;
export const SURFACE_KEYS: readonly SurfaceKey[];
/** The fetched .glb is not this package's surface: `expected` are the package's signatures, `found` the file's. */
export class SurfaceMismatchError extends Error {
  constructor(packageName: string, url: string, expected: SurfaceSignatures, found: SurfaceSignatures);
  readonly name: 'SurfaceMismatchError';
  readonly packageName: string;
  readonly url: string;
  readonly expected: SurfaceSignatures;
  readonly found: SurfaceSignatures;
}
/** three.js is not the release the package was built for (`expected` and `found` are REVISION strings). */
export class ThreeRevisionError extends Error {
  constructor(packageName: string, expected: string, found: string);
  readonly name: 'ThreeRevisionError';
  readonly packageName: string;
  readonly expected: string;
  readonly found: string;
}
/** Throws ThreeRevisionError unless `revision` (three's REVISION) is CREATURE.threeRevision. */
export function checkThreeRevision(revision: string | number): void;
export function expectedSurface(): SurfaceSignatures;
/** Throws SurfaceMismatchError unless `extras` (a .glb's asset.extras) carry this package's signatures. */
export function checkSurface(extras: Record<string, unknown> | null | undefined, url: string | URL): void;
/** Where the surface comes from: `surfaceUrl`, else `new URL(CREATURE.surfaceFile, assetBase)` (a relative
 * base resolves against the page), else `fallback()`. Both options at once is a TypeError. */
export function resolveSurfaceUrl(options: { surfaceUrl?: string | URL | null; assetBase?: string | URL | null } | undefined, fallback: () => string | URL): string;
/** Fetch, parse and check the surface: throws on HTTP errors, a non-glTF body, or SurfaceMismatchError. */
export function loadSurface(url: string | URL): Promise<ParsedSurface>;

export interface GravityProvider {
  /** Gravity (m/s²) at sim time `time` into `out`. */
  at(time: number, out: Vec): Vec;
  /** True when `at` returns the same vector at every time: the core then samples it once. */
  readonly constant?: boolean;
}

/** A support frame is 12 numbers: origin, tangent ex, outward normal ny, tangent ez. */
export interface SupportSurfaceProvider {
  readonly name: string;
  readonly supportId: number;
  /** True when the frame never moves (flat ground, the slope): the core then samples it once. */
  readonly static?: boolean;
  frame(time: number, out: Float64Array): Float64Array;
  closestPoint(time: number, p: ArrayLike<number>, out: Vec): Vec;
  normal(time: number, p: ArrayLike<number>, out: Vec): Vec;
  velocity(time: number, p: ArrayLike<number>, out: Vec): Vec;
  acceleration(time: number, p: ArrayLike<number>, out: Vec): Vec;
  featureId(time: number, p: ArrayLike<number>): number;
}

export type WaterChannel = 'freeSurfacePoint' | 'freeSurfaceNormal' | 'geometricNormalVelocityMps' | 'waterColumnDepthMeters' | 'materialCurrentVelocityMps';

/** Channels it does not list are absent (a swimmer needing one is refused), never zero. */
export interface WaterSurfaceProvider {
  readonly channels: readonly WaterChannel[];
  createSample(): Record<string, Float64Array>;
  /** `query` holds (x, z, time): world x and z in metres and sim time in seconds, in an array so a step passes
   * no boxed number. Writes the listed channels into `out` and returns it. */
  sample(query: ArrayLike<number>, out: Record<string, Float64Array>): Record<string, Float64Array>;
}

export interface Driver {
  readonly hz: number;
  readonly step: number;
  readonly accumulator: number;
  readonly alpha: number;
  /** Whole fixed steps due after a frame of dt seconds (dt clamped to [0, 0.25], accumulator capped). */
  advance(dt: number): number;
  reset(): void;
}

export interface MotionGates {
  plantDrift: number; ikResidual: number; drawnFoot: number; clampedTicks: number; plantedSamples: number;
  bothSwingTicks: number;
  /** Fewest feet planted on any tick since reset (the leg count until a foot lifts). */
  fewestPlanted: number;
  steps: number; ropeAnchor: number; swimTracking: number; apexError: number;
  apexSquash: number; squashDet: number;
}

/** One creature's locomotion in float64; integer ticks are authoritative. */
export interface Motion {
  readonly kind: LocomotionType;
  readonly tick: number;
  /** The individual's size factor (its body and every motion length are scaled by it). */
  readonly size: number;
  /** Per-slot quaternions (xyzw) and translations, creature-local. */
  readonly quats: Float64Array;
  readonly trans: Float64Array;
  /** x, y, z, cos yaw, sin yaw, squash. */
  readonly root: Float64Array;
  /** Worst values since reset (allocates a plain object). */
  readonly gates: MotionGates;
  reset(): void;
  step(): void;
  stepTicks(n?: number): void;
  seekTick(n: number): void;
  renderPose(alpha: number, outQuats: Float64Array, outTrans: Float64Array, outRoot: Float64Array): void;
  /** (x, y, z, planted) per leg: each plant point in world space at the current tick. */
  feet(out: Float64Array): Float64Array;
  stateVector(): number[];
  stateHash(): string;
}

export class TierRefusedError extends Error {}
/** Throws TierRefusedError unless a swimmer (`kind`) has water representing every channel it reads. */
export function assertWaterFor(kind: string, water: WaterSurfaceProvider | null, who?: string): void;
export function createMotion(data: MotionData, lcg: Lcg, options?: {
  support?: SupportSurfaceProvider; gravity?: GravityProvider; water?: WaterSurfaceProvider | null; seed?: number;
  position?: [number, number, number];
  /** Genes overriding the seed's (drawGenome layout); the heading still comes from the seed. */
  genome?: ArrayLike<number> | null;
}): Motion;
export function createDriver(hz: number): Driver;
export const MAX_FRAME_S: number;
export const MAX_ACCUMULATOR_S: number;
export const STANDARD_GRAVITY: number;
export const SWIMMER_CHANNELS: readonly WaterChannel[];
export function builtinSupports(): { flat: SupportSurfaceProvider; slope: SupportSurfaceProvider; translating: SupportSurfaceProvider; rotating: SupportSurfaceProvider };
export function createFlatGround(): SupportSurfaceProvider;
export function createSlope(angle?: number): SupportSurfaceProvider;
export function createTranslatingPlatform(velocity?: [number, number, number]): SupportSurfaceProvider;
export function createRotatingPlatform(centre?: [number, number, number], omega?: number): SupportSurfaceProvider;
export function createGravity(vector?: [number, number, number]): GravityProvider;
export function createAnalyticWater(options?: { channels?: WaterChannel[]; waves?: [number, number, number][]; level?: number; depth?: number }): WaterSurfaceProvider;
/** Support-local (u, h, w) at v[vo..vo+2] to world. */
export function toWorld(frame: ArrayLike<number>, v: ArrayLike<number>, vo: number, out: Vec, o: number): void;
/** World p[po..po+2] to support-local (u, h, w). */
export function toLocal(frame: ArrayLike<number>, p: ArrayLike<number>, po: number, out: Vec, o: number): void;
export function derive(data: MotionData, gravity: ArrayLike<number>): Record<string, number>;
export function ticksFromSeconds(seconds: number, hz: number): number;
