"""Shared paths for the test suite."""

from __future__ import annotations

import importlib
import importlib.util
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.backends import NumpyBackend
from creaturegen.surface.cache import exclusive
from creaturegen.surface.extract import Extraction, extract
from creaturegen.surface.field64 import BodyField
from creaturegen.surface.grid import Grid, make_grid
from creaturegen.surface.sampling import sample_band

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
#: The six conformance specs live beside the checkout (CI clones with shared/ beside it).
SHARED_REFERENCE_SPECS = REPO.parent / "shared" / "reference-specs"
#: Every creature example (paths under examples/); each builds with every gate.
CREATURE_EXAMPLES = [
    "reference/biped.json",
    "reference/flyer.json",
    "reference/hexapod.json",
    "reference/hopper.json",
    "reference/quadruped.json",
    "reference/swimmer.json",
    "beetle.json",
    "lizard.json",
    "moth.json",
]
#: ``make test-full`` (CREATUREGEN_TEST_FULL=1) runs the per-example browser parity jobs on every example;
#: ``make test`` on a fixed subset that covers every locomotion family the runtime has (hop, walk with a rope
#: tail, swim, flight), so that it stays near its time budget on two cores. ``make parity`` and ``make
#: bestiary`` run the parity job of every example too.
TEST_FULL = os.environ.get("CREATUREGEN_TEST_FULL") == "1"
PARITY_SUBSET = [
    "reference/hopper.json",
    "reference/quadruped.json",
    "reference/swimmer.json",
    "reference/flyer.json",
]
PARITY_EXAMPLES = CREATURE_EXAMPLES if TEST_FULL else PARITY_SUBSET
#: Frost examples whose full parity job runs in ``make test`` ("default" is the bare spec, the defaults'
#: acceptance); every one in ``make test-full``.
FROST_PARITY_SUBSET = ("default", "frost-budgeted")

#: Creature specs under tests/fixtures/ that the motion tests (gates, envelope, JS core parity, allocation)
#: run beside the examples, named ``fixtures/<file>``; the browser parity jobs do not build them. The spider
#: is an octopod; the kangaroo a hopper on its two hind legs.
MOTION_FIXTURES = ["fixtures/spider.json", "fixtures/kangaroo.json"]


def spec_file(name: str) -> Path:
    """The spec a test names: ``fixtures/<file>`` under tests/, anything else under examples/."""
    if name.startswith("fixtures/"):
        return REPO / "tests" / name
    return EXAMPLES / name


@pytest.fixture
def repo() -> Path:
    return REPO


def shared_folder(factory: pytest.TempPathFactory, name: str) -> Path:
    """A folder for the whole run. Under pytest-xdist (``make test`` runs two workers) each worker has a
    base temp of its own, and their parent is the run's: the workers share the folder there, so an example
    is extracted and packaged once per run, not once per worker."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        folder = factory.getbasetemp().parent / name
        folder.mkdir(exist_ok=True)
        return folder
    return factory.mktemp(name)


@contextmanager
def environment(name: str, value: str) -> Iterator[None]:
    """``$name`` set to ``value`` (seen by CLI children too) for the block, then as it was."""
    previous = os.environ.get(name)
    os.environ[name] = value
    try:
        yield
    finally:
        if previous is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = previous


@pytest.fixture(scope="session", autouse=True)
def surface_cache_root(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """One surface cache for the whole run, also seen by CLI children through $CREATUREGEN_CACHE:
    every example is extracted once, whichever test (or worker) builds it first (surface, package or
    parity); SurfaceCache.building makes a second worker wait for the first one's entry."""
    root = str(shared_folder(tmp_path_factory, "surface-cache"))
    with environment("CREATUREGEN_CACHE", root):
        yield root


@pytest.fixture(scope="session", autouse=True)
def one_envelope_process() -> Iterator[None]:
    """The pytest workers already fill the machine's cores: builds step their motion envelope in-process
    ($CREATUREGEN_WORKERS, motion/envelope.py); test_motion_envelope.py sets it to test the worker path."""
    with environment("CREATUREGEN_WORKERS", "1"):
        yield


@pytest.fixture(scope="session", autouse=True)
def no_build_pictures() -> Iterator[None]:
    """Builds in tests skip the README picture (a Chromium launch each) through $CREATUREGEN_PICTURE;
    test_creature_picture.py asks for it explicitly with --picture on."""
    with environment("CREATUREGEN_PICTURE", "off"):
        yield


