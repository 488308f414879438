// The body field in TSL: the same formulas, in the same order, as creaturegen's numpy reference
// (field/primitives.py, field/blend.py, field/sampler.py). Distances and *unnormalised* gradients are
// carried together (vec4: d, ∇d), so normals come from the analytic gradient of the very loop that
// measures the distance: no finite differences.
//
// A program is a tape (creature/tape.py): instruction i = (op, a, b, k) writes register i, the LEAF
// instructions first. Two dynamic loops bounded by the program's own counts run it, the leaves (the slot
// formula alone) and then the blends (never the slot formula: a lane runs every branch of an `if` it
// cannot skip, and SwiftShader masks rather than skips), so every candidate region shares one pipeline
// and no vertex pays for slots outside its program.
import {
  Break, Fn, If, Loop, abs, array, clamp, exp, float, int, log, max, min, select, sqrt, vec3, vec4,
} from 'three/tsl';

export const OP = Object.freeze({ LEAF: 0, POLY: 1, COPY: 2, LSE: 3, MIN: 4 });

// Three explicit products summed left to right, as the reference sampler (field/primitives.py) writes its dot products.
const dot3 = (u, v) => u.x.mul(v.x).add(u.y.mul(v.y)).add(u.z.mul(v.z));

// The reference's helper axis (field/primitives.py): the coordinate axis least aligned with `axis`
// (lowest index on ties), its axial part removed, normalised.
function perpendicular(axis) {
  const ax = abs(axis.x), ay = abs(axis.y), az = abs(axis.z);
  const useX = ax.lessThanEqual(ay).and(ax.lessThanEqual(az));
  const useY = useX.not().and(ay.lessThanEqual(az));
  const basis = select(useX, vec3(1, 0, 0), select(useY, vec3(0, 1, 0), vec3(0, 0, 1)));
  const v = basis.sub(axis.mul(dot3(basis, axis)));
  return v.div(sqrt(dot3(v, v)));
}

/**
 * The field nodes of one pose layout. `pose` is a vec4 storage node holding `rows` vec4 per slot:
 * (a, ra), (b, rb), (k, rgb), quaternion, (t, roundCone). `programs` is a vec4 storage node: program
 * headers (offset, count, leaves, 0) first, then instructions, leaves leading. `registers` bounds the register file (K).
 */
/** The size of the instance whose rows start at `base`: root row 1 .w (core/pose.js writeRootRows). */
export function rootSize({ slotCount, rows }, pose, base) {
  return pose.element(base.add(slotCount * rows + 1)).w;
}

