"""The disk cache of reference surfaces: each entry one .glb and its JSON sidecar (surface/glb.py).

The cache: a surface is identified by (compilerSignature, topologySignature, geometryDigest, tier);
the topologySignature is only known once the surface is built (it includes the deformation methods
chosen), so a lookup goes through an index file keyed by (compilerSignature, geometryDigest, tier,
settingsDigest). Folder names use 16-hex-digit prefixes for readable paths, but every full signature
is stored in the JSON and compared on read: a prefix collision is a miss, never a wrong hit. Every
file is written atomically (temporary file in the same folder, then ``os.replace``), entries are
written before the index that points at them, and anything unreadable, inconsistent or corrupt (the
sidecar records the .glb's SHA-256) reads as a miss, which the next ``store`` overwrites.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

from ..cachedir import default_cache_root
from .asset import SurfaceAsset
from .glb import GlbFormatError, parse_glb, write_glb, write_sidecar

_HEX = re.compile(r"[0-9a-f]{16,}")
_TIER = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")
CACHE_KEY: Final = "cacheKey"
PREFIX: Final = 16


def _check_hex(value: str, what: str) -> str:
    if not isinstance(value, str) or not _HEX.fullmatch(value):
        raise ValueError(f"{what}: lowercase hex of at least {PREFIX} digits expected, got {value!r}")
    return value


def _check_tier(tier: str) -> str:
    if not isinstance(tier, str) or not _TIER.fullmatch(tier):
        raise ValueError(f"tier: {tier!r} is not a safe folder-name fragment")
    return tier


def _read_json(path: Path) -> dict[str, Any] | None:
    try:
        value = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return value if isinstance(value, dict) else None


@contextlib.contextmanager
def exclusive(lock: Path) -> Iterator[None]:
    """An exclusive advisory lock on the file ``lock`` (created if missing): one process at a time past
    this point. Without ``fcntl`` (not POSIX) it lets everyone through."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover (not POSIX)
        yield
        return
    with lock.open("a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


@dataclass(frozen=True)
class CachedSurface:
    asset: SurfaceAsset
    sidecar: dict[str, object]
    folder: Path


class SurfaceCache:
    """Surfaces on disk under ``root``; see the module docstring for the layout and its guarantees.

    ``<root>/<compiler[:16]>/<geometry[:16]>/<topology[:16]>-<tier>/surface.glb`` and ``surface.json``;
    ``<root>/<compiler[:16]>/<geometry[:16]>/index-<tier>-<settings[:16]>.json`` maps a lookup key to
    the full topologySignature.
    """

    GLB = "surface.glb"
    SIDECAR = "surface.json"

    def __init__(self, root: Path | None = None) -> None:
        self.root = Path(root) if root is not None else default_cache_root()

    def geometry_folder(self, compiler: str, geometry: str) -> Path:
        c = _check_hex(compiler, "compilerSignature")
        g = _check_hex(geometry, "geometryDigest")
        return self.root / c[:PREFIX] / g[:PREFIX]

    def entry_folder(self, compiler: str, topology: str, geometry: str, tier: str) -> Path:
        t = _check_hex(topology, "topologySignature")
        return self.geometry_folder(compiler, geometry) / f"{t[:PREFIX]}-{_check_tier(tier)}"

    def index_path(self, compiler: str, geometry: str, tier: str, settings_digest: str) -> Path:
        s = _check_hex(settings_digest, "settingsDigest")
        return self.geometry_folder(compiler, geometry) / f"index-{_check_tier(tier)}-{s[:PREFIX]}.json"

    @contextlib.contextmanager
    def building(self, compiler: str, geometry: str, tier: str, settings_digest: str) -> Iterator[None]:
        """Hold the build of one lookup key: a second build of the same surface sharing this cache (another
        process: a parallel build, a test worker) waits here, then finds the entry instead of extracting
        it again. An advisory lock file beside the index; where the platform has no ``fcntl`` the builds
        simply both run (entries are written atomically, so the result is the same)."""
        path = self.index_path(compiler, geometry, tier, settings_digest).with_suffix(".lock")
        path.parent.mkdir(parents=True, exist_ok=True)
        with exclusive(path):
            yield

    def lookup(self, compiler: str, geometry: str, tier: str, settings_digest: str) -> CachedSurface | None:
        """The stored surface for this key, or ``None`` (missing, mismatched or corrupt: all misses)."""
        index = _read_json(self.index_path(compiler, geometry, tier, settings_digest))
        wanted = {
            "compilerSignature": compiler,
            "geometryDigest": geometry,
            "tier": tier,
            "settingsDigest": settings_digest,
        }
        if index is None or any(index.get(k) != v for k, v in wanted.items()):
            return None
        topology = index.get("topologySignature")
        if not isinstance(topology, str) or not _HEX.fullmatch(topology):
            return None
        return self.read_entry(compiler, topology, geometry, tier)

    def read_entry(self, compiler: str, topology: str, geometry: str, tier: str) -> CachedSurface | None:
        """The entry stored under the full key, verified against its sidecar, or ``None``."""
        folder = self.entry_folder(compiler, topology, geometry, tier)
        sidecar = _read_json(folder / self.SIDECAR)
        if sidecar is None:
            return None
        key = sidecar.pop(CACHE_KEY, None)
        wanted = {"compilerSignature": compiler, "topologySignature": topology, "geometryDigest": geometry}
        if not isinstance(key, dict) or key.get("tier") != tier:
            return None
        if any(key.get(k) != v for k, v in wanted.items()):
            return None
        try:
            data = (folder / self.GLB).read_bytes()
            if hashlib.sha256(data).hexdigest() != key.get("glbSha256"):
                return None
            asset = parse_glb(data)
        except (OSError, GlbFormatError):
            return None
        return CachedSurface(asset=asset, sidecar=sidecar, folder=folder)

    def store(
        self,
        compiler: str,
        topology: str,
        geometry: str,
        tier: str,
        settings_digest: str,
        asset: SurfaceAsset,
        sidecar: dict[str, object],
    ) -> Path:
        """Write the entry (surface.glb, then surface.json), then the index; returns the entry folder."""
        if CACHE_KEY in sidecar:
            raise ValueError(f"sidecar: {CACHE_KEY!r} is reserved for the cache")
        folder = self.entry_folder(compiler, topology, geometry, tier)
        index = self.index_path(compiler, geometry, tier, settings_digest)
        data = write_glb(folder / self.GLB, asset, name=f"surface-{tier}")
        key = {
            "compilerSignature": compiler,
            "topologySignature": topology,
            "geometryDigest": geometry,
            "tier": tier,
            "glbSha256": hashlib.sha256(data).hexdigest(),
        }
        write_sidecar(folder / self.SIDECAR, {**sidecar, CACHE_KEY: key})
        write_sidecar(
            index,
            {
                "compilerSignature": compiler,
                "geometryDigest": geometry,
                "tier": tier,
                "settingsDigest": settings_digest,
                "topologySignature": topology,
            },
        )
        return folder
