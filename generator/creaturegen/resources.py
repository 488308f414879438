"""Where the tool's shipped data lives: the package templates, the lab pages and the lab's three.

Templates and the lab ship inside the ``creaturegen`` package (package data), so they are found through
``importlib.resources`` the same way in a checkout, an editable install and a wheel. A missing folder or
file is an error that says what is missing: an emitter that found no template would otherwise write a
package with no JavaScript and exit 0.

The lab pages import three from ``node_modules/three``. A checkout has it under ``web_lab/node_modules``
(``make setup``); an installed tool has no node_modules, so the first command that needs the lab installs
three@0.185.1 with npm into a cache folder (``$CREATUREGEN_LAB_MODULES``, default
``~/.cache/creaturegen/lab``) and serves it from there.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

#: The three.js release every package is written for (the web lab's and the packages' pinned version).
THREE_VERSION = "0.185.1"
#: Overrides where an installed tool keeps the lab's node_modules.
LAB_MODULES_ENV = "CREATUREGEN_LAB_MODULES"


class MissingResourceError(RuntimeError):
    """Shipped data the tool needs is not where the install put it (a broken or partial install)."""


def _package_dir(name: str) -> Path:
    root = Path(str(resources.files("creaturegen"))) / name
    if not root.is_dir():
        raise MissingResourceError(
            f"creaturegen's {name}/ folder is missing from {root.parent} (a broken install): reinstall "
            "creaturegen (pip install --force-reinstall creaturegen)"
        )
    return root


def templates_dir(kind: str) -> Path:
    """``templates/<kind>/`` (creature or frost), which must hold at least the entry module."""
    folder = _package_dir("templates") / kind
    if not (folder / "index.js").is_file():
        raise MissingResourceError(
            f"creaturegen's package template {kind!r} is missing or incomplete ({folder}/index.js not "
            "found): reinstall creaturegen"
        )
    return folder


def web_lab_dir() -> Path:
    """The lab's static pages (served by lab/server.py)."""
    return _package_dir("web_lab")


def _has_three(modules: Path) -> bool:
    manifest = modules / "three" / "package.json"
    if not manifest.is_file():
        return False
    return str(json.loads(manifest.read_text()).get("version")) == THREE_VERSION


def lab_modules(install: bool = False) -> Path | None:
    """The node_modules folder holding three@THREE_VERSION for the lab, or None when there is none (and
    ``install`` is False). With ``install``, an installed tool fetches it once with npm."""
    local = web_lab_dir() / "node_modules"
    if _has_three(local):
        return local
    cache = Path(os.environ.get(LAB_MODULES_ENV) or Path.home() / ".cache" / "creaturegen" / "lab")
    modules = cache / "node_modules"
    if _has_three(modules):
        return modules
    if not install:
        return None
    npm = shutil.which("npm")
    if npm is None:
        raise MissingResourceError(
            f"the lab needs three@{THREE_VERSION} from npm and npm is not installed: install Node.js >= 18 "
            f"(it provides npm), or put a node_modules with three@{THREE_VERSION} in ${LAB_MODULES_ENV}"
        )
    cache.mkdir(parents=True, exist_ok=True)
    print(f"==> installing three@{THREE_VERSION} for the lab into {cache} (once)", file=sys.stderr)
    done = subprocess.run(
        [npm, "install", "--no-audit", "--no-fund", "--prefix", str(cache), f"three@{THREE_VERSION}"],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0 or not _has_three(modules):
        tail = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
        raise MissingResourceError(f"npm could not install three@{THREE_VERSION} into {cache}: {tail[0]}")
    return modules


def playwright_missing() -> str | None:
    """None when Playwright (the lab's browser driver, extra ``creaturegen[lab]``) imports, else the one
    line that says what to install."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return (
            "the lab needs Playwright, which this install lacks: pip install 'creaturegen[lab]' "
            "(and a Chromium: apt-get install chromium, or python -m playwright install chromium)"
        )
    return None
