"""What a consumer of a creature package gets (issue "Ship it"): a surface asset named per package and
geometry, loaded from one static ``new URL(..., import.meta.url)`` literal or from ``assetBase``; a .glb
whose signatures are checked when it loads; types for every entry point and a typed ``CREATURE``; a
three.js revision check; a README whose page runs as written; and a ``files`` list of what runs.

The JS runs in Node against the built package (three from the lab's node_modules), except the README page,
which runs in headless Chromium (browser marker). The strict TypeScript check installs typescript and
@types/three with npm and is skipped, saying why, when npm cannot reach its registry.
"""

from __future__ import annotations

import base64
import hashlib
import json
import re
import shutil
import subprocess
import tarfile
import typing
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import EXAMPLES, build_example, missing_setup, node, run_cli, shared_folder
from creaturegen.creature.assets import (
    REPORT_PATH,
    SIDECAR_PATH,
    SPEC_PATH,
    shipped_spec,
    surface_file,
    surface_path,
)
from creaturegen.creature.plan import program_data, program_tapes
from creaturegen.emit.lint import lint_sources
from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion.compiled import compile_creature
from creaturegen.motion.rig import build_motion
from creaturegen.resources import lab_modules
from creaturegen.rig import compile_rig
from creaturegen.rig.signatures import signatures
from creaturegen.spec import CharacterSpec, load_spec, slugify, validate_bytes
from creaturegen.spec.character import LocomotionType
from creaturegen.surface.glb import parse_program, program_digest
from test_runtime_constants import js_constant

HOPPER = "reference/hopper.json"
#: Examples whose motion data between them have legs, ropes and wings (the typed shapes of each).
MOTION_SHAPES = ("reference/quadruped.json", "reference/flyer.json", "reference/hopper.json", "lizard.json")
THREE_TYPES = "@types/three@0.185.0"
TYPESCRIPT = "typescript@5"


# --- fixtures --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def hopper(creature_out: Path) -> Path:
    return build_example(HOPPER, creature_out)


def three_modules() -> Path:
    modules = lab_modules(install=True)
    assert modules is not None, "three@0.185.1 for the lab is missing: run `make setup`"
    return modules / "three"


def install_site(root: Path, package: Path, three: Path | None = None) -> Path:
    """A consumer folder: node_modules/<slug> (a copy, so its imports resolve here) and three."""
    modules = root / "node_modules"
    modules.mkdir(parents=True, exist_ok=True)
    shutil.copytree(package, modules / package.name)
    (modules / "three").symlink_to(three or three_modules(), target_is_directory=True)
    return root


