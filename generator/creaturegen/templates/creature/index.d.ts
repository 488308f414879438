// Types of the package entry: the pure-JS core (`./core`) and the population API of the three/TSL adapter
// (also exported by `./tsl`). The three.js types come from @types/three, an optional peer dependency.
import type { Camera, Group, Light, Mesh, Object3D, WebGPURenderer } from 'three/webgpu';
import type {
  DebugMode, Driver, GravityProvider, LookData, Motion, SupportSurfaceProvider, TierName, WaterSurfaceProvider,
} from './core/index.js';

export * from './core/index.js';

export interface PopulationOptions {
  /** Bodies the population can hold; every page is allocated up front (default 64). */
  capacity?: number;
  /** Bodies per page: one material and one draw call each (default 64; clamped so that a page's deform
   *  storage fits the device's maxStorageBufferBindingSize). */
  pageSize?: number;
  /** The shipped tiers to load (default: every one, CREATURE.tiers); each gets its own pages. */
  tiers?: TierName[];
  /** The tier spawn() puts a body in (default: the finest loaded). */
  tier?: TierName;
  /** At most this many bodies in a tier at once (default: capacity for each). */
  tierCapacity?: Partial<Record<TierName, number>>;
  debugMode?: DebugMode;
  /** Shading controls over CREATURE.look (roughness, metalness in [0, 1]; distanceRange in (0, 0.1]). */
  look?: Partial<LookData>;
  /** The surface .glb's own URL (e.g. what a bundler's file loader returned for
   *  `<package>/assets/<CREATURE.surfaceFile>`). Default: the package's copy, `new URL(..., import.meta.url)`. */
  surfaceUrl?: string | URL | Partial<Record<TierName, string | URL>>;
  /** The folder the .glb was copied to (ending in '/'): it is fetched from `new URL(CREATURE.surfaceFile, assetBase)`;
   *  a relative base resolves against the page. Give surfaceUrl or assetBase, not both. */
  assetBase?: string | URL;
  /** The ground every body walks on (default: flat ground at y = 0; see builtinSupports()). */
  support?: SupportSurfaceProvider;
  /** Gravity, never scaled by creature scale (default: 9.80665 m/s² down). */
  gravity?: GravityProvider;
  /** Required for a swimmer (refused with TierRefusedError without one, or with a missing channel). */
  water?: WaterSurfaceProvider;
}

export interface SpawnOptions {
  /** Unsigned 32-bit seed: the individual's genome (heading, colour, gait and size genes) from the package's LCG. */
  seed?: number;
  /** Where the body's path starts; the locomotion puts it on the support, the water or at its altitude. */
  position?: [number, number, number];
  /** The loaded tier it starts in (default: the population's `tier`). */
  tier?: TierName;
}

export interface InstanceInfo {
  alive: boolean;
  /** Held still by pause(): not stepped, not re-deformed, still drawn. */
  paused: boolean;
  seed: number;
  /** Population tick at spawn: the body's own tick is the population's minus this. */
  spawnTick: number;
  /** The body's own tick (null when dead). */
  tick: number | null;
  /** x, y, z, cos yaw, sin yaw, squash (null when dead). */
  root: number[] | null;
  /** Posed world AABB: min xyz, max xyz. */
  bounds: number[];
  /** Genes in [-1, 1): hue, chroma, lightness, the gait genes, then size (null when dead). */
  genome: number[] | null;
  /** The tier drawing it (null when dead). */
  tier: TierName | null;
  /** Its length on screen in pixels at the last chooseTiers (null before one, or when dead). */
  sizePx: number | null;
}

export interface PopulationTier {
  readonly name: TierName;
  /** Bodies it can hold (tierCapacity) and holds now. */
  readonly capacity: number;
  readonly count: number;
  /** CREATURE.tiers[].projectedSizeMaxPx: the largest length on screen it draws within half a pixel. */
  readonly ceiling: number;
  readonly vertices: number;
  readonly pageSize: number;
  readonly pages: { mesh: Mesh; shell: Mesh | null }[];
}

