// Types of the three/TSL adapter (`<package>/tsl`): the population API (declared by the package entry,
// index.d.ts) and the node builders it is made of. Needs @types/three (an optional peer dependency).
import type {
  BufferGeometry, ComputeNode, Mesh, MeshStandardNodeMaterial, Node, StorageBufferNode, WebGPURenderer,
} from 'three/webgpu';
import type { CreatureData, DebugMode, LookData, ParsedSurface, TierName } from '../core/index.js';

export type {
  CreaturePopulation, InstanceInfo, PopulationOptions, SpawnOptions,
} from '../index.js';
export { DEBUG_MODES, assertThreeRevision, createCreaturePopulation } from '../index.js';

// --- the node builders the population is made of (used by the creaturegen lab; stable within a release) ---

/** Layout constants every node graph of this creature shares (layoutOf(CREATURE)). */
export interface Layout {
  rows: number; maxParts: number; slotCount: number; registers: number; fullProgram: number; noProgram: number; skinProgram: number;
  gradientFloor: number; tiny: number; kFloor: number; bodyScale: number;
  correction: CreatureData['correction']; vertices: number;
}
export type PoseStorage = StorageBufferNode<'vec4'>;

export const OP: Readonly<{ LEAF: 0; POLY: 1; COPY: 2; LSE: 3; MIN: 4 }>;
/** The field nodes of one pose layout: per-slot distance, program evaluation (vec4: d, ∇d) and the size row. */
export interface BodyField {
  slotField(p: Node, base: Node, slot: Node): Node;
  evaluate(p: Node, base: Node, program: Node, options?: { colour?: boolean; kFloor?: number }): { value: Node; colour: Node | null };
  runProgram(p: Node, base: Node, program: Node): Node;
  size(base: Node): Node;
  /** Σ wᵢ·rgb(slotᵢ) / Σ wᵢ over four baked colour slots and weights (vec4 nodes): a skin vertex's albedo. */
  bakedColour(base: Node, slots: Node, weights: Node): Node;
}
export function createField(options: {
  pose: PoseStorage; programs: PoseStorage; rows: number; slotCount: number; registers: number; gradientFloor: number; tiny: number;
}): BodyField;
export function rootSize(layout: { slotCount: number; rows: number }, pose: PoseStorage, base: Node): Node;

export const METHOD: Readonly<{ LBS: 0; DQ: 1; COR: 2 }>;
export interface BodySkin {
  skinVertex(v: Node, base: Node, slots: Node, weights: Node, method: Node, centre: Node): Node;
  /** Skinned position and skinned rest normal `n` from one blend (inline in a Fn). */
  skinVertexNormal(v: Node, n: Node, base: Node, slots: Node, weights: Node, method: Node, centre: Node): { position: Node; normal: Node };
  /** deform.skin_lbs's normal: cofactor(Σ wᵢRᵢ)·n, normalised. */
  lbsNormal(n: Node, base: Node, slots: Node, weights: Node): Node;
  correctVertex(p0: Node, base: Node, program: Node, trust: Node): { position: Node; accepted: Node };
  lbs(v: Node, base: Node, slots: Node, weights: Node): Node;
}
export function createSkin(options: { pose: PoseStorage; rows: number; field: BodyField; correction: Layout['correction'] }): BodySkin;
/** R(q)·v on nodes (q xyzw). */
export function rotate(q: Node, v: Node): Node;

export interface BodyFunctions { field: BodyField; skin: BodySkin }
export interface VertexInputs {
  rest: Node; slots: Node; weights: Node; cor: Node; skin: Node; normal: Node; colourSlots: Node; colourWeights: Node;
}
export interface BodyVertex {
  skinned: Node; position: Node; accepted: Node; program: Node; code: Node; gradient: Node; distance: Node; colour: Node | null;
}
/** The candidate code of a vertex no candidate region covers (it runs the full program). */
export const NO_PROGRAM: number;
/** The candidate code of a vertex that evaluates no field (a skin-represented tier). */
export const SKIN_PROGRAM: number;
export function layoutOf(data: CreatureData): Layout;
export function bodyFunctions(layout: Layout, pose: PoseStorage, programs: PoseStorage): BodyFunctions;
export function bodyVertex(layout: Layout, fns: BodyFunctions, inputs: VertexInputs & { base: Node; skinOnly: boolean; colour?: boolean; path?: VertexPath | 'any'; look?: LookUniforms | null }): BodyVertex;

