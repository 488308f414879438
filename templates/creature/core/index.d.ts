// Types of the pure-JS core (no three imports): the plan as data, the LCG, pose rows, the .glb reader,
// stateHash, and the locomotion core with its providers. Vectors are plain arrays or Float64Arrays.

type Vec = ArrayLike<number> & { [index: number]: number };

export const CREATURE: Readonly<Record<string, unknown>>;
export function lcgNext(state: number, a: number, c: number): number;
/** The first state of an instance's LCG stream (murmur3's 32-bit finaliser of the seed). */
export function mixSeed(seed: number): number;
export function instanceYaw(seed: number, lcg: { a: number; c: number }): number;
/** R(q)·v with q at q[qo..qo+3] (xyzw) and v at v[vo..vo+2]; vectors travel as (array, offset) so no call boxes a double. */
export function rotate(q: ArrayLike<number>, qo: number, v: ArrayLike<number>, vo: number, out: Vec, o: number): void;
/** An instance's slot rows; `size` (the motion's) scales the rest ends, radii and blend widths. */
export function writePoseRows(data: unknown, quats: ArrayLike<number>, trans: ArrayLike<number>, colours: ArrayLike<number> | null, co: number, tmp: Float64Array, target: Float32Array, base: number, bounds: Float64Array, size?: number): void;
/** Floats in a genome: hue, chroma, lightness, the gait genes, then size (each signed, in [-1, 1)). */
export const GENOME_LENGTH: number;
/** LCG draw (1-based) of the size gene. */
export const SIZE_DRAW: number;
/** The genome of the individual spawned from `seed` (LCG draws 3 onwards). */
export function drawGenome(seed: number, lcg: { a: number; c: number }, out?: Float64Array): Float64Array;
/** Per-slot linear rgb of an individual (its colour genes applied in OKLab to the authored colours). */
export function genomeColours(data: unknown, genome: ArrayLike<number>, out: Float64Array, o?: number): Float64Array;
/** The motion data of an individual: gene-listed gait parameters scaled by 1 + jitter·gene. */
export function expressGait<T extends object>(motion: T, genome: ArrayLike<number>): T;
/** An individual's size factor, 1 + genes.size·gene: a similarity of the whole body (gravity unscaled). */
export function individualSize(motion: unknown, genome: ArrayLike<number>): number;
/** The motion data with every field `motion.lengths` names scaled by `size`. */
export function expressSize<T extends object>(motion: T, size: number): T;
/** The motion data of an individual: expressSize, then expressGait. */
export function express<T extends object>(motion: T, genome: ArrayLike<number>): T;
/** The root rows (x, y, z, alive), (cos yaw, sin yaw, squash, size). */
export function writeRootRows(root: ArrayLike<number>, alive: number, target: Float32Array, at: number, size?: number): void;
export function rootBounds(local: ArrayLike<number>, root: ArrayLike<number>, out: Float64Array, at: number): void;
export function hashBytes(bytes: Uint8Array | Uint8Array[], tick: number): string;
export function parseGlb(buffer: ArrayBuffer): { attributes: Record<string, { array: Float32Array | Uint16Array | Uint32Array; itemSize: number }>; index: { array: Uint16Array | Uint32Array }; extras: Record<string, unknown> };

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
  readonly kind: string;
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
export function createMotion(data: unknown, lcg: { a: number; c: number }, options?: {
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
export function derive(data: unknown, gravity: ArrayLike<number>): Record<string, number>;
export function ticksFromSeconds(seconds: number, hz: number): number;
