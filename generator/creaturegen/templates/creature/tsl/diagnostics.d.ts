// Types of the diagnostics entry (`<package>/diagnostics`): GPU readbacks of a population for labs and
// parity jobs, not for an app's frame loop. Needs @types/three (an optional peer dependency).
import type { BufferGeometry, WebGPURenderer } from 'three/webgpu';
import type { CreatureData } from '../core/index.js';
import type { CreaturePopulation } from '../index.js';
import type { Layout, PoseStorage, ShellCounts, VertexOrder } from './index.js';

// Only what is declared `export` below is public: without this, TypeScript exports every top-level
// declaration of a declaration file.
export {};

export interface CreatureDiagnostics {
  readSkinned(id: number): Promise<{ skinned: Float32Array; corrected: Float32Array; accepted: Float32Array; gradient: Float32Array; distance: Float32Array }>;
  probeField(id: number, xyz: Float32Array, program?: number): Promise<Float32Array>;
  readPose(id: number): Promise<Float32Array>;
  /** The debug shell of instance `id` as the 'shell' view draws it (creature-local), slot after slot. */
  readShell(id: number): Promise<{ counts: ShellCounts; placed: Float32Array; position: Float32Array; distance: Float32Array }>;
  /** What the passes draw: the page's deform storage for instance `id` (creature-local). */
  readDeformed(id: number): Promise<{ position: Float32Array; gradient: Float32Array; distance: Float32Array; accepted: Float32Array; colour: Float32Array; program: Float32Array }>;
  /** Pose rows of instance `id` from the CPU staging copy (what the next upload sends). */
  stagedPose(id: number): Float32Array;
  /** The debug-mode variants built so far ('off' is the shipped one). */
  variantKeys(): string[];
}

/** What the diagnostics read of a population beyond its public API (stable within a release). */
export interface PopulationInternals {
  readonly data: CreatureData;
  readonly layout: Layout;
  readonly programs: PoseStorage;
  readonly geometry: BufferGeometry;
  readonly records: PoseStorage;
  readonly order: VertexOrder;
  locate(id: number): { page: object; index: number };
  stagedPose(id: number): Float32Array;
  variantKeys(): string[];
}

/** Readbacks of a population this package created (throws for any other object). */
export function createDiagnostics(renderer: WebGPURenderer, population: CreaturePopulation, options?: { maxPoints?: number }): CreatureDiagnostics;
/** The internals of a population this package created (throws for any other object). */
export function populationInternals(population: CreaturePopulation): PopulationInternals;
