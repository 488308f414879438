// Skinning the reference mesh from the pose page, and the bounded local correction: the formulas of
// creaturegen's surface/skinning.py (LBS, dual quaternion, centre of rotation; the method per vertex is
// its joint's choice, baked into the asset) and of creature/reference.py (the per-vertex correction).
import { Fn, If, Loop, Break, abs, float, int, normalize, select, sqrt, vec3, vec4 } from 'three/tsl';

const dot3 = (u, v) => u.x.mul(v.x).add(u.y.mul(v.y)).add(u.z.mul(v.z));
const dot4 = (u, v) => u.x.mul(v.x).add(u.y.mul(v.y)).add(u.z.mul(v.z)).add(u.w.mul(v.w));

// R(q)·v by v + 2w(u×v) + 2u×(u×v), quaternions xyzw (the JS core's formula).
export function rotate(q, v) {
  const c = q.xyz.cross(v);
  return v.add(c.mul(q.w).add(q.xyz.cross(c)).mul(2));
}

// a ⊗ b, xyzw.
function qmul(a, b) {
  return vec4(
    a.w.mul(b.x).add(a.x.mul(b.w)).add(a.y.mul(b.z)).sub(a.z.mul(b.y)),
    a.w.mul(b.y).sub(a.x.mul(b.z)).add(a.y.mul(b.w)).add(a.z.mul(b.x)),
    a.w.mul(b.z).add(a.x.mul(b.y)).sub(a.y.mul(b.x)).add(a.z.mul(b.w)),
    a.w.mul(b.w).sub(a.x.mul(b.x)).sub(a.y.mul(b.y)).sub(a.z.mul(b.z)),
  );
}

export const METHOD = Object.freeze({ LBS: 0, DQ: 1, COR: 2 });

/**
 * Skinning and correction over one pose layout. `field` is createField's result; `correction` holds
 * { budget, earlyOut, gradientFloor }.
 */
