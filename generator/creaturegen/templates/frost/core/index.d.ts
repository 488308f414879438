// Types of the pure-JS entry ('<package>/core'): no three.js types needed.

/** One pointer move between two timestamped samples. Positions in history UV (origin top-left, v down). */
export interface PointerSegment {
  t0: number;
  t1: number;
  start: [number, number];
  end: [number, number];
  /** In [0, 1]; default 1. The segment deposits with the average of its two pressures. */
  pressure0?: number;
  pressure1?: number;
  /**
   * The pointer it came from (attachPointer uses the pointerId); default 0. A stream's segments are
   * time-ordered and disjoint; streams may overlap in time (several strokes at once, up to
   * `PLAN.params.maxStreams`), and a texel under several takes the largest coverage.
   */
  stream?: number;
}

/** A segment with its defaults filled in. */
export interface NormalizedSegment {
  t0: number;
  t1: number;
  start: [number, number];
  end: [number, number];
  pressure0: number;
  pressure1: number;
  stream: number;
}

export type IntervalDecision = 'advance' | 'none' | 'catch-up' | 'discontinuity';

/**
 * One piecewise-constant input interval of a frame: the segments active throughout it (one per stream at
 * most; none is pure decay). A catch-up step (`age` a number) is the part of one late segment that lay
 * before the frame's previous instant: the history decayed over those `dt` seconds and `age` more, and the
 * law's catch-up form deposits it exactly.
 */
export interface FrameStep {
  dt: number;
  segments: NormalizedSegment[];
  age: number | null;
}

export type TierName = 'full' | 'balanced' | 'budgeted';
export type HistoryFormat = 'rgba16float' | 'rgba32float';

/** The decay/deposit law of one history channel. */
export interface ChannelParams {
  decay: number;
  fill: number;
  radius: number;
  noise: number;
  [key: string]: unknown;
}

/** The simulation numbers of the plan (the same FrostParams creaturegen's numpy reference runs). */
export interface FrostParams {
  visible: ChannelParams;
  tilt: ChannelParams;
  softness: number;
  diffusivity: number;
  diffusionStability: number;
  policy: 'full-field' | 'dirty-tiles';
  tileSize: number;
  idleWhenConverged: boolean;
  tolerance: number;
  /** Longest interval one advance integrates (seconds). */
  maxInterval: number;
  /** Longest interval caught up in advances of at most maxInterval before it is a discontinuity (seconds). */
  catchUp: number;
  maxSteps: number;
  /** (step, segment) pairs per update dispatch; a chunk ends before it would hold more. */
  maxPairs: number;
  /** Pointer streams that may deposit at once. */
  maxStreams: number;
  /** Bin entries per dispatch; past it a chunk is one bin (the unbinned cost). */
  binCapacity: number;
  discontinuity: 'reset' | 'freeze';
  resizePolicy: 'clear' | 'preserve-remap';
  historyScale: number;
  seed: number;
  workgroup2d: [number, number];
  workgroupLinear: number;
  [key: string]: unknown;
}

export interface TierSettings {
  historyScale: number;
  blurScale: number;
  detail: boolean;
  fresnel: boolean;
}

/** How one normal map follows from an 8-bit height plane of the structure file. */
export interface NormalScale {
  spacing: number;
  scale: number;
}

/** The plan's description of the structure file (see decodeStructureFile). */
export interface StructureFileLayout {
  file: string;
  bytes: number;
  adler32: number;
  sha256: string;
  resolution: number;
  planes: string[];
  filters: Array<'none' | 'sub' | 'up' | 'gradient'>;
  normals: { main: NormalScale; detail: NormalScale };
}

/** The build plan of this package, as data. */
export interface FrostPlan {
  readonly name: string;
  readonly slug: string;
  readonly version: string;
  readonly specSha256: string;
  readonly params: FrostParams;
  readonly tier: { name: TierName; historyFormat: HistoryFormat; historyFormatRequested: string; maxHistoryScale: number };
  readonly tiers: Record<TierName, TierSettings>;
  readonly refraction: Record<string, number>;
  readonly composite: Record<string, unknown>;
  readonly fades: { side: number; corner: number };
  readonly blur: { sigma: number; epsilon: number };
  readonly structure: { resolution: number; seed: number; sha256: string; [key: string]: unknown };
  readonly assets: { structure: StructureFileLayout };
  readonly three: { revision: string; range: string };
  readonly noiseSalts: number[];
  readonly debugViews: string[];
  readonly memory: Record<string, unknown>;
  readonly gates: Array<Record<string, unknown>>;
}

