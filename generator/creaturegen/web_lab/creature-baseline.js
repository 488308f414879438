// The forbidden baseline of a creature package, for bench/runtime.py only (lab code: the shipped package
// never contains it). It is the design the seed rules out, built from the package's own exported TSL:
//
// * field: a masked full-budget unroll. Every slot's distance is computed at every evaluation (all P
//   slots, unrolled), and the vertex's candidate program only masks which of them enter the blend: its
//   tape runs over the precomputed distances, so the value equals the shipped field's;
// * normals and Newton steps: 6-tap central differences, i.e. six extra full evaluations per field query.
//
// The body path around it is the package's own: the deform pre-pass (createDeformKernel), skinning
// (createSkin), the bounded correction (createSkin's correctVertex, handed this field instead of the analytic
// one, so the trial logic and its depth are the same), bodyVertex, the material, the root transform. Per field query the
// baseline evaluates 7·P slot distances where the shipped path runs one K-instruction tape that carries
// distance and gradient together: the seed's ratio 7P/K at equal depth.
import {
  Fn, If, Loop, abs, array, clamp, exp, float, instanceIndex, int, log, max, min, select, sqrt, vec3, vec4,
} from 'three/tsl';

const dot3 = (u, v) => u.x.mul(v.x).add(u.y.mul(v.y)).add(u.z.mul(v.z));

/**
 * The baseline's field over one pose storage node: `distance(p, base, program)` (all P slots, masked by the
 * program's tape) and `runProgram(p, base, program)` = vec4(d, central-difference ∇d), the drop-in for the
 * shipped createField().runProgram. `step` is the central-difference half step (model units).
 */
