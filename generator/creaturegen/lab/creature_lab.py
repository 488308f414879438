"""The creature lab session of the parity job: the lab page (web_lab/creature.html) opened on a built
package in headless Chromium (WebGPU on SwiftShader), and the decoding of what it reads back.

The README picture (lab/picture.py) opens the same page; the gates (creature_pose.py, creature_skin.py,
creature_population.py, creature_views.py) drive it through ``window.__lab``.
"""

from __future__ import annotations

import base64
import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from playwright.sync_api import Page

from .browser import LabPage, launch_lab_page
from .server import WEB_LAB, serve

DEFAULT_CANVAS = (192, 144)
#: The pose tick the GPU gates run at (away from rest: feet in swing, the hopper in the air), and the seed
#: and spawn position of instance 0 (the lab's defaults).
PARITY_TICK = 37
LAB_SEED = 1
LAB_POSITION = (0.0, 0.0, 0.0)


def b64_floats(text: str) -> npt.NDArray[np.float32]:
    return np.frombuffer(base64.b64decode(text), dtype=np.float32)


def rgba_image(shot: dict[str, Any]) -> npt.NDArray[np.uint8]:
    raw = np.frombuffer(base64.b64decode(shot["rgba"]), dtype=np.uint8)
    return raw.reshape(int(shot["height"]), int(shot["width"]), 4)


@contextlib.contextmanager
def open_creature_lab(
    package: Path, canvas: tuple[int, int] = DEFAULT_CANVAS, **query: int
) -> Iterator[Page]:
    """The creature lab page on ``package`` (any folder: its parent is served as /out/); ``query`` adds
    page parameters (capacity, pageSize, seed)."""
    with open_creature_lab_page(package, canvas, **query) as lab_page:
        yield lab_page.page


@contextlib.contextmanager
def open_creature_lab_page(
    package: Path, canvas: tuple[int, int] = DEFAULT_CANVAS, **query: int
) -> Iterator[LabPage]:
    """open_creature_lab with the page's console transcript since launch (the parity gates read it)."""
    params = {"pkg": package.name, "w": canvas[0], "h": canvas[1], "seed": LAB_SEED, **query}
    url_path = "creature.html?" + "&".join(f"{k}={v}" for k, v in params.items())
    with (
        serve(WEB_LAB, mounts={"out": package.parent}) as base,
        launch_lab_page(base + url_path, timeout_s=300) as lab_page,
    ):
        error = lab_page.lab.get("error")
        if error:
            raise RuntimeError(f"{package.name}: the lab failed to load the package: {error}")
        yield lab_page
