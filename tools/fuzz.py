"""``make fuzz``: the spec gate over many generated documents, then real builds of mutated valid specs.

Part 1 (``--cases``, 50,000 by default): documents from tests/fuzz_specs.py (valid examples mutated at
random places, random JSON, four encodings) through the gate in this process. Counted: tracebacks (any
exception but SpecValidationError), unnamed errors (empty place, control characters, text that cannot be
printed as UTF-8), slow cases (over 2 s) and Python warnings raised while validating.

Part 2 (``--builds``, 50 by default): mutated documents that pass the gate, each built by ``creaturegen
build`` in a subprocess with ``--picture off`` and a time limit. Counted by exit code (0 built, 2 named
error, 3 named refusal; anything else, a traceback on stderr, a Python warning on stderr or the time limit
is a failure). Writes ``out/fuzz/report.json`` with every failure's input kept under ``out/fuzz/cases/``.
"""

from __future__ import annotations

import argparse
import collections
import json
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "tests"))

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from creaturegen.spec import validate_bytes  # noqa: E402
from creaturegen.spec.errors import SpecValidationError  # noqa: E402
from fuzz_specs import documents, encode, mutated_specs, unusable  # noqa: E402

SLOW_S = 2.0


def gate_cases(count: int, keep: Path) -> dict[str, Any]:
    found: collections.Counter[str] = collections.Counter()
    samples: dict[str, str] = {}
    slowest = 0.0

    def note(kind: str, data: bytes) -> None:
        found[kind] += 1
        if kind not in samples:
            path = keep / f"gate-{len(samples):03d}.json"
            path.write_bytes(data)
            samples[kind] = str(path)

    @settings(max_examples=count, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(documents, st.integers(0, 3))
    def run(doc: Any, style: int) -> None:
        nonlocal slowest
        data = encode(doc, style)
        start = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                validate_bytes(data, "<fuzz>")
            except SpecValidationError as exc:
                for e in exc.errors:
                    if unusable(e.path, e.message):
                        note("unnamed error", data)
            except Exception as exc:  # the failure this run exists to find
                frame = traceback.extract_tb(exc.__traceback__)[-1]
                note(f"traceback {type(exc).__name__} at {Path(frame.filename).name}:{frame.lineno}", data)
        for w in caught:
            note(f"warning {w.category.__name__}: {str(w.message)[:80]}", data)
        seconds = time.perf_counter() - start
        slowest = max(slowest, seconds)
        if seconds > SLOW_S:
            note("slow (> 2 s)", data)

    run()
    return {"cases": count, "failures": dict(found), "samples": samples, "slowestSeconds": round(slowest, 3)}


def build_cases(count: int, keep: Path, timeout: float) -> dict[str, Any]:
    """Mutated specs that pass the gate, built for real; each outcome counted by kind."""
    valid: list[bytes] = []

    @settings(max_examples=40 * count, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(mutated_specs())
    def collect(doc: Any) -> None:
        if len(valid) >= count:
            return
        data = encode(doc, 0)
        try:
            validate_bytes(data)
        except SpecValidationError:
            return
        valid.append(data)

    collect()
    outcomes: collections.Counter[str] = collections.Counter()
    failures = []
    for n, data in enumerate(valid):
        spec = keep / f"build-{n:03d}.json"
        spec.write_bytes(data)
        with tempfile.TemporaryDirectory() as out:
            command = [
                sys.executable,
                "-m",
                "creaturegen.cli",
                "build",
                str(spec),
                "--picture",
                "off",
                "-o",
                out,
            ]
            start = time.perf_counter()
            try:
                done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, check=False)
                code, err = done.returncode, done.stderr
            except subprocess.TimeoutExpired:
                code, err = -1, "timeout"
            seconds = time.perf_counter() - start
        kind = {0: "built", 2: "named error (2)", 3: "named refusal (3)", -1: "timeout"}.get(
            code, f"exit {code}"
        )
        if "Traceback" in err:
            kind = "traceback"
        elif "Warning" in err:
            kind = f"{kind} with a warning"
        outcomes[kind] += 1
        if kind not in ("built", "named error (2)", "named refusal (3)"):
            failures.append(
                {"spec": str(spec), "kind": kind, "seconds": round(seconds, 1), "stderr": err[-1500:]}
            )
        print(f"  build {n + 1}/{len(valid)}: {kind} ({seconds:.1f} s)", flush=True)
    return {"builds": len(valid), "outcomes": dict(outcomes), "failures": failures}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=50_000)
    parser.add_argument("--builds", type=int, default=50)
    parser.add_argument("--build-timeout", type=float, default=300.0)
    parser.add_argument("-o", "--out", type=Path, default=REPO / "out" / "fuzz")
    args = parser.parse_args()
    keep = args.out / "cases"
    keep.mkdir(parents=True, exist_ok=True)
    print(f"==> fuzz: {args.cases} documents through the gate", flush=True)
    report: dict[str, Any] = {"gate": gate_cases(args.cases, keep)}
    print(f"    {report['gate']['failures'] or 'no failures'}", flush=True)
    if args.builds:
        print(f"==> fuzz: {args.builds} builds of mutated valid specs", flush=True)
        report["build"] = build_cases(args.builds, keep, args.build_timeout)
        print(f"    {report['build']['outcomes']}", flush=True)
    (args.out / "report.json").write_text(json.dumps(report, indent=2) + "\n")
    print(f"wrote {args.out / 'report.json'}")
    failed = bool(report["gate"]["failures"]) or bool(report.get("build", {}).get("failures"))
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
