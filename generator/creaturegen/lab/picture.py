"""The package README's picture: the built package rendered by the creature lab (headless Chromium,
WebGPU on SwiftShader) and read back from a render target, before the package folder is committed.

It is part of the build, so a build with the picture needs the lab (Chromium, Playwright and three from npm).
``picture_unavailable`` says why it cannot run here, so ``--picture auto`` can build without it and say so.
The command line hands ``render_picture`` to the package writer (creature/build.py), which never imports
the lab: the lab runs packages, it is not part of making one.
"""

from __future__ import annotations

import base64
from pathlib import Path

import numpy as np

from ..creature.assets import PICTURE_PATH
from .png import encode_png

__all__ = ["PICTURE_PATH", "PICTURE_SIZE", "picture_unavailable", "render_picture"]

#: The README picture's size (pixels); its path in the package is the package layout's (PICTURE_PATH).
PICTURE_SIZE = (480, 320)
#: The tick and seed it shows (the parity job's pose, so the picture is the body the gates measured).
PICTURE_TICK = 37
PICTURE_SEED = 1


def picture_unavailable() -> str | None:
    """None when the lab can render here, else the reason it cannot."""
    from ..resources import MissingResourceError, lab_modules, playwright_missing

    missing = playwright_missing()
    if missing is not None:
        return missing
    from .browser import find_chromium

    try:
        lab_modules(install=True)
        find_chromium()
    except (RuntimeError, MissingResourceError) as exc:
        return str(exc)
    return None


def render_picture(package: Path) -> bytes:
    """PNG bytes of body 0 of ``package`` (a package folder, possibly not yet committed) in the lab."""
    from .creature_lab import open_creature_lab

    with open_creature_lab(package, PICTURE_SIZE, seed=PICTURE_SEED, capacity=1, pageSize=1) as page:
        page.evaluate(f"() => window.__lab.seekTick({PICTURE_TICK})")
        shot = page.evaluate("() => window.__lab.capturePixels('portrait')")
        page.evaluate("() => window.__lab.finish()")
        errors: list[str] = page.evaluate("() => window.__lab.errors")
        if errors:
            raise RuntimeError(f"GPU errors while rendering the picture: {errors[:3]}")
    raw = np.frombuffer(base64.b64decode(shot["rgba"]), dtype=np.uint8)
    return encode_png(raw.reshape(int(shot["height"]), int(shot["width"]), 4))