export const PLAN: FrostPlan;

/**
 * 'advance' | 'none' (equal instants) | 'catch-up' (longer than maxInterval, at most catchUp: a stalled frame)
 * | 'discontinuity' (reversed, non-finite or longer).
 */
export function classifyInterval(
  previous: number, current: number, maxInterval: number, catchUp: number,
): IntervalDecision;
/** Where the advances of a caught-up interval end: ceil(elapsed / maxInterval) equal pieces, the last at `current`. */
export function advanceInstants(previous: number, current: number, maxInterval: number): number[];
/** Why a segment is refused, or null (`lastEnd`: where its stream's previous segment ended). */
export function validateSegment(segment: NormalizedSegment, lastEnd: number | null): string | null;
/** Why a segment is refused for overlapping `maxStreams` or more other streams' queued segments, or null. */
export function tooManyStreams(
  segment: NormalizedSegment, pending: readonly NormalizedSegment[], maxStreams: number,
): string | null;
export function normalizeSegment(segment: PointerSegment): NormalizedSegment;
/** Pointer NDC in [-1, 1], y up, to history UV (origin top-left, v down). */
export function pointerUV(ndcX: number, ndcY: number): [number, number];
/** floor(x·scale + 0.5), at least 1, per axis. */
export function scaledSize(width: number, height: number, scale: number): [number, number];
/** Cut [previous, current) at every segment boundary inside it. */
export function splitInterval(previous: number, current: number, segments: readonly NormalizedSegment[]): FrameStep[];
/** Catch-up steps: the parts [max(t0, origin), min(t1, previous)] of segments queued since the last update. */
export function lateSteps(
  previous: number, segments: readonly NormalizedSegment[], origin: number, from?: number,
): FrameStep[];
/** Dispatch-sized groups: each ends before it would hold more than maxSteps steps or maxPairs pairs. */
export function chunkSteps(steps: readonly FrameStep[], maxSteps: number, maxPairs: number): FrameStep[][];
/** Inclusive texel box [x0, y0, x1, y1] a segment's capsule reaches over dt, or null. */
export function texelBox(
  segment: NormalizedSegment, dt: number, reach: number, width: number, height: number,
): [number, number, number, number] | null;

/** The pairs of one chunk binned into screen tiles (CSR), reused from frame to frame. */
export class StepBins {
  constructor(params: FrostParams);
  bin(chunk: readonly FrameStep[], width: number, height: number, unbinned?: boolean): this;
  /** Law evaluations of the dispatch: sum over updated bins of texels × entries. */
  texelSteps(updated: (bin: number) => boolean): number;
  readonly single: boolean;
  readonly size: number;
  readonly binsX: number;
  readonly count: number;
  readonly pairs: number;
  readonly total: number;
  readonly start: Uint32Array;
  readonly entries: Uint32Array;
}
/** Substeps keeping D·(dt/n)/dx² ≤ 1/4; 0 without diffusion. */
export function diffusionSubsteps(diffusivity: number, dt: number, height: number, stability: number): number;

/** Per-tile analytic bounds decide what a frame dispatches (see the README). */
export class TileScheduler {
  constructor(params: FrostParams, width: number, height: number);
  readonly tileWidth: number;
  readonly tileHeight: number;
  readonly tilesX: number;
  readonly tilesY: number;
  readonly width: number;
  readonly height: number;
  readonly count: number;
  /** Row-major tile ids to update / to retire after plan(). */
  readonly update: Uint32Array;
  readonly retire: Uint32Array;
  plan(steps: readonly FrameStep[], frameDt: number, substeps: number): { updateCount: number; retireCount: number };
  markAll(boundVisible: number, boundTilt: number): void;
  maxBounds(): [number, number];
}

/** The installed three.js is not the release this package was written for. */
export class FrostRevisionError extends Error {
  constructor(message: string);
}
/** The three.js revision this package requires, e.g. '185'. */
export const THREE_REVISION: string;
/** Throws FrostRevisionError unless `revision` (three's REVISION) is this package's release. */
export function checkThreeRevision(revision: string | number): void;

/** A fetched asset is not this package's file (wrong size or content, or a failed download). */
export class FrostAssetError extends Error {
  constructor(message: string);
}
/** Decode the structure file into the RGBA8 structure and normal maps the GPU samples (N × N each). */
export function decodeStructureFile(
  bytes: Uint8Array,
  layout: StructureFileLayout,
  source?: string,
): Promise<{ structure: Uint8Array; normals: Uint8Array }>;
