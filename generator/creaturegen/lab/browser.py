"""Drive a lab page in headless Chromium with WebGPU on SwiftShader, through Python Playwright.

The page is the only place GPU results come from: it reads buffers back from the device and
publishes them as ``window.__lab``. This module waits for that object and hands it over as JSON
data, together with everything the page printed, so that a failure explains itself.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from playwright.sync_api import ConsoleMessage, Page, Playwright, sync_playwright
from playwright.sync_api import Error as PlaywrightError
from playwright.sync_api import TimeoutError as PlaywrightTimeoutError

#: Exactly the DESIGN.md set ("Real components"), verified on Debian 12 with Debian's chromium 156.
#: Without --enable-unsafe-webgpu there is no adapter and three silently falls back to WebGL2; the
#: swiftshader switches pin the software adapter so results do not depend on the host GPU.
#: --use-angle=swiftshader is needed as soon as a page presents WebGPU to a canvas: without it the first
#: canvas frame loses the device ("A valid external Instance reference no longer exists"), measured with
#: the frost lab; compute-only and render-target pages work either way.
CHROMIUM_FLAGS: tuple[str, ...] = (
    "--no-sandbox",
    "--enable-unsafe-webgpu",
    "--enable-features=Vulkan",
    "--use-angle=swiftshader",
    "--use-vulkan=swiftshader",
    "--use-webgpu-adapter=swiftshader",
    "--disable-vulkan-surface",
    "--disable-background-networking",
)

CHROMIUM_ENV = "CREATUREGEN_CHROMIUM"
SYSTEM_CHROMIUM = Path("/usr/bin/chromium")

#: Evaluated in the page; true once the page has finished (successfully or not).
READY_EXPRESSION = "() => Boolean(window.__lab && window.__lab.ready === true)"

_INSTALL_HINT = (
    "run `make setup` (as root it apt-installs Debian's chromium; otherwise it runs "
    "`.venv/bin/python -m playwright install chromium`), or point CREATUREGEN_CHROMIUM at a Chromium binary"
)


class LabPageError(RuntimeError):
    """The lab page could not be loaded or never published ``window.__lab.ready``."""


def _is_executable(path: Path) -> bool:
    return path.is_file() and os.access(path, os.X_OK)


def _playwright_bundled_chromium(playwright: Playwright | None) -> Path | None:
    # Playwright reports where its own download would live even when it was never installed.
    try:
        if playwright is not None:
            return Path(playwright.chromium.executable_path)
        with sync_playwright() as owned:
            return Path(owned.chromium.executable_path)
    except PlaywrightError:
        return None


def find_chromium(playwright: Playwright | None = None) -> Path:
    """Pick the browser binary: an explicit override first, then Debian's, then Playwright's download.

    An override that does not exist is an error rather than a silent fallback, so a typo can never
    make the tests run against a different browser than the one asked for.
    """
    override = os.environ.get(CHROMIUM_ENV, "").strip()
    if override:
        candidate = Path(override)
        if not _is_executable(candidate):
            raise RuntimeError(
                f"{CHROMIUM_ENV}={override!r} is not an executable file; fix or unset it ({_INSTALL_HINT})"
            )
        return candidate
    if _is_executable(SYSTEM_CHROMIUM):
        return SYSTEM_CHROMIUM
    bundled = _playwright_bundled_chromium(playwright)
    if bundled is not None and _is_executable(bundled):
        return bundled
    looked = [
        f"${CHROMIUM_ENV} (unset)",
        str(SYSTEM_CHROMIUM),
        f"Playwright's Chromium ({bundled or 'unknown'})",
    ]
    raise RuntimeError(f"no Chromium found; looked at {', '.join(looked)}. To fix: {_INSTALL_HINT}")


@dataclass
class LabPage:
    """A loaded lab page after ``window.__lab.ready``; ``lab`` is the telemetry as plain JSON data."""

    page: Page
    url: str
    executable: Path
    lab: dict[str, Any]
    console: list[str] = field(default_factory=list)
    page_errors: list[str] = field(default_factory=list)

    def transcript(self) -> str:
        """Console and page errors as one block, for assertion messages."""
        return _transcript(self.console, self.page_errors)


def _transcript(console: list[str], page_errors: list[str]) -> str:
    lines = ["console:", *(f"  {line}" for line in console or ["(empty)"])]
    lines += ["page errors:", *(f"  {line}" for line in page_errors or ["(none)"])]
    return "\n".join(lines)


def _wait_until_ready(
    page: Page, url: str, console: list[str], page_errors: list[str], timeout_s: float
) -> None:
    # Poll in short slices so an uncaught page error (e.g. a module that failed to resolve, which
    # means the page will never become ready) fails at once instead of after the whole timeout.
    deadline = time.monotonic() + timeout_s
    while True:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise LabPageError(
                f"{url} did not set window.__lab.ready within {timeout_s:g} s\n"
                f"{_transcript(console, page_errors)}"
            )
        try:
            page.wait_for_function(READY_EXPRESSION, timeout=min(remaining, 0.5) * 1000)
            return
        except PlaywrightTimeoutError:
            if page_errors:
                raise LabPageError(
                    f"{url} raised before window.__lab.ready\n{_transcript(console, page_errors)}"
                ) from None


@contextlib.contextmanager
def launch_lab_page(
    url: str,
    *,
    timeout_s: float = 90.0,
    extra_args: tuple[str, ...] = (),
    viewport: tuple[int, int] | None = None,
) -> Iterator[LabPage]:
    """Open ``url`` in a fresh headless Chromium and yield it once ``window.__lab.ready`` is true.

    A fresh browser per call keeps GPU state (pipeline caches, lost devices) from leaking between
    tests; SwiftShader start-up is cheap next to shader compilation anyway. ``viewport`` (CSS pixels)
    replaces Playwright's default 1280x720, e.g. for a page that sizes its canvas to the window.
    """
    console: list[str] = []
    page_errors: list[str] = []
    with sync_playwright() as playwright:
        executable = find_chromium(playwright)
        try:
            browser = playwright.chromium.launch(
                executable_path=executable,
                headless=True,
                args=[*CHROMIUM_FLAGS, *extra_args],
                timeout=timeout_s * 1000,
            )
        except PlaywrightError as exc:
            raise LabPageError(
                f"could not start {executable} with {' '.join(CHROMIUM_FLAGS)}: {exc}"
            ) from exc
        try:
            page = browser.new_page(
                viewport=None if viewport is None else {"width": viewport[0], "height": viewport[1]}
            )

            def on_console(message: ConsoleMessage) -> None:
                console.append(f"[{message.type}] {message.text}")

            def on_page_error(error: PlaywrightError) -> None:
                page_errors.append(f"{error.name}: {error.message}")

            page.on("console", on_console)
            page.on("pageerror", on_page_error)
            response = page.goto(url, wait_until="load", timeout=timeout_s * 1000)
            if response is None or not response.ok:
                status = "no response" if response is None else f"HTTP {response.status}"
                raise LabPageError(f"{url}: {status}")
            _wait_until_ready(page, url, console, page_errors, timeout_s)
            lab = page.evaluate("() => window.__lab")
            if not isinstance(lab, dict):
                raise LabPageError(f"{url}: window.__lab is {type(lab).__name__}, expected an object")
            yield LabPage(
                page=page,
                url=url,
                executable=executable,
                lab=lab,
                console=console,
                page_errors=page_errors,
            )
        finally:
            browser.close()
