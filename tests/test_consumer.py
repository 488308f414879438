"""The consumer job: creaturegen as a user meets it, outside this repository.

A wheel of the tool is installed into a fresh venv (a normal install, not editable, without the lab
extra); that install builds two creature packages (one at the hero tier, one at the distant tier, whose
skin representation evaluates the field only on its field vertices) and a frost package; each is
``npm pack``-ed and the tarballs are installed beside three@0.185.1 into a fresh project in a temporary
folder. The project then type-checks the packages' README snippets and a typed use of every export with
``tsc --strict``, bundles one page with esbuild and with Vite, and runs the page three ways in Chromium
(WebGPU on SwiftShader): unbundled through an import map into node_modules (the reference), the esbuild
bundle and the Vite build.

What must hold: each creature renders its own body (its silhouette matches the same package's unbundled
render and not the other package's), bodies move between ticks, frost renders, no error anywhere. The
planted-defect tests show the job fails when a template is missing, when one package's asset is replaced
by another's (the old colliding-name failure), and when an export loses its type.
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from conftest import shared_folder
from creaturegen.emit.packsize import npm_json
from creaturegen.lab.browser import launch_lab_page
from creaturegen.lab.server import serve
from creaturegen.surface.cache import exclusive

REPO = Path(__file__).resolve().parent.parent
CONSUMER = REPO / "tests" / "consumer"
#: slug → (spec, tier): one package shipping hero and distant (bodies move between them), one in the lower
#: tiers' skin representation alone (surface/skin_tier.py), so both representations and a two-tier package
#: meet the wheel, the tarball, tsc and the bundlers.
CREATURES = {
    "hopper-squash-core": ("examples/reference/hopper.json", "hero,distant"),
    "quadruped-rope-tail": ("examples/reference/quadruped.json", "distant"),
}
FROST = ("frost-pane-balanced", "examples/frost/frost-balanced.json")
#: What the runtime fetches (the creature's surface, frost's structure); spec.json and preview.png are not.
RUNTIME_ASSETS = (".glb", ".bin")
#: Silhouette agreement with the package's own unbundled render, and the most it may share with the other's.
SAME_IOU = 0.97
OTHER_IOU = 0.9

pytestmark = pytest.mark.browser


def _run(
    command: list[str],
    cwd: Path,
    env: dict[str, str] | None = None,
    timeout: float = 600,
    stderr: bool = True,
) -> str:
    done = subprocess.run(
        command, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout, check=False
    )
    if done.returncode != 0:
        tail = f"{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
        pytest.fail(f"{' '.join(command)} exited {done.returncode} in {cwd}:\n{tail}")
    return done.stdout + done.stderr if stderr else done.stdout


def _npm() -> str:
    npm = shutil.which("npm")
    if npm is None:
        pytest.fail("npm is not installed (make setup needs Node.js >= 18)")
    return npm


@dataclass
class Consumer:
    root: Path  # the fresh project
    build_logs: dict[str, str]
    tarballs: dict[str, Path]
    env: dict[str, str]


def _wheel(factory: pytest.TempPathFactory) -> Path:
    """The tool's wheel, built once per run: ``pip wheel`` of the checkout builds in its ``build/`` folder,
    and two xdist workers building there at once break each other's build ("could not delete")."""
    folder = shared_folder(factory, "consumer-wheel")
    with exclusive(folder / ".lock"):
        found = sorted(folder.glob("creaturegen-*.whl"))
        if not found:
            pip = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet"]
            _run([*pip, "-w", str(folder), str(REPO)], folder)
            found = sorted(folder.glob("creaturegen-*.whl"))
    return found[0]


