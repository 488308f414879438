"""The creature parity job: run a built package in the lab (headless Chromium, WebGPU on SwiftShader)
and diff what the GPU computed, read back from the device, against the numpy reference.

Gates, all measured in the run (thresholds are relative to the body scale L where they are lengths):
- pose pages: the GPU pose rows (slots and root) after seekTick vs the Python locomotion reference
  (motion/simulate.py) in float32;
- field: GPU probeField (a compute kernel running the material's own TSL field program) vs numpy float64
  at ≥ 4096 seeded points on caps, inside tapers, across blends and over the box: |Δd| and the normal
  angle (points where numpy's own float32 and float64 normals disagree by more than the tolerance sit on a
  gradient seam and are counted, not gated);
- skinning: GPU-skinned vertex positions vs numpy LBS/DQ/CoR on the same pose; where the tier is
  skin-represented (vertices with program SKIN_PROGRAM evaluate no field), the drawn normal of those
  vertices vs numpy's skinned normal and their drawn colour vs the baked colour of the individual, and the
  field gates over the other vertices only;
- correction: every vertex the GPU corrected is no farther from the numpy posed field than its skinned
  position, and the corrected residual is reported;
- debug shell (the 'shell' view): vertices per slot vs the seed's (2 + 2·capRings)·radial + 2 for the tier,
  every slot's shell placed on its pose row and snapped onto the union field, GPU vs numpy
  (creature_shell.py);
- look: setLook (roughness, metalness) changes the picture and creates no GPU object; setting the
  package's look back restores it pixel for pixel (creature_look.py);
- shadows: the silhouette seen from the sun vs the shadow footprint on the ground (the depth pass uses the
  same position function), max distance of a disagreeing texel to the other mask's edge;
- no GPU validation errors; no pipelines and no buffers created by a burst of spawns that fills the lab's
  first pose page and opens its second, and one tick and frame of them all after reveal;
- stateHash(seekTick(n)) == stateHash(stepTicks(n));
- motion: the JS locomotion core in the page vs Python (relative 1e-12), and every planted foot as the GPU
  pose buffer draws it (rows read back, root squash/yaw/position applied) on its plant point;
- tiers (a package built with several, ``--tier hero,distant``): the tier each body gets over a camera
  walk vs creature/lod.py, no GPU object created by the moves, the moved bodies' surfaces, and each
  coarser tier's silhouette vs the finest (creature_tiers.py);
- genetics grid: 64 individuals (seeds 0..63) spawned in an 8×8 grid and stepped: every one's GPU pose
  rows (its OKLab-mutated colours and the pose its size and gait genes give) vs its Python reference, no two
  individuals alike; parity/grid.png shows them.

This module runs the groups against one lab session and writes the report; the session is
creature_lab.py, the gates creature_pose.py (pose pages, field, motion, stateHash), creature_skin.py
(skinning, correction, display path), creature_shell.py (debug shell), creature_population.py (spawn
burst, genetics grid) and creature_views.py (shadows, pictures).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path

from ..creature import reference as cref
from .creature_lab import DEFAULT_CANVAS, LAB_POSITION, LAB_SEED, PARITY_TICK, open_creature_lab_page
from .creature_look import look_and_occlusion
from .creature_population import (
    GRID_SIDE,
    PAGE_SIZE,
    PAGES_IN_BURST,
    SPARE_PAGES,
    counter_gates,
    cull_gates,
    grid_gates,
    moves_every_tick,
)
from .creature_pose import hash_gate, motion_gates, pose_and_field_gates
from .creature_shell import shell_gates
from .creature_skin import skin_gates
from .creature_tiers import shipped_ceilings, tier_gates
from .creature_views import pictures, shadow_gate
from .report import ParityReport, adapter_gate, console_problems

GATE_GROUPS = (
    "population",
    "hash",
    "field",
    "motion",
    "skin",
    "shell",
    "look",
    "shadow",
    "cull",
    "tiers",
    "grid",
)


def run_creature_parity(
    package: Path,
    canvas: tuple[int, int] = DEFAULT_CANVAS,
    groups: tuple[str, ...] = GATE_GROUPS,
    debug_pictures: bool = False,
) -> ParityReport:
    """The creature gates (all groups by default) for one built package; writes parity/report.json and
    PNGs (front.png always, debug views on request) into it. GPU validation errors are always gated."""
    package = package.resolve()
    ref = cref.load_reference(package)
    # Instance 0 as the lab spawns it, at the parity tick: what every pose, field and skin gate compares.
    motion = cref.instance_motion(ref, LAB_SEED, PARITY_TICK, LAB_POSITION)
    report = ParityReport(package=package.name)
    (package / "parity").mkdir(exist_ok=True)
    seconds: dict[str, float] = {}
    start = time.perf_counter()
    capacity = GRID_SIDE * GRID_SIDE if "grid" in groups else (PAGES_IN_BURST + SPARE_PAGES) * PAGE_SIZE
    with open_creature_lab_page(package, canvas, capacity=capacity, pageSize=PAGE_SIZE) as lab_page:
        page = lab_page.page
        seconds["load"] = time.perf_counter() - start
        report.measurements["adapter"] = page.evaluate("() => window.__lab.info()")["adapter"]
        adapter_gate(report, report.measurements["adapter"])
        report.measurements["bootMs"] = page.evaluate("() => window.__lab.bootMs")

        def phase(name: str, run: Callable[[], object]) -> None:
            if name in groups:
                t = time.perf_counter()
                run()
                seconds[name] = time.perf_counter() - t

        moving = moves_every_tick(ref)
        phase("population", lambda: counter_gates(page, report, moving))
        phase("hash", lambda: hash_gate(page, report))
        page.evaluate(f"() => window.__lab.seekTick({PARITY_TICK})")
        phase("field", lambda: pose_and_field_gates(page, ref, motion, report))
        phase("motion", lambda: motion_gates(page, ref, motion, report))
        phase("skin", lambda: skin_gates(page, ref, motion, report))
        finest = json.loads((package / "build-report.json").read_text())["tier"]
        phase("shell", lambda: shell_gates(page, ref, motion, finest, report))
        phase("look", lambda: look_and_occlusion(page, ref, motion, report))
        # A package shipping several tiers: bodies moved between them by their size on screen. Before the
        # shadow gate, whose edits of the page materials make every page rebuild its bindings when next
        # drawn (the lab's doing, which the walk's device count would charge to the tier moves); it puts
        # instance 0 back as the lab spawned it, at the parity tick.
        if len(shipped_ceilings(package)) > 1:
            phase("tiers", lambda: tier_gates(page, package, report, ref.rig.body_scale, PARITY_TICK))
        phase("shadow", lambda: shadow_gate(page, package, report))
        t = time.perf_counter()
        pictures(page, package, debug_pictures, report)
        seconds["pictures"] = time.perf_counter() - t
        # After the pictures: culling spreads bodies around body 0 and takes them away again.
        phase("cull", lambda: cull_gates(page, report, ref.rig.body_scale, moving))
        # Last: the grid replaces every body (instance 0 included) of the lab.
        phase("grid", lambda: grid_gates(page, ref, package, report))
        page.evaluate("() => window.__lab.finish()")
        errors: list[str] = page.evaluate("() => window.__lab.errors")
        report.gate("GPU validation errors", len(errors), 0, "errors")
        report.measurements["gpuErrors"] = errors[:20]
        console = console_problems(lab_page.console) + list(lab_page.page_errors)
        report.gate("console errors and warnings (pipeline compiles included)", len(console), 0, "lines")
        report.measurements["consoleProblems"] = console[:20]
        report.measurements["slots"] = ref.rig.slot_count
        report.measurements["bodyScale"] = ref.rig.body_scale
        report.measurements["seconds"] = seconds
    (package / "parity" / "report.json").write_text(
        json.dumps(report.as_dict(), indent=2, sort_keys=True) + "\n"
    )
    return report
