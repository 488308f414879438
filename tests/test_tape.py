"""The program tape the runtime interprets: leaves first, and the same values as the reference graph.

The TSL interpreter (templates/creature/tsl/field.js) runs a tape's LEAF instructions in one loop and its
blends in a second, trusting the layout compile_tape promises. This interprets the tape in numpy with
the reference's own blend formulas and compares it with ``evaluate_graph`` bit for bit, so a tape whose
reordering renumbered an operand wrongly fails here before any browser runs.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import CREATURE_EXAMPLES, spec_file
from creaturegen.creature.plan import program_data
from creaturegen.creature.tape import COPY, LEAF, LSE, MIN, POLY, Tape, compile_tape
from creaturegen.field.blend import hard_min, lse_smin, poly_smin
from creaturegen.field.primitives import primitive_field
from creaturegen.field.sampler import evaluate_graph
from creaturegen.model.graph import BlendGraph, BlendOp, Ref
from creaturegen.rig import compile_rig
from creaturegen.spec import load_spec

Array = np.ndarray


def run_tape(tape: Tape, d_slots: Array, g_slots: Array) -> tuple[Array, Array]:
    """The tape instruction by instruction, as field.js runs it, with field/blend.py's formulas."""
    regs: list[tuple[Array, Array]] = []
    for op, a, b, k in tape.instructions:
        if op == LEAF:
            regs.append((d_slots[a], g_slots[a]))
        elif op == POLY:
            (dl, gl), (dr, gr) = regs[a], regs[b]
            d, g, _ = poly_smin(dl, gl, dr, gr, k)
            regs.append((d, g))
        elif op == COPY:
            regs.append(regs[a])
        elif op == LSE:
            members = regs[a : a + b]
            d, g, _ = lse_smin(np.stack([m[0] for m in members]), np.stack([m[1] for m in members]), k)
            regs.append((d, g))
        else:
            assert op == MIN
            d, g, _ = hard_min(np.stack([regs[a][0], regs[b][0]]), np.stack([regs[a][1], regs[b][1]]))
            regs.append((d, g))
    return regs[-1]


def assert_leaves_first(tape: Tape) -> None:
    """LEAF instructions lead, every operand names an earlier register, an LSE reads its copies."""
    ops = [ins[0] for ins in tape.instructions]
    leaves = tape.leaf_count
    assert ops[:leaves] == [LEAF] * leaves
    assert LEAF not in ops[leaves:]
    assert tuple(ins[1] for ins in tape.instructions[:leaves]) == tape.leaves
    for i, (op, a, b, _) in enumerate(tape.instructions):
        if op in (POLY, MIN):
            assert a < i
            assert b < i
        elif op == COPY:
            assert a < i
        elif op == LSE:
            assert a + b == i
            assert all(ins[0] == COPY for ins in tape.instructions[a:i])


@pytest.mark.parametrize("name", CREATURE_EXAMPLES)
def test_tape_runs_leaves_first_to_the_reference_values(name: str) -> None:
    rig = compile_rig(load_spec(spec_file(name)))
    tape = compile_tape(rig.graph)
    assert_leaves_first(tape)
    points = np.random.default_rng(7).uniform(-1.0, 1.0, (512, 3)) * rig.body_scale
    d_slots, g_slots = primitive_field(rig.slots, points)
    d_ref, g_ref = evaluate_graph(rig.graph, d_slots, g_slots)
    d_tape, g_tape = run_tape(tape, d_slots, g_slots)
    np.testing.assert_array_equal(d_tape, d_ref)
    np.testing.assert_array_equal(g_tape, g_ref)


def test_an_interleaved_graph_is_reordered_and_renumbered() -> None:
    # min(poly(s0, s1), lse(s2, poly(s0, s1), s3)): leaves are met between blends in graph order.
    graph = BlendGraph(
        (
            BlendOp("poly", (Ref("slot", 0), Ref("slot", 1)), 0.1, "blend.nodes[a]"),
            BlendOp("lse", (Ref("slot", 2), Ref("op", 0), Ref("slot", 3)), 0.2, "blend.nodes[b]"),
        ),
        (Ref("op", 0), Ref("op", 1)),
    )
    tape = compile_tape(graph)
    assert_leaves_first(tape)
    assert tape.leaves == (0, 1, 2, 3)
    rng = np.random.default_rng(3)
    d_slots, g_slots = rng.normal(size=(4, 64)), rng.normal(size=(4, 64, 3))
    d_ref, g_ref = evaluate_graph(graph, d_slots, g_slots)
    d_tape, g_tape = run_tape(tape, d_slots, g_slots)
    np.testing.assert_array_equal(d_tape, d_ref)
    np.testing.assert_array_equal(g_tape, g_ref)
    # The runtime's header carries the leaf count beside the offset and the length.
    assert program_data([tape])[:4] == [1.0, float(len(tape)), 4.0, 0.0]