@pytest.fixture(scope="module")
def consumer(tmp_path_factory: pytest.TempPathFactory) -> Consumer:
    """Wheel → fresh venv → builds → npm pack → fresh project with the tarballs, esbuild and Vite bundles."""
    work = tmp_path_factory.mktemp("consumer")
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    env["CREATUREGEN_PICTURE"] = "auto"  # as a user has it: the build says why it cannot draw the picture
    wheel = _wheel(tmp_path_factory)
    _run([sys.executable, "-m", "venv", str(work / "venv")], work)
    pip = work / "venv" / "bin" / "pip"
    _run([str(pip), "install", "--quiet", "--disable-pip-version-check", str(wheel)], work, env)
    tool = work / "venv" / "bin" / "creaturegen"
    logs = {}
    for slug, (spec, tier) in CREATURES.items():
        command = [str(tool), "build", str(REPO / spec), "--tier", tier, "-o", str(work / "out")]
        logs[slug] = _run(command, work, env)
    logs[FROST[0]] = _run([str(tool), "build", str(REPO / FROST[1]), "-o", str(work / "out")], work, env)
    tarballs = {}
    npm = _npm()
    for slug in [*CREATURES, FROST[0]]:
        packed = npm_json(_run([npm, "pack", "--json", "--pack-destination", str(work)], work / "out" / slug))
        tarballs[slug] = work / packed[0]["filename"]
    app = work / "app"
    app.mkdir()
    for name in ("package.json", "package-lock.json", "page.js"):
        shutil.copy(CONSUMER / name, app / name)
    packages = json.dumps([*CREATURES, FROST[0]])
    config = (CONSUMER / "vite.config.js").read_text().replace("exclude: []", f"exclude: {packages}")
    (app / "vite.config.js").write_text(config)
    _run([npm, "ci", "--no-audit", "--no-fund"], app)
    _run([npm, "install", "--no-audit", "--no-fund", "--no-save", *map(str, tarballs.values())], app)
    _write_entry(app)
    return Consumer(app, logs, tarballs, env)


def _write_entry(app: Path) -> None:
    """entry.js imports the packages by name, as an app does; the HTML pages load it three ways."""
    a, b = CREATURES
    (app / "entry.js").write_text(
        f"import * as a from '{a}';\nimport * as b from '{b}';\nimport * as frost from '{FROST[0]}';\n"
        "import { report, runConsumer } from './page.js';\n\n"
        "report(runConsumer({ creatures: [a, b], frost }));\n"
    )
    imports = {
        "three": "/node_modules/three/build/three.webgpu.js",
        "three/webgpu": "/node_modules/three/build/three.webgpu.js",
        "three/tsl": "/node_modules/three/build/three.tsl.js",
        **{slug: f"/node_modules/{slug}/index.js" for slug in [*CREATURES, FROST[0]]},
    }
    importmap = json.dumps({"imports": imports})
    (app / "unbundled.html").write_text(
        f'<!doctype html><link rel="icon" href="data:,"><script type="importmap">{importmap}</script>'
        '<script type="module" src="/entry.js"></script>\n'
    )
    (app / "index.html").write_text(
        '<!doctype html><link rel="icon" href="data:,"><script type="module" src="/entry.js"></script>\n'
    )
    (app / "esbuild.html").write_text(
        '<!doctype html><link rel="icon" href="data:,">'
        '<script type="module" src="/dist-esbuild/entry.js"></script>\n'
    )


def _esbuild(app: Path) -> None:
    """esbuild bundles the JS; it does not rewrite ``new URL('../assets/…', import.meta.url)``, so (as the
    package READMEs say) the packages' runtime assets are copied into an ``assets/`` folder beside the
    bundle's folder, where those URLs point. Unique names per package mean nothing is overwritten."""
    _run(["npx", "esbuild", "entry.js", "--bundle", "--format=esm", "--outdir=dist-esbuild"], app)
    assets = app / "assets"
    assets.mkdir(exist_ok=True)
    for slug in [*CREATURES, FROST[0]]:
        for file in (app / "node_modules" / slug / "assets").iterdir():
            if file.suffix not in RUNTIME_ASSETS:
                continue
            target = assets / file.name
            assert not target.exists(), f"{file.name} of {slug} collides with another package's asset"
            shutil.copy(file, target)


def _run_page(root: Path, page: str) -> dict[str, Any]:
    with serve(root) as base:
        return _open_page(base + page)


def _open_page(url: str) -> dict[str, Any]:
    with launch_lab_page(url, timeout_s=240) as lab:
        result: dict[str, Any] = lab.page.evaluate("() => window.__lab")
        result["console"] = [line for line in lab.console if line.startswith(("[error]", "[warning]"))]
        result["pageErrors"] = list(lab.page_errors)
    return result


def _masks(result: dict[str, Any]) -> dict[str, list[np.ndarray]]:
    size = int(result["size"])
    return {
        body["slug"]: [
            np.frombuffer(base64.b64decode(m), dtype=np.uint8).reshape(size, size) for m in body["masks"]
        ]
        for body in result["bodies"]
    }