export function createBaselineField(tsl, layout, pose, programs, step) {
  const { OP } = tsl;
  const rows = layout.rows;
  const P = layout.slotCount;

  // Distance only, the formulas of the package's field.js slotField (no gradient work).
  const slotDistance = (p, base, slot) => {
    const o = base.add(slot.mul(rows));
    const rowA = pose.element(o).toVar();
    const rowB = pose.element(o.add(1)).toVar();
    const roundCone = pose.element(o.add(4)).w;
    const a = rowA.xyz, ra = rowA.w, rb = rowB.w;
    const ba = rowB.xyz.sub(a).toVar();
    const len = sqrt(dot3(ba, ba)).toVar();
    const floorLen = max(float(layout.gradientFloor).mul(len.add(max(ra, rb))), float(layout.tiny));
    const degenerate = len.lessThanEqual(floorLen).toVar();
    const pa = p.sub(a).toVar();
    const lenSq = select(degenerate, float(1), dot3(ba, ba));
    const tRaw = select(degenerate, float(0), dot3(pa, ba).div(lenSq)).toVar();
    const safeLen = select(degenerate, float(1), len);
    const d = float(0).toVar();
    If(roundCone.greaterThan(0.5), () => {
      const dr = ra.sub(rb);
      const nested = abs(dr).greaterThanEqual(len).or(degenerate);
      const sn = select(nested, float(0), dr.div(safeLen)).toVar();
      const c = select(nested, float(1), sqrt(max(len.sub(dr).mul(len.add(dr)), 0)).div(safeLen)).toVar();
      const q = pa.sub(ba.mul(tRaw)).toVar();
      const x = sqrt(dot3(q, q)).toVar();
      const cl = c.mul(len);
      const capA = nested.not().and(cl.mul(tRaw).lessThan(sn.mul(x))).or(nested.and(ra.greaterThanEqual(rb)));
      const capB = nested.not().and(cl.mul(tRaw.sub(1)).greaterThan(sn.mul(x))).or(nested.and(ra.lessThan(rb)));
      const pb = pa.sub(ba);
      const sideD = sn.mul(tRaw.mul(len)).add(c.mul(x)).sub(ra);
      d.assign(select(capA, sqrt(dot3(pa, pa)).sub(ra), select(capB, sqrt(dot3(pb, pb)).sub(rb), sideD)));
    }).Else(() => {
      const t = clamp(tRaw, 0, 1);
      const q = pa.sub(ba.mul(t)).toVar();
      d.assign(sqrt(dot3(q, q)).sub(ra.add(rb.sub(ra).mul(t))));
    });
    return d;
  };

  // Every slot's distance (full budget), then the program's tape over them (distance-only blends).
  const distance = Fn(([p, base, program]) => {
    const all = array('float', P).toVar();
    Loop(P, ({ i }) => { all.element(i).assign(slotDistance(p, base, i)); });
    const header = programs.element(program);
    const offset = int(header.x).toVar();
    const count = int(header.y).toVar();
    const regs = array('float', layout.registers).toVar();
    const size = tsl.rootSize(layout, pose, base).toVar(); // the instance's size scales blend widths
    Loop(count, ({ i }) => {
      const ins = programs.element(offset.add(i)).toVar();
      const op = int(ins.x).toVar();
      const ia = int(ins.y), ib = int(ins.z), k = ins.w.mul(size);
      If(op.equal(OP.LEAF), () => {
        regs.element(i).assign(all.element(ia));
      }).ElseIf(op.equal(OP.POLY), () => {
        const l = regs.element(ia), r = regs.element(ib);
        const h = clamp(float(0.5).add(float(0.5).mul(l.sub(r)).div(k)), 0, 1).toVar();
        const omh = float(1).sub(h);
        regs.element(i).assign(l.mul(omh).add(r.mul(h)).sub(k.mul(h).mul(omh)));
      }).ElseIf(op.equal(OP.COPY), () => {
        regs.element(i).assign(regs.element(ia));
      }).ElseIf(op.equal(OP.LSE), () => {
        const m = regs.element(ia).toVar();
        Loop({ start: int(1), end: ib }, ({ i: j }) => { m.assign(min(m, regs.element(ia.add(j)))); });
        const total = float(0).toVar();
        Loop(ib, ({ i: j }) => { total.addAssign(exp(regs.element(ia.add(j)).sub(m).negate().div(k))); });
        regs.element(i).assign(m.sub(k.mul(log(total))));
      }).Else(() => {
        const l = regs.element(ia), r = regs.element(ib);
        regs.element(i).assign(select(r.lessThan(l), r, l));
      });
    });
    return regs.element(count.sub(1));
  }).setLayout({
    name: 'cgBaselineDistance',
    type: 'float',
    inputs: [{ name: 'p', type: 'vec3' }, { name: 'base', type: 'int' }, { name: 'program', type: 'int' }],
  });

  // One query: the distance plus six more full evaluations for the central-difference gradient. The seven
  // taps run in one loop with one call site, so the shader holds one copy of the unroll per query site.
  const runProgram = Fn(([p, base, program]) => {
    const d = float(0).toVar();
    const g = vec3(0).toVar();
    Loop(7, ({ i }) => {
      const axis = i.sub(1).div(2);
      const sign = select(i.mod(2).equal(1), float(1), float(-1));
      const unit = select(axis.equal(0), vec3(1, 0, 0), select(axis.equal(1), vec3(0, 1, 0), vec3(0, 0, 1)));
      const e = select(i.equal(0), vec3(0), unit.mul(sign.mul(step)));
      const tap = distance(p.add(e), base, program).toVar();
      If(i.equal(0), () => { d.assign(tap); }).Else(() => { g.addAssign(unit.mul(sign.mul(tap).div(2 * step))); });
    });
    return vec4(d, g);
  });

  return { distance, runProgram };
}

/**
 * The baseline's field and skin builders over one pose page: the shipped skin and correction logic over the
 * baseline field, whose `evaluate` (the final per-vertex evaluation: distance and normal) is the masked
 * full-budget unroll with central differences too. The baseline skips the albedo blend (a constant grey),
 * which only makes it cheaper: the measured ratio understates the shipped path's advantage.
 */