/** vec4 per drawn vertex in a page's deform storage: (position, distance), (gradient, accepted), (albedo, program). */
export const DEFORM_STRIDE: number;
/** vec4 per rest vertex in the vertex records. */
export const RECORD_STRIDE: number;
/** One dispatch of the pre-pass: the vertices of one path (deform.js PATHS) of every listed body. */
export interface DeformSegmentKernel { kernel: ComputeNode; count: number }
export interface DeformKernel { kernels: DeformSegmentKernel[]; list: PoseStorage; vertices: number; size: number }
/** The branch of the body path a vertex takes. */
export type VertexPath = 'skin' | 'field' | 'corrected';
export const PATHS: readonly VertexPath[];
/** The order the pre-pass runs a body's vertices in and its segments, one per path. */
export interface VertexOrder { order: PoseStorage; segments: { path: VertexPath; start: number; count: number }[] }
export function vertexRecords(geometry: BufferGeometry): PoseStorage;
export function vertexOrder(geometry: BufferGeometry): VertexOrder;
export function recordInputs(records: PoseStorage, v: Node): VertexInputs;
export function deformStorage(size: number, vertices: number): PoseStorage;
export function deformView(deform: PoseStorage): PoseStorage;
/** A page's instance list (one int per body): the bodies the next pre-pass runs. */
export function instanceList(size: number): PoseStorage;
export function createDeformKernel(layout: Layout, fns: BodyFunctions, options: {
  pose: PoseStorage; records: PoseStorage; order: VertexOrder; deform: PoseStorage; list: PoseStorage; size: number; vertices: number; skinOnly?: boolean; look?: LookUniforms | null;
}): DeformKernel;
/** Run `deform` over the first `count` bodies of its page's instance list; returns the vertices processed. */
export function dispatchDeform(renderer: WebGPURenderer, deform: DeformKernel, count: number): number;

/** Throws unless `mode` is one of DEBUG_MODES; returns it. */
export function checkDebugMode(mode: string): DebugMode;
/** The population's shading uniforms (one set shared by every page and variant). */
export type LookUniforms = { [K in keyof LookData]: Node & { value: number } };
/** The field's self-occlusion at p with gradient g (1 with look.aoTaps 0), inline in a Fn. */
export function selfOcclusion(layout: Layout, fns: BodyFunctions, p: Node, g: Node, base: Node, look: LookUniforms): Node;
export const LOOK_INTEGERS: readonly (keyof LookData)[];
export const LOOK_DEFORM: readonly (keyof LookData)[];
export function createLookUniforms(look: LookData): LookUniforms;
/** setLook's controls: [lowest, highest, lowest allowed]. */
export const LOOK_RANGES: Readonly<Record<keyof LookData, readonly [number, number, boolean]>>;
export function checkLook<T extends Partial<LookData>>(changes: T): T;
export function createBodyMaterial(layout: Layout, pose: PoseStorage, deform: PoseStorage, drawList: PoseStorage, mode: DebugMode, look: LookUniforms): MeshStandardNodeMaterial;
export function rootRotate(root1: Node, v: Node): Node;
export function rootPoint(root1: Node, p: Node): Node;
export function rootNormal(root1: Node, n: Node): Node;
/** The debug shell's counts per tier (hero, repeated, distant): segments around, rings per cap, snap steps. */
export const SHELL_TIERS: readonly TierName[];
export const SHELL_RADIAL: readonly number[];
export const SHELL_CAP_RINGS: readonly number[];
export const SHELL_SNAP_STEPS: readonly number[];
/** A tier's shell counts; vertices = (2 + 2·capRings)·radial + 2 per slot. */
export interface ShellCounts { radial: number; capRings: number; steps: number; vertices: number }
export function shellCounts(tier: TierName): ShellCounts;
/** The unit shell of one slot: `position` the direction from its end's centre, `cgEnd` the end (0 or 1). */
export function shellGeometry(counts: ShellCounts): BufferGeometry;
/** One shell vertex placed on its slot's pose row and snapped onto the field (inline, in a Fn). */
export function shellVertex(layout: Layout, fns: BodyFunctions, pose: PoseStorage, inputs: { base: Node; slot: Node; dir: Node; end: Node; steps: number }): { placed: Node; position: Node; value: Node };
export function createShellMesh(layout: Layout, fns: BodyFunctions, pose: PoseStorage, drawList: PoseStorage, name: string, tier: TierName): Mesh;

/** Throws unless `renderer` is an initialised WebGPURenderer on the WebGPU backend. */
export function assertWebGPU(renderer: WebGPURenderer): void;
/** The program tapes a loaded surface carries, as one read-only vec4 storage node. */
export function programStorage(surface: ParsedSurface): PoseStorage;
/** BufferGeometry of the parsed reference surface with the skinning attributes the material reads. */
export function surfaceGeometry(surface: ParsedSurface): BufferGeometry;
/** The .glb's file name in assets/ (CREATURE.surfaceFile). */
export const SURFACE_FILE: string;
/** The package's own copy of the surface: `new URL('../assets/<SURFACE_FILE>', import.meta.url)`, as a string. */
export function defaultSurfaceUrl(): string;
/** Every shipped tier's own copy of its surface (CREATURE.tiers order), as functions returning the URL. */
export const TIER_SURFACE_URLS: Readonly<Partial<Record<TierName, () => string>>>;