export function createField({ pose, programs, rows, slotCount, registers, gradientFloor, tiny }) {
  if (!Number.isInteger(slotCount) || slotCount < 1) throw new Error(`createField: slotCount must be a positive integer (got ${slotCount})`);
  // The reference's segment frame and both distance forms (field/primitives.py primitive_field), with
  // their gradients. Returns vec4(d, ∇d).
  const slotField = (p, base, slot) => {
    const o = base.add(slot.mul(rows));
    const rowA = pose.element(o).toVar();
    const rowB = pose.element(o.add(1)).toVar();
    const roundCone = pose.element(o.add(4)).w;
    const a = rowA.xyz, ra = rowA.w, rb = rowB.w;
    const ba = rowB.xyz.sub(a).toVar();
    const len = sqrt(dot3(ba, ba)).toVar();
    const scale = len.add(max(ra, rb));
    const floorLen = max(float(gradientFloor).mul(scale), float(tiny)).toVar();
    const degenerate = len.lessThanEqual(floorLen).toVar();
    const pa = p.sub(a).toVar();
    const lenSq = select(degenerate, float(1), dot3(ba, ba));
    const tRaw = select(degenerate, float(0), dot3(pa, ba).div(lenSq)).toVar();
    const safeLen = select(degenerate, float(1), len);
    const axis = select(degenerate, vec3(0, 0, 1), ba.div(safeLen)).toVar();
    const perp = perpendicular(axis).toVar();
    const result = vec4(0).toVar();
    If(roundCone.greaterThan(0.5), () => {
      // The round-cone form of primitive_field (field/primitives.py).
      const dr = ra.sub(rb);
      const nested = abs(dr).greaterThanEqual(len).or(degenerate);
      const sn = select(nested, float(0), dr.div(safeLen)).toVar();
      const c = select(nested, float(1), sqrt(max(len.sub(dr).mul(len.add(dr)), 0)).div(safeLen)).toVar();
      const q = pa.sub(ba.mul(tRaw)).toVar();
      const x = sqrt(dot3(q, q)).toVar();
      const cl = c.mul(len);
      const capA = nested.not().and(cl.mul(tRaw).lessThan(sn.mul(x))).or(nested.and(ra.greaterThanEqual(rb))).toVar();
      const capB = nested.not().and(cl.mul(tRaw.sub(1)).greaterThan(sn.mul(x))).or(nested.and(ra.lessThan(rb))).toVar();
      const pb = pa.sub(ba).toVar();
      const paLen = sqrt(dot3(pa, pa));
      const pbLen = sqrt(dot3(pb, pb));
      const sideD = sn.mul(tRaw.mul(len)).add(c.mul(x)).sub(ra);
      const d = select(capA, paLen.sub(ra), select(capB, pbLen.sub(rb), sideD));
      const gA = select(paLen.lessThanEqual(floorLen), axis.negate(), pa.div(select(paLen.lessThanEqual(floorLen), float(1), paLen)));
      const gB = select(pbLen.lessThanEqual(floorLen), axis, pb.div(select(pbLen.lessThanEqual(floorLen), float(1), pbLen)));
      const qHat = select(x.lessThanEqual(floorLen), perp, q.div(select(x.lessThanEqual(floorLen), float(1), x)));
      const gSide = qHat.mul(c).add(axis.mul(sn));
      result.assign(vec4(d, select(capA, gA, select(capB, gB, gSide))));
    }).Else(() => {
      // The tapered-capsule form of primitive_field (field/primitives.py).
      const t = clamp(tRaw, 0, 1);
      const q = pa.sub(ba.mul(t)).toVar();
      const x = sqrt(dot3(q, q)).toVar();
      const d = x.sub(ra.add(rb.sub(ra).mul(t)));
      const below = tRaw.lessThan(0), above = tRaw.greaterThan(1);
      const fallback = select(below, axis.negate(), select(above, axis, perp));
      const short = x.lessThanEqual(floorLen);
      const qHat = select(short, fallback, q.div(select(short, float(1), x)));
      const slope = select(degenerate, float(0), rb.sub(ra).div(safeLen));
      const interior = below.or(above).not();
      const g = qHat.sub(axis.mul(select(interior, slope, float(0))));
      result.assign(vec4(d, g));
    });
    return result;
  };

  // A slot's colour row: (k, rgb), rgb the individual's linear slot colour (core/pose.js).
  const colourRow = (base, slot) => pose.element(base.add(slot.mul(rows)).add(2));

  // blend.poly_smin: h from the distances, gradient mixed with the same h (exact).
  const poly = (l, r, k) => {
    const h = clamp(float(0.5).add(float(0.5).mul(l.x.sub(r.x)).div(k)), 0, 1).toVar();
    const omh = float(1).sub(h);
    const d = l.x.mul(omh).add(r.x.mul(h)).sub(k.mul(h).mul(omh));
    return vec4(d, l.yzw.mul(omh).add(r.yzw.mul(h)));
  };

  /**
   * Run program `program` at point `p` for the instance whose pose rows start at `base`, inline (call it
   * inside a Fn). Returns { value: vec4(d, ∇d), colour }: with `colour`, field/colour.proximity_colour
   * over the program's leaves, read from the leaf registers this run already filled (linear RGB).
   */
  const evaluate = (p, base, program, { colour = false, kFloor = 0 } = {}) => {
    // The instance's size (root row 1 .w): blend widths scale with the body (the slot rows already do).
    const size = rootSize({ slotCount, rows }, pose, base).toVar();
    const header = programs.element(program);
    const offset = int(header.x).toVar();
    const count = int(header.y).toVar();
    const leaves = int(header.z).toVar();
    const regs = array('vec4', registers).toVar();
    Loop(leaves, ({ i }) => {
      regs.element(i).assign(slotField(p, base, int(programs.element(offset.add(i)).y)));
    });
    Loop({ start: leaves, end: count }, ({ i }) => {
      const ins = programs.element(offset.add(i)).toVar();
      const op = int(ins.x).toVar();
      const ia = int(ins.y), ib = int(ins.z), k = ins.w.mul(size);
      If(op.equal(OP.POLY), () => {
        regs.element(i).assign(poly(regs.element(ia), regs.element(ib), k));
      }).ElseIf(op.equal(OP.COPY), () => {
        regs.element(i).assign(regs.element(ia));
      }).ElseIf(op.equal(OP.LSE), () => {
        // blend.lse_smin: shift by the minimum, terms summed left to right, softmax-weighted gradient.
        const m = regs.element(ia).x.toVar();
        Loop({ start: int(1), end: ib }, ({ i: j }) => { m.assign(min(m, regs.element(ia.add(j)).x)); });
        const total = float(0).toVar();
        Loop(ib, ({ i: j }) => { total.addAssign(exp(regs.element(ia.add(j)).x.sub(m).negate().div(k))); });
        const g = vec3(0).toVar();
        Loop(ib, ({ i: j }) => {
          const r = regs.element(ia.add(j));
          g.addAssign(r.yzw.mul(exp(r.x.sub(m).negate().div(k)).div(total)));
        });
        regs.element(i).assign(vec4(m.sub(k.mul(log(total))), g));
      }).Else(() => {
        // blend.hard_min: the right operand wins only when strictly smaller.
        const l = regs.element(ia), r = regs.element(ib);
        regs.element(i).assign(select(r.x.lessThan(l.x), r, l));
      });
    });
    const value = regs.element(count.sub(1)).toVar();
    if (!colour) return { value, colour: null };
    const dMin = float(3.4e38).toVar();
    Loop(leaves, ({ i }) => { dMin.assign(min(dMin, regs.element(i).x)); });
    const sum = float(0).toVar();
    const rgb = vec3(0).toVar();
    Loop(leaves, ({ i }) => {
      const row = colourRow(base, int(programs.element(offset.add(i)).y));
      const w = exp(max(regs.element(i).x.sub(dMin), 0).negate().div(max(row.x, size.mul(kFloor))));
      sum.addAssign(w);
      rgb.addAssign(row.yzw.mul(w));
    });
    return { value, colour: rgb.div(sum) };
  };

  /**
   * The baked colour of a vertex that evaluates no field: Σ wᵢ·rgb(slotᵢ) / Σ wᵢ over its four baked
   * colour slots and weights (vec4 each), rgb the individual's slot colour, the row the colour kernel
   * above reads (linear RGB).
   */
  const bakedColour = (base, slots, weights) => {
    const rgb = vec3(0).toVar();
    const sum = float(0).toVar();
    for (let c = 0; c < 4; c++) {
      const w = weights.element(c);
      rgb.addAssign(colourRow(base, int(slots.element(c))).yzw.mul(w));
      sum.addAssign(w);
    }
    return rgb.div(sum);
  };

  /** vec4(d, ∇d) of program `program` at `p` (evaluate without the colour). */
  const runProgram = Fn(([p, base, program]) => evaluate(p, base, program).value);

  /** The instance's size (the body path scales its rest vertex, centre of rotation and trust radius). */
  const size = (base) => rootSize({ slotCount, rows }, pose, base);

  return { slotField, evaluate, runProgram, size, bakedColour };
}


