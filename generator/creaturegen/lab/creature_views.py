"""Parity gates on rendered views: the silhouette seen from the sun vs the shadow footprint on the
ground (the depth pass uses the same position function), max distance of a disagreeing texel to the other
mask's edge; and the pictures written beside the report (front.png, the debug views on request, each
gated to differ from the shipped view and to be more than one colour).
"""

from __future__ import annotations

import base64
from pathlib import Path

import numpy as np
import numpy.typing as npt
from playwright.sync_api import Page
from scipy import ndimage

from .creature_lab import rgba_image
from .png import write_png
from .report import ParityReport

#: Silhouette vs shadow footprint: a disagreeing texel may lie at most this far from the other's edge.
SHADOW_TEXELS = 2.0


def shadow_mismatch(silhouette: npt.NDArray[np.bool_], footprint: npt.NDArray[np.bool_]) -> tuple[float, int]:
    """(largest distance in texels from a disagreeing texel to the other mask, disagreeing texels)."""
    only_sil = silhouette & ~footprint
    only_foot = footprint & ~silhouette
    dist_to_foot = ndimage.distance_transform_edt(~footprint)
    dist_to_sil = ndimage.distance_transform_edt(~silhouette)
    worst = max(
        float(dist_to_foot[only_sil].max()) if only_sil.any() else 0.0,
        float(dist_to_sil[only_foot].max()) if only_foot.any() else 0.0,
    )
    return worst, int(only_sil.sum() + only_foot.sum())


def shadow_gate(page: Page, package: Path, report: ParityReport) -> None:
    shot = page.evaluate("() => window.__lab.shadowParity(128)")
    size = int(shot["size"])
    sil = np.frombuffer(base64.b64decode(shot["silhouette"]), np.uint8).reshape(size, size, 4)
    foot = np.frombuffer(base64.b64decode(shot["footprint"]), np.uint8).reshape(size, size, 4)
    silhouette = sil[..., :3].max(axis=2) > 127
    lum = foot[..., :3].astype(np.float64).mean(axis=2)
    lit = float(np.median(lum[~silhouette])) if (~silhouette).any() else 255.0
    footprint = lum < 0.5 * lit
    worst, count = shadow_mismatch(silhouette, footprint)
    report.gate("silhouette vs shadow footprint", worst, SHADOW_TEXELS, "texels")
    report.measurements["shadow"] = {
        "size": size,
        "silhouetteTexels": int(silhouette.sum()),
        "footprintTexels": int(footprint.sum()),
        "disagreeingTexels": count,
    }
    write_png(package / "parity" / "silhouette.png", sil)
    write_png(package / "parity" / "footprint.png", foot)


def pictures(page: Page, package: Path, debug: bool, report: ParityReport) -> None:
    """front.png (the README's picture); with ``debug``, the distance, normals and candidates views too
    (each is a material variant compiled on first use, ~10 s on SwiftShader), each gated to differ from
    the shipped view and to be more than one colour (a mode that never reaches the shader draws the body
    as shipped; a broken one draws nothing)."""
    front = rgba_image(page.evaluate("() => window.__lab.capturePixels('front')"))
    write_png(package / "parity" / "front.png", front)
    same: list[str] = []
    blank: list[str] = []
    for mode in ("distance", "normals", "candidates", "shell") if debug else ():
        page.evaluate(f"() => window.__lab.setDebugMode('{mode}')")
        picture = rgba_image(page.evaluate("() => window.__lab.capturePixels('front')"))
        write_png(package / "parity" / f"debug-{mode}.png", picture)
        if np.array_equal(picture, front):
            same.append(mode)
        if bool((picture[..., :3] == picture[0, 0, :3]).all()):
            blank.append(mode)
    page.evaluate("() => window.__lab.setDebugMode('off')")
    if debug:
        report.gate(f"debug views identical to the shipped view {same}", len(same), 0, "views")
        report.gate(f"debug views of one colour {blank}", len(blank), 0, "views")
