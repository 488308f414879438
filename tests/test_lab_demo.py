"""The lab for people: the index at ``/`` (every built package with its demo, lab page and README) and the two
demo pages, which use a package through its public API only (web_lab/demo-creature.*, web_lab/demo-frost.*).

The browser tests open them headless (WebGPU on SwiftShader) in a small window, so that a frame takes a
fraction of a second (a frame stalled past the frost effect's maxInterval, 1 s, is caught up in advances of
at most that, up to catchUpSeconds). A screenshot of a WebGPU canvas is blank headless, so the frost wipe
is checked through readbacks: the effect's history (``readHistory()``) and the composite's own view of it,
rendered off-screen.
"""

from __future__ import annotations

import json
import shutil
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from conftest import build_example, shared_folder
from creaturegen.lab import server
from creaturegen.lab.browser import LabPage, launch_lab_page
from creaturegen.lab.server import WEB_LAB, package_listing, serve

CREATURE = "reference/hopper.json"
FROST = "frost/frost-balanced.json"
#: CSS pixels of the demo windows: small enough for SwiftShader to keep several frames a second.
VIEWPORT = (480, 300)
STROKE_V = 0.75
#: The wipe scrubs back and forth over u in [0.4, 0.6] on the row v = STROKE_V (history UV, v down).
STROKE_POINTS = [[0.4, STROKE_V], [0.45, STROKE_V], [0.5, STROKE_V], [0.55, STROKE_V], [0.6, STROKE_V]]
#: Far from the stroke (the visible deposit radius is 0.06 UV): the history stays untouched there.
AWAY_POINTS = [[0.5, 0.3], [0.15, STROKE_V], [0.85, STROKE_V]]


@pytest.fixture(scope="module")
def lab_out(tmp_path_factory: pytest.TempPathFactory, creature_out: Path) -> Path:
    """One creature and one frost package, built once per run, copied into an out folder of their own (the
    index must list exactly what is there)."""
    frost_out = shared_folder(tmp_path_factory, "frost-out")
    out = tmp_path_factory.mktemp("lab-demo-out")
    for package in (build_example(CREATURE, creature_out), build_example(FROST, frost_out)):
        shutil.copytree(package, out / package.name)
    return out


@pytest.fixture(scope="module")
def base_url(lab_out: Path) -> Iterator[str]:
    with serve(WEB_LAB, mounts={"out": lab_out}) as url:
        yield url


def slug_of(lab_out: Path, kind: str) -> str:
    (entry,) = [e for e in package_listing(lab_out) if e["kind"] == kind]
    return str(entry["slug"])


def fetch(url: str) -> tuple[int, bytes]:
    try:
        with urllib.request.urlopen(url, timeout=30) as response:
            return int(response.status), bytes(response.read())
    except urllib.error.HTTPError as exc:
        return exc.code, b""


def assert_clean(lab_page: LabPage) -> None:
    lab = lab_page.page.evaluate("() => ({ error: window.__lab.error, errors: window.__lab.errors })")
    assert lab["error"] is None, f"{lab['error']}\n{lab_page.transcript()}"
    assert lab["errors"] == [], lab_page.transcript()
    assert lab_page.page_errors == [], lab_page.transcript()
    console_errors = [line for line in lab_page.console if line.startswith("[error]")]
    assert console_errors == [], lab_page.transcript()


def wait_frames(lab_page: LabPage, n: int) -> None:
    frames = lab_page.page.evaluate("() => window.__lab.frames()")
    lab_page.page.wait_for_function(f"() => window.__lab.frames() >= {frames + n}", timeout=60_000)


def canvas_size(lab_page: LabPage) -> list[int]:
    size: list[int] = lab_page.page.evaluate(
        "() => { const c = document.querySelector('canvas'); return [c.width, c.height]; }"
    )
    return size


# Without a browser: the listing, the server's answers and the command's output.


