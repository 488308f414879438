"""`creaturegen build` on frost specs: the package layout, its determinism and hygiene, hostile names,
invalid specs and the build report; what `npm pack` publishes (size, files, links, the README snippet)."""

from __future__ import annotations

import hashlib
import json
import re
import shutil
import subprocess
from pathlib import Path, PurePosixPath
from typing import Any

import pytest

from conftest import EXAMPLES, run_cli
from creaturegen.spec.types import slugify

FROST_EXAMPLES = ("frost-full", "frost-balanced", "frost-budgeted")

LAYOUT = (
    "package.json",
    "README.md",
    "index.js",
    "index.d.ts",
    "core/plan.js",
    "core/frost-core.js",
    "core/index.js",
    "core/index.d.ts",
    "core/revision.js",
    "core/structure-file.js",
    "tsl/assets.js",
    "tsl/composite.js",
    "tsl/controls.js",
    "tsl/dispatch.js",
    "tsl/frame.js",
    "tsl/frost-effect.js",
    "tsl/history.js",
    "tsl/intake.js",
    "tsl/kernels.js",
    "tsl/readback.js",
    "tsl/separable-blur.js",
    "tsl/state.js",
    "tsl/structure.js",
    "tsl/index.js",
    "tsl/index.d.ts",
    "examples/minimal.js",
    "build-report.json",
)

#: The published package of frost-full must stay this small (it was 1.53 MB with raw RGBA8 maps).
PACKED_LIMIT = 500_000

#: `<slug>-<role>-<12 hex digits of the file's sha256>.<ext>`
ASSET_NAME = re.compile(r"^(?P<slug>[a-z0-9-]+)-(?P<role>structure)-(?P<digest>[0-9a-f]{12})\.bin$")
#: A URL resolved against the module: the only form bundlers follow is a plain string literal.
STATIC_ASSET_URL = re.compile(r"""new URL\(\s*(['"])\.\./assets/([^'"`$]+)\1\s*,\s*import\.meta\.url\s*\)""")
DYNAMIC_URL = re.compile(r"new URL\(\s*(`|[A-Za-z_$])")

#: Clock and randomness reads in any spelling: `Math.random`, `performance?.now`, `Date['now']`, ...
NONDETERMINISM = re.compile(
    r"\b(Math|Date|performance)\s*(\?\.|\.)\s*(random|now)\b"
    r"|\b(Math|Date|performance)\s*(\?\.)?\s*\[\s*['\"`](random|now)['\"`]\s*\]"
)
FRUSTUM_OFF = re.compile(r"frustumCulled\s*=\s*false")
THREE_IMPORT = re.compile(r"""(from\s*|import\s*\(?\s*|require\s*\(\s*)['"]three(/[^'"]*)?['"]""")