export function createSkin({ pose, rows, field, correction }) {
  const quat = (base, s) => pose.element(base.add(s.mul(rows)).add(3));
  const shift = (base, s) => pose.element(base.add(s.mul(rows)).add(4)).xyz;

  // LBS, as the reference's skin_lbs (surface/skinning.py): v + Σ wᵢ((Rᵢ − I)v + tᵢ), which returns the rest vertex bit for bit at rest.
  const lbs = (v, base, slots, weights) => {
    const acc = vec3(0).toVar();
    for (let c = 0; c < 4; c++) {
      const s = int(slots.element(c));
      const w = weights.element(c);
      acc.addAssign(rotate(quat(base, s), v).sub(v).add(shift(base, s)).mul(w));
    }
    return v.add(acc);
  };

  // The hemisphere-aligned blend of the influences' rotations (real) and, for DQ, of their dual parts: the
  // dominant influence (largest weight, first on ties) sets every influence's hemisphere sign.
  const blendQuats = (base, slots, weights) => {
    const dom = int(slots.x).toVar();
    const best = weights.x.toVar();
    for (let c = 1; c < 4; c++) {
      If(weights.element(c).greaterThan(best), () => { best.assign(weights.element(c)); dom.assign(int(slots.element(c))); });
    }
    const ref = quat(base, dom).toVar();
    const real = vec4(0).toVar();
    const dual = vec4(0).toVar();
    for (let c = 0; c < 4; c++) {
      const s = int(slots.element(c));
      const q = quat(base, s).toVar();
      const sw = select(dot4(q, ref).lessThan(0), weights.element(c).negate(), weights.element(c));
      real.addAssign(q.mul(sw));
      dual.addAssign(qmul(vec4(shift(base, s), 0), q).mul(sw.mul(0.5)));
    }
    return { real, dual };
  };

  // DQ, as the reference's skin_dq: the normalised blended dual quaternion (real part br, dual part bd) applied to v.
  const dqApply = ({ br, bd }, v) => {
    const conj = vec4(br.xyz.negate(), br.w);
    const translation = qmul(bd, conj).xyz.mul(2);
    return rotate(br, v).add(translation);
  };

  // deform.skin_lbs's normal: cofactor(M)·n = det(M)·M⁻ᵀn, M = Σ wᵢRᵢ by its columns cₖ = Σ wᵢRᵢeₖ, so
  // n₀(c₁×c₂) + n₁(c₂×c₀) + n₂(c₀×c₁), normalised.
  const lbsNormal = (n, base, slots, weights) => {
    const c0 = vec3(0).toVar(), c1 = vec3(0).toVar(), c2 = vec3(0).toVar();
    for (let c = 0; c < 4; c++) {
      const q = quat(base, int(slots.element(c))).toVar();
      const w = weights.element(c);
      c0.addAssign(rotate(q, vec3(1, 0, 0)).mul(w));
      c1.addAssign(rotate(q, vec3(0, 1, 0)).mul(w));
      c2.addAssign(rotate(q, vec3(0, 0, 1)).mul(w));
    }
    return normalize(c1.cross(c2).mul(n.x).add(c2.cross(c0).mul(n.y)).add(c0.cross(c1).mul(n.z)));
  };
  // deform.skin_dq / skin_cor's normal: the blended (normalised) rotation of the position's own blend.
  const rotatedNormal = (br, n) => normalize(rotate(br, n));

  // Every method's position from one blend of the influences: LBS at the vertex (LBS) or at its centre of
  // rotation (CoR's translation), one hemisphere-aligned quaternion blend (DQ's real and dual parts, CoR's
  // rotation), each formula's own operations in its own order: skin_lbs, skin_dq and skin_cor
  // (surface/skinning.py), CoR as v' = R(v − p*) + LBS(p*). One pass instead of three: a lane group runs
  // every method any of its lanes uses, and SwiftShader every branch of an `if`, so three branches cost
  // three blends for each vertex.
  const skinMethods = (v, base, slots, weights, method, centre) => {
    const isLbs = method.lessThan(0.5).toVar();
    const isDq = method.lessThan(1.5).toVar();
    const linear = lbs(select(isLbs, v, centre), base, slots, weights).toVar();
    const { real, dual } = blendQuats(base, slots, weights);
    const norm = sqrt(dot4(real, real));
    const br = real.div(norm).toVar();
    const viaDq = dqApply({ br, bd: dual.div(norm) }, v);
    const viaCor = rotate(br, v.sub(centre)).add(linear);
    return { isLbs, isDq, br, position: select(isLbs, linear, select(isDq, viaDq, viaCor)) };
  };

  /** The skinned (uncorrected) position of one vertex; `method` is its joint's choice (0, 1, 2). */
  const skinVertex = Fn(([v, base, slots, weights, method, centre]) => skinMethods(v, base, slots, weights, method, centre).position);

  /**
   * The skinned position and the skinned rest normal `n` of one vertex (a vertex that evaluates no field),
   * each method's normal from the same blend its position uses (skinning.py skin_lbs, skin_dq, skin_cor).
   * Inline (call it inside a Fn): returns { position, normal } nodes.
   */
  const skinVertexNormal = (v, n, base, slots, weights, method, centre) => {
    const body = skinMethods(v, base, slots, weights, method, centre);
    const position = body.position.toVar();
    const normal = select(body.isLbs, lbsNormal(n, base, slots, weights), rotatedNormal(body.br, n)).toVar();
    return { position, normal };
  };

  /**
   * Bounded Newton correction toward the zero set: Δp = −(d/|∇d|²)∇d clamped to the vertex's trust
   * radius, halved on a failed trial, at most `budget` trials; the result is kept only if it improved
   * |d| and its field normal still faces the skinned one (the per-vertex inversion proxy). Only vertices
   * with a positive trust radius (the build's region policy) run it. Inline (call it inside a Fn):
   * returns { position, accepted } nodes.
   */
  const correctVertex = (p0, base, program, trust) => {
    const out = p0.toVar();
    const accepted = float(0).toVar();
    If(trust.greaterThan(0), () => {
      const r0 = field.runProgram(p0, base, program).toVar();
      const p = p0.toVar();
      const d = r0.x.toVar();
      const g = r0.yzw.toVar();
      const gg = dot3(g, g).toVar();
      If(gg.greaterThanEqual(correction.gradientFloor), () => {
        const start = abs(d).toVar();
        const scale = float(1).toVar();
        const step = vec3(0).toVar();
        Loop(int(correction.budget), () => {
          If(abs(d).lessThanEqual(trust.mul(correction.earlyOut)), () => { Break(); });
          If(scale.equal(1), () => {
            const s = g.mul(d.div(gg).negate()).toVar();
            const len = sqrt(dot3(s, s));
            If(len.greaterThan(trust), () => { s.mulAssign(trust.div(len)); });
            step.assign(s);
          });
          const trial = p.add(step.mul(scale)).toVar();
          const rt = field.runProgram(trial, base, program).toVar();
          If(abs(rt.x).lessThan(abs(d)), () => {
            p.assign(trial); d.assign(rt.x); g.assign(rt.yzw); gg.assign(dot3(g, g)); scale.assign(1);
            If(gg.lessThan(correction.gradientFloor), () => { Break(); });
          }).Else(() => { scale.mulAssign(0.5); });
        });
        const improved = abs(d).lessThan(start).or(abs(d).lessThanEqual(trust.mul(correction.earlyOut)));
        const facing = dot3(g, r0.yzw).greaterThan(0);
        If(improved.and(facing), () => { accepted.assign(1); out.assign(p); });
      });
    });
    return { position: out, accepted };
  };

  return { skinVertex, skinVertexNormal, correctVertex, lbs, lbsNormal };
}

