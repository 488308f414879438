"""Reading a surface sidecar (assets/surface.json) back: gate rows and signatures of a cached build.

A cache hit returns what the cold build recorded, so the gates a hit reports are rebuilt from the rows the
cold path wrote; the posed-skin gates are read for the CLI and the build report from the same rows.
"""

from __future__ import annotations

from .gates import Direction, SurfaceGate


def posed_gate_rows(sidecar: dict[str, object]) -> list[dict[str, object]]:
    """The posed-skin gates (surface/posed.py) as the sidecar records them (cache hits included)."""
    posed = sidecar.get("posed")
    rows = posed.get("gates", []) if isinstance(posed, dict) else []
    return [r for r in rows if isinstance(r, dict)] if isinstance(rows, list) else []


def gate_rows(sidecar: dict[str, object]) -> list[dict[str, object]]:
    rows = sidecar.get("gates", [])
    assert isinstance(rows, list)
    return [{k: v for k, v in row.items() if k != "passed"} for row in rows]


def gate_from_row(row: dict[str, object]) -> SurfaceGate:
    direction: Direction = "min" if row.get("direction") == "min" else "max"
    value, threshold = row["value"], row["threshold"]
    assert isinstance(value, int | float)
    assert isinstance(threshold, int | float)
    return SurfaceGate(
        str(row["name"]),
        float(value),
        float(threshold),
        str(row["unit"]),
        direction,
        str(row.get("detail", "")),
    )


def signature_rows(sidecar: dict[str, object]) -> dict[str, str]:
    sig = sidecar.get("signatures", {})
    assert isinstance(sig, dict)
    return {str(k): str(v) for k, v in sig.items()}