def test_package_listing_reads_build_reports_and_skips_escapes(tmp_path: Path) -> None:
    out = tmp_path / "out"
    (out / "a-creature").mkdir(parents=True)
    report = {"kind": "creature", "name": "A", "package": "a-creature", "tier": "hero"}
    report |= {"workload": {"vertices": 10, "triangles": 16, "slots": 2}, "gates": [{"passed": True}]}
    (out / "a-creature" / "build-report.json").write_text(json.dumps(report))
    (out / "broken").mkdir()
    (out / "broken" / "build-report.json").write_text("{")
    (out / "no-report").mkdir()
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "build-report.json").write_text(json.dumps({"kind": "frost", "name": "X"}))
    (out / "escape").symlink_to(outside, target_is_directory=True)

    listing = {entry["slug"]: entry for entry in package_listing(out)}
    assert sorted(listing) == ["a-creature", "broken"]
    creature = listing["a-creature"]
    assert creature["demo"] == "/demo-creature.html?pkg=a-creature"
    assert creature["lab"] == "/creature.html?pkg=a-creature"
    assert creature["readme"] == "/out/a-creature/README.md"
    assert creature["tier"] == "hero"
    assert creature["figures"] == {"vertices": 10, "triangles": 16, "slots": 2, "gates passed": "1/1"}
    assert "error" in listing["broken"]
    assert "demo" not in listing["broken"]
    assert package_listing(tmp_path / "missing") == []

    with serve(WEB_LAB, mounts={"out": out}) as url:
        status, body = fetch(url + "packages.json")
        assert status == 200
        assert [e["slug"] for e in json.loads(body)["packages"]] == ["a-creature", "broken"]
        status, body = fetch(url)
        assert status == 200
        assert b"index.js" in body
        # The listing is no way around the mount's rules: neither ".." nor a symlink leaves it.
        assert fetch(url + "out/escape/build-report.json")[0] == 404
        assert fetch(url + "out/../../pyproject.toml")[0] == 404
        assert fetch(url + "out/%2e%2e/%2e%2e/pyproject.toml")[0] == 404


