"""Validation benchmark: the spec gate on the worst shapes a hostile or generated spec can take within the
1 MiB limit (issue 25: a 4,000-part parent chain used to take 92 s, 20,000 bad parts past 60 s, a loop
of 980 blend nodes 5 to 10 s). Each shape is validated ``--repeats`` times; the JSON holds bytes, error
count and best/median seconds. The bar: every shape under 2 s on the 2-core CI machine.

    python bench/validate.py --out bench/results/validate.json
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

from creaturegen.spec import validate_bytes
from creaturegen.spec.errors import SpecValidationError
from creaturegen.spec.gate import MAX_SPEC_BYTES

REPO = Path(__file__).resolve().parent.parent


def _largest(make: Any) -> bytes:
    """The largest n (by halving steps) whose compact JSON fits the limit."""
    n, step = 1, 1
    while len(json.dumps(make(n * 2), separators=(",", ":"))) <= MAX_SPEC_BYTES:
        n *= 2
    step = n // 2
    while step:
        if len(json.dumps(make(n + step), separators=(",", ":"))) <= MAX_SPEC_BYTES:
            n += step
        step //= 2
    return json.dumps(make(n), separators=(",", ":")).encode()


def _sphere(i: int, **extra: Any) -> dict[str, Any]:
    return {"id": f"p{i}", "shape": "sphere", "offset": [0, 0, 0], "r": 0.1, **extra}


def shapes() -> dict[str, bytes]:
    lizard = json.loads((REPO / "examples" / "lizard.json").read_text())
    return {
        "parent chain": _largest(
            lambda n: {
                "name": "x",
                "parts": [_sphere(i, **({"parent": f"p{i - 1}"} if i else {})) for i in range(n)],
            }
        ),
        "parent loop": _largest(
            lambda n: {"name": "x", "parts": [_sphere(i, parent=f"p{(i + 1) % n}") for i in range(n)]}
        ),
        "parts with a bad radius": _largest(
            lambda n: {"name": "x", "parts": [{**_sphere(i), "r": -1} for i in range(n)]}
        ),
        "repeated ids": _largest(lambda n: {"name": "x", "parts": [{**_sphere(0)} for _ in range(n)]}),
        "blend loop": _largest(
            lambda n: {
                **lizard,
                "blend": {
                    "mode": "tree",
                    "roots": [{"node": "n0"}],
                    "nodes": [
                        {
                            "id": f"n{i}",
                            "left": {"node": f"n{(i + 1) % n}"},
                            "right": {"part": "head"},
                            "k": 0.05,
                        }
                        for i in range(n)
                    ],
                },
            }
        ),
        "deep nesting": b"[" * (MAX_SPEC_BYTES // 2) + b"]" * (MAX_SPEC_BYTES // 2),
        "wide unknown fields": _largest(lambda n: {"name": "x", **{f"k{i}": i for i in range(n)}}),
    }


def measure(data: bytes, repeats: int) -> dict[str, Any]:
    times, errors = [], 0
    for _ in range(repeats):
        start = time.perf_counter()
        try:
            validate_bytes(data)
        except SpecValidationError as exc:
            errors = len(exc.errors)
        times.append(time.perf_counter() - start)
    return {"bytes": len(data), "errors": errors, "bestS": min(times), "medianS": statistics.median(times)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "validate.json")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    results = {}
    for name, data in shapes().items():
        results[name] = measure(data, args.repeats)
        r = results[name]
        print(
            f"  {name:26} {r['bytes']:>9} B  {r['errors']:>6} errors  {r['medianS']:.3f} s", file=sys.stderr
        )
    worst = max(r["medianS"] for r in results.values())
    report = {"limitBytes": MAX_SPEC_BYTES, "shapes": results, "worstMedianS": worst, "barS": 2.0}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n")
    print(f"wrote {args.out}; worst median {worst:.3f} s (bar 2 s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