@pytest.fixture(scope="module")
def site(hopper: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return install_site(tmp_path_factory.mktemp("site"), hopper)


def run_js(cwd: Path, script: str) -> Any:
    """An ES module run by node in ``cwd`` (bare imports resolve from its node_modules); its last stdout
    line is JSON."""
    done = subprocess.run(
        [node(), "--input-type=module", "-e", script],
        cwd=cwd,
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-4000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


#: Replaces fetch with a reader of file: URLs (Node's fetch has none), as a page's fetch of a served file.
FILE_FETCH = """
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
globalThis.fetch = async (url) => {
  try {
    const bytes = readFileSync(fileURLToPath(String(url)));
    const body = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
    return { ok: true, status: 200, arrayBuffer: async () => body };
  } catch {
    return { ok: false, status: 404, arrayBuffer: async () => new ArrayBuffer(0) };
  }
};
const caught = async (promise) => {
  try { await promise; return null; } catch (e) {
    return { name: e.name, message: e.message, mismatch: e instanceof SurfaceMismatchError,
      revision: e instanceof ThreeRevisionError, expected: e.expected ?? null, found: e.found ?? null,
      url: e.url ?? null, packageName: e.packageName ?? null };
  }
};
"""


def package_report(package: Path) -> dict[str, Any]:
    report: dict[str, Any] = json.loads((package / REPORT_PATH).read_text())
    return report


def tampered_glb(glb: bytes, digest: str) -> tuple[bytes, str]:
    """The .glb with another geometryDigest in its JSON (same length, so every offset stays valid): the
    file of another creature, as far as the signatures tell."""
    other = "".join("0123456789abcdef"[(int(c, 16) + 1) % 16] for c in digest)
    assert glb.count(digest.encode()) >= 1
    return glb.replace(digest.encode(), other.encode()), other


# --- 1. asset names and URLs ---------------------------------------------------------------------------


def test_surface_asset_is_named_by_package_geometry_and_programs(hopper: Path) -> None:
    report = package_report(hopper)
    digest = report["signatures"]["geometryDigest"]
    glb = next((hopper / "assets").glob("*.glb")).read_bytes()
    program = parse_program(glb)
    assert program is not None
    programs = program_digest(program)
    both = hashlib.sha256(f"{digest}:{programs}".encode()).hexdigest()
    name = f"{hopper.name}-{both[:12]}.glb"
    assert surface_file(hopper.name, digest, programs) == name
    # Another tier's programs over the same mesh get another name.
    assert surface_file(hopper.name, digest, "0" * 64) != name
    assert report["assets"] == {"surface": f"assets/{name}", "spec": SPEC_PATH, "sidecar": SIDECAR_PATH}
    assert surface_path(hopper) == hopper / "assets" / name
    assert [p.name for p in (hopper / "assets").glob("*.glb")] == [name]
    data = run_js(
        hopper, "import('./core/data.js').then(m => console.log(JSON.stringify(m.CREATURE.surfaceFile)))"
    )
    assert data == name
    for path in hopper.rglob("*"):
        if path.is_file() and path.suffix in {".js", ".ts", ".md", ".json"}:
            assert "surface.glb" not in path.read_text(), (
                f"{path.relative_to(hopper)} names the old shared asset"
            )


def test_surface_path_without_a_build_report(hopper: Path, tmp_path: Path) -> None:
    """An installed copy ships no build report: the one .glb of assets/ is the surface; of several (a
    package shipping several tiers), the one core/data.js names."""
    copy = tmp_path / hopper.name
    shutil.copytree(hopper, copy)
    (copy / REPORT_PATH).unlink()
    assert surface_path(copy) == copy / surface_path(hopper).relative_to(hopper)
    (copy / "assets" / "extra.glb").write_bytes(b"")
    assert surface_path(copy) == copy / surface_path(hopper).relative_to(hopper)
    (copy / "core" / "data.js").unlink()
    with pytest.raises(FileNotFoundError, match=r"expected one surface \.glb"):
        surface_path(copy)


#: The form asset-aware bundlers look for: a literal first argument, import.meta.url second.
STATIC_URL = re.compile(r"""new URL\(\s*(["'])([^"'`$+]+)\1\s*,\s*import\.meta\.url\s*\)""")


def test_default_url_is_one_static_literal(hopper: Path) -> None:
    name = surface_path(hopper).name
    uses = {}
    for path in sorted(hopper.rglob("*.js")):
        text = path.read_text()
        if "import.meta.url" in text:
            uses[path.relative_to(hopper).as_posix()] = text
    assert list(uses) == ["tsl/asset.js"], "the package resolves files against import.meta.url in one place"
    code = "\n".join(
        x for x in uses["tsl/asset.js"].splitlines() if not x.lstrip().startswith(("//", "*", "/*"))
    )
    # One static expression per shipped surface (one tier here).
    assert code.count("import.meta.url") == 1
    text = code
    assert [m.group(2) for m in STATIC_URL.finditer(text)] == [f"../assets/{name}"]


def test_default_url_resolves_to_the_shipped_file(site: Path, hopper: Path) -> None:
    script = (
        f"const m = await import('{hopper.name}/tsl');"
        "console.log(JSON.stringify([m.defaultSurfaceUrl(), m.SURFACE_FILE]));"
    )
    url, name = run_js(site, script)
    installed = site / "node_modules" / hopper.name
    assert url == (installed / "assets" / name).as_uri()
    assert (installed / "assets" / name).is_file()


def test_two_packages_merge_assets_without_a_collision(hopper: Path, tmp_path: Path) -> None:
    """Two creature packages with their assets copied into one served folder (what a copy step or a
    bundler does): each finds its own file there through assetBase, and neither file is overwritten."""
    spec = json.loads((hopper / SPEC_PATH).read_text())
    spec["name"] = "Hopper Twin"
    source = tmp_path / "twin.json"
    source.write_text(json.dumps(spec))
    done = run_cli("build", str(source), "-o", str(tmp_path / "out"))
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    twin = tmp_path / "out" / slugify("Hopper Twin")
    merged = tmp_path / "public" / "assets"
    merged.mkdir(parents=True)
    for package in (hopper, twin):
        for glb in (package / "assets").glob("*.glb"):
            assert not (merged / glb.name).exists(), f"{glb.name} collides"
            shutil.copy(glb, merged / glb.name)
    assert len(list(merged.iterdir())) == 2
    base = merged.as_uri() + "/"
    for package in (hopper, twin):
        script = (
            f"import {{ SurfaceMismatchError, ThreeRevisionError, loadSurface, resolveSurfaceUrl }}"
            f" from {json.dumps((package / 'core' / 'index.js').as_uri())};"
            + FILE_FETCH
            + f"const url = resolveSurfaceUrl({{ assetBase: {json.dumps(base)} }}, () => 'unused');"
            "const surface = await loadSurface(url);"
            "console.log(JSON.stringify([url, surface.extras.geometryDigest]));"
        )
        url, digest = run_js(package, script)
        assert url == (merged / surface_path(package).name).as_uri()
        assert digest == package_report(package)["signatures"]["geometryDigest"]


def test_surface_url_options(hopper: Path) -> None:
    core = json.dumps((hopper / "core" / "index.js").as_uri())
    script = f"""
import {{ CREATURE, resolveSurfaceUrl }} from {core};
const out = {{}};
const fallback = () => 'https://pkg.example/assets/own.glb';
const attempt = (options) => {{
  try {{ return resolveSurfaceUrl(options, fallback); }} catch (e) {{ return e.name; }}
}};
out.default = attempt({{}});
out.base = attempt({{ assetBase: 'https://cdn.example/creatures/' }});
out.baseUrl = attempt({{ assetBase: new URL('https://cdn.example/a/b/') }});
out.url = attempt({{ surfaceUrl: 'https://x.example/s.glb' }});
out.both = attempt({{ surfaceUrl: 'https://x.example/s.glb', assetBase: 'https://cdn.example/' }});
out.relativeOutsideAPage = attempt({{ assetBase: '/static/' }});
globalThis.document = {{ baseURI: 'https://site.example/app/index.html' }};
out.relativeInAPage = attempt({{ assetBase: 'static/' }});
out.file = CREATURE.surfaceFile;
console.log(JSON.stringify(out));
"""
    out = run_js(hopper, script)
    name = out["file"]
    assert out["default"] == "https://pkg.example/assets/own.glb"
    assert out["base"] == f"https://cdn.example/creatures/{name}"
    assert out["baseUrl"] == f"https://cdn.example/a/b/{name}"
    assert out["url"] == "https://x.example/s.glb"
    assert out["both"] == "TypeError"
    assert out["relativeOutsideAPage"] == "TypeError"
    assert out["relativeInAPage"] == f"https://site.example/app/static/{name}"


# --- 2. the signature check -----------------------------------------------------------------------------


def test_foreign_surface_is_refused_by_name(hopper: Path, tmp_path: Path) -> None:
    """The quadruped-with-the-hopper's-file case: a .glb of other signatures under this package's name.
    loadSurface and createCreaturePopulation (past its renderer check) reject with SurfaceMismatchError,
    which names the package, the URL and both digests; the package's own file loads."""
    own = surface_path(hopper)
    digest = package_report(hopper)["signatures"]["geometryDigest"]
    bytes_, other = tampered_glb(own.read_bytes(), digest)
    foreign = tmp_path / own.name
    foreign.write_bytes(bytes_)
    site = install_site(tmp_path / "site", hopper)
    base = json.dumps(tmp_path.as_uri() + "/")
    renderer = (
        "{ backend: { isWebGPUBackend: true, device: { limits: { maxStorageBufferBindingSize: 1 << 27 } } } }"
    )
    script = (
        f"import {{ SurfaceMismatchError, ThreeRevisionError, createCreaturePopulation, loadSurface }}"
        f" from '{hopper.name}';" + FILE_FETCH + f"const foreign = {json.dumps(foreign.as_uri())};"
        f"const own = {json.dumps((site / 'node_modules' / hopper.name / 'assets' / own.name).as_uri())};"
        "const out = { load: await caught(loadSurface(foreign)), ownLoads: await caught(loadSurface(own)),"
        f"  population: await caught(createCreaturePopulation({renderer}, {{ surfaceUrl: foreign }})),"
        f"  base: await caught(createCreaturePopulation({renderer}, {{ assetBase: {base} }})),"
        "  missing: await caught(loadSurface(foreign + '.missing')) };"
        "console.log(JSON.stringify(out));"
    )
    out = run_js(site, script)
    assert out["ownLoads"] is None
    for case in ("load", "population", "base"):
        error = out[case]
        assert error is not None, f"{case}: the foreign surface loaded"
        assert error["name"] == "SurfaceMismatchError"
        assert error["mismatch"], case
        assert error["packageName"] == hopper.name
        assert error["url"] == foreign.as_uri()
        assert error["expected"]["geometryDigest"] == digest
        assert error["found"]["geometryDigest"] == other
        for text in (hopper.name, foreign.as_uri(), digest, other):
            assert text in error["message"], (case, text, error["message"])
    assert out["missing"]["name"] == "Error"
    assert "HTTP 404" in out["missing"]["message"]
    assert own.name in out["missing"]["message"]


def test_glb_without_signatures_is_refused(hopper: Path, tmp_path: Path) -> None:
    """A glTF that is no creaturegen asset (no extras at all) is refused the same way."""
    glb = surface_path(hopper).read_bytes()
    length = int.from_bytes(glb[12:16], "little")
    document = json.loads(glb[20 : 20 + length])
    document["asset"].pop("extras")
    text = json.dumps(document).encode()
    text += b" " * (length - len(text))
    plain = tmp_path / "plain.glb"
    plain.write_bytes(glb[:20] + text + glb[20 + length :])
    script = (
        "import { SurfaceMismatchError, ThreeRevisionError, loadSurface }"
        f" from {json.dumps((hopper / 'core' / 'index.js').as_uri())};"
        + FILE_FETCH
        + f"console.log(JSON.stringify(await caught(loadSurface({json.dumps(plain.as_uri())}))));"
    )
    error = run_js(hopper, script)
    assert error["name"] == "SurfaceMismatchError"
    assert error["found"] == dict.fromkeys(error["expected"])
    assert "geometryDigest (none)" in error["message"]


def test_surface_with_other_programs_is_refused(hopper: Path, tmp_path: Path) -> None:
    """The program tapes ride in the .glb: a file whose programs are another build's (another
    programDigest, as another tier of the same mesh has), or that carries none (the surface cache's
    .glb), is refused with SurfaceMismatchError naming programDigest; the tapes it carries are the ones
    the Python reference compiles (creature/plan.py program_data)."""
    glb = surface_path(hopper).read_bytes()
    program = parse_program(glb)
    assert program is not None
    programs = program_digest(program)
    report = package_report(hopper)
    creature = compile_creature(load_spec(hopper / SPEC_PATH))
    tapes, _ = program_tapes(creature, report["tier"])
    assert program.tolist() == np.asarray(program_data(tapes), dtype=np.float32).tolist()
    other_tier, _ = tampered_glb(glb, programs)
    length = int.from_bytes(glb[12:16], "little")
    document = json.loads(glb[20 : 20 + length])
    document["nodes"][0]["extras"].pop("programAccessor")
    text = json.dumps(document, separators=(",", ":")).encode()
    bare = glb[:20] + text + b" " * (length - len(text)) + glb[20 + length :]
    assert parse_program(bare) is None
    files = {"otherTier": other_tier, "bare": bare}
    for name, data in files.items():
        (tmp_path / f"{name}.glb").write_bytes(data)
    script = (
        "import { SurfaceMismatchError, ThreeRevisionError, loadSurface }"
        f" from {json.dumps((hopper / 'core' / 'index.js').as_uri())};"
        + FILE_FETCH
        + "const out = {};"
        + "".join(
            f"out.{name} = await caught(loadSurface({json.dumps((tmp_path / f'{name}.glb').as_uri())}));"
            for name in files
        )
        + "console.log(JSON.stringify(out));"
    )
    out = run_js(hopper, script)
    for name in files:
        error = out[name]
        assert error is not None, name
        assert error["name"] == "SurfaceMismatchError", (name, error)
        assert error["expected"]["programDigest"] == programs
        assert error["found"]["programDigest"] != programs
        assert "programDigest" in error["message"], error["message"]


# --- 3. three's revision and the types -------------------------------------------------------------------


def fake_three(root: Path, revision: str) -> Path:
    """three 0.185.1's ES builds with REVISION patched: what a consumer with another release installs."""
    real = three_modules()
    fake = root / "three"
    (fake / "build").mkdir(parents=True)
    shutil.copy(real / "package.json", fake / "package.json")
    for name in ("three.webgpu.js", "three.tsl.js"):
        shutil.copy(real / "build" / name, fake / "build" / name)
    core = (real / "build" / "three.core.js").read_text()
    assert core.count("const REVISION = '185';") == 1
    (fake / "build" / "three.core.js").write_text(
        core.replace("const REVISION = '185';", f"const REVISION = '{revision}';")
    )
    return fake


def test_another_three_revision_is_refused(hopper: Path, site: Path, tmp_path: Path) -> None:
    script = (
        "import { SurfaceMismatchError, ThreeRevisionError, createCreaturePopulation }"
        f" from '{hopper.name}';"
        + FILE_FETCH
        + "console.log(JSON.stringify(await caught(createCreaturePopulation(null))));"
    )
    other = install_site(tmp_path / "r187", hopper, fake_three(tmp_path / "fake", "187"))
    error = run_js(other, script)
    assert error["name"] == "ThreeRevisionError"
    assert error["revision"]
    assert error["expected"] == "185"
    assert error["found"] == "187"
    assert f"{hopper.name}: built for three r185 (three@0.185.x); found r187" in error["message"]
    # r185 passes the check: the same call then fails on the missing renderer instead.
    error = run_js(site, script)
    assert error["name"] == "Error"
    assert "needs WebGPURenderer on a WebGPU backend" in error["message"]


DECLARED = re.compile(
    r"^export\s+(?:declare\s+)?(?:const|function|class|interface|type)\s+(\w+)", re.MULTILINE
)
RE_EXPORTED = re.compile(r"^export\s+(?:type\s+)?\{([^}]*)\}\s*from\s*'([^']+)'", re.MULTILINE)
STAR = re.compile(r"^export\s+\*\s+from\s+'([^']+)'", re.MULTILINE)


def declared_names(dts: Path) -> set[str]:
    """Names a .d.ts exports: its own declarations, re-exports and `export *` (followed)."""
    text = dts.read_text()
    names = set(DECLARED.findall(text))
    for group, _ in RE_EXPORTED.findall(text):
        names |= {n.strip() for n in group.split(",") if n.strip()}
    for target in STAR.findall(text):
        names |= declared_names((dts.parent / target).with_suffix("").with_suffix(".d.ts"))
    return names


def test_every_runtime_export_is_typed(hopper: Path, site: Path) -> None:
    package = json.loads((hopper / "package.json").read_text())
    script = (
        "const out = {};"
        "for (const sub of ['', '/core', '/tsl'])"
        f"  out[sub] = Object.keys(await import('{hopper.name}' + sub)).sort();"
        "console.log(JSON.stringify(out));"
    )
    runtime = run_js(site, script)
    for sub, names in runtime.items():
        entry = package["exports"]["." + sub]
        assert list(entry) == ["types", "default"], f"'.{sub}': the types condition must come first"
        dts = hopper / entry["types"]
        assert dts.is_file(), entry
        missing = sorted(set(names) - declared_names(dts))
        assert not missing, f"'{hopper.name}{sub}' exports {missing} without types ({entry['types']})"
    assert package["types"] == package["exports"]["."]["types"]


def test_the_string_unions_are_the_python_definitions(hopper: Path) -> None:
    """DebugMode, TierName and LocomotionType in core/index.d.ts are rendered from the values the
    runtime and the spec gate use, not written out a second time (the shipped DEBUG_MODES is that list)."""
    from creaturegen.candidates import TIERS
    from creaturegen.creature.plan import DEBUG_MODES
    from creaturegen.spec.character import LocomotionType

    text = (hopper / "core" / "index.d.ts").read_text()
    for name, values in (
        ("DebugMode", DEBUG_MODES),
        ("TierName", tuple(TIERS)),
        ("LocomotionType", typing.get_args(LocomotionType)),
    ):
        union = re.search(rf"^export type {name} = (.+);$", text, re.M)
        assert union is not None, name
        assert [json.loads(v) for v in union.group(1).split(" | ")] == list(values), name
    material = (hopper / "tsl" / "material.js").read_text()
    assert js_constant(material, "DEBUG_MODES") == list(DEBUG_MODES)


def top_level(text: str) -> str:
    """``text`` with everything inside (), [], {} and <> removed: the members of one interface body."""
    out, depth = [], 0
    for char in text:
        depth += char in "([{<"
        if depth == 0:
            out.append(char)
        depth -= char in ")]}>"
    return "".join(out)


def interface_members(dts: Path, name: str) -> set[str]:
    """The member names of ``export interface name { ... }`` (its own, not those of nested types)."""
    text = re.sub(r"/\*.*?\*/", "", dts.read_text(), flags=re.DOTALL)
    start = text.find(f"export interface {name} {{")
    assert start >= 0, f"interface {name} is missing from {dts.name}"
    opening = text.index("{", start)
    depth, end = 0, opening
    for end in range(opening, len(text)):
        depth += text[end] == "{"
        depth -= text[end] == "}"
        if depth == 0:
            break
    return set(re.findall(r"(?:readonly\s+)?(\w+)\??:", top_level(text[opening + 1 : end])))


def test_creature_data_is_typed_field_for_field(hopper: Path) -> None:
    """CREATURE is typed by CreatureData (so `createMotion(CREATURE.motion, LCG, …)` type-checks):
    every field of the plan is declared, and every field of the motion data of creatures with legs, ropes
    and wings."""
    dts = hopper / "core" / "index.d.ts"
    assert "export const CREATURE: CreatureData;" in dts.read_text()
    keys = run_js(
        hopper, "import('./core/data.js').then(m => console.log(JSON.stringify(Object.keys(m.CREATURE))))"
    )
    assert interface_members(dts, "CreatureData") == set(keys)
    shapes: dict[str, set[str]] = {
        "MotionData": set(),
        "LegData": set(),
        "RopeData": set(),
        "WingData": set(),
    }
    for name in MOTION_SHAPES:
        spec = load_spec(EXAMPLES / name)
        assert isinstance(spec, CharacterSpec)
        rig = compile_rig(spec)
        motion = build_motion(spec, rig, build_skeleton(spec, rig))
        shipped = motion.to_json()
        shapes["MotionData"] |= set(shipped)
        for field, interface in (("legs", "LegData"), ("ropes", "RopeData"), ("wings", "WingData")):
            items = shipped[field]
            assert isinstance(items, list)
            for item in items:
                assert isinstance(item, dict)
                shapes[interface] |= set(item)
    for interface, fields in shapes.items():
        assert fields, f"no example has {interface}"
        assert interface_members(dts, interface) == fields, interface
    union = re.search(r"export type LocomotionType = ([^;]+);", dts.read_text())
    assert union
    assert set(re.findall(r"[\"']([a-z]+)[\"']", union.group(1))) == set(typing.get_args(LocomotionType))


def test_types_peer_and_three_pin_are_declared(hopper: Path) -> None:
    package = json.loads((hopper / "package.json").read_text())
    assert (
        package["peerDependencies"]["@types/three"]
        == package["peerDependencies"]["three"]
        == ">=0.185.0 <0.186.0"
    )
    assert package["peerDependenciesMeta"] == {"@types/three": {"optional": True}}
    readme = (hopper / "README.md").read_text()
    assert f"npm install {hopper.name} three@0.185\n" in readme
    assert "@types/three@0.185" in readme
    assert "optional peer" in readme
    assert "ThreeRevisionError" in readme


# --- 4. the README page ---------------------------------------------------------------------------------


def code_blocks(readme: str, language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```$", readme, re.MULTILINE | re.DOTALL)


def readme_page(package: Path) -> tuple[str, str]:
    """The README's index.html and main.js, as written."""
    readme = (package / "README.md").read_text()
    (html,) = code_blocks(readme, "html")
    scripts = [b for b in code_blocks(readme, "js") if "renderer.setAnimationLoop" in b]
    assert len(scripts) == 1, "the README shows one complete page script"
    return html, scripts[0]


def test_readme_page_is_the_shipped_example(hopper: Path) -> None:
    html, script = readme_page(hopper)
    example = (hopper / "examples" / "minimal.js").read_text()
    header, _, body = example.partition("\n")
    assert header.startswith("// Code generated by creaturegen")
    assert script == body, "README main.js and examples/minimal.js differ"
    assert '<script type="module" src="./main.js"></script>' in html
    for piece in (
        "new THREE.WebGPURenderer(",
        "await renderer.init();",
        "renderer.setPixelRatio(",
        "renderer.setSize(",
        "document.body.appendChild(renderer.domElement);",
        "new THREE.Scene()",
        "new THREE.PerspectiveCamera(",
        "Light(",
        "window.addEventListener('resize'",
        "renderer.setAnimationLoop(",
        "population.update(",
        "renderer.render(scene, camera);",
    ):
        assert piece in script, piece
    imports = re.findall(r"^import .* from '([^']+)';$", script, re.MULTILINE)
    assert imports == ["three/webgpu", hopper.name], "the page uses three and the package entry only"
    # The shipped-code rules hold for it too (no clock of its own: dt comes from the frame timestamps).
    assert lint_sources({"tsl/examples-minimal.js": example}) == []


#: Counts animation frames, so the test waits for the loop rather than for a fixed time.
FRAME_COUNTER = """
window.__frames = 0;
window.__failed = false;
const raf = window.requestAnimationFrame.bind(window);
window.requestAnimationFrame = (fn) => raf((t) => { window.__frames += 1; fn(t); });
window.addEventListener('error', () => { window.__failed = true; });
window.addEventListener('unhandledrejection', () => { window.__failed = true; });
"""


#: The page's canvas as a PNG data URL, taken in an animation frame right after the page's own (a WebGPU
#: canvas holds its picture only until the frame is presented; page screenshots do not see it headless).
GRAB_CANVAS = """() => new Promise((resolve) => requestAnimationFrame(() => {
  resolve(document.querySelector('canvas').toDataURL('image/png'));
}))"""


@pytest.mark.browser
def test_readme_page_runs_as_written(hopper: Path, tmp_path: Path) -> None:
    """index.html and main.js exactly as the README shows them, beside a node_modules with three and the
    package: the page renders frames and the lit body shows (neither background nor black)."""
    import imageio.v3 as iio
    from playwright.sync_api import sync_playwright

    from creaturegen.lab.browser import CHROMIUM_FLAGS, find_chromium
    from creaturegen.lab.server import serve

    html, script = readme_page(hopper)
    root = install_site(tmp_path / "page", hopper)
    (root / "index.html").write_text(html)
    (root / "main.js").write_text(script)
    errors: list[str] = []
    with serve(root) as base, sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=find_chromium(playwright), args=list(CHROMIUM_FLAGS)
        )
        try:
            page = browser.new_page(viewport={"width": 320, "height": 240})
            page.on("pageerror", lambda e: errors.append(f"{e.name}: {e.message}"))
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            failed: list[str] = []
            page.on("response", lambda r: failed.append(r.url) if r.status >= 400 else None)
            page.add_init_script(FRAME_COUNTER)
            page.goto(f"{base}index.html", wait_until="load")
            page.wait_for_function("() => window.__frames > 20 || window.__failed", timeout=120_000)
            missing = [url for url in failed if not url.endswith("/favicon.ico")]
            assert not missing, missing
            assert not [e for e in errors if "status of 404" not in e], errors
            shot = iio.imread(base64.b64decode(page.evaluate(GRAB_CANVAS).split(",", 1)[1]))
        finally:
            browser.close()
    rgb = np.asarray(shot)[..., :3].astype(int)
    background = np.array([0x1D, 0x24, 0x30])
    body = np.abs(rgb - background).sum(axis=2) > 40
    assert body.mean() > 0.02, f"the body covers {body.mean():.3%} of the page"
    assert rgb[body].mean() > 40, "the body renders (almost) black: is the scene lit?"


def npm() -> str:
    found = shutil.which("npm")
    assert found is not None, "npm must be on PATH"
    return found


def packed(package: Path, destination: Path) -> tuple[list[str], Path]:
    """`npm pack` of the package (what npm publishes and installs): its file list and the tarball."""
    done = subprocess.run(
        [npm(), "pack", "--json", "--pack-destination", str(destination)],
        cwd=package,
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    (info,) = json.loads(done.stdout)
    return sorted(f["path"] for f in info["files"]), destination / info["filename"]


@pytest.fixture(scope="module")
def typescript(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A scratch project with three, @types/three and TypeScript from npm (once per run), or a skip that
    says why when the registry cannot be reached."""
    root = shared_folder(tmp_path_factory, "ts-consumer")
    if not (root / "node_modules" / "typescript").is_dir():
        (root / "package.json").write_text('{ "name": "consumer", "private": true, "type": "module" }\n')
        done = subprocess.run(
            [npm(), "install", "--no-audit", "--no-fund", "three@0.185.1", THREE_TYPES, TYPESCRIPT],
            cwd=root,
            capture_output=True,
            text=True,
            check=False,
            timeout=300,
        )
        if done.returncode != 0:
            missing_setup(f"npm could not install TypeScript and {THREE_TYPES}: {done.stderr.strip()[-300:]}")
    return root


#: What the README's core section writes, with a locally declared error check.
CORE_USE = """
import * as THREE from 'three/webgpu';
import { CREATURE, LCG, SurfaceMismatchError, builtinSupports, createGravity, createMotion } from '{slug}';
import { createCreaturePopulation, layoutOf } from '{slug}/tsl';
import { drawGenome } from '{slug}/core';

const support = builtinSupports().flat;
const motion = createMotion(CREATURE.motion, LCG, { support, gravity: createGravity(), seed: 7 });
motion.stepTicks(10);
const genome: Float64Array = drawGenome(7, LCG);
export async function start(renderer: THREE.WebGPURenderer): Promise<number> {
  try {
    const population = await createCreaturePopulation(renderer, { assetBase: '/static/', capacity: 4 });
    return population.pageSize + layoutOf(CREATURE).vertices + genome.length;
  } catch (error) {
    if (error instanceof SurfaceMismatchError) return error.found.geometryDigest === null ? -1 : -2;
    throw error;
  }
}
"""


def test_readme_code_type_checks_strictly(hopper: Path, typescript: Path, tmp_path: Path) -> None:
    """The README page (main.js, checked as JavaScript) and the core API as the README uses it (TypeScript)
    under `tsc --strict`, against the package as npm installs it and @types/three."""
    files, tarball = packed(hopper, tmp_path)
    project = tmp_path / "project"
    shutil.copytree(typescript, project, symlinks=True)
    target = project / "node_modules" / hopper.name
    shutil.rmtree(target, ignore_errors=True)
    with tarfile.open(tarball) as archive:
        archive.extractall(tmp_path / "unpacked", filter="data")
    shutil.move(tmp_path / "unpacked" / "package", target)
    _, script = readme_page(hopper)
    (project / "main.js").write_text(script)
    (project / "use.ts").write_text(CORE_USE.replace("{slug}", hopper.name))
    tsc = project / "node_modules" / "typescript" / "bin" / "tsc"
    common = [
        "--strict",
        "--noEmit",
        "--target",
        "es2022",
        "--module",
        "esnext",
        "--moduleResolution",
        "bundler",
    ]
    for sources in (["--allowJs", "--checkJs", "main.js"], ["use.ts"]):
        done = subprocess.run(
            [node(), str(tsc), *common, *sources],
            cwd=project,
            capture_output=True,
            text=True,
            check=False,
            timeout=300,
        )
        assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "examples/minimal.js" in files


# --- 5. what ships ----------------------------------------------------------------------------------------


def test_npm_ships_what_runs(hopper: Path, tmp_path: Path) -> None:
    files, _ = packed(hopper, tmp_path)
    code = sorted(
        p.relative_to(hopper).as_posix()
        for folder in ("core", "tsl", "examples")
        for p in (hopper / folder).rglob("*")
        if p.is_file()
    )
    expected = {"package.json", "README.md", "index.js", "index.d.ts", SPEC_PATH, *code}
    expected.add(surface_path(hopper).relative_to(hopper).as_posix())
    assert set(files) == expected
    assert REPORT_PATH not in files
    assert SIDECAR_PATH not in files
    runtime = "\n".join((hopper / f).read_text() for f in files if f.endswith(".js"))
    assert "surface.json" not in runtime, "the runtime reads the sidecar, so it must ship"
    assert json.loads((hopper / "package.json").read_text())["license"] == "MIT"


def test_shipped_spec_has_no_dangling_schema(hopper: Path) -> None:
    authored = (EXAMPLES / HOPPER).read_bytes()
    assert b'"$schema"' in authored, "the example no longer names a schema: this test checks nothing"
    shipped = (hopper / SPEC_PATH).read_bytes()
    assert shipped == shipped_spec(authored)
    assert "$schema" not in json.loads(shipped)
    expected = validate_bytes(authored, "authored")
    rebuilt = validate_bytes(shipped, "shipped")
    assert isinstance(expected, CharacterSpec)
    assert isinstance(rebuilt, CharacterSpec)
    assert signatures(compile_rig(rebuilt)) == signatures(compile_rig(expected))
    plain = json.dumps({"name": "x"}).encode()
    assert shipped_spec(plain) == plain, "a spec without $schema ships byte for byte"


#: Markdown links and images, and HTML src/href attributes.
LINK = re.compile(r"\]\(([^)\s]+)\)|\b(?:src|href)=\"([^\"]+)\"")


def test_readme_links_resolve_inside_the_package(hopper: Path, tmp_path: Path) -> None:
    """Every relative link of the README names a file npm ships (a site's own main.js and node_modules are
    the page's, not the package's)."""
    files, _ = packed(hopper, tmp_path)
    readme = (hopper / "README.md").read_text()
    html, _ = readme_page(hopper)
    prose = readme.replace(html, "")
    targets = [a or b for a, b in LINK.findall(prose)]
    relative = [t for t in targets if not re.match(r"[a-z]+:|#|/", t)]
    missing = [t for t in relative if t.split("#")[0] not in files]
    assert not missing, missing


def test_files_list_the_picture_the_readme_shows() -> None:
    """With a picture the README shows assets/preview.png, so `files` must list it; without, it must not."""
    from creaturegen.creature.assets import PICTURE_PATH, shipped_files

    assert PICTURE_PATH in shipped_files("assets/x-0123456789ab.glb", PICTURE_PATH)
    assert PICTURE_PATH not in shipped_files("assets/x-0123456789ab.glb", None)
