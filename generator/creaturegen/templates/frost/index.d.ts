// Types of the package entry: the effect and its pure-JS helpers (see core/index.d.ts, tsl/index.d.ts).
export type {
  FrostPlan, HistoryFormat, IntervalDecision, PointerSegment, StructureFileLayout, TierName,
} from './core/index.js';
export { FrostAssetError, FrostRevisionError, PLAN, TileScheduler, pointerUV } from './core/index.js';
export type {
  DebugViewName, FrameReport, FrostControlName, FrostCounters, FrostEffect, FrostEffectOptions, FrostMemory,
} from './tsl/index.js';
export { DEBUG_VIEWS, createFrostEffect } from './tsl/index.js';
