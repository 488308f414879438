import type { Camera, Object3D, RenderPipeline, WebGPURenderer } from 'three/webgpu';

/** One pointer move between two timestamped samples. Positions in history UV (origin top-left, v down). */
export interface PointerSegment {
  t0: number;
  t1: number;
  start: [number, number];
  end: [number, number];
  /** In [0, 1]; default 1. The segment deposits with the average of its two pressures. */
  pressure0?: number;
  pressure1?: number;
}

export type IntervalDecision = 'advance' | 'none' | 'discontinuity';

export interface FrameReport {
  decision: IntervalDecision;
  steps: number;
  dispatches: number;
  texels: number;
  updateTiles: number;
  retiredTiles: number;
  substeps: number;
}

export interface FrostCounters {
  frames: number;
  idleFrames: number;
  discontinuities: number;
  dispatches: number;
  texelsDispatched: number;
  lastFrame: FrameReport | null;
  segmentsQueued: number;
  segmentsRejected: number;
  resizes: number;
}

export type TierName = 'full' | 'balanced' | 'budgeted';

export interface FrostEffectOptions {
  /** Start in another tier than the authored one. */
  tier?: TierName;
}

export interface FrostEffect {
  readonly tier: TierName;
  readonly historySize: [number, number];
  readonly format: 'rgba16float' | 'rgba32float';
  readonly counters: FrostCounters;
  readonly pipeline: RenderPipeline;
  /** Queue a pointer segment; throws on reversed, overlapping or non-finite input. */
  pointer(segment: PointerSegment): void;
  /** Advance the history from one render instant to the next (seconds). Equal instants do nothing. */
  update(previousInstant: number, currentInstant: number): FrameReport;
  /** Render the scene through the effect (RenderPipeline owns presentation). */
  render(): void;
  /** CSS size and device-pixel ratio; the history follows the declared resize policy. */
  resize(width: number, height: number, dpr?: number): boolean;
  setTier(name: TierName): void;
  setDebugView(name: string): void;
  /** Diagnostics only: reads the latest history back (R, G, B, A per texel). */
  readHistory(): Promise<{ width: number; height: number; data: Float32Array }>;
  memory(): { historyBytesDerived: number; historyTextures: [number, number][]; bytesPerTexel: number; structureBytes: number };
  dispose(): void;
}

export const DEBUG_VIEWS: readonly string[];
export const PLAN: Readonly<Record<string, unknown>>;
export function pointerUV(ndcX: number, ndcY: number): [number, number];
export class TileScheduler {}

/** Requires an initialised WebGPURenderer on a WebGPU backend; throws otherwise. */
export function createFrostEffect(
  renderer: WebGPURenderer,
  scene: Object3D,
  camera: Camera,
  options?: FrostEffectOptions,
): Promise<FrostEffect>;
