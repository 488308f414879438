"""`creaturegen build` on creature specs: the package layout and its headers, byte-identical rebuilds, a
core free of three, the shipped-code lint, a hostile name, invalid specs, the JS core against the Python
reference under `node --test`, and the committed golden record (tests/golden/, `make golden`).

One hopper build is shared by the module; the session's surface cache (conftest) extracts the surface once,
so the rebuild and the hostile-name build take seconds."""

from __future__ import annotations

import hashlib
import importlib.util
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from conftest import EXAMPLES, REPO, node, run_cli, run_node_tests
from creaturegen import __version__, cli
from creaturegen.creature import pose as pose_module
from creaturegen.creature.assets import shipped_spec, surface_path
from creaturegen.emit.lint import Finding, lint_package, lint_sources, shipped_sources
from creaturegen.emit.render import to_json
from creaturegen.emit.writer import header_text
from creaturegen.field.primitives import slot_uses_round_cone
from creaturegen.model import layout as col
from creaturegen.model import lcg as lcg_module
from creaturegen.model.genome import draw_genome, genetics_data, genome_colours, slot_lab
from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion.providers import AnalyticWater
from creaturegen.motion.rig import build_motion
from creaturegen.motion.simulate import Motion
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec, load_spec, slugify

HOPPER = EXAMPLES / "reference" / "hopper.json"
HOPPER_SLUG = "hopper-squash-core"

LAYOUT = (
    "package.json",
    "README.md",
    "index.js",
    "index.d.ts",
    "core/index.js",
    "core/data.js",
    "core/lcg.js",
    "core/pose.js",
    "core/index.d.ts",
    "tsl/index.js",
    "tsl/index.d.ts",
    "tsl/asset.js",
    "core/surface.js",
    "examples/minimal.js",
    "assets/surface.json",
    "build-report.json",
)
#: The input spec (minus a $schema that would not resolve in the package): no header, it is the input.
VERBATIM = "assets/spec.json"
#: Module specifiers of import/export statements, bare imports and dynamic import() calls.
IMPORT_SPECIFIER = re.compile(
    r"""^\s*(?:import|export)\b[^;'"`]*?\bfrom\s*['"]([^'"]+)['"]"""
    r"""|^\s*import\s*['"]([^'"]+)['"]"""
    r"""|\bimport\s*\(\s*['"`]([^'"`]+)['"`]""",
    re.MULTILINE,
)