def _tier_masks(result: dict[str, Any]) -> dict[tuple[str, str], np.ndarray]:
    """(slug, tier) → the body drawn by that coarser tier at the last tick (page.js tierMasks)."""
    size = int(result["size"])
    return {
        (body["slug"], tier): np.frombuffer(base64.b64decode(m), dtype=np.uint8).reshape(size, size)
        for body in result["bodies"]
        for tier, m in body.get("tierMasks", {}).items()
    }


def _iou(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.logical_and(a, b).sum() / max(np.logical_or(a, b).sum(), 1))


@pytest.fixture(scope="module")
def reference(consumer: Consumer) -> dict[str, Any]:
    result = _run_page(consumer.root, "unbundled.html")
    _assert_clean(result)
    return result


def _assert_clean(result: dict[str, Any]) -> None:
    assert result.get("error") is None, f"{result.get('error')}\n{result.get('stack', '')}"
    assert result["errors"] == [], result["errors"]
    assert result["console"] == [], result["console"]
    assert result["pageErrors"] == [], result["pageErrors"]
    assert result["revision"] == "185"


def test_installed_tool_builds_quietly(consumer: Consumer) -> None:
    """A normal install writes whole packages, says in one line what the missing lab extra would add, and
    passes on no driver noise."""
    for slug, log in consumer.build_logs.items():
        assert "XDG_RUNTIME_DIR" not in log, f"{slug}: driver noise reached the user"
        assert "Traceback" not in log
        package = consumer.tarballs[slug]
        assert package.stat().st_size > 0
    for slug in CREATURES:
        assert "pip install 'creaturegen[lab]'" in consumer.build_logs[slug]
    listing = _run(["tar", "-tzf", str(consumer.tarballs[CREATURES.__iter__().__next__()])], consumer.root)
    for required in (
        "package/index.js",
        "package/index.d.ts",
        "package/tsl/population.js",
        "package/README.md",
    ):
        assert required in listing
    assert "package/build-report.json" not in listing


def test_unbundled_reference_renders_two_creatures_and_frost(reference: dict[str, Any]) -> None:
    masks = _masks(reference)
    assert set(masks) == set(CREATURES)
    for slug, (first, second) in masks.items():
        assert first.mean() > 0.02, f"{slug}: the body covers almost nothing"
        moved = float(np.logical_xor(first, second).mean())
        assert moved > 0.002, f"{slug}: the body did not move between ticks ({moved:.4f} of pixels changed)"
    a, b = (masks[s][0] for s in CREATURES)
    assert _iou(a, b) < OTHER_IOU, "two different creatures render the same silhouette"
    # The two-tier hopper drawn by its distant tier: the same body, from its own lighter mesh.
    tiers = _tier_masks(reference)
    assert set(tiers) == {("hopper-squash-core", "distant")}
    coarse = tiers[("hopper-squash-core", "distant")]
    assert _iou(coarse, masks["hopper-squash-core"][-1]) > OTHER_IOU, "the distant tier draws another body"
    assert reference["frost"]["litPixels"] > 0.9 * reference["size"] ** 2


@pytest.mark.parametrize("bundler", ["esbuild", "vite-build", "vite-dev"])
def test_bundled_page_matches_the_unbundled_one(
    consumer: Consumer, reference: dict[str, Any], bundler: str
) -> None:
    if bundler == "esbuild":
        _esbuild(consumer.root)
        result = _run_page(consumer.root, "esbuild.html")
    elif bundler == "vite-build":
        _run(
            ["npx", "vite", "build", "--outDir", "dist-vite", "--emptyOutDir", "--logLevel", "warn"],
            consumer.root,
        )
        result = _run_page(consumer.root / "dist-vite", "index.html")
    else:
        with _vite_dev(consumer.root) as base:
            result = _open_page(base + "index.html")
    _assert_clean(result)
    got, want = _masks(result), _masks(reference)
    for slug in CREATURES:
        other = next(s for s in CREATURES if s != slug)
        for tick in range(2):
            same = _iou(got[slug][tick], want[slug][tick])
            assert same >= SAME_IOU, f"{bundler}: {slug} tick {tick} IoU {same:.3f} with its own render"
        assert _iou(got[slug][0], want[other][0]) < OTHER_IOU, f"{bundler}: {slug} renders {other}'s body"
    for key, coarse in _tier_masks(reference).items():
        same = _iou(_tier_masks(result)[key], coarse)
        assert same >= SAME_IOU, f"{bundler}: {key} IoU {same:.3f} with its own unbundled render"
    assert result["frost"]["litPixels"] > 0.9 * result["size"] ** 2


