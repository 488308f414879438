"""A built frost package's runtime outside the build: its JavaScript structure-file decoder (Node) against the
numpy bake, byte for byte; refusal of a foreign file; the three.js revision check; every runtime export and
effect method declared in the .d.ts files; and, in Chromium, the README page script and the assetBase option.

Node and the lab's three are required (the tests fail, never skip, without them).
"""

from __future__ import annotations

import base64
import dataclasses
import hashlib
import json
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import EXAMPLES, run_cli
from creaturegen.frost.brush import Segment
from creaturegen.frost.params import params_from_plan
from creaturegen.frost.schedule import bin_steps
from creaturegen.frost.structure import generate_structure
from creaturegen.frost.timeline import (
    advance_instants,
    chunk_steps,
    classify_interval,
    late_steps,
    split_interval,
)
from creaturegen.lab.browser import launch_lab_page
from creaturegen.lab.frost_history import strokes_at_once
from creaturegen.lab.frost_texels import shipped_structure
from creaturegen.lab.server import WEB_LAB, serve
from creaturegen.resources import lab_modules
from creaturegen.spec.frost import Structure
from creaturegen.spec.types import slugify

#: A spec whose normals are differenced over 2 texels (main) at resolution 1024, with a non-unit strength.
WIDE_SPACING = {"resolution": 1024, "normalStrength": 1.7, "seed": 3, "crystalScale": 5.5}


def _node() -> str:
    node = shutil.which("node")
    assert node is not None, "node (20+) must be on PATH"
    return node