@pytest.fixture(scope="session")
def creature_out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One output folder for example packages, shared by every test (and worker) that needs a built
    creature."""
    return shared_folder(tmp_path_factory, "creature-out")


def build_example(name: str, out_root: Path, tier: str = "hero") -> Path:
    """examples/<name> (or a ``fixtures/`` spec, see spec_file) built through the command line into
    ``out_root`` (``out_root/<tier>`` for a tier other than hero; once per run: a worker that finds another
    one building it waits, then uses its package)."""
    import json

    from creaturegen.spec import slugify

    spec = spec_file(name)
    slug = slugify(json.loads(spec.read_text())["name"])
    if tier != "hero":
        out_root = out_root / tier
        out_root.mkdir(parents=True, exist_ok=True)
    package = out_root / slug
    with exclusive(out_root / f".{slug}.lock"):
        if not package.exists():
            result = run_cli("build", str(spec), "-o", str(out_root), "--tier", tier)
            assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-4000:]
    return package


def node() -> str:
    found = shutil.which("node")
    assert found is not None, "node (20+) must be on PATH"
    return found


def run_node_tests(script: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """``node --test`` on tests/js/<script> with ``env`` added: the JS core against a Python reference.
    Fails the caller's assertion unless every test passed."""
    done = subprocess.run(
        [node(), "--test", "--test-reporter=spec", str(REPO / "tests" / "js" / script)],
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, **env},
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert re.search(r"\bfail 0\b", done.stdout), done.stdout
    return done


def run_cli(*args: str, cwd: Path = REPO) -> subprocess.CompletedProcess[str]:
    """The installed command line in a child process, as a user runs it."""
    return subprocess.run(
        [sys.executable, "-m", "creaturegen.cli", *args], capture_output=True, text=True, check=False, cwd=cwd
    )


def load_bench(name: str) -> ModuleType:
    """bench/<name>.py as a module, the way `python bench/<name>.py` sees its folder on sys.path."""
    folder = str(REPO / "bench")
    if folder not in sys.path:
        sys.path.insert(0, folder)
    spec = importlib.util.spec_from_file_location(f"bench_{name}", REPO / "bench" / f"{name}.py")
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while the class is created
    spec.loader.exec_module(module)
    return module


def json_numbers(value: Any, path: str = "") -> Iterator[tuple[str, float]]:
    """Every number in a JSON value with its path (booleans are not numbers here)."""
    if isinstance(value, bool):
        return
    if isinstance(value, int | float):
        yield path, float(value)
    elif isinstance(value, dict):
        for key, item in value.items():
            yield from json_numbers(item, f"{path}.{key}")
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from json_numbers(item, f"{path}[{i}]")


@dataclass(frozen=True)
class RestSurface:
    """A creature's rest surface on the first lattice of a tier, sampled with numpy: where the surface
    tests start (the build adds refinement, the cache and the backend choice on top)."""

    spec: CharacterSpec
    rig: CompiledRig
    grid: Grid
    field: BodyField
    extraction: Extraction


def rest_surface(path: Path, tier: str) -> RestSurface:
    spec = load_spec(path)
    assert isinstance(spec, CharacterSpec), f"{path} is not a creature spec"
    rig = compile_rig(spec)
    grid = make_grid(rig.slots, rig.graph, tier, rig.slot_parts)
    band = sample_band(grid, NumpyBackend(rig.graph, rig.slots), rig.graph, rig.slots, rig.body_scale)
    field = BodyField(rig.graph, rig.slots)
    return RestSurface(spec, rig, grid, field, extract(field, band, rig.body_scale))


#: Set by `make test` (and so CI): a missing piece of the real setup fails instead of skipping, so a
#: broken machine cannot pass by skipping the tests that need wgpu, node or npm.
STRICT_ENV = "CREATUREGEN_STRICT_SETUP"


def missing_setup(reason: str) -> None:
    """Skip for ``reason`` in a local run; fail under ``$CREATUREGEN_STRICT_SETUP=1`` (make test)."""
    if os.environ.get(STRICT_ENV) == "1":
        pytest.fail(f"{reason} (make test needs it: run `make setup`)")
    pytest.skip(reason)


def gallery_shows_every_card(page_path: Path, cards: int, invalid: int = 0) -> None:
    """The gallery from disk in Chromium: every card visible, its pictures loaded, filtering and
    sorting by the page's own controls."""
    from playwright.sync_api import sync_playwright

    from creaturegen.lab.browser import find_chromium

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=find_chromium(playwright), args=["--no-sandbox"])
        try:
            page = browser.new_page()
            errors: list[str] = []
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(page_path.as_uri())
            assert page.locator(".card:not(.hidden)").count() == cards
            images = page.locator(".card img")
            for i in range(images.count()):
                assert images.nth(i).evaluate("img => img.complete && img.naturalWidth > 0")
            assert page.inner_text("#shown") == f"{cards} of {cards} shown"
            page.select_option("#status", "invalid")
            assert page.locator(".card:not(.hidden)").count() == invalid
            page.select_option("#status", "all")
            page.fill("#filter", "zz-no-such-creature")
            assert page.locator(".card:not(.hidden)").count() == 0
            page.fill("#filter", "")
            page.select_option("#sort", "seconds")
            assert page.locator(".card:not(.hidden)").count() == cards
            assert not errors, errors
        finally:
            browser.close()