export function baselineFunctions(tsl, layout, pose, programs, step) {
  const shipped = tsl.bodyFunctions(layout, pose, programs);
  const baseline = createBaselineField(tsl, layout, pose, programs, step);
  const evaluate = (p, base, program, { colour = false } = {}) => ({
    value: baseline.runProgram(p, base, program).toVar(),
    colour: colour ? vec3(0.6) : null,
  });
  const field = { ...shipped.field, evaluate, runProgram: baseline.runProgram, distance: baseline.distance };
  const skin = tsl.createSkin({ pose, rows: layout.rows, field, correction: layout.correction });
  return { field, skin, shipped };
}

/**
 * The baseline deform pre-pass of one page: the package's own createDeformKernel (same dispatches, same
 * storage, same material reading it) over the baseline functions. Swapping `page.kernel` between this and
 * the shipped kernel changes nothing but the field path. Each vertex path's kernel gets baseline functions
 * of its own: the distance function has a WGSL layout (cgBaselineDistance), and with one such function
 * node shared by two compute nodes of a page the second kernel's shader failed to compile here ("unresolved
 * value NodeBuffer_…", three r185 on SwiftShader).
 */
export function createBaselineKernel(tsl, layout, page, records, order, programs, step) {
  const kernels = order.segments.flatMap((segment) => tsl.createDeformKernel(layout, baselineFunctions(tsl, layout, page.pose, programs, step), {
    pose: page.pose, records, order: { order: order.order, segments: [segment] }, deform: page.deform, list: page.list, size: page.size,
    vertices: layout.vertices,
  }).kernels);
  return { kernels, list: page.list, vertices: layout.vertices, size: page.size };
}

/**
 * The plain-LBS baseline of one page: what a three.js SkinnedMesh (or an instanced skinned mesh) does with
 * the same mesh. Every vertex of the listed bodies is skinned by linear blend skinning alone (the
 * package's createSkin lbs), its normal by the cofactor of the blended matrix (lbsNormal) and its colour
 * blended from its four influences' slot colours (bakedColour); no correction, no field evaluation. It
 * writes the page's own deform storage through the page's own instance list, so the material, the root
 * transform, the uploads and the draws are the shipped ones: only the body path differs.
 */
export function createLbsKernel(tsl, layout, page, records, programs) {
  const fns = tsl.bodyFunctions(layout, page.pose, programs);
  const vertices = layout.vertices;
  const rowsPerInstance = layout.maxParts * layout.rows;
  const kernel = Fn(() => {
    const entry = int(instanceIndex).div(vertices).toVar();
    const v = int(instanceIndex).sub(entry.mul(vertices)).toVar();
    const j = page.list.element(entry).toVar();
    const base = j.mul(rowsPerInstance).toVar();
    const alive = page.pose.element(base.add(layout.slotCount * layout.rows)).w;
    If(alive.greaterThan(0.5), () => {
      const r = tsl.recordInputs(records, v);
      const s = fns.field.size(base).toVar();
      const position = fns.skin.lbs(r.rest.mul(s), base, r.slots, r.weights);
      const normal = fns.skin.lbsNormal(r.normal, base, r.slots, r.weights);
      const colour = fns.field.bakedColour(base, r.slots, r.weights);
      const o = j.mul(vertices).add(v).mul(tsl.DEFORM_STRIDE).toVar();
      page.deform.element(o).assign(vec4(position, 0));
      page.deform.element(o.add(1)).assign(vec4(normal, 0));
      page.deform.element(o.add(2)).assign(vec4(colour, float(layout.skinProgram)));
    });
  })().compute(page.size * vertices);
  kernel.setName('cgDeformPlainLbs');
  return { kernels: [{ kernel, count: vertices }], list: page.list, vertices, size: page.size };
}