def run_node(script: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """An ES-module script in Node (top-level await allowed), from ``cwd``."""
    return subprocess.run(
        [_node(), "--input-type=module", "-e", script],
        cwd=cwd,
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )


def build(spec: dict[str, Any], out: Path) -> Path:
    source = out / f"{slugify(str(spec['name']))}.json"
    out.mkdir(parents=True, exist_ok=True)
    source.write_text(json.dumps(spec))
    result = run_cli("build", str(source), "-o", str(out))
    assert result.returncode == 0, result.stderr
    return out / slugify(str(spec["name"]))


def example_spec(example: str, **changes: Any) -> dict[str, Any]:
    spec: dict[str, Any] = json.loads((EXAMPLES / "frost" / f"{example}.json").read_text())
    spec.pop("$schema", None)
    spec.update(changes)
    return spec


def three_modules() -> Path:
    modules = lab_modules(install=True)
    assert modules is not None, "the lab's node_modules (three 0.185.1) must be installed (make setup)"
    return modules


@pytest.fixture(scope="module")
def packages(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two example packages and one with wide-spacing normals, each under <root>/<slug> beside a
    node_modules/three link, so Node resolves the packages' three imports the way an app does."""
    root = tmp_path_factory.mktemp("frost-assets")
    (root / "node_modules").mkdir()
    (root / "node_modules" / "three").symlink_to(three_modules() / "three", target_is_directory=True)
    specs = {
        "balanced": example_spec("frost-balanced"),
        "budgeted": example_spec("frost-budgeted"),
        "wide": example_spec("frost-balanced", name="Frost Wide Spacing", structure=WIDE_SPACING),
    }
    return {key: build(spec, root) for key, spec in specs.items()}


DECODE = """
import {{ readFileSync }} from 'node:fs';
import {{ createHash }} from 'node:crypto';
const {{ PLAN }} = await import({plan});
const {{ decodeStructureFile }} = await import({decoder});
const layout = PLAN.assets.structure;
const bytes = new Uint8Array(readFileSync({asset}));
try {{
  const {{ structure, normals }} = await decodeStructureFile(bytes, layout, 'the file');
  const digest = createHash('sha256').update(structure).update(normals).digest('hex');
  console.log(JSON.stringify({{ digest, structure: structure.length, normals: normals.length }}));
}} catch (error) {{
  console.log(JSON.stringify({{ error: error.name, message: error.message }}));
}}
"""


def decode_in_node(package: Path, asset: Path) -> dict[str, Any]:
    script = DECODE.format(
        plan=json.dumps((package / "core" / "plan.js").as_uri()),
        decoder=json.dumps((package / "core" / "structure-file.js").as_uri()),
        asset=json.dumps(str(asset)),
    )
    done = run_node(script, package)
    assert done.returncode == 0, done.stderr
    result: dict[str, Any] = json.loads(done.stdout)
    return result


def structure_asset(package: Path) -> Path:
    (asset,) = (package / "assets").iterdir()
    return asset


@pytest.mark.parametrize("key", ["balanced", "budgeted", "wide"])
def test_js_decoder_gives_the_numpy_bake_byte_for_byte(packages: dict[str, Path], key: str) -> None:
    """The runtime inflates the file and derives the normals in float64 JavaScript; the result must be the
    texels numpy baked (its sha256 covers structure and normals)."""
    package = packages[key]
    report = json.loads((package / "build-report.json").read_text())
    decoded = decode_in_node(package, structure_asset(package))
    assert "error" not in decoded, decoded
    n = report["structure"]["resolution"]
    assert decoded["structure"] == decoded["normals"] == 4 * n * n
    spec = Structure.model_validate({k: v for k, v in report["structure"].items() if k != "sha256"})
    assert decoded["digest"] == generate_structure(spec).sha256 == report["structureSha256"]
    if key == "wide":
        assert report["assets"]["structure"]["normals"]["main"]["spacing"] == 2


def test_js_decoder_refuses_another_packages_file(packages: dict[str, Path], tmp_path: Path) -> None:
    mine, other = packages["balanced"], packages["wide"]
    swapped = decode_in_node(mine, structure_asset(other))
    assert swapped["error"] == "FrostAssetError"
    assert "asset mismatch" in swapped["message"]
    damaged = tmp_path / "damaged.bin"
    data = bytearray(structure_asset(mine).read_bytes())
    data[len(data) // 2] ^= 0xFF
    damaged.write_bytes(bytes(data))
    result = decode_in_node(mine, damaged)
    assert "error" in result, "a corrupted deflate stream must not decode"


def test_shipped_structure_matches_the_bake(packages: dict[str, Path]) -> None:
    """The parity job's numpy decode of the shipped file is the bake itself."""
    package = packages["balanced"]
    structure, normals = shipped_structure(package)
    report = json.loads((package / "build-report.json").read_text())
    assert hashlib.sha256(structure.tobytes() + normals.tobytes()).hexdigest() == report["structureSha256"]


def fake_three(root: Path, revision: str) -> Path:
    """A node_modules/three that is the real r185 except for REVISION (local exports shadow `export *`)."""
    real = three_modules() / "three" / "build"
    folder = root / "node_modules" / "three"
    folder.mkdir(parents=True)
    (folder / "package.json").write_text(
        json.dumps(
            {"name": "three", "type": "module", "exports": {"./webgpu": "./webgpu.js", "./tsl": "./tsl.js"}}
        )
    )
    webgpu = json.dumps((real / "three.webgpu.js").as_uri())
    (folder / "webgpu.js").write_text(
        f"export * from {webgpu};\nexport const REVISION = {json.dumps(revision)};\n"
    )
    (folder / "tsl.js").write_text(f"export * from {json.dumps((real / 'three.tsl.js').as_uri())};\n")
    return folder


CREATE = """
const {{ createFrostEffect }} = await import({index});
const renderer = {{ backend: {{ isWebGPUBackend: true }} }};
try {{
  await createFrostEffect(renderer, null, null);
  console.log(JSON.stringify({{ error: null }}));
}} catch (error) {{
  console.log(JSON.stringify({{ error: error.name, message: error.message }}));
}}
"""


@pytest.mark.parametrize(("revision", "refused"), [("187", True), ("184", True), ("185", False)])
def test_another_three_revision_is_refused_by_name(
    packages: dict[str, Path], tmp_path: Path, revision: str, refused: bool
) -> None:
    root = tmp_path / f"r{revision}"
    fake_three(root, revision)
    package = root / "pkg"
    shutil.copytree(packages["budgeted"], package)
    done = run_node(CREATE.format(index=json.dumps((package / "index.js").as_uri())), root)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    if refused:
        assert result["error"] == "FrostRevisionError"
        assert result["message"] == (
            f"frost: this package is built for three r185 (three@0.185.x); found r{revision}"
        )
    else:
        # r185 passes the check and goes on to fetch its asset (which Node cannot do from a file: URL).
        assert result["error"] == "FrostAssetError", result


def test_revision_check_accepts_dev_builds_of_the_release(packages: dict[str, Path]) -> None:
    revision = json.dumps((packages["budgeted"] / "core" / "revision.js").as_uri())
    script = (
        f"const m = await import({revision});\n"
        "m.checkThreeRevision('185'); m.checkThreeRevision('185dev'); m.checkThreeRevision(185);\n"
        "try { m.checkThreeRevision('186dev'); console.log('accepted'); }\n"
        "catch (e) { console.log(e instanceof m.FrostRevisionError ? e.name : 'other'); }\n"
    )
    done = run_node(script, packages["budgeted"])
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "FrostRevisionError"


#: Values: `export const|function|class NAME`, `export { A, B as C } from`; `export type|interface` are types.
DTS_VALUE = re.compile(r"^export (?:declare )?(?:const|function|class|let) (\w+)", re.MULTILINE)
DTS_REEXPORT = re.compile(r"^export \{([^}]*)\} from", re.MULTILINE)


def declared_values(dts: str) -> set[str]:
    names = set(DTS_VALUE.findall(dts))
    for group in DTS_REEXPORT.findall(dts):
        names |= {part.split(" as ")[-1].strip() for part in group.split(",") if part.strip()}
    return names


def test_declaration_pattern_sees_values_not_types() -> None:
    dts = "export const A: 1;\nexport function b(): void;\nexport class C {}\n"
    dts += "export { D, E as F } from './x.js';\nexport type G = 1;\n"
    dts += "export interface H {}\nexport type { I } from './y.js';\n"
    assert declared_values(dts) == {"A", "b", "C", "D", "F"}


@pytest.mark.parametrize("entry", ["index", "core/index", "tsl/index"])
def test_every_runtime_export_is_declared(packages: dict[str, Path], entry: str) -> None:
    package = packages["balanced"]
    module = json.dumps((package / f"{entry}.js").as_uri())
    done = run_node(f"console.log(JSON.stringify(Object.keys(await import({module}))))", package)
    assert done.returncode == 0, done.stderr
    runtime = set(json.loads(done.stdout))
    declared = declared_values((package / f"{entry}.d.ts").read_text())
    assert runtime, entry
    assert runtime <= declared, f"{entry}.js exports {sorted(runtime - declared)} without a declaration"
    assert declared <= runtime, f"{entry}.d.ts declares {sorted(declared - runtime)}, which do not exist"


def interface_members(dts: str, name: str) -> set[str]:
    body = re.search(rf"export interface {name} \{{(.*?)^\}}", dts, flags=re.DOTALL | re.MULTILINE)
    assert body is not None, name
    return set(re.findall(r"^  (?:readonly )?(\w+)\??[(:]", body.group(1), flags=re.MULTILINE))


# --- in Chromium ----------------------------------------------------------------------------------------


def lab_url(base: str, slug: str, **query: str) -> str:
    extra = "".join(f"&{k}={v}" for k, v in query.items())
    return f"{base}frost.html?pkg={slug}&w=96&h=64{extra}"


@pytest.mark.browser
def test_effect_object_is_typed_method_for_method(packages: dict[str, Path]) -> None:
    """What createFrostEffect returns at runtime (setControl, reset, debugView, ...) is what FrostEffect
    declares."""
    package = packages["budgeted"]
    with (
        serve(WEB_LAB, mounts={"out": package.parent}) as base,
        launch_lab_page(lab_url(base, package.name)) as lab,
    ):
        assert lab.lab.get("error") is None, lab.lab.get("error")
        keys = set(lab.page.evaluate("() => window.__lab.info().effectKeys"))
    declared = interface_members((package / "tsl" / "index.d.ts").read_text(), "FrostEffect")
    assert {"setControl", "reset", "debugView", "readStructure"} <= keys
    assert keys == declared


@pytest.mark.browser
def test_asset_base_fetches_moved_assets(packages: dict[str, Path], tmp_path: Path) -> None:
    """A bundle that did not copy the assets: without assetBase the effect fails with a message that names
    the fix; with assetBase pointing at the moved files it loads them, and the GPU holds the shipped
    texels."""
    out = tmp_path / "out"
    package = out / packages["budgeted"].name
    shutil.copytree(packages["budgeted"], package)
    _, normals = shipped_structure(package)
    (out / "cdn").mkdir()
    for asset in (package / "assets").iterdir():
        asset.rename(out / "cdn" / asset.name)
    with serve(WEB_LAB, mounts={"out": out}) as base:
        with launch_lab_page(lab_url(base, package.name)) as lab:
            error = str(lab.lab.get("error"))
            for needed in ("FrostAssetError", "HTTP 404", "assetBase"):
                assert needed in error, error
        with launch_lab_page(lab_url(base, package.name, assetBase="/out/cdn/")) as lab:
            assert lab.lab.get("error") is None, lab.lab.get("error")
            raw = lab.page.evaluate("() => window.__lab.readStructure()")
    n = int(raw["resolution"])
    gpu = np.frombuffer(base64.b64decode(raw["normals"]), dtype=np.uint8).reshape(n, n, 4)
    np.testing.assert_array_equal(gpu, normals)


SNIPPET_PAGE = """<!doctype html>
<html><head><meta charset="utf-8"><link rel="icon" href="data:,">
<style>html, body {{ margin: 0; overflow: hidden; }}</style>
<script type="importmap">{importmap}</script>
<script>window.__lab = {{ ready: false, error: null }};</script>
<script type="module">
// The script wires its pointer handler right after createFrostEffect resolves: that registration is the
// page's signal that the effect exists (the script itself exposes nothing).
let wired = false;
const add = HTMLCanvasElement.prototype.addEventListener;
HTMLCanvasElement.prototype.addEventListener = function (type, ...rest) {{
  if (type === 'pointermove') wired = true;
  return add.call(this, type, ...rest);
}};
const errors = [];
const logError = console.error;
console.error = (...args) => {{ errors.push(args.map(String).join(' ')); logError(...args); }};
const frame = () => new Promise((resolve) => requestAnimationFrame(resolve));
try {{
  await import('/pkg/{slug}/examples/minimal.js');
  for (let i = 0; i < 600 && !wired && errors.length === 0; i++) await frame();
  for (let i = 0; i < 20; i++) await frame();
  const canvas = document.querySelector('canvas');
  const failed = errors.length ? errors.join('; ') : (wired ? null : 'effect never ready');
  window.__lab = {{ ready: true, error: failed, canvas: canvas && [canvas.width, canvas.height],
    engine: canvas && canvas.getAttribute('data-engine') }};
}} catch (error) {{
  window.__lab = {{ ready: true, error: String(error && error.stack || error) }};
}}
</script></head><body></body></html>
"""


@pytest.mark.browser
def test_readme_page_script_runs_as_written(packages: dict[str, Path], tmp_path: Path) -> None:
    """examples/minimal.js (the README's script, byte for byte) in a blank page with an import map to
    three: it renders frames, takes pointer moves over the canvas and a resize, and nothing throws or logs
    an error."""
    package = packages["budgeted"]
    slug = package.name
    imports = {
        "three": "/node_modules/three/build/three.webgpu.js",
        "three/webgpu": "/node_modules/three/build/three.webgpu.js",
        "three/tsl": "/node_modules/three/build/three.tsl.js",
        slug: f"/pkg/{slug}/index.js",
    }
    (tmp_path / "index.html").write_text(
        SNIPPET_PAGE.format(importmap=json.dumps({"imports": imports}), slug=slug)
    )
    mounts = {"node_modules": three_modules(), "pkg": package.parent}
    with serve(tmp_path, mounts=mounts) as base, launch_lab_page(base + "index.html", timeout_s=180) as lab:
        assert lab.lab.get("error") is None, f"{lab.lab.get('error')}\n{lab.transcript()}"
        assert lab.lab["engine"] == "three.js r185 webgpu"
        width, height = lab.lab["canvas"]
        assert width > 0
        assert height > 0
        page = lab.page
        for step in range(12):
            page.mouse.move(width * (0.2 + 0.05 * step), height * 0.5)
            page.wait_for_timeout(20)
        page.set_viewport_size({"width": 640, "height": 400})
        page.wait_for_timeout(500)
        resized = page.evaluate("() => [document.querySelector('canvas').width, innerWidth]")
        assert resized[1] == 640
        assert resized[0] > 0
        page.wait_for_timeout(300)
        errors = [line for line in lab.console if line.startswith(("[error]", "[warning]"))]
        assert errors == [], lab.transcript()
        assert lab.page_errors == [], lab.transcript()


def test_js_time_policy_is_the_numpy_time_policy(packages: dict[str, Path]) -> None:
    """classifyInterval and a stall's advance ends (advanceInstants) in the JS core against numpy's, exactly:
    every decision, and cut instants equal to the last bit (both JSON forms round-trip doubles)."""
    intervals = [
        (0.0, 0.0),
        (1.0, 0.5),
        (0.0, 1.0),
        (0.0, 1.0 + 2**-40),
        (0.1, 2.6),
        (1 / 3, 4.0),
        (0.0, 4.0 + 1e-9),
        (12.345, 14.2),
        (0.0, float("nan")),
        (0.0, float("inf")),
    ]
    limits = [(1.0, 4.0), (1.0, 1.0), (0.3, 1.7)]
    core = packages["budgeted"] / "core" / "frost-core.js"
    script = f"""
const {{ advanceInstants, classifyInterval }} = await import({json.dumps(core.as_uri())});
const intervals = {json.dumps([[p, c] for p, c in intervals])};  // NaN and Infinity: JS literals too
const out = [];
for (const [maxInterval, catchUp] of {json.dumps(limits)}) {{
  for (const [p, c] of intervals) {{
    const decision = classifyInterval(p, c, maxInterval, catchUp);
    out.push([decision, decision === 'catch-up' ? advanceInstants(p, c, maxInterval) : []]);
  }}
}}
console.log(JSON.stringify(out));
"""
    done = run_node(script, packages["budgeted"])
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout)
    expected = []
    for max_interval, catch_up in limits:
        for previous, current in intervals:
            decision = classify_interval(previous, current, max_interval, catch_up)
            ends = advance_instants(previous, current, max_interval) if decision == "catch-up" else []
            expected.append([decision, ends])
    assert got == expected
    assert sum(d == "catch-up" for d, _ in got) >= 6


def test_js_late_steps_are_the_numpy_late_steps(packages: dict[str, Path]) -> None:
    # The JS core's catch-up steps (what the runtime writes to the step buffer) against numpy's, for
    # segments before, across and after `previous`, one clipped by the origin, and from a start index.
    raw = [
        (0.05, 0.12, (0.1, 0.2), (0.2, 0.3)),
        (0.12, 0.31, (0.2, 0.3), (0.4, 0.35)),
        (0.31, 0.52, (0.4, 0.35), (0.6, 0.5)),
        (0.52, 0.7, (0.6, 0.5), (0.7, 0.5)),
    ]
    segments = [Segment(t0=a, t1=b, start=s, end=e, pressure0=0.5, pressure1=0.9) for a, b, s, e in raw]
    core = packages["budgeted"] / "core" / "frost-core.js"
    script = f"""
const {{ lateSteps, normalizeSegment }} = await import({json.dumps(core.as_uri())});
const raw = {json.dumps([[a, b, list(s), list(e)] for a, b, s, e in raw])};
const segs = raw.map(([t0, t1, start, end]) =>
  normalizeSegment({{ t0, t1, start, end, pressure0: 0.5, pressure1: 0.9 }}));
const out = [];
for (const [previous, origin, from] of [[0.5, 0.0, 0], [0.5, 0.2, 0], [0.5, 0.0, 1], [0.9, 0.6, 0]]) {{
  out.push(lateSteps(previous, segs, origin, from).map((s) => [segs.indexOf(s.segments[0]), s.dt, s.age]));
}}
console.log(JSON.stringify(out));
"""
    done = run_node(script, packages["budgeted"])
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout)
    cases = [(0.5, 0.0, 0), (0.5, 0.2, 0), (0.5, 0.0, 1), (0.9, 0.6, 0)]
    for (previous, origin, start), js in zip(cases, got, strict=True):
        expected = [
            [segments.index(s.segments[0]), s.dt, s.age]
            for s in late_steps(previous, segments[start:], origin)
        ]
        assert js == expected, (previous, origin, start)


def test_js_bins_chunks_and_steps_are_numpy_s_for_several_strokes(packages: dict[str, Path]) -> None:
    """Several streams at once: the JS core's splitInterval (every active segment per step), chunkSteps
    (by steps and pairs) and StepBins (entries per screen tile, CSR) against numpy's, on crossing strokes
    of a frost parity job; every bin's entry list must hold its pairs in step order."""
    segments = strokes_at_once(6)
    params = params_from_plan(json.loads((packages["budgeted"] / "build-report.json").read_text())["params"])
    width, height = 160, 96
    core = packages["budgeted"] / "core" / "frost-core.js"
    plan = packages["budgeted"] / "core" / "plan.js"
    script = f"""
const {{ splitInterval, chunkSteps, StepBins, normalizeSegment }} = await import({json.dumps(core.as_uri())});
const {{ PLAN }} = await import({json.dumps(plan.as_uri())});
const segs = {json.dumps([dataclasses.asdict(g) for g in segments])}.map(normalizeSegment);
const steps = splitInterval(0.05, 0.3, segs);
const chunks = chunkSteps(steps, PLAN.params.maxSteps, 7);
const bins = new StepBins(PLAN.params);
const out = {{ steps: steps.map((s) => [s.dt, s.segments.map((g) => segs.indexOf(g))]), chunks: [] }};
for (const chunk of chunks) {{
  bins.bin(chunk, {width}, {height});
  const perBin = [];
  let ordered = true;
  for (let b = 0; b < bins.count; b++) {{
    perBin.push(bins.start[b + 1] - bins.start[b]);
    for (let e = bins.start[b] + 1; e < bins.start[b + 1]; e++) {{
      ordered &&= bins.entries[e] > bins.entries[e - 1];
    }}
  }}
  out.chunks.push({{ size: chunk.length, perBin, ordered, single: bins.single }});
}}
console.log(JSON.stringify(out));
"""
    done = run_node(script, packages["budgeted"])
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout)
    steps = split_interval(0.05, 0.3, segments)
    assert [[s.dt, [segments.index(g) for g in s.segments]] for s in steps] == got["steps"]
    assert max(len(s.segments) for s in steps) >= 4  # the strokes do overlap in time
    chunks = chunk_steps(steps, params.max_steps, 7)
    assert [len(c) for c in chunks] == [c["size"] for c in got["chunks"]]
    for chunk, js in zip(chunks, got["chunks"], strict=True):
        bins = bin_steps(chunk, params, width, height)
        assert js["perBin"] == bins.entries.tolist()
        assert js["ordered"]
        assert js["single"] is False