export interface CreaturePopulation {
  readonly object3d: Group;
  readonly tick: number;
  readonly capacity: number;
  /** Bodies per page: the requested pageSize clamped to what one storage binding of the device holds. */
  readonly pageSize: number;
  /** GPU bytes of deform storage per body (three vec4 per mesh vertex). */
  readonly deformBytesPerBody: number;
  readonly count: number;
  readonly debugMode: DebugMode;
  readonly stats: {
    uploads: number; uploadBytes: number; lastFrameBytes: number; spawns: number; ticks: number;
    /** Deform pre-pass dispatches so far, and the vertices the last flush deformed. */
    deformDispatches: number; lastFrameDeformedVertices: number;
    /** Bodies the last flush re-deformed: those whose pose rows changed since their last pre-pass. */
    lastFrameDeformedBodies: number;
    /** Live bodies the last flush left drawn, and those it culled (cullWith). */
    lastFrameDrawnBodies: number; lastFrameCulledBodies: number;
    /** Bodies moved between tiers so far, and moves refused because the tier was full. */
    tierMoves: number; tierMovesRefused: number;
  };
  /** The loaded tiers, finest first. */
  readonly tiers: readonly PopulationTier[];
  /** One pose page: its body mesh (one draw per pass) and, once debug mode 'shell' was shown, its shell. */
  readonly pages: { mesh: Mesh; shell: Mesh | null }[];
  /** Validation plus an O(slots) write; returns the instance id. Throws when full. */
  spawn(options?: SpawnOptions): number;
  despawn(id: number): void;
  readonly support: SupportSurfaceProvider;
  readonly gravity: GravityProvider;
  readonly water: WaterSurfaceProvider | null;
  /** The fixed-step driver update() uses. */
  readonly driver: Driver;
  /** Advance every body n fixed ticks (pose of the current step); returns the bytes uploaded. */
  stepTicks(n?: number): number;
  /** Every body re-simulated to tick n (same state as stepping there); returns the bytes uploaded. */
  seekTick(n: number): number;
  /** One render frame of dt seconds: the fixed steps due, then the interpolated render pose; returns steps. */
  update(dt: number): number;
  /** The locomotion core of a live instance, or null. */
  motion(id: number): Motion | null;
  /** Upload the dirty pose ranges left by spawn/despawn and run the deform pre-pass over them. */
  flush(): number;
  instance(id: number): InstanceInfo;
  stateHash(): string;
  setDebugMode(mode: DebugMode): void;
  /** The shading controls now (CREATURE.look at creation, then what setLook wrote). */
  readonly look: LookData;
  /** Change shading controls: uniform writes, no material, pipeline or buffer created; throws a RangeError
   *  naming a control that is unknown or out of range. Returns the controls now. */
  setLook(changes: Partial<LookData>): LookData;
  /**
   * Cull bodies by their posed bounds against these cameras or shadow-casting lights at every flush: only
   * bodies one of them sees are deformed and drawn. No arguments: no culling (the default).
   */
  cullWith(...views: Array<Camera | Light>): void;
  /** Hold a live body still (neither stepped nor re-deformed; still drawn); resume() steps it on. */
  pause(id: number): void;
  resume(id: number): void;
  /** Move every live body into loaded tier `tier` (throws when it cannot hold them all). */
  setTier(tier: TierName): void;
  /** Move one live body into a loaded tier, keeping its id, motion and genome; false when the tier is full. */
  setBodyTier(id: number, tier: TierName): boolean;
  /**
   * Give every live body the tier its length on screen asks for (chooseTier, with hysteresis), seen from
   * `camera` in a viewport `viewportHeight` pixels tall. Allocates nothing, creates no GPU object; returns
   * the bodies moved.
   */
  chooseTiers(camera: Camera, viewportHeight: number): number;
  /** Build every shipped variant (deform compute, display, shadow) before the first visible frame. */
  warm(scene: Object3D, camera: Camera): Promise<void>;
  dispose(): void;
}

export const DEBUG_MODES: readonly DebugMode[];
/** Throws ThreeRevisionError unless `revision` (default: three's REVISION) is the release the package targets. */
export function assertThreeRevision(revision?: string): void;
/**
 * Requires three r185 (else ThreeRevisionError) and an initialised WebGPURenderer on a WebGPU backend.
 * Rejects with SurfaceMismatchError when the fetched .glb is not this package's surface.
 */
export function createCreaturePopulation(renderer: WebGPURenderer, options?: PopulationOptions): Promise<CreaturePopulation>;
