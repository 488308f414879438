"""Where the build's caches live on disk: the surface entries and the motion envelopes beside them.

One folder for every stage's cache, so ``$CREATUREGEN_CACHE`` moves them all (tests point it at a
temporary folder; the corpus gives each build its own).
"""

from __future__ import annotations

import os
from pathlib import Path


def default_cache_root() -> Path:
    """``$CREATUREGEN_CACHE`` when set, else ``~/.cache/creaturegen/surface``."""
    configured = os.environ.get("CREATUREGEN_CACHE")
    return Path(configured) if configured else Path.home() / ".cache" / "creaturegen" / "surface"