def tree(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def build(spec: Path, out: Path) -> subprocess.CompletedProcess[str]:
    return run_cli("build", str(spec), "-o", str(out))


def built_package(spec: Path, out: Path) -> Path:
    result = build(spec, out)
    assert result.returncode == 0, result.stdout + result.stderr
    folders = sorted(p.name for p in out.iterdir())
    assert len(folders) == 1, f"expected one package folder, found {folders} (leftover staging?)"
    return out / folders[0]


@pytest.fixture(scope="module")
def hopper(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """examples/reference/hopper.json built once through the command line."""
    folder = built_package(HOPPER, tmp_path_factory.mktemp("hopper"))
    assert folder.name == HOPPER_SLUG
    return folder


# --- layout and headers ---------------------------------------------------------------------------


def test_layout(hopper: Path) -> None:
    files = tree(hopper)
    assert surface_path(hopper).relative_to(hopper).as_posix() in files
    missing = [name for name in LAYOUT if name not in files]
    assert not missing, missing
    empty = [name for name in LAYOUT if not files[name]]
    assert not empty, empty
    assert any(name.startswith("core/") for name in files)
    assert sum(name.startswith("tsl/") and name.endswith(".js") for name in files) >= 2
    unexpected = [n for n in files if not n.endswith((".js", ".ts", ".md", ".json", ".glb"))]
    assert not unexpected, f"files of unknown type (header rules do not cover them): {unexpected}"


def test_package_json(hopper: Path) -> None:
    package = json.loads((hopper / "package.json").read_text())
    assert package["name"] == HOPPER_SLUG
    assert package["version"] == __version__
    assert package["type"] == "module"
    exports = package["exports"]
    assert {".", "./core", "./tsl"} <= set(exports)
    release = ">=0.185.0 <0.186.0"
    assert package["peerDependencies"] == {"three": release, "@types/three": release}
    assert package["peerDependenciesMeta"] == {"@types/three": {"optional": True}}
    assert package["license"] == "MIT"
    targets = [package["main"], package["types"]]
    for entry in (exports["."], exports["./core"], exports["./tsl"]):
        assert set(entry) == {"types", "default"}, "typed entry points name their .d.ts"
        targets += [entry["types"], entry["default"]]
    for target in targets:
        assert (hopper / target).is_file(), target
    assert "dependencies" not in package, "three is a peer dependency; the package has no others"


def test_every_generated_file_carries_the_header(hopper: Path) -> None:
    spec_bytes = HOPPER.read_bytes()
    sha = hashlib.sha256(spec_bytes).hexdigest()
    line = f"Code generated by creaturegen {__version__} from {sha}. DO NOT EDIT."
    assert line == header_text(sha)
    checked: dict[str, list[str]] = {"comment": [], "json": []}
    for name, content in tree(hopper).items():
        if name.endswith((".js", ".ts")):
            assert content.startswith(f"// {line}\n".encode()), f"{name}: {content[:120]!r}"
            checked["comment"].append(name)
        elif name.endswith(".md"):
            assert content.startswith(f"<!-- {line} -->\n".encode()), f"{name}: {content[:120]!r}"
            checked["comment"].append(name)
        elif name == VERBATIM:
            assert content == shipped_spec(spec_bytes), f"{name} is not the input spec"
        elif name.endswith(".json"):
            value = json.loads(content)
            assert isinstance(value, dict), name
            assert value.get("//") == line, f'{name}: the "//" key is {value.get("//")!r}'
            checked["json"].append(name)
    assert len(checked["comment"]) >= 10, checked
    assert {"package.json", "build-report.json", "assets/surface.json"} <= set(checked["json"])


# --- reproducibility ------------------------------------------------------------------------------


def test_rebuild_is_byte_identical(hopper: Path, tmp_path: Path) -> None:
    """A second build into another folder: every file, bytes included, is the same."""
    first = tree(hopper)
    second = tree(built_package(HOPPER, tmp_path / "again"))
    assert sorted(first) == sorted(second)
    different = [name for name in first if first[name] != second[name]]
    assert not different, different


# --- a core free of three, and the shipped-code lint -----------------------------------------------


def test_core_has_no_three(hopper: Path) -> None:
    scripts = sorted((hopper / "core").glob("*.js"))
    assert len(scripts) >= 4
    for script in scripts:
        text = script.read_text()
        specifiers = [next(g for g in groups if g) for groups in IMPORT_SPECIFIER.findall(text)]
        # the core imports its own modules only: no 'three', no 'three/tsl', no bare package at all
        outside = [s for s in specifiers if not s.startswith("./")]
        assert not outside, f"core/{script.name} imports {outside}"
        code = "\n".join(x for x in text.splitlines() if not x.lstrip().startswith(("//", "*", "/*")))
        assert re.search(r"['\"`]three\b", code) is None, f"core/{script.name} names a three module"
    # and it runs without three anywhere (the temporary folder has no node_modules to resolve it from)
    imports = "".join(f"await import({json.dumps(s.as_uri())});" for s in scripts)
    done = subprocess.run(
        [node(), "--input-type=module", "-e", imports],
        capture_output=True,
        text=True,
        check=False,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr


def test_lint_finds_nothing_in_the_package(hopper: Path) -> None:
    sources = shipped_sources(hopper)
    expected = {n for n in tree(hopper) if n.startswith(("core/", "tsl/")) and n.endswith((".js", ".ts"))}
    assert set(sources) == expected
    findings = lint_package(hopper)
    assert findings == [], "\n".join(map(str, findings))


def test_deform_storage_layout_is_one_definition_in_python_and_js(hopper: Path) -> None:
    """The build report's deformBytesPerBody and the runtime's page clamp use the same stride: the shipped
    module's own constant, which tests/test_runtime_constants.py pins to the plan's."""
    from creaturegen.creature.plan import DEFORM_STRIDE

    js = (hopper / "tsl" / "deform.js").read_text()
    assert f"export const DEFORM_STRIDE = {DEFORM_STRIDE};" in js
    assert "deformStride" not in (hopper / "core" / "data.js").read_text()
    workload = json.loads((hopper / "build-report.json").read_text())["workload"]
    assert workload["deformBytesPerBody"] == workload["vertices"] * DEFORM_STRIDE * 16


#: (rule, snippet): each must be found, at the line it starts on.
PLANTED = [
    ("nondeterminism", "const r = Math.random();"),
    ("nondeterminism", "const t = Date.now();"),
    ("nondeterminism", "const t = performance.now();"),
    ("nondeterminism", "const t = performance?.now();"),
    ("nondeterminism", "const t = performance['now']();"),
    ("nondeterminism", "const t = performance?.['now']();"),
    ("nondeterminism", 'const r = Math["random"]();'),
    ("nondeterminism", "const r = Math [ `random` ]();"),
    ("nondeterminism", "const t = globalThis.performance . now();"),
    ("nondeterminism", "const t = performance\n  .now();"),
    ("nondeterminism", "const { now } = performance;"),
    ("nondeterminism", "const { random: rnd } = Math;"),
    ("nondeterminism", "const stamp = new Date();"),
    ("nondeterminism", "crypto.getRandomValues(bytes);"),
    ("nondeterminism", "import { Fn, time } from 'three/tsl';"),
    ("nondeterminism", "const clock = new THREE.Clock();"),
    ("frustum-culling-off", "mesh.frustumCulled = false;"),
    ("frustum-culling-off", "mesh.frustumCulled=false;"),
    ("frustum-culling-off", "mesh['frustumCulled'] = false;"),
    ("frustum-culling-off", "Object.assign(mesh, { frustumCulled: false });"),
    ("finite-difference", "const dx = sdf(p.add(vec3(eps, 0, 0)));"),
    ("finite-difference", "const dy = sdf(p.add(vec3(0.0, h, 0.0)));"),
    ("finite-difference", "const e = [0, 0, EPS];"),
    ("finite-difference", "const g = field(p.add(e)).sub(field(p.sub(e)));"),
    ("finite-difference", "const g = (f(x + h) - f(x - h)) / (2 * h);"),
    ("finite-difference", "const q = p.add(epsilon);"),
    ("finite-difference", "n = k.xyy.mul(map(p.add(k.xyy.mul(s))));"),
    ("finite-difference", "const n = cross(dFdx(pos), dFdy(pos));"),
    ("finite-difference", "const w = fwidth(d);"),
    ("finite-difference", "function centralDifferenceNormal(p) {}"),
]

#: Look-alikes that are fine.
CLEAN = """\
// no finite differences: the gradient is analytic; offsets live in [0, period)
const now = tick / 60;
update(last, now);
const randomSeed = 7, period = 120;
const t = Date.UTC(2020, 0, 1) + new Date(0).getTime();
const up = vec3(0, 1, 0), zero = vec3(0), lift = [0, height, 0];
mesh.frustumCulled = true;
if (mesh.frustumCulled === false) throw new Error('culling is on');
const h1 = Math.imul(h2, 3) + step;
const rotated = a.add(b).sub(c);
import { hashBytes } from './three-free.js';
"""


@pytest.mark.parametrize(("rule", "snippet"), PLANTED, ids=[s for _, s in PLANTED])
def test_lint_finds_planted_code(rule: str, snippet: str) -> None:
    text = f"// planted\nconst a = 1;\n{snippet}\nexport {{ a }};\n"
    findings = lint_sources({"tsl/planted.js": text})
    assert [(f.path, f.line, f.rule) for f in findings if f.rule == rule][:1] == [("tsl/planted.js", 3, rule)]
    assert str(findings[0]).startswith("tsl/planted.js:3: ")


def test_lint_three_import_only_in_core() -> None:
    text = "// x\nimport * as THREE from 'three/webgpu';\nconst m = await import('three');\n"
    findings = lint_sources({"core/a.js": text, "tsl/a.js": text})
    assert findings == [
        Finding("core/a.js", 2, "three-in-core", "from 'three/webgpu'"),
        Finding("core/a.js", 3, "three-in-core", "import('three'"),
    ]


def test_lint_leaves_look_alikes_alone() -> None:
    assert lint_sources({"core/clean.js": CLEAN, "tsl/clean.js": CLEAN}) == []


# --- a hostile name reaches code only as JSON --------------------------------------------------------

#: Quotes, backslashes, a template literal, HTML/script and comment closers, and line separators that a
#: JS string literal would not survive unescaped (control characters are refused by the spec rules).
HOSTILE_NAME = "Hop \"q\" 'a' \\b\\ `${globalThis.x}` </script><!-- */ é\u2028\u2029\u0085 ❄"


@pytest.fixture(scope="module")
def hostile(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("hostile")
    spec = json.loads(HOPPER.read_text())
    spec.pop("$schema")
    spec["name"] = HOSTILE_NAME
    source = folder / "hostile.json"
    source.write_text(json.dumps(spec, ensure_ascii=False), encoding="utf-8")
    assert isinstance(load_spec(source), CharacterSpec)
    return built_package(source, folder / "out")


def test_hostile_name_appears_only_as_json(hostile: Path) -> None:
    assert hostile.name == slugify(HOSTILE_NAME) == "hop-q-a-b-globalthis-x-script"
    escaped = to_json(HOSTILE_NAME)
    files = tree(hostile)
    for name, content in files.items():
        if name.endswith((".js", ".ts")):
            assert HOSTILE_NAME.encode() not in content, f"{name} holds the raw name"
            text = content.decode()
            for separator in ("\u2028", "\u2029", "\u0085"):
                assert separator not in text, f"{name} holds the name's {separator!r} unescaped"
            # every trace of the name in code sits inside its JSON string literal
            assert text.count("${globalThis.x}") == text.count(escaped), f"{name} holds the name unescaped"
    assert files["core/data.js"].decode().count(escaped) == 1
    assert json.loads(files["build-report.json"])["name"] == HOSTILE_NAME
    package = json.loads(files["package.json"])
    assert package["name"] == hostile.name
    assert package["description"].endswith(f": {HOSTILE_NAME}")
    entry = json.dumps((hostile / "core" / "index.js").as_uri())
    script = f"import({entry}).then(m => console.log(JSON.stringify(m.CREATURE.name)))"
    done = subprocess.run(
        [node(), "--input-type=module", "-e", script], capture_output=True, text=True, check=False, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == HOSTILE_NAME


def test_hostile_package_parses(hostile: Path) -> None:
    scripts = sorted(hostile.rglob("*.js"))
    assert len(scripts) >= 10
    for script in scripts:
        done = subprocess.run([node(), "--check", str(script)], capture_output=True, text=True, check=False)
        assert done.returncode == 0, f"{script.relative_to(hostile)}: {done.stderr}"


# --- invalid specs write nothing ----------------------------------------------------------------------


def _broken(case: str) -> bytes:
    spec = json.loads(HOPPER.read_text())
    if case == "syntax":
        return HOPPER.read_bytes()[:-3]
    if case == "radius":
        spec["parts"][0]["r"] = -1
    elif case == "control-character":
        spec["name"] = "Hopper\x07Core"
    elif case == "unknown-parent":
        spec["parts"][1]["parent"] = "nope"
    return json.dumps(spec).encode()


INVALID = [
    ("syntax", "bad.json:"),
    ("radius", "bad.json: part.core.r: must be > 0"),
    ("control-character", "bad.json: name: must not contain control characters"),
    ("unknown-parent", 'bad.json: part.belly.parent: unknown part "nope"'),
]


def listing(folder: Path) -> tuple[dict[str, bytes], list[str]]:
    """Every file with its bytes, and every path (folders included)."""
    return tree(folder), sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


def occupied(out: Path) -> tuple[dict[str, bytes], list[str]]:
    """An output folder that already holds a package and a stray file: a failed build must keep both."""
    (out / HOPPER_SLUG).mkdir(parents=True)
    (out / HOPPER_SLUG / "index.js").write_text("// an earlier build\n")
    (out / "notes.txt").write_text("mine")
    return listing(out)


@pytest.mark.parametrize(("case", "message"), INVALID, ids=[case for case, _ in INVALID])
def test_invalid_spec_exits_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str, message: str
) -> None:
    """In process (the child-process path is the next test): exit status 2, the error named, no write."""
    source = tmp_path / "bad.json"
    source.write_bytes(_broken(case))
    out = tmp_path / "out"
    before = occupied(out)
    assert cli.main(["build", str(source), "-o", str(out)]) == 2
    stderr = capsys.readouterr().err
    assert message in stderr.replace(str(source), "bad.json"), stderr
    assert listing(out) == before
    fresh = tmp_path / "fresh"
    assert cli.main(["build", str(source), "-o", str(fresh)]) == 2
    assert not fresh.exists() or list(fresh.iterdir()) == []


def test_invalid_spec_from_the_command_line(tmp_path: Path) -> None:
    source = tmp_path / "bad.json"
    source.write_bytes(_broken("radius"))
    out = tmp_path / "out"
    before = occupied(out)
    result = build(source, out)
    assert result.returncode == 2, result.stdout + result.stderr
    assert "part.core.r: must be > 0" in result.stderr
    assert "Traceback" not in result.stderr
    assert listing(out) == before


# --- the JS core against the Python reference ----------------------------------------------------------

#: Seeds for LCG draws and instance headings (negative and > 2^32 wrap like JS's `>>> 0`).
SEEDS = (0, 1, 7, 4801, 2**31, 2**32 - 1, -1, 2**40 + 5)
#: Seeds whose bodies are stepped tick by tick and written as pose rows at every tick of TICKS.
POSED_SEEDS = (7, 4801, 2**32 - 1)
TICKS = 240
LCG_DRAWS = 16


def python_reference(spec_path: Path) -> dict[str, Any]:
    """What the JS core must reproduce: LCG draws and headings (creature/pose.py), and the pose rows and
    root rows of the locomotion reference (motion/simulate.py) at every tick, as float32 bit patterns."""
    spec = load_spec(spec_path)
    assert isinstance(spec, CharacterSpec)
    rig = compile_rig(spec)
    data = build_motion(spec, rig, build_skeleton(spec, rig))
    genetics = genetics_data(spec.genetics)
    lab = slot_lab(rig.slots[:, col.RGB])
    lcg = []
    for seed in SEEDS:
        state, draws = seed % (1 << 32), []
        for _ in range(LCG_DRAWS):
            state = lcg_module.lcg_next(state)
            draws.append(state)
        lcg.append({"seed": seed, "draws": draws})
    cases = []
    for seed in POSED_SEEDS:
        motion = Motion(data, water=AnalyticWater(), seed=seed)
        colours = genome_colours(genetics, lab, draw_genome(seed))
        frames = []
        for tick in range(TICKS + 1):
            if tick:
                motion.step()
            rows = np.concatenate(
                [
                    pose_module.pose_rows(rig, motion.quats, motion.trans, colours, motion.size).ravel(),
                    pose_module.root_rows(motion.root, size=motion.size).ravel(),
                ]
            )
            frames.append({"tick": tick, "root": list(motion.root), "rowBits": rows.view(np.uint32).tolist()})
        cases.append({"seed": seed, "size": motion.size, "frames": frames})
    return {
        "slotCount": rig.slot_count,
        "constants": {
            "poseRows": pose_module.POSE_ROWS,
            "lcg": {"a": lcg_module.LCG_A, "c": lcg_module.LCG_C},
            "roundCone": [int(x) for x in slot_uses_round_cone(rig.slots)],
        },
        "lcg": lcg,
        "instances": [
            {"seed": seed, "mixed": lcg_module.mix_seed(seed), "yaw": lcg_module.instance_yaw(seed)}
            for seed in SEEDS
        ],
        "cases": cases,
        "frameCount": sum(len(c["frames"]) for c in cases),
    }


def test_python_reference_is_sane() -> None:
    """The reference itself: the hopper moves, squashes (so the root rows carry s != 1) and keeps unit
    quaternions in its rows."""
    reference = python_reference(HOPPER)
    frames = reference["cases"][0]["frames"]
    squash = [f["root"][5] for f in frames]
    assert min(squash) < 0.99 < 1.01 < max(squash), "the hopper never squashes in 240 ticks"
    rows = np.array([f["rowBits"] for f in frames], dtype=np.uint32).view(np.float32)
    quats = rows[:, : reference["slotCount"] * 20].reshape(len(frames), -1, 20)[:, :, 12:16]
    assert np.allclose(np.linalg.norm(quats, axis=2), 1.0, atol=1e-6)
    assert np.ptp(quats, axis=0).max() > 0.05, "the pose does not move"


def test_js_core_matches_python(hopper: Path, tmp_path: Path) -> None:
    reference = tmp_path / "reference.json"
    reference.write_text(json.dumps(python_reference(HOPPER)))
    env = {"CREATURE_CORE": str(hopper / "core" / "index.js"), "CREATURE_REFERENCE": str(reference)}
    done = run_node_tests("creature_core.test.mjs", env)
    assert re.search(r"\bpass 4\b", done.stdout), done.stdout


# --- the golden record -----------------------------------------------------------------------------------


def regen_golden() -> ModuleType:
    """tools/regen-golden.py as a module: the record format has one definition, shared with the script."""
    path = REPO / "tools" / "regen-golden.py"
    spec = importlib.util.spec_from_file_location("regen_golden", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_golden_record(hopper: Path) -> None:
    golden = regen_golden()
    assert golden.CASES["creature-hopper"] == HOPPER.relative_to(REPO).as_posix()
    stored = golden.stored("creature-hopper")
    assert stored, "tests/golden/creature-hopper/ is missing: run `make golden` and commit tests/golden/"
    built = golden.record(hopper)
    diff = golden.differences(stored, built)
    assert not diff, (
        "the hopper package no longer matches its golden record (tests/golden/creature-hopper/):\n  "
        + "\n  ".join(diff)
        + "\nIf the change is intended (a template or the compiler changed), run `make golden` "
        "(.venv/bin/python tools/regen-golden.py), review the diff and commit tests/golden/."
    )
    manifest = json.loads(stored[golden.BINARY_MANIFEST])
    assert set(manifest["files"]) == {surface_path(hopper).relative_to(hopper).as_posix()}
    assert any(name.startswith("package/core/") for name in stored)


def test_the_golden_record_catches_a_template_copy_the_build_altered(hopper: Path, tmp_path: Path) -> None:
    """Files the build copies verbatim are named in verbatim.json instead of stored; a build whose copy is
    no longer the template's bytes (here: one line appended) no longer matches the record, by name."""
    golden = regen_golden()
    stored = golden.stored("creature-hopper")
    copies = json.loads(stored[golden.VERBATIM_MANIFEST])["files"]
    assert "core/hash.js" in copies
    assert "package/core/hash.js" not in stored
    altered = tmp_path / hopper.name
    shutil.copytree(hopper, altered)
    hashjs = altered / "core" / "hash.js"
    hashjs.write_bytes(hashjs.read_bytes() + b"// extra\n")
    diff = golden.differences(stored, golden.record(altered))
    assert any(line.startswith("package/core/hash.js: in the build, not in the record") for line in diff)
    assert any(line.startswith("verbatim.json") for line in diff), diff
