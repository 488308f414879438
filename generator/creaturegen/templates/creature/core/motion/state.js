// What every stage of one tick reads and writes (creaturegen's Python reference: motion/state.py,
// MotionState): the individual's motion data, its root, its posed slots, its feet and ropes, the gates
// measured on them, and the typed scratch the stages share. createMotion (motion.js) makes one state per
// creature and composes the stages (root.js, base-pose.js, gait.js, hop.js, flight.js, swim.js, ropes.js),
// each a plain function of the state. The state is stateful by nature: feet, ropes and the swimmer
// integrate, so the state at tick n is reached only by stepping from tick 0.
// Everything a step touches is allocated here, once per creature: nothing allocates after createMotion.
// Doubles reach the stages through typed arrays, never as arguments or return values (see quat.js).

// Worst values since reset, measured every tick (motion/state.py Gates), in one typed array indexed by G.
export const GATE_NAMES = ['plantDrift', 'ikResidual', 'drawnFoot', 'clampedTicks', 'plantedSamples', 'bothSwingTicks',
  'fewestPlanted', 'steps', 'ropeAnchor', 'swimTracking', 'apexError', 'apexSquash', 'squashDet'];
export const G = Object.freeze(Object.fromEntries(GATE_NAMES.map((name, i) => [name, i])));

/**
 * One creature's locomotion state. `data` is the individual's motion data (CREATURE.motion expressed by
 * its genes), `d` the numbers derived from it at spawn (derived.js), `rootAt(state, n, frame, out)` the
 * support frame and root at tick n (motion.js). Created once; every later write goes into its typed arrays.
 */
export function createState({ data, d, kind, size, isWalker, support, gravity, water, gravity0, theta0, position, rootAt }) {
  const S = data.parent.length;
  const L = data.legs.length;
  const hopOut = new Float64Array(3);
  return {
    // The individual, its providers, and where it spawned (the path's start angle and the spawn position).
    data, d, kind, size, isWalker, support, gravity, water,
    hasCurrent: water ? water.channels.includes('materialCurrentVelocityMps') : false,
    sample: water ? water.createSample() : null,
    theta0,
    position: Float64Array.from(position),
    rootAt,
    // The output: per-slot quaternion and translation, the root (x, y, z, cos yaw, sin yaw, squash), and
    // the previous fixed step's (renderPose interpolates between them).
    quats: new Float64Array(4 * S),
    trans: new Float64Array(3 * S),
    root: new Float64Array(6),
    prevQuats: new Float64Array(4 * S),
    prevTrans: new Float64Array(3 * S),
    prevRoot: new Float64Array(6),
    // The path's centre (a water current carries it), the tick, and what integrates: the feet (planted,
    // support-local plant, swing start and target, lift tick), the rope nodes, the swimmer's (y, vy).
    centre: new Float64Array(3),
    tick: 0,
    planted: new Uint8Array(L),
    plant: new Float64Array(3 * L),
    swingFrom: new Float64Array(3 * L),
    swingTo: new Float64Array(3 * L),
    liftTick: new Int32Array(L),
    nodes: data.ropes.map((r) => new Float64Array(3 * r.rest.length)),
    prevNodes: data.ropes.map((r) => new Float64Array(3 * r.rest.length)),
    swim: new Float64Array(2),
    gates: new Float64Array(GATE_NAMES.length),

    // --- scratch ---
    // The support frame of this tick, and a frame and root ahead (a lifting foot's landing).
    frame: new Float64Array(12),
    frame2: new Float64Array(12),
    root2: new Float64Array(6),
    // A static support (flat ground, the slope) is sampled once; a constant gravity too (ropes.js).
    staticFrame: support.frame(0, new Float64Array(12)),
    grav: Float64Array.from(gravity0),
    // Shared vectors, and sin, cos, angle (trig.js sincos).
    v3: new Float64Array(3),
    w3: new Float64Array(3),
    n3: new Float64Array(3),
    g3: new Float64Array(3),
    turned: new Float64Array(3),
    sc: new Float64Array(3),
    // root.js and motion.js rootAt: a distance along the path, (u, w, ψ) on it, the still pose's (u, w, ψ),
    // the hop's (distance, lift, squash), its (lift, squash) and the level (lift 0, squash 1).
    dist1: new Float64Array(1),
    onPath: new Float64Array(3),
    still: new Float64Array(3),
    hopOut,
    hopLift: hopOut.subarray(1, 3),
    level: new Float64Array([0, 1]),
    // swim.js: the water query (x, z, time); numbers in an array are never boxed.
    query: new Float64Array(3),
    // base-pose.js, flight.js, swim.js: per-slot local rotations and which slots have one.
    locals: new Float64Array(4 * S),
    hasLocal: new Uint8Array(S),
    axis4: new Float64Array(4),
    // gait.js and hop.js: a foot's home and landing, its support-local target, its creature-frame target,
    // and a hopper's airborne foot (its take-off and landing plants, creature frame).
    atHome: new Float64Array(3),
    ahead: new Float64Array(3),
    local: new Float64Array(3),
    target: new Float64Array(3),
    airFrom: new Float64Array(3),
    airTo: new Float64Array(3),
    // ik.js: knee 0..2, foot 3..5, flags 6 (clamped), 7 (residual); rest and posed frames; the hinge.
    ik: new Float64Array(16),
    frames: new Float64Array(12),
    u3: new Float64Array(3),
    hinge1: new Float64Array(3),
    // ropes.js: the anchor (creature-local and world), the body point before it (world), a node and the
    // one before it (support-local), every node creature-local, and the parallel transport's frames.
    anchorLocal: new Float64Array(3),
    anchorWorld: new Float64Array(3),
    beforeWorld: new Float64Array(3),
    ropeLocal: new Float64Array(6),
    localNodes: new Float64Array(3 * Math.max(1, ...data.ropes.map((r) => r.rest.length))),
    e0: new Float64Array(3),
    e1: new Float64Array(3),
    q: new Float64Array(4),
  };
}

/** The gates at reset: every worst value 0, the apex squash 1, the fewest planted feet every leg. */
export function resetGates(st) {
  const gv = st.gates;
  gv.fill(0);
  gv[G.apexSquash] = 1;
  gv[G.fewestPlanted] = st.data.legs.length;
}

/** The gates as a plain object (allocates; the per-tick path writes the typed array only). */
export function readGates(st) {
  const out = {};
  for (const [name, index] of Object.entries(G)) out[name] = st.gates[index];
  return out;
}
