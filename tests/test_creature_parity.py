"""Creature parity through Playwright: every buildable example package on WebGPU (SwiftShader) against the
numpy and locomotion references, with every gate of creaturegen.lab.creature_parity; plus proofs that the
job catches a wrong GPU field formula, a shadow pass that does not use the deformed position, a pre-pass
that skips the correction and a population that uploads a stale pose. Fails (never skips)
when the browser or node_modules is missing.

Every gate runs on every example, the spawn burst's frame included. The deform pre-pass runs each body's
vertex path once per tick in software, so that frame's cost grows with the bodies in it (hence a burst
of one page plus one body, creature_population.PAGE_SIZE).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from conftest import PARITY_EXAMPLES, TEST_FULL, build_example
from creaturegen.lab.creature_parity import GATE_GROUPS, run_creature_parity
from creaturegen.lab.creature_population import PAGE_SIZE, SPAWNS


@pytest.fixture
def out_root(creature_out: Path) -> Path:
    return creature_out


def build(name: str, out_root: Path) -> Path:
    return build_example(name, out_root)


def _subset(cases: list[Any], ids: list[str], keep: set[str]) -> list[Any]:
    """Planted variants by id: `make test` runs those in ``keep`` (each gate group's other variant plants a
    second defect in the same gates), `make test-full` every one."""
    return [pytest.param(*case, id=i) for case, i in zip(cases, ids, strict=True) if TEST_FULL or i in keep]


#: The genetics grid (64 individuals deformed and each re-simulated in Python) runs on the hopper, the
#: cheapest body; the others skip it to keep `make test` short (`seconds.grid` in each report says what
#: it costs; `creaturegen parity` runs it everywhere).
GRID_EXAMPLES = ("reference/hopper.json",)


#: The hopper's whole job runs in `make test` on its two-tier package (test_creature_tiers: every group reads
#: the finest tier, which is this package's hero body), so the hero-only package runs it in test-full alone.
TWO_TIER_EXAMPLE = "reference/hopper.json"


@pytest.mark.browser
@pytest.mark.parametrize("name", [n for n in PARITY_EXAMPLES if TEST_FULL or n != TWO_TIER_EXAMPLE])
def test_every_example_passes_every_parity_gate(name: str, out_root: Path) -> None:
    package = build(name, out_root)
    assert_every_gate(package, name)


def assert_every_gate(package: Path, name: str) -> None:
    """The whole parity job (the grid only on GRID_EXAMPLES) passes and wrote what it measured."""
    groups = GATE_GROUPS if name in GRID_EXAMPLES else tuple(g for g in GATE_GROUPS if g != "grid")
    report = run_creature_parity(package, groups=groups)
    assert report.passed, report.summary()
    written = json.loads((package / "parity" / "report.json").read_text())
    assert written["status"] == "pass"
    names = {g["name"] for g in written["gates"]}
    for expected in (
        "GPU validation errors",
        "GPU-skinned vertices vs numpy",
        "silhouette vs shadow footprint",
        "drawn vertices (deform storage) vs the GPU body path",
        f"pipelines created by {SPAWNS} spawns after reveal",
        f"pose pages in use after {SPAWNS} spawns of pageSize {PAGE_SIZE}",
        "pose rows (slots and root): GPU vs the Python locomotion reference",
        "planted feet in the GPU pose buffer vs their plant points",
        "debug shell on the pose rows: GPU vs numpy",
    ):
        assert expected in names
    assert written["measurements"]["field"]["points"] >= 4096
    assert (package / "parity" / "front.png").stat().st_size > 1000
    if name in GRID_EXAMPLES:
        assert "genome colours of 64 individuals: GPU pose rows vs Python (OKLab mutation)" in names
        grid = written["measurements"]["grid"]
        print(f"{name} grid: {grid}")
        low, high = grid["speedRatio"]
        # Paces above 1 are capped where the step length sits at its reach limit (the lizard's does).
        assert high - low > 0.05, f"{name}: the grid's speeds {grid['speedRatio']} hardly vary"
        small, large = grid["size"]
        assert large - small > 0.05, f"{name}: the grid's sizes {grid['size']} hardly vary"
        assert (package / "parity" / "grid.png").stat().st_size > 1000


@pytest.mark.browser
def test_a_lower_tier_package_passes_every_parity_gate(out_root: Path) -> None:
    """The skin representation (surface/skin_tier.py): skin vertices are checked against numpy's skinned
    normals and baked colours, field vertices as at the hero tier."""
    package = build_example("reference/hopper.json", out_root, "distant")
    report = run_creature_parity(package, groups=tuple(g for g in GATE_GROUPS if g != "grid"))
    assert report.passed, report.summary()
    written = json.loads((package / "parity" / "report.json").read_text())
    names = {g["name"] for g in written["gates"]}
    assert "drawn normal of skin-program vertices vs numpy skinned normal" in names
    assert "drawn colour of skin-program vertices vs numpy baked colour" in names
    counts = written["measurements"]["skinProgram"]
    print(f"distant hopper: {counts}")
    assert counts["vertices"] > counts["fieldVertices"] > 0


@pytest.mark.browser
@pytest.mark.parametrize(
    ("swap", "gate"),
    [
        (
            ("rotatedNormal(body.br, n)).toVar();", "n).toVar();"),
            "drawn normal of skin-program vertices vs numpy skinned normal",
        ),
        (
            ("c1.cross(c2).mul(n.x)", "c2.cross(c1).mul(n.x)"),
            "drawn normal of skin-program vertices vs numpy skinned normal",
        ),
    ],
)
def test_the_job_catches_a_wrong_skin_normal(
    out_root: Path, tmp_path: Path, swap: tuple[str, str], gate: str
) -> None:
    """An unrotated DQ/CoR normal and an LBS cofactor out of order, in the shipped skin.js."""
    package = build_example("reference/hopper.json", out_root, "distant")
    planted = _planted(package, tmp_path, "skin.js", [swap])
    report = run_creature_parity(planted, groups=("skin",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert gate in failed, report.summary()


@pytest.mark.browser
def test_the_job_catches_a_baked_colour_that_drops_a_leaf(out_root: Path, tmp_path: Path) -> None:
    package = build_example("reference/hopper.json", out_root, "distant")
    swap = (
        "for (let c = 0; c < 4; c++) {\n      const w = weights",
        "for (let c = 0; c < 3; c++) {\n      const w = weights",
    )
    failed, summary = _failures(package, tmp_path, "field.js", [swap], ("skin",))
    assert "drawn colour of skin-program vertices vs numpy baked colour" in failed, summary


def _failures(
    package: Path, tmp_path: Path, file: str, swaps: list[tuple[str, str]], groups: tuple[str, ...]
) -> tuple[set[str], str]:
    """The gates the job fails on a planted copy of ``package`` (see ``_planted``), and its summary."""
    report = run_creature_parity(_planted(package, tmp_path, file, swaps), groups=groups)
    return {g["name"] for g in report.gates if g["status"] == "fail"}, report.summary()


def _planted(package: Path, tmp_path: Path, file: str, swaps: list[tuple[str, str]]) -> Path:
    """A copy of the package with a wrong GPU formula (the Python reference is untouched)."""
    return _planted_files(package, tmp_path, {file: swaps})


def _planted_files(package: Path, tmp_path: Path, plants: dict[str, list[tuple[str, str]]]) -> Path:
    """``_planted`` over several files of ``tsl/`` (a defect that spans modules)."""
    copy = tmp_path / package.name
    shutil.copytree(package, copy)
    for file, swaps in plants.items():
        path = copy / "tsl" / file
        text = path.read_text()
        for old, new in swaps:
            assert old in text, f"the planted error no longer applies: {old!r} not in {file}"
            text = text.replace(old, new)
        path.write_text(text)
    return copy


@pytest.mark.browser
def test_the_job_catches_a_field_formula_without_the_taper_term(out_root: Path, tmp_path: Path) -> None:
    package = build("reference/hopper.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "field.js",
        [
            # Tapered form: the radius no longer varies along the segment.
            ("const d = x.sub(ra.add(rb.sub(ra).mul(t)));", "const d = x.sub(ra);"),
            # Round cone: the side distance loses its axial (taper) term.
            ("const sideD = sn.mul(tRaw.mul(len)).add(c.mul(x)).sub(ra);", "const sideD = c.mul(x).sub(ra);"),
        ],
    )
    report = run_creature_parity(planted, groups=("field",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert any(name.startswith("field |d_gpu - d_numpy|") for name in failed), report.summary()


@pytest.mark.browser
def test_the_job_catches_a_shadow_pass_that_ignores_the_deformation(out_root: Path, tmp_path: Path) -> None:
    package = build("reference/hopper.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "material.js",
        [
            (
                "  material.colorNode = vColour;",
                "  material.colorNode = vColour;\n"
                "  material.castShadowPositionNode = attribute('position', 'vec3');",
            )
        ],
    )
    report = run_creature_parity(planted, groups=("shadow",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert "silhouette vs shadow footprint" in failed, report.summary()


@pytest.mark.browser
def test_the_job_catches_a_deform_pre_pass_that_skips_the_correction(out_root: Path, tmp_path: Path) -> None:
    """The passes draw the deform storage; a pre-pass that stores the uncorrected skin fails the drawn gate
    while the diagnostics kernel (the body path itself) still passes its own."""
    package = build("reference/hopper.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "deform.js",
        [
            (
                "...recordInputs(records, v), base, skinOnly, colour: true",
                "...recordInputs(records, v), base, skinOnly: true, colour: true",
            )
        ],
    )
    report = run_creature_parity(planted, groups=("skin",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert failed == {"drawn vertices (deform storage) vs the GPU body path"}, report.summary()


@pytest.mark.browser
def test_the_job_catches_a_body_path_that_ignores_the_size(out_root: Path, tmp_path: Path) -> None:
    """The lab's instance 0 spawns at a size other than 1 (tests/test_size.py): skinning the unscaled rest
    mesh under the scaled pose rows fails the skinning gate against numpy."""
    package = build("reference/hopper.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "body.js",
        [
            (
                "skinVertex(rest.mul(s), base, slots, weights, skin.x, cor.mul(s))",
                "skinVertex(rest, base, slots, weights, skin.x, cor)",
            )
        ],
    )
    report = run_creature_parity(planted, groups=("skin",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert "GPU-skinned vertices vs numpy" in failed, report.summary()


@pytest.mark.browser
def test_the_job_catches_a_population_that_uploads_a_stale_pose(out_root: Path, tmp_path: Path) -> None:
    """Slots of the previous step under the current root: the feet slide by one step of body motion,
    which the foot-drift markers measure on the GPU pose buffer (and the pose-row gate sees too)."""
    package = build("reference/biped.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "staging.js",
        [
            (
                "writeInstance(state, page, j, m.quats, m.trans, m.root);",
                "writeInstance(state, page, j, m.prevQuats, m.prevTrans, m.root);",
            )
        ],
    )
    report = run_creature_parity(planted, groups=("field", "motion"))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert "planted feet in the GPU pose buffer vs their plant points" in failed, report.summary()
    assert "pose rows (slots and root): GPU vs the Python locomotion reference" in failed, report.summary()
    assert "motion state in the lab vs Python at tick 37 (relative)" not in failed, report.summary()


@pytest.mark.browser
def test_the_job_fails_on_what_the_page_logs(out_root: Path, tmp_path: Path) -> None:
    """r185 reports a failed pipeline with console.error inside an error scope and skips the draw, which
    renderer.onError never sees: the job gates the console itself (here a warning the package logs)."""
    package = build("reference/hopper.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "population.js",
        [
            (
                "export async function createCreaturePopulation(renderer, options = {}) {",
                "export async function createCreaturePopulation(renderer, options = {}) {\n"
                "  console.error('THREE.WebGPURenderer: planted pipeline failure');",
            )
        ],
    )
    report = run_creature_parity(planted, groups=("hash",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert failed == {"console errors and warnings (pipeline compiles included)"}, report.summary()


def test_the_adapter_gate_fails_off_swiftshader() -> None:
    from creaturegen.lab.report import ParityReport, adapter_gate

    report = ParityReport(package="planted")
    adapter_gate(report, {"architecture": "swiftshader", "vendor": "google", "description": None})
    adapter_gate(report, {"architecture": "gen-12lp", "vendor": "intel", "description": "Mesa Intel"})
    assert [g["status"] for g in report.gates] == ["pass", "fail"]


@pytest.mark.browser
@pytest.mark.parametrize(
    ("planted_defect", "swap", "gate"),
    [
        (
            "yaw",
            ("root1.x.mul(v.x).add(root1.y.mul(v.z))", "root1.x.mul(v.x).sub(root1.y.mul(v.z))"),
            "display path world positions vs numpy's root transform",
        ),
        (
            "squash",
            ("p.y.mul(root1.z)", "p.y.div(root1.z)"),
            "display path world positions vs numpy's root transform",
        ),
        (
            "normal",
            (
                "return rootRotate(root1, normalize(vec3(n.x.mul(q), n.y.div(root1.z), n.z.mul(q))));",
                "return normalize(vec3(n.x.mul(q), n.y.div(root1.z), n.z.mul(q)));",
            ),
            "display path normals vs numpy (median)",
        ),
    ],
)
def test_the_job_catches_a_wrong_display_transform(
    out_root: Path, tmp_path: Path, planted_defect: str, swap: tuple[str, str], gate: str
) -> None:
    """The root transform runs only in the display and shadow shaders (material.js); every other readback
    is taken before it. The display-path readback renders the material's own positionNode."""
    package = build("reference/hopper.json", out_root)
    planted = _planted(package, tmp_path, "material.js", [swap])
    report = run_creature_parity(planted, groups=("skin",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert gate in failed, f"{planted_defect}: {report.summary()}"


#: Code a planted spawn runs first, and the counter gate it must trip (the other must stay quiet).
_SPAWN_ALLOCATIONS = {
    "buffer": "      renderer.backend.device.createBuffer({ size: 16, usage: 0x0040 }).destroy();",
    "pipeline": (
        "      { const device = renderer.backend.device;\n"
        "        const code = '@compute @workgroup_size(1) fn main() {}';\n"
        "        const module = device.createShaderModule({ code });\n"
        "        const compute = { module, entryPoint: 'main' };\n"
        "        device.createComputePipeline({ layout: 'auto', compute }); }"
    ),
}


@pytest.mark.browser
@pytest.mark.parametrize(("kind", "other"), [("buffer", "pipeline"), ("pipeline", "buffer")])
def test_the_job_catches_a_spawn_that_allocates(
    out_root: Path, tmp_path: Path, kind: str, other: str
) -> None:
    """Spawning is an O(slots) write into existing storage, and every pipeline exists before the reveal: a
    spawn that creates a buffer, or compiles a pipeline (a per-body kernel, say), fails its counter gate,
    which counts the device's own calls, and only that one."""
    package = build("reference/hopper.json", out_root)
    head = "    spawn({ seed = 0, position = [0, 0, 0], tier = home.name } = {}) {"
    planted = _planted(package, tmp_path, "population.js", [(head, f"{head}\n{_SPAWN_ALLOCATIONS[kind]}")])
    report = run_creature_parity(planted, groups=("population",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert f"{kind}s created by {SPAWNS} spawns after reveal" in failed, report.summary()
    assert f"{other}s created by {SPAWNS} spawns after reveal" not in failed, report.summary()


@pytest.mark.browser
def test_the_job_catches_a_spawn_that_spreads_bodies_over_pages(out_root: Path, tmp_path: Path) -> None:
    """Each page is one draw per pass: a spawn that deals bodies round-robin over the pages instead of
    filling the first free slot uses every page for nine bodies, and the pages-in-use gate fails."""
    package = build("reference/hopper.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "population.js",
        [
            (
                "      const slot = freeSlot(into);\n",
                "      const turn = population.count % into.pages.length;\n"
                "      const turned = [...into.pages.slice(turn), ...into.pages.slice(0, turn)];\n"
                "      const slot = freeSlot({ pages: turned });\n",
            )
        ],
    )
    report = run_creature_parity(planted, groups=("population",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert f"pose pages in use after {SPAWNS} spawns of pageSize {PAGE_SIZE}" in failed, report.summary()


def test_the_moved_gates_expect_nothing_of_a_still_creature(out_root: Path) -> None:
    """A creature without locomotion (corpus seed 2) stands still in the Python reference, so its tick
    deforms no body already deformed; a hopper moves every tick. build-many's parity jobs over generated
    creatures found the gates expecting every tick to move body 0."""
    from creaturegen.creature.reference import load_reference
    from creaturegen.lab.creature_population import moves_every_tick

    assert not moves_every_tick(load_reference(build("fixtures/still-creature.json", out_root)))
    assert moves_every_tick(load_reference(build("reference/hopper.json", out_root)))


MOVED_GATE = "bodies deformed by a tick that moves every live body (pre-pass: all of them)"
STILL_GATE = "bodies deformed by a frame in which no pose changed (pre-pass: only what moved)"
PAUSE_GATE = "bodies deformed by a tick with every body but one paused, beyond that one"
SPAWN_GATE = "bodies deformed by a frame whose only change is one spawn beside still bodies (only what moved)"


@pytest.mark.browser
@pytest.mark.parametrize(
    ("planted_defect", "swap", "gate", "quiet"),
    [
        (
            "a pre-pass over every drawn body, moved or not",
            ("    if (!page.moved[j]) continue;\n", ""),
            SPAWN_GATE,
            MOVED_GATE,
        ),
        (
            "a change test that compares the new rows with themselves (no body ever moves)",
            ("changed = rows[base + i] !== previous[i];", "changed = rows[base + i] !== rows[base + i];"),
            MOVED_GATE,
            STILL_GATE,
        ),
    ],
)
def test_the_job_catches_a_pre_pass_that_ignores_what_moved(
    out_root: Path, tmp_path: Path, planted_defect: str, swap: tuple[str, str], gate: str, quiet: str
) -> None:
    """The pre-pass runs only the bodies whose pose rows changed since their last pre-pass: a flush that
    deforms every live body of a changed page fails the one-spawn gate, one that never sees a change fails
    the all-moved gate; each leaves the other's quiet gate alone."""
    package = build("reference/hopper.json", out_root)
    report = run_creature_parity(_planted(package, tmp_path, "staging.js", [swap]), groups=("population",))
    failed, summary = {g["name"] for g in report.gates if g["status"] == "fail"}, report.summary()
    assert gate in failed, (planted_defect, summary)
    assert quiet not in failed, (planted_defect, summary)


@pytest.mark.browser
def test_the_job_catches_a_population_that_steps_paused_bodies(out_root: Path, tmp_path: Path) -> None:
    """pause(id) holds a body still: a population that steps and rewrites it anyway re-deforms it, and the
    paused-body gate (bodies deformed by the tick, the paused body's staged rows) fails."""
    package = build("reference/hopper.json", out_root)
    planted = _planted_files(
        package,
        tmp_path,
        {
            "staging.js": [
                ("if (!page.alive[j] || page.paused[j]) continue;", "if (!page.alive[j]) continue;")
            ],
            "population.js": [
                (
                    "if (page.alive[j] && !page.paused[j]) writeCurrent(state, page, j);",
                    "if (page.alive[j]) writeCurrent(state, page, j);",
                )
            ],
        },
    )
    report = run_creature_parity(planted, groups=("population",))
    failed, summary = {g["name"] for g in report.gates if g["status"] == "fail"}, report.summary()
    assert PAUSE_GATE in failed, summary
    assert STILL_GATE not in failed, summary


@pytest.mark.browser
@pytest.mark.parametrize(
    ("planted_defect", "file", "swap", "gates"),
    [
        (
            "culled bodies drawn and deformed anyway",
            "staging.js",
            ("if (!seen(state, page, j)) { culled++; continue; }", "if (!seen(state, page, j)) culled++;"),
            {"bodies drawn in body 0's portrait view of 5 spread 6.0 L apart (rest culled)"},
        ),
        (
            "a pre-pass that forgets the bodies that moved while culled",
            "staging.js",
            (
                "  state.stats.lastFrameDeformedBodies += n;\n",
                "  page.moved.fill(0);\n  state.stats.lastFrameDeformedBodies += n;\n",
            ),
            {
                "bodies deformed when culling stops vs the bodies culled while they moved",
                "drawn vertices of 5 bodies after culling vs the GPU body path at their pose",
            },
        ),
        (
            "a cull that allocates a GPU buffer whenever its views change",
            "population.js",
            (
                "      state.viewsChanged = true;\n",
                "      state.viewsChanged = true;\n"
                "      state.renderer.backend.device.createBuffer({ size: 256, usage: 128 });\n",  # STORAGE
            ),
            {"pipelines and buffers created by culling on, a culled tick and culling off (device count)"},
        ),
    ],
)
def test_the_job_catches_wrong_culling(
    out_root: Path, tmp_path: Path, planted_defect: str, file: str, swap: tuple[str, str], gates: set[str]
) -> None:
    """Culling by posed bounds (cullWith): a cull that keeps drawing what it culls, one that loses the
    bodies that moved while culled (they come back with a stale surface), and one that creates a GPU
    buffer when its views change, each fail their gates."""
    package = build("reference/hopper.json", out_root)
    report = run_creature_parity(_planted(package, tmp_path, file, [swap]), groups=("cull",))
    failed, summary = {g["name"] for g in report.gates if g["status"] == "fail"}, report.summary()
    assert gates <= failed, (planted_defect, summary)


@pytest.mark.browser
def test_the_job_catches_a_page_drawn_twice_in_a_pass(out_root: Path, tmp_path: Path) -> None:
    """A second mesh per page over the same geometry and material (an outline proxy, say) keeps the pages
    in use right but draws each page twice in the display pass: the draws-beyond-pages gate fails, and
    the pages-in-use gate stays quiet (the defect is in the draws, not in where bodies go)."""
    twin = (
        "  page.mesh.material = materialFor(state, page, m);\n",
        "  page.mesh.material = materialFor(state, page, m);\n"
        "  if (!page.twin) {\n"
        "    page.twin = new THREE.Mesh(page.tier.geometry, null);\n"
        "    page.twin.boundingSphere = page.mesh.boundingSphere;\n"
        "    group.add(page.twin);\n"
        "  }\n"
        "  page.twin.material = page.mesh.material;\n",
    )
    count = (
        "  page.mesh.count = n;\n",
        "  page.mesh.count = n;\n  if (page.twin) page.twin.count = page.mesh.count;\n",
    )
    package = build("reference/hopper.json", out_root)
    planted = _planted_files(package, tmp_path, {"pages.js": [twin], "staging.js": [count]})
    report = run_creature_parity(planted, groups=("population",))
    failed, summary = {g["name"] for g in report.gates if g["status"] == "fail"}, report.summary()
    assert "body draw calls in a render pass beyond pages in use (encoder count)" in failed, summary
    assert f"pose pages in use after {SPAWNS} spawns of pageSize {PAGE_SIZE}" not in failed, summary


@pytest.mark.browser
def test_the_job_catches_a_wrong_gradient(out_root: Path, tmp_path: Path) -> None:
    """A blend gradient with its y component doubled leaves every distance right and every normal wrong."""
    package = build("reference/hopper.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "field.js",
        [
            (
                "return vec4(d, l.yzw.mul(omh).add(r.yzw.mul(h)));",
                "return vec4(d, l.yzw.mul(omh).add(r.yzw.mul(h)).mul(vec3(1, 2, 1)));",
            )
        ],
    )
    report = run_creature_parity(planted, groups=("field",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert "field normal angle GPU vs numpy (off seams)" in failed, report.summary()
    assert not any(name.startswith("field |d_gpu - d_numpy|") for name in failed), report.summary()


@pytest.mark.browser
def test_the_job_catches_corrections_outside_the_region_policy(out_root: Path, tmp_path: Path) -> None:
    """Every vertex given a trust radius corrects vertices the build never proved need it."""
    package = build("reference/hopper.json", out_root)
    planted = _planted(
        package,
        tmp_path,
        "body.js",
        [
            (
                "fns.skin.correctVertex(skinned, base, program, skin.y.mul(s))",
                "fns.skin.correctVertex(skinned, base, program, float(layout.bodyScale * 0.01).mul(s))",
            )
        ],
    )
    report = run_creature_parity(planted, groups=("skin",))
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert "corrections outside the region policy" in failed, report.summary()


@pytest.mark.browser
def test_debug_views_draw_their_own_pictures_and_a_dead_switch_fails(out_root: Path, tmp_path: Path) -> None:
    """Counting PNGs cannot see a debug mode that never reaches the material: each view must differ from
    the shipped one and be more than one colour, and a setDebugMode that keeps the shipped material fails."""
    package = build("reference/hopper.json", out_root)
    report = run_creature_parity(package, groups=(), debug_pictures=True)
    assert report.passed, report.summary()
    planted = _planted(
        package,
        tmp_path,
        "population.js",
        [("    setDebugMode(m) {\n", "    setDebugMode(m) {\n      m = 'off';\n")],
    )
    report = run_creature_parity(planted, groups=(), debug_pictures=True)
    failed = {g["name"] for g in report.gates if g["status"] == "fail"}
    assert any(name.startswith("debug views identical to the shipped view") for name in failed), (
        report.summary()
    )


@pytest.mark.browser
@pytest.mark.parametrize(
    ("swap", "gate"),
    _subset(
        [
            (
                ("p.sub(r.yzw.mul(r.x.div(gg)))", "p.sub(r.yzw.mul(r.x.div(gg)).mul(0.5))"),
                "debug shell after 2 snap steps: GPU vs numpy (off seams)",
            ),
            (
                ("SHELL_CAP_RINGS = Object.freeze([3, 2, 2])", "SHELL_CAP_RINGS = Object.freeze([4, 2, 2])"),
                "debug shell vertices per slot vs (2 + 2·3)·12 + 2 (hero)",
            ),
        ],
        ["half-newton-steps", "hero-cap-rings"],
        {"half-newton-steps"},
    ),
)
def test_the_job_catches_a_wrong_debug_shell(
    swap: tuple[str, str], gate: str, out_root: Path, tmp_path: Path
) -> None:
    """The 'shell' view snapping by half steps, or drawn with the wrong ring count for its tier."""
    package = build("reference/hopper.json", out_root)
    failed, summary = _failures(package, tmp_path, "shell.js", [swap], ("shell",))
    assert gate in failed, summary


@pytest.mark.browser
@pytest.mark.parametrize(
    ("file", "swaps", "gate"),
    _subset(
        [
            (
                "material.js",
                [
                    ("  material.roughnessNode = look.roughness;\n", ""),
                    ("  material.metalnessNode = look.metalness;\n", ""),
                ],
                "front view under setLook",
            ),
            (
                "population.js",
                [
                    (
                        "for (const [name, value] of Object.entries(changes)) "
                        "state.look[name].value = value;",
                        "for (const page of pages) {\n"
                        "        const m = page.mesh.material.clone();\n"
                        "        m.roughnessNode = null;\n"
                        "        m.roughness = changes.roughness ?? 0.55;\n"
                        "        page.mesh.material = m;\n"
                        "      }",
                    )
                ],
                "GPU objects created by setLook",
            ),
        ],
        ["look-not-in-the-shader", "look-rebuilds-materials"],
        {"look-rebuilds-materials"},
    ),
)
def test_the_job_catches_a_look_that_is_not_a_uniform_write(
    file: str, swaps: list[tuple[str, str]], gate: str, out_root: Path, tmp_path: Path
) -> None:
    """Controls the material never reads (the picture does not change), or a setLook that marks every
    material for a rebuild (the device creates objects)."""
    package = build("reference/hopper.json", out_root)
    failed, summary = _failures(package, tmp_path, file, swaps, ("look",))
    assert any(name.startswith(gate) for name in failed), summary


@pytest.mark.browser
@pytest.mark.parametrize(
    ("file", "swap"),
    _subset(
        [
            ("body.js", ("reach.mul(float(i.add(1)))", "reach.mul(float(i.add(2)))")),
            (
                "population.js",
                (
                    "if (Object.keys(changes).some((name) => LOOK_DEFORM.includes(name))) "
                    "for (const page of pages) deformAll(state, page);",
                    "",
                ),
            ),
        ],
        ["taps-one-step-too-far", "setlook-without-re-deform"],
        {"taps-one-step-too-far"},
    ),
)
def test_the_job_catches_a_wrong_self_occlusion(
    file: str, swap: tuple[str, str], out_root: Path, tmp_path: Path
) -> None:
    """Occlusion taps placed one step too far out, or a setLook that leaves the stored albedo as it was."""
    package = build("reference/hopper.json", out_root)
    failed, summary = _failures(package, tmp_path, file, [swap], ("look",))
    assert any(name.startswith("self-occlusion (") for name in failed), summary