def test_lab_command_prints_the_index_first(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    (out / "pane").mkdir(parents=True)
    (out / "pane" / "build-report.json").write_text(json.dumps({"kind": "frost", "name": "Pane"}))

    class Stopped:
        server_address = ("127.0.0.1", 8765)

        def serve_forever(self) -> None:
            raise KeyboardInterrupt

        def server_close(self) -> None:
            return

    def fake_make_server(*args: Any, **kwargs: Any) -> Stopped:
        return Stopped()

    monkeypatch.setattr(server, "make_server", fake_make_server)
    assert server.main(["--out", str(out)]) == 0
    urls = [line.split()[0] for line in capsys.readouterr().out.splitlines() if line.startswith("    http")]
    assert urls[0] == "http://127.0.0.1:8765/"
    assert "http://127.0.0.1:8765/demo-frost.html?pkg=pane" in urls
    assert "http://127.0.0.1:8765/frost.html?pkg=pane" in urls


# In the browser.


@pytest.mark.browser
def test_index_lists_every_built_package_with_working_links(base_url: str, lab_out: Path) -> None:
    built = sorted(p.name for p in lab_out.iterdir() if (p / "build-report.json").is_file())
    assert len(built) == 2
    with launch_lab_page(base_url) as lab_page:
        assert_clean(lab_page)
        assert sorted(e["slug"] for e in lab_page.lab["packages"]) == built
        rows = lab_page.page.eval_on_selector_all(
            "#packages tbody tr",
            "rows => rows.map(r => ({ slug: r.dataset.slug,"
            " links: [...r.querySelectorAll('a')].map(a => [a.dataset.role, a.href]) }))",
        )
    assert sorted(r["slug"] for r in rows) == built
    for row in rows:
        roles = dict(row["links"])
        assert sorted(roles) == ["demo", "lab", "readme"], row
        for role, href in roles.items():
            status, body = fetch(href)
            assert status == 200, f"{row['slug']} {role}: {href} answered {status}"
            if role == "readme":
                assert body.startswith(b"<!-- Code generated by creaturegen"), body[:200]
            else:
                assert b'<script type="module"' in body
        assert roles["demo"].endswith(f"?pkg={row['slug']}")


@pytest.mark.browser
def test_creature_demo_walks_a_population(base_url: str, lab_out: Path) -> None:
    slug = slug_of(lab_out, "creature")
    url = f"{base_url}demo-creature.html?pkg={slug}&count=12"
    with launch_lab_page(url, viewport=VIEWPORT) as lab_page:
        assert_clean(lab_page)
        page = lab_page.page
        assert lab_page.lab["count"] == 12
        assert canvas_size(lab_page) == list(VIEWPORT)  # devicePixelRatio is 1 headless
        before = page.evaluate("() => window.__lab.roots()")
        tick = page.evaluate("() => window.__lab.tick()")
        wait_frames(lab_page, 4)
        page.wait_for_function(f"() => window.__lab.tick() >= {tick + 20}", timeout=60_000)
        after = page.evaluate("() => window.__lab.roots()")
        assert [b["seed"] for b in before] == list(range(1, 13))
        assert all(b["root"] is not None for b in before + after)
        scale = lab_page.lab["bodyScale"]
        moved = [
            sum((x - y) ** 2 for x, y in zip(a["root"][:3], b["root"][:3], strict=True)) ** 0.5
            for a, b in zip(before, after, strict=True)
        ]
        assert sum(m > 0.05 * scale for m in moved) >= 10, moved
        # The canvas follows the window.
        page.set_viewport_size({"width": 400, "height": 260})
        wait_frames(lab_page, 2)
        assert canvas_size(lab_page) == [400, 260]
        assert_clean(lab_page)


@pytest.mark.browser
@pytest.mark.parametrize("wiring", ["auto", "page"])
def test_frost_demo_wipes_the_pane_under_a_mouse_stroke(base_url: str, lab_out: Path, wiring: str) -> None:
    """``auto``: the package's effect.attachPointer where it has one (the page's wiring otherwise); ``page``:
    the page's own pointer events -> effect.pointer, which it falls back to for packages without it."""
    slug = slug_of(lab_out, "frost")
    has_attach = "attachPointer" in (lab_out / slug / "tsl" / "frost-effect.js").read_text(encoding="utf-8")
    views = ["final", "historyNextR"]
    points = STROKE_POINTS + AWAY_POINTS
    url = f"{base_url}demo-frost.html?pkg={slug}&pointer={wiring}"
    with launch_lab_page(url, viewport=VIEWPORT) as lab_page:
        _stroke_wipes_the_pane(lab_page, expected_source(wiring, has_attach), points, views)
        _follows_the_window(lab_page)


def expected_source(wiring: str, has_attach: bool) -> str:
    return "effect.attachPointer" if wiring == "auto" and has_attach else "page fallback"


def _stroke_wipes_the_pane(
    lab_page: LabPage, expected: str, points: list[list[float]], views: list[str]
) -> None:
    """One stroke on a frozen pane, its history and composite checked. A frame the loaded machine stalls
    past maxInterval during the stroke is caught up (counters.catchUps), so the stroke deposits anyway; only
    a stall past catchUp (a clock jump) would drop it."""
    assert_clean(lab_page)
    page = lab_page.page
    assert lab_page.lab["pointerSource"].startswith(expected)
    assert canvas_size(lab_page) == list(VIEWPORT)
    history = page.evaluate("(p) => window.__lab.history(p)", points)
    assert history["values"] == [0] * len(points), "the pane starts frozen"
    assert history["mean"] == 0, "the pane starts frozen"
    jumps = page.evaluate("() => window.__lab.counters().discontinuities")

    width, height = VIEWPORT
    page.mouse.move(0.4 * width, STROKE_V * height)
    page.mouse.down()
    for sweep in range(3):  # wipe back and forth, the way one wipes a window
        for i in range(11):
            u = 0.4 + 0.02 * (i if sweep % 2 == 0 else 10 - i)
            page.mouse.move(u * width, STROKE_V * height)
            page.wait_for_timeout(25)
    page.mouse.up()
    wait_frames(lab_page, 1)

    history = page.evaluate("(p) => window.__lab.history(p)", points)
    composite = page.evaluate("(a) => window.__lab.capture(a[0], { views: a[1] })", [points, views])
    counters = page.evaluate("() => window.__lab.counters()")
    detail = f"history {history}\ncomposite {composite}\ncounters {counters}\n{lab_page.transcript()}"
    print(f"stalled frames caught up during the test: {counters['catchUps']}")
    assert counters["discontinuities"] == jumps, f"a frame stalled past catchUp during the stroke\n{detail}"
    stroke, away = history["values"][: len(STROKE_POINTS)], history["values"][len(STROKE_POINTS) :]
    assert counters["segmentsQueued"] >= 20, detail
    assert counters["segmentsRejected"] == 0, detail
    # The thaw relaxes back within about a second (decay 1.05 /s), so these are lower bounds, not levels.
    assert min(stroke) > 0.05, detail
    assert max(stroke) > 0.2, detail
    assert max(away) == 0, detail
    assert history["mean"] > 0, detail
    # The composite pass sees the same history: its history view is lit under the stroke only.
    shown = [rgb[0] for rgb in composite["historyNextR"]]
    assert min(shown[: len(STROKE_POINTS)]) > 20, detail
    assert max(shown[len(STROKE_POINTS) :]) < 1, detail
    assert len(composite["final"]) == len(points)


def _follows_the_window(lab_page: LabPage) -> None:
    """The canvas and the effect follow the window."""
    page = lab_page.page
    page.set_viewport_size({"width": 400, "height": 260})
    wait_frames(lab_page, 2)
    assert canvas_size(lab_page) == [400, 260]
    assert page.evaluate("() => window.__lab.counters().resizes") >= 1
    assert page.evaluate("() => window.__lab.capture([]).then(c => [c.width, c.height])") == [400, 260]
    assert_clean(lab_page)
