"""Every outcome of a batch, kept by a key of what decided it, so a rerun only runs what changed.

A job's key digests the spec's bytes, the tier, the build options and the compiler's own source and
templates. ``OUT/results/<key>.json`` is written the moment a job ends (a batch stopped halfway resumes
where it was); a job is done when its record says built, invalid or refused and, for a built one, its
package is still in place with the signatures and spec digest the record holds; a built package whose
parity report is missing when parity is asked for runs only its parity job. Errors, timeouts and lost
workers are run again.
"""

from __future__ import annotations

import hashlib
import json
import os
from functools import cache
from pathlib import Path
from typing import Any

from .. import __version__
from .task import package_figures

PACKAGE_ROOT = Path(__file__).resolve().parent.parent
#: Outcomes that the same spec, tier and compiler always reproduce (the others are run again).
FINAL = frozenset({"built", "invalid", "refused"})


@cache
def compiler_digest() -> str:
    """sha256 over the compiler's Python source and templates: what a build's outcome depends on (wider
    than a stage's code digest, which keys the surface cache by the surface's own packages)."""
    h = hashlib.sha256(__version__.encode())
    for path in sorted(
        p for p in PACKAGE_ROOT.rglob("*") if p.is_file() and not {"__pycache__", "web_lab"} & set(p.parts)
    ):
        h.update(str(path.relative_to(PACKAGE_ROOT)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def job_key(spec_id: str, spec_data: bytes, tier: str, options: dict[str, Any]) -> str:
    """The key of one job's record: the spec's id in the batch (its package folder), bytes and tier, the
    build options and the compiler."""
    h = hashlib.sha256(spec_data)
    h.update(f"\0{spec_id}\0{tier}\0".encode())
    h.update(json.dumps(options, sort_keys=True).encode())
    h.update(compiler_digest().encode())
    return h.hexdigest()[:32]


def package_folder(out: Path, spec_id: str, tier: str) -> Path:
    """``OUT/packages/<id>.<tier>``: one level, so ``creaturegen lab --out OUT/packages`` lists them all."""
    return out / "packages" / f"{spec_id}.{tier}"


def load_record(results: Path, key: str) -> dict[str, Any] | None:
    try:
        record = json.loads((results / f"{key}.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def save_record(results: Path, key: str, record: dict[str, Any]) -> None:
    """Written to a temporary name and renamed: a batch killed mid-write leaves no half record."""
    results.mkdir(parents=True, exist_ok=True)
    temp = results / f".{key}.{os.getpid()}.tmp"
    temp.write_text(json.dumps(record, indent=1, sort_keys=True), encoding="utf-8")
    os.replace(temp, results / f"{key}.json")


def package_intact(record: dict[str, Any], out: Path) -> bool:
    """A built record's package is in place with the signatures and spec digest the record holds."""
    try:
        built = package_figures(out / record.get("package", ""))
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return False
    return (built["signatures"], built["specSha256"]) == (record.get("signatures"), record.get("specSha256"))


def parity_ran(record: dict[str, Any], out: Path) -> bool:
    ran = (record.get("parity") or {}).get("status") in ("passed", "failed")
    return ran and (out / record.get("package", "") / "parity" / "report.json").is_file()


def next_step(record: dict[str, Any] | None, out: Path, parity: bool) -> str:
    """``"done"`` when ``record`` stands as it is (module docstring), ``"parity"`` when only its parity job
    is missing, ``"build"`` when the job runs again."""
    if record is None or record.get("status") not in FINAL:
        return "build"
    if record["status"] != "built":
        return "done"
    if not package_intact(record, out):
        return "build"
    return "parity" if parity and not parity_ran(record, out) else "done"


def summary(records: list[dict[str, Any]], tiers: list[str]) -> dict[str, Any]:
    """Per tier: how many built, the build times, the refusals by gate, posed and parity failures."""
    out: dict[str, Any] = {}
    for tier in tiers:
        rows = [r for r in records if r["tier"] == tier]
        if not rows:
            continue
        built = [r for r in rows if r["status"] == "built"]
        times = sorted(r["seconds"] for r in rows if "seconds" in r)
        causes: dict[str, int] = {}
        for r in rows:
            if r["status"] != "built":
                cause = r.get("gate") or r["status"]
                causes[cause] = causes.get(cause, 0) + 1
        parity = [r["parity"] for r in built if r.get("parity")]
        out[tier] = {
            "specs": len(rows),
            "built": len(built),
            "rate": round(len(built) / len(rows), 4),
            "medianSeconds": times[len(times) // 2] if times else 0.0,
            "maxSeconds": times[-1] if times else 0.0,
            "refusalsNamingAPart": sum(1 for r in rows if r["status"] != "built" and r.get("parts")),
            "causes": dict(sorted(causes.items(), key=lambda kv: -kv[1])),
            "builtFailingPosedGates": sum(1 for r in built if r.get("posedFailed")),
            "posedFailures": {
                g: sum(1 for r in built if g in r.get("posedFailed", []))
                for g in ("posed.inverted", "posed.folds", "posed.selfIntersections")
            },
            "parityPassed": sum(1 for p in parity if p.get("status") == "passed"),
            "parityRun": len(parity),
        }
    return out