def tree(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def build(spec: Path, out: Path) -> subprocess.CompletedProcess[str]:
    return run_cli("build", str(spec), "-o", str(out))


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Each frost example built once through the command line; example -> package folder."""
    packages = {}
    for example in FROST_EXAMPLES:
        out = tmp_path_factory.mktemp(example)
        result = build(EXAMPLES / "frost" / f"{example}.json", out)
        assert result.returncode == 0, result.stderr
        assert "wrote " in result.stdout
        spec = json.loads((EXAMPLES / "frost" / f"{example}.json").read_text())
        packages[example] = out / slugify(spec["name"])
        assert sorted(p.name for p in out.iterdir()) == [packages[example].name], "leftover staging folder"
    return packages


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_layout(built: dict[str, Path], example: str) -> None:
    folder = built[example]
    files = set(tree(folder))
    missing = [name for name in LAYOUT if name not in files]
    assert not missing, missing
    for name in LAYOUT:
        assert (folder / name).stat().st_size > 0, name


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_package_json(built: dict[str, Path], example: str) -> None:
    folder = built[example]
    package = json.loads((folder / "package.json").read_text())
    spec = json.loads((EXAMPLES / "frost" / f"{example}.json").read_text())
    assert package["name"] == slugify(spec["name"]) == folder.name
    assert package["type"] == "module"
    assert package["license"] == "MIT"
    assert package["peerDependencies"] == {
        "three": ">=0.185.0 <0.186.0",
        "@types/three": ">=0.185.0 <0.186.0",
    }
    assert package["peerDependenciesMeta"] == {"@types/three": {"optional": True}}
    exports = package["exports"]
    for entry, stem in ((".", "index"), ("./core", "core/index"), ("./tsl", "tsl/index")):
        assert exports[entry] == {"types": f"./{stem}.d.ts", "default": f"./{stem}.js"}, entry
        for target in exports[entry].values():
            assert (folder / target).is_file(), target
    assert (folder / package["main"]).is_file()
    assert (folder / package["types"]).is_file()
    assert "build-report.json" not in package["files"]
    for entry in package["files"]:
        assert (folder / entry).exists(), f"files lists {entry}, which the build did not write"


def npm_pack(folder: Path) -> dict[str, Any]:
    """What `npm pack` would publish: name, size (the .tgz bytes) and the file list."""
    npm = shutil.which("npm")
    assert npm is not None, "npm must be on PATH"
    done = subprocess.run(
        [npm, "pack", "--dry-run", "--json"],
        cwd=folder,
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    packed: dict[str, Any] = json.loads(done.stdout)[0]
    return packed


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_npm_pack_publishes_the_runtime_and_nothing_else(built: dict[str, Path], example: str) -> None:
    folder = built[example]
    packed = npm_pack(folder)
    files = packed["files"]
    assert isinstance(files, list)
    published = {str(f["path"]) for f in files}
    expected = {name for name in tree(folder) if name != "build-report.json"}
    assert published == expected
    assert not any(name.startswith("parity/") for name in published)
    if example == "frost-full":
        size = packed["size"]
        assert isinstance(size, int)
        assert size <= PACKED_LIMIT, f"frost-full packs to {size} bytes (limit {PACKED_LIMIT})"


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_asset_names_carry_the_slug_and_a_content_digest(built: dict[str, Path], example: str) -> None:
    folder = built[example]
    report = json.loads((folder / "build-report.json").read_text())
    assets = sorted((folder / "assets").iterdir())
    assert [p.name for p in assets] == [report["assets"]["structure"]["file"]]
    for path in assets:
        match = ASSET_NAME.match(path.name)
        assert match is not None, path.name
        assert match["slug"] == folder.name
        assert hashlib.sha256(path.read_bytes()).hexdigest()[:12] == match["digest"]


def test_asset_names_never_collide_between_packages(built: dict[str, Path]) -> None:
    names = [p.name for folder in built.values() for p in (folder / "assets").iterdir()]
    assert len(names) == len(set(names)) == len(built)


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_every_asset_has_one_static_url(built: dict[str, Path], example: str) -> None:
    """Bundlers follow a string-literal URL resolved against import.meta.url; a template literal or a
    variable in its place is what broke Vite's dependency optimiser."""
    folder = built[example]
    sources = {name: content.decode() for name, content in tree(folder).items() if name.endswith(".js")}
    referenced = []
    for name, text in sources.items():
        assert DYNAMIC_URL.search(text) is None or name == "tsl/assets.js", f"{name} builds a URL dynamically"
        referenced += [m.group(2) for m in STATIC_ASSET_URL.finditer(text)]
    assert sorted(referenced) == sorted(p.name for p in (folder / "assets").iterdir())


def test_url_patterns_catch_variants() -> None:
    assert STATIC_ASSET_URL.search("new URL('../assets/a-structure-0123456789ab.bin', import.meta.url)")
    assert STATIC_ASSET_URL.search('new URL( "../assets/x.bin" ,import.meta.url )')
    for dynamic in ("new URL(`../assets/${name}`, import.meta.url)", "new URL(name, import.meta.url)"):
        assert STATIC_ASSET_URL.search(dynamic) is None
        assert DYNAMIC_URL.search(dynamic)
    assert DYNAMIC_URL.search("new URL('../assets/x.bin', import.meta.url)") is None


#: Markdown links and images: [text](target) and ![alt](target).
MARKDOWN_LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
#: Package paths the README names in code spans, e.g. `examples/minimal.js` or `assets/<file>`.
PACKAGE_PATH = re.compile(r"`((?:assets|examples|core|tsl)/[^`\s]+)`")


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_readme_links_and_paths_are_published(built: dict[str, Path], example: str) -> None:
    folder = built[example]
    readme = (folder / "README.md").read_text()
    published = {str(f["path"]) for f in npm_pack(folder)["files"]}
    targets = [
        t for t in MARKDOWN_LINK.findall(readme) if not re.match(r"^[a-z]+:", t) and not t.startswith("#")
    ]
    targets += PACKAGE_PATH.findall(readme)
    assert any(t.startswith("examples/") for t in targets)
    for target in targets:
        path = PurePosixPath(target.split("#", 1)[0])
        assert str(path) in published, f"README points at {target}, which npm pack does not publish"


def test_link_patterns_catch_variants() -> None:
    text = "![final](parity/final.png) see [the guide](docs/a.md) and [site](https://x.y) `assets/z.bin`"
    assert MARKDOWN_LINK.findall(text) == ["parity/final.png", "docs/a.md", "https://x.y"]
    assert PACKAGE_PATH.findall(text) == ["assets/z.bin"]


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_readme_snippet_is_the_shipped_example(built: dict[str, Path], example: str) -> None:
    """The README's page script is examples/minimal.js byte for byte (minus its generated-code header),
    so type-checking and running that file checks the README."""
    folder = built[example]
    readme = (folder / "README.md").read_text()
    blocks = re.findall(r"```js\n(.*?)```", readme, flags=re.DOTALL)
    shipped = (folder / "examples" / "minimal.js").read_text()
    header, body = shipped.split("\n", 1)
    assert header.startswith("// Code generated by creaturegen ")
    assert blocks[0] == body
    imports = re.findall(r"""^import .* from (['"])([^'"]+)\1;$""", body, flags=re.MULTILINE)
    assert {source for _, source in imports} == {"three/webgpu", folder.name}
    for needed in (
        "new THREE.WebGPURenderer",
        "setPixelRatio",
        "setSize",
        "appendChild",
        "await renderer.init()",
        "setAnimationLoop",
        "addEventListener('resize'",
        "frost.attachPointer(renderer.domElement)",
        "frost.resize(",
        "frost.update(",
        "frost.render()",
    ):
        assert needed in body, needed


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_generated_headers(built: dict[str, Path], example: str) -> None:
    folder = built[example]
    checked = 0
    for name, content in tree(folder).items():
        text_start = content[:200]
        if name.endswith((".js", ".ts")):
            assert text_start.startswith(b"// Code generated by creaturegen "), name
            checked += 1
        elif name.endswith(".md"):
            assert text_start.startswith(b"<!-- Code generated by creaturegen "), name
            checked += 1
    assert checked >= 15


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_shipped_js_hygiene(built: dict[str, Path], example: str) -> None:
    folder = built[example]
    sources = {name: content.decode() for name, content in tree(folder).items() if name.endswith(".js")}
    assert len(sources) >= 11
    for name, text in sources.items():
        match = NONDETERMINISM.search(text)
        assert match is None, f"{name}: {match.group(0) if match else ''}"
        assert FRUSTUM_OFF.search(text) is None, name
        if name.startswith("core/"):
            assert THREE_IMPORT.search(text) is None, f"{name} imports three"
    # the TSL side does import three: the pattern itself is alive
    assert THREE_IMPORT.search(sources["tsl/frost-effect.js"])


def test_hygiene_patterns_catch_variants() -> None:
    for bad in (
        "Math.random()",
        "Date.now()",
        "performance.now()",
        "performance?.now()",
        "performance['now']()",
        'Date["now"]()',
        "Math [ `random` ]()",
        "globalThis.performance . now()",
    ):
        assert NONDETERMINISM.search(bad), bad
    for fine in ("const now = ms / 1000;", "update(last, now)", "randomSeed", "Date.UTC(2020)"):
        assert NONDETERMINISM.search(fine) is None, fine
    assert FRUSTUM_OFF.search("mesh.frustumCulled=false;")
    for bad in ("import * as T from 'three';", 'import { Fn } from "three/tsl";', "await import('three')"):
        assert THREE_IMPORT.search(bad), bad
    assert THREE_IMPORT.search("import { PLAN } from './plan.js';") is None


@pytest.mark.parametrize("example", FROST_EXAMPLES)
def test_build_report(built: dict[str, Path], example: str) -> None:
    report = json.loads((built[example] / "build-report.json").read_text())
    assert report["kind"] == "frost"
    assert report["package"] == built[example].name
    gates = report["gates"]
    assert gates
    for gate in gates:
        assert {"name", "value", "threshold", "status"} <= set(gate)
        assert gate["status"] in {"pass", "fail"}
        assert (gate["status"] == "pass") == (gate["value"] <= gate["threshold"])
    assert gates[-1]["status"] == "pass"
    chosen = report["historyFormat"]["historyFormat"]
    assert chosen in {"rgba16float", "rgba32float"}
    assert gates[-1]["name"] == f"quantisation drift ({chosen})"
    expected = {"frost-full": "rgba32float", "frost-balanced": "rgba16float", "frost-budgeted": "rgba32float"}
    assert chosen == expected[example]


def test_build_is_byte_identical(built: dict[str, Path]) -> None:
    """A second build of one spec replaces the package in place with exactly the same bytes."""
    folder = built["frost-balanced"]
    first = tree(folder)
    result = build(EXAMPLES / "frost" / "frost-balanced.json", folder.parent)
    assert result.returncode == 0, result.stderr
    second = tree(folder)
    assert sorted(first) == sorted(second)
    different = [name for name in first if first[name] != second[name]]
    assert not different, different
    assert [p.name for p in folder.parent.iterdir()] == [folder.name], "backup or staging folder left behind"


HOSTILE_NAME = "Pane \"q\" 'a' \\back\\ </script><script>x</script> ${globalThis.x} `t` é\u2028❄"


def test_hostile_name_reaches_js_only_as_json(tmp_path: Path) -> None:
    spec = json.loads((EXAMPLES / "frost" / "frost-balanced.json").read_text())
    spec.pop("$schema")
    spec["name"] = HOSTILE_NAME
    spec["structure"] = {"resolution": 64}
    spec["tier"]["historyFormat"] = "rgba16float"
    source = tmp_path / "hostile.json"
    source.write_text(json.dumps(spec), encoding="utf-8")
    out = tmp_path / "out"
    result = build(source, out)
    assert result.returncode == 0, result.stderr
    folder = out / slugify(HOSTILE_NAME)
    assert folder.name == "pane-q-a-back-script-script-x-script-globalthis-x-t"
    for name, content in tree(folder).items():
        if name.endswith((".js", ".ts")):
            text = content.decode()
            assert HOSTILE_NAME not in text, name
    plan = folder / "core" / "plan.js"
    node = shutil.which("node")
    assert node is not None, "node (20+) must be on PATH"
    script = f"import({json.dumps(plan.as_uri())}).then(m => console.log(JSON.stringify(m.PLAN.name)))"
    evaluated = subprocess.run(
        [node, "--input-type=module", "-e", script], capture_output=True, text=True, check=False, timeout=60
    )
    assert evaluated.returncode == 0, evaluated.stderr
    assert json.loads(evaluated.stdout) == HOSTILE_NAME
    package = json.loads((folder / "package.json").read_text())
    assert package["name"] == folder.name
    assert HOSTILE_NAME in package["description"]


def test_invalid_spec_writes_nothing(tmp_path: Path) -> None:
    spec = json.loads((EXAMPLES / "frost" / "frost-full.json").read_text())
    spec["brush"]["radius"] = -1.0
    source = tmp_path / "bad.json"
    source.write_text(json.dumps(spec))
    out = tmp_path / "out"
    result = build(source, out)
    assert result.returncode == 2, result.stdout + result.stderr
    assert "brush.radius" in result.stderr
    assert "Traceback" not in result.stderr
    assert not out.exists() or list(out.iterdir()) == []


def test_requested_format_that_fails_the_gate_writes_nothing(tmp_path: Path) -> None:
    spec = json.loads((EXAMPLES / "frost" / "frost-budgeted.json").read_text())
    spec.pop("$schema")
    spec["tier"]["historyFormat"] = "rgba16float"
    source = tmp_path / "half.json"
    source.write_text(json.dumps(spec))
    out = tmp_path / "out"
    result = build(source, out)
    assert result.returncode == 3, result.stdout + result.stderr  # a valid spec a build gate refuses
    assert "tier.historyFormat" in result.stderr
    assert "auto" in result.stderr
    assert not out.exists() or list(out.iterdir()) == []


def test_auto_refuses_when_no_format_passes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The format gate can fail in "auto" too: with a tolerance no format meets, nothing ships (exit 3)."""
    from creaturegen.cli import main
    from creaturegen.frost import formats

    monkeypatch.setattr(formats, "HALF_FLOAT_TOLERANCE", 0.0)
    out = tmp_path / "out"
    assert main(["build", str(EXAMPLES / "frost" / "frost-budgeted.json"), "-o", str(out)]) == 3
    assert not out.exists() or list(out.iterdir()) == []