@contextlib.contextmanager
def _vite_dev(root: Path) -> Iterator[str]:
    """Vite's dev server (dependency pre-bundling included) on a free port, stopped afterwards."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    server = subprocess.Popen(
        ["npx", "vite", "--host", "127.0.0.1", "--port", str(port), "--strictPort"],
        cwd=root,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        base = f"http://127.0.0.1:{port}/"
        for _ in range(600):
            try:
                with urllib.request.urlopen(base, timeout=1):
                    break
            except OSError:
                if server.poll() is not None:
                    pytest.fail(f"vite dev server exited: {server.stdout.read() if server.stdout else ''}")
                time.sleep(0.1)
        yield base
    finally:
        server.terminate()
        server.wait(timeout=20)


def test_typescript_strict(consumer: Consumer) -> None:
    """The README snippets shipped in each package and a typed use of the API type-check with --strict."""
    snippets = [
        str(p.relative_to(consumer.root))
        for slug in [*CREATURES, FROST[0]]
        for p in sorted((consumer.root / "node_modules" / slug / "examples").glob("*.[jt]s"))
    ]
    assert len(snippets) >= 3, f"every package ships its README snippet as a file (found {snippets})"
    _tsc(consumer.root, snippets)


def _tsc(root: Path, files: list[str]) -> str:
    shutil.copy(CONSUMER / "typed.ts", root / "typed.ts")
    config = {
        "compilerOptions": {
            "strict": True,
            "noEmit": True,
            "allowJs": True,
            "checkJs": True,
            "target": "ES2022",
            "module": "ESNext",
            "moduleResolution": "Bundler",
            "skipLibCheck": True,
            "lib": ["ES2022", "DOM"],
        },
        "files": ["typed.ts", *files],
    }
    (root / "tsconfig.json").write_text(json.dumps(config, indent=2))
    return _run(["npx", "tsc", "-p", "tsconfig.json"], root)


# --- planted defects ------------------------------------------------------------------------------


def test_planted_missing_template_is_an_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An install without its templates refuses to build (exit 2, nothing written) instead of writing a
    package with no JavaScript."""
    from creaturegen import resources
    from creaturegen.cli import main

    empty = tmp_path / "pkg"
    (empty / "templates").mkdir(parents=True)
    monkeypatch.setattr(resources.resources, "files", lambda _name: empty)
    out = tmp_path / "out"
    code = main(["build", str(REPO / FROST[1]), "-o", str(out)])
    assert code == 2
    assert not out.exists() or not any(out.iterdir())


def test_planted_swapped_asset_fails(consumer: Consumer, reference: dict[str, Any]) -> None:
    """One package's .glb under the other's name (what a shared ``assets/surface.glb`` did) is refused by
    name at load, so the page fails instead of drawing the wrong body."""
    planted = consumer.root.parent / "planted-app"
    shutil.copytree(consumer.root, planted, symlinks=True, ignore=shutil.ignore_patterns("dist-vite"))
    if not (planted / "dist-esbuild").is_dir():
        _esbuild(planted)
    a, b = (
        next(p for p in (planted / "node_modules" / slug / "assets").iterdir() if p.suffix == ".glb")
        for slug in CREATURES
    )
    shutil.copy(b, planted / "assets" / a.name)
    result = _run_page(planted, "esbuild.html")
    assert result.get("error"), "the page drew a body from another package's asset"
    assert "Mismatch" in result["error"], result["error"]


def test_planted_untyped_export_fails(consumer: Consumer) -> None:
    """Removing one export's declaration from a package's diagnostics entry types makes the strict
    type-check fail (the entry is resolved through package.json "exports")."""
    slug = next(iter(CREATURES))
    dts = consumer.root / "node_modules" / slug / "tsl" / "diagnostics.d.ts"
    original = dts.read_text()
    planted = original.replace("export function createDiagnostics", "declare function createDiagnostics")
    assert planted != original
    try:
        dts.write_text(planted)
        with pytest.raises(pytest.fail.Exception, match="createDiagnostics"):
            _tsc(consumer.root, [])
    finally:
        dts.write_text(original)
