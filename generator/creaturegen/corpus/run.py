"""``make corpus``: build a fixed corpus of generated creatures at every tier and report what happened.

Each (spec, tier) is one ``creaturegen build`` in its own process, exactly as a user runs it (exit code,
stderr message, wall time), with a private surface cache so every time is a cold build. Results are kept
under ``OUT/results/`` keyed by the spec's bytes, the tier and a digest of the compiler's own source and
templates: a rerun after an unrelated change rebuilds nothing, a compiler change rebuilds everything, and
the report always holds the figures of the code it was run with. ``OUT/report.json`` holds per spec and tier
the status, time, exit code, the failed gate with its value and threshold, and the parts the message names;
``OUT/index.html`` is a gallery with a picture of each creature and its result per tier.
"""

from __future__ import annotations

import argparse
import hashlib
import html
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from .. import __version__
from ..candidates import TIERS
from ..motion.envelope import WORKERS_ENV, usable_cpus
from .random import random_creature

PACKAGE_ROOT = Path(__file__).resolve().parent.parent
#: The fixed corpus of ``make corpus``: seeds 0 .. COUNT - 1.
DEFAULT_COUNT = 200
#: Per-build wall limit; a build past it is recorded as a timeout (the acceptance asks max ≤ 60 s cold).
BUILD_TIMEOUT_S = 600.0

_GATE = re.compile(
    r"gate (?P<gate>[\w.\-]+) = (?P<value>[-+0-9.eE]+|nan|inf)\s*(?P<unit>[^,]*), threshold "
    r"(?P<threshold>[-+0-9.eE]+)"
)
_PART = re.compile(r"part\.([A-Za-z][A-Za-z0-9_-]*)")


@cache
def compiler_digest() -> str:
    """sha256 over the compiler's Python source and templates: what a build's outcome depends on (wider
    than surface/identity.py source_digest, which keys the surface cache by the surface's own packages)."""
    h = hashlib.sha256(__version__.encode())
    for root in [PACKAGE_ROOT]:  # the templates ship inside it; the lab pages build nothing
        for path in sorted(
            p for p in root.rglob("*") if p.is_file() and not {"__pycache__", "web_lab"} & set(p.parts)
        ):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def write_specs(folder: Path, seeds: Iterable[int], locomotion: str | None = None) -> list[Path]:
    """One ``seed-NNNNN.json`` per seed (pretty-printed, as a person would save it); a file already holding
    the same text is left alone."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for seed in seeds:
        spec = random_creature(seed, locomotion)
        path = folder / f"seed-{seed:05d}.json"
        text = json.dumps(spec, indent=2) + "\n"
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
        paths.append(path)
    return paths


@dataclass(frozen=True)
class Job:
    spec: Path
    tier: str

    def key(self) -> str:
        h = hashlib.sha256(self.spec.read_bytes())
        h.update(self.tier.encode())
        h.update(compiler_digest().encode())
        return h.hexdigest()[:32]


def parse_refusal(stderr: str) -> dict[str, Any]:
    """The gate, value, threshold and parts a refusal message names (empty fields when it names none)."""
    lines = [
        line for line in stderr.splitlines() if line and not line.startswith(("  surface:", "error: XDG"))
    ]
    message = lines[-1] if lines else ""
    found = _GATE.search(message)
    result: dict[str, Any] = {"message": message[:2000], "parts": sorted(set(_PART.findall(message)))}
    if "no skinning method passes" in message:
        result["gate"] = "deform.sweep"
    if found:
        result["gate"] = found["gate"]
        result["value"] = float(found["value"])
        result["threshold"] = float(found["threshold"])
        result["unit"] = found["unit"].strip()
    return result


def run_job(job: Job, packages: Path, timeout: float = BUILD_TIMEOUT_S, workers: int = 1) -> dict[str, Any]:
    """One cold ``creaturegen build`` in its own process and its own surface cache, stepping its motion
    envelope in ``workers`` processes (motion/envelope.py: the outcome does not depend on it)."""
    out = packages / job.tier
    with tempfile.TemporaryDirectory(prefix="creaturegen-corpus-") as cache_dir:
        env = {**os.environ, "CREATUREGEN_CACHE": cache_dir, "PYTHONUNBUFFERED": "1"}
        env.setdefault(WORKERS_ENV, str(workers))
        command = [
            sys.executable,
            "-m",
            "creaturegen.cli",
            "build",
            str(job.spec),
            "--tier",
            job.tier,
            "--picture",
            "off",
            "-o",
            str(out),
        ]
        start = time.perf_counter()
        try:
            done = subprocess.run(
                command, capture_output=True, text=True, env=env, timeout=timeout, check=False
            )
            code, stdout, stderr = done.returncode, done.stdout, done.stderr
        except subprocess.TimeoutExpired as exc:
            code, stdout, stderr = -1, str(exc.stdout or ""), f"timeout after {timeout:.0f} s"
        seconds = time.perf_counter() - start
    status = {0: "built", 2: "invalid", 3: "refused"}.get(code, "timeout" if code == -1 else "error")
    record: dict[str, Any] = {
        "spec": job.spec.name,
        "tier": job.tier,
        "status": status,
        "exitCode": code,
        "seconds": round(seconds, 3),
    }
    if status == "built":
        folder = re.search(r"wrote (.+?)/ \(geometryDigest", stdout)
        record["package"] = folder.group(1) if folder else ""
        mesh = re.search(r"mesh \{'vertices': (\d+), 'triangles': (\d+)", stdout)
        if mesh:
            record["vertices"], record["triangles"] = int(mesh.group(1)), int(mesh.group(2))
        # Posed-skin gates are recorded, not enforced (surface/posed.py): read from the build report.
        report = Path(record["package"]) / "build-report.json"
        rows = json.loads(report.read_text())["surface"]["posedGates"] if report.is_file() else []
        record["posedFailed"] = [r["name"] for r in rows if not r["passed"]]
    else:
        record.update(parse_refusal(stderr))
        if status == "error":
            record["stderrTail"] = stderr[-3000:]
    return record


def _picture(record: dict[str, Any], spec_path: Path, pictures: Path) -> str | None:
    """Gallery thumbnail of a built hero package (None when it cannot be drawn)."""
    from ..creature.assets import surface_path
    from ..rig import compile_rig
    from ..spec import CharacterSpec, load_spec
    from .preview import write_preview

    if not record.get("package"):
        return None
    try:
        glb = surface_path(Path(record["package"]))
    except (FileNotFoundError, ValueError):
        return None
    spec = load_spec(spec_path)
    assert isinstance(spec, CharacterSpec)
    target = pictures / f"{spec_path.stem}.png"
    write_preview(compile_rig(spec), glb, target)
    return target.name


def _summary(records: list[dict[str, Any]], tiers: Sequence[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for tier in tiers:
        rows = [r for r in records if r["tier"] == tier]
        built = [r for r in rows if r["status"] == "built"]
        times = sorted(r["seconds"] for r in rows)
        causes: dict[str, int] = {}
        for r in rows:
            if r["status"] != "built":
                cause = r.get("gate") or r["status"]
                causes[cause] = causes.get(cause, 0) + 1
        out[tier] = {
            "specs": len(rows),
            "built": len(built),
            "rate": round(len(built) / len(rows), 4) if rows else 0.0,
            "medianSeconds": times[len(times) // 2] if times else 0.0,
            "maxSeconds": times[-1] if times else 0.0,
            "refusalsNamingAPart": sum(1 for r in rows if r["status"] != "built" and r.get("parts")),
            "causes": dict(sorted(causes.items(), key=lambda kv: -kv[1])),
            "builtFailingPosedGates": sum(1 for r in built if r.get("posedFailed")),
            "posedFailures": {
                g: sum(1 for r in built if g in r.get("posedFailed", []))
                for g in ("posed.inverted", "posed.folds", "posed.selfIntersections")
            },
        }
    return out


_STYLE = (
    "body{font:13px system-ui,sans-serif;margin:16px;background:#fafafa}"
    ".grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(210px,1fr));gap:10px}"
    ".card{background:#fff;border:1px solid #ddd;border-radius:6px;padding:8px}"
    ".card img,.none{width:192px;height:192px;display:block;margin:auto;background:#eef0f4}"
    ".name{font-weight:600;margin-top:4px}.meta{color:#666;font-size:11px;margin-bottom:4px}"
    ".ok{color:#17662a}.no{color:#a11;cursor:help}.warn{color:#8a5a00}"
)


def _badge(tier: str, record: dict[str, Any]) -> str:
    """One line per tier: status and time; a refusal names its gate and parts, the whole message on hover."""
    text = f"{tier}: {record['status']} {record['seconds']:.1f} s"
    if record["status"] == "built" and record.get("posedFailed"):
        posed = ", ".join(g.removeprefix("posed.") for g in record["posedFailed"])
        return f'<div class="warn">{html.escape(text)} — posed skin: {html.escape(posed)}</div>'
    if record["status"] == "built":
        return f'<div class="ok">{html.escape(text)}</div>'
    named = " ".join(x for x in (record.get("gate", ""), ", ".join(record.get("parts", []))) if x)
    title = html.escape(record.get("message", record["status"]), quote=True)
    return f'<div class="no" title="{title}">{html.escape(text)} — {html.escape(named)}</div>'


def _card(name: str, info: dict[str, Any], rows: dict[str, dict[str, Any]], tiers: Sequence[str]) -> str:
    picture = info.get("picture")
    image = (
        f'<img src="pictures/{html.escape(picture)}" alt="">'
        if picture
        else '<div class="none">not built</div>'
    )
    meta = " · ".join(
        [
            name,
            str(info.get("locomotion", "none")),
            f"{info.get('parts', 0)} parts",
            f"scale {info.get('scale', 1)}",
            f"blend {info.get('blend', 'default')}",
        ]
    )
    badges = "".join(_badge(t, rows[t]) for t in tiers if t in rows)
    title = html.escape(str(info.get("name", name)))
    text = f'<div class="name">{title}</div><div class="meta">{html.escape(meta)}</div>'
    return f'<div class="card">{image}{text}{badges}</div>'


def _gallery(report: dict[str, Any], specs: dict[str, dict[str, Any]]) -> str:
    """index.html: the rates per tier, then a card per creature with its picture and a line per tier."""
    head = "".join(
        f"<li><b>{t}</b>: {s['built']}/{s['specs']} built ({100 * s['rate']:.1f} %), median "
        f"{s['medianSeconds']:.1f} s, max {s['maxSeconds']:.1f} s</li>"
        for t, s in report["summary"].items()
    )
    by_spec: dict[str, dict[str, dict[str, Any]]] = {}
    for r in report["results"]:
        by_spec.setdefault(r["spec"], {})[r["tier"]] = r
    cards = "".join(_card(n, specs.get(n, {}), by_spec[n], report["tiers"]) for n in sorted(by_spec))
    return (
        f"<!doctype html><meta charset=utf-8><title>creaturegen corpus</title><style>{_STYLE}</style>"
        f"<h1>creaturegen corpus</h1><p>creaturegen {html.escape(report['creaturegen'])}, "
        f"{len(by_spec)} generated specs, compiler digest {report['compilerDigest'][:12]}; "
        f'hover a red line for the whole refusal.</p><ul>{head}</ul><div class="grid">{cards}</div>\n'
    )


def _progress(done: int, total: int, started: float, record: dict[str, Any], cached: bool) -> None:
    elapsed = time.perf_counter() - started
    eta = elapsed / max(done, 1) * (total - done)
    what = record["status"] + (f" ({record.get('gate', '')})" if record["status"] != "built" else "")
    print(
        f"[{done}/{total}] {record['spec']} {record['tier']}: {what} {record['seconds']:.1f} s"
        f"{' (cached)' if cached else ''}; elapsed {elapsed:.0f} s, eta {eta:.0f} s",
        flush=True,
    )


def run_corpus(
    out: Path, seeds: Sequence[int], tiers: Sequence[str], jobs: int, pictures: bool = True
) -> dict[str, Any]:
    """Build every (seed, tier) not already measured with this compiler; write report.json and index.html."""
    spec_paths = write_specs(out / "specs", seeds)
    results = out / "results"
    results.mkdir(parents=True, exist_ok=True)
    packages = out / "packages"
    work = [Job(p, t) for p in spec_paths for t in tiers]
    records: dict[Job, dict[str, Any]] = {}
    todo = []
    for job in work:
        path = results / f"{job.key()}.json"
        if path.is_file():
            records[job] = json.loads(path.read_text())
        else:
            todo.append(job)
    print(
        f"==> corpus: {len(work)} builds ({len(work) - len(todo)} measured before with this compiler), "
        f"{jobs} at a time",
        flush=True,
    )
    started = time.perf_counter()
    done = len(work) - len(todo)
    # Builds side by side share the cores; each steps its envelope in its share of them.
    workers = max(1, usable_cpus() // max(1, jobs))
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures: dict[Future[dict[str, Any]], Job] = {
            pool.submit(run_job, job, packages, workers=workers): job for job in todo
        }
        for future in as_completed(futures):
            job = futures[future]
            record = future.result()
            (results / f"{job.key()}.json").write_text(json.dumps(record, indent=1, sort_keys=True))
            records[job] = record
            done += 1
            _progress(done, len(work), started, record, False)
    specs_info: dict[str, dict[str, Any]] = {}
    picture_folder = out / "pictures"
    picture_folder.mkdir(exist_ok=True)
    for path in spec_paths:
        raw = json.loads(path.read_text())
        info: dict[str, Any] = {
            "name": raw["name"],
            "locomotion": (raw.get("locomotion") or {}).get("type", "none"),
            "parts": len(raw["parts"]),
            "scale": raw.get("scale", 1),
            "blend": (raw.get("blend") or {}).get("mode", "default"),
        }
        built = [records[Job(path, t)] for t in tiers if records[Job(path, t)]["status"] == "built"]
        if pictures and built:
            target = picture_folder / f"{path.stem}.png"
            try:
                info["picture"] = (
                    target.name if target.is_file() else _picture(built[0], path, picture_folder)
                )
            except (OSError, ValueError) as exc:
                print(f"  no picture for {path.name}: {exc}", file=sys.stderr)
        specs_info[path.name] = info
    ordered = [records[job] for job in work]
    report = {
        "creaturegen": __version__,
        "compilerDigest": compiler_digest(),
        "seeds": [min(seeds), max(seeds)] if seeds else [],
        "tiers": list(tiers),
        "summary": _summary(ordered, tiers),
        "specs": specs_info,
        "results": ordered,
    }
    (out / "report.json").write_text(json.dumps(report, indent=1, sort_keys=True))
    (out / "index.html").write_text(_gallery(report, specs_info))
    return report


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m creaturegen.corpus",
        description="Build a fixed corpus of generated creatures at every tier; write report.json and a "
        "gallery (index.html).",
    )
    parser.add_argument("-o", "--out", default="out/corpus", help="output folder (default: out/corpus)")
    parser.add_argument(
        "--count", type=int, default=DEFAULT_COUNT, help="specs, seeds 0..count-1 (default 200)"
    )
    parser.add_argument("--first", type=int, default=0, help="first seed (default 0)")
    parser.add_argument("--tiers", default=",".join(TIERS), help="tiers (default hero,repeated,distant)")
    parser.add_argument(
        "--jobs", type=int, default=os.cpu_count() or 1, help="builds at a time (default: cores)"
    )
    parser.add_argument("--no-pictures", action="store_true", help="skip the gallery thumbnails")
    args = parser.parse_args(argv)
    tiers = [t for t in args.tiers.split(",") if t]
    unknown = [t for t in tiers if t not in TIERS]
    if unknown or args.count < 1:
        print(
            f"--tiers: unknown tier {unknown[0]!r}" if unknown else "--count: must be >= 1", file=sys.stderr
        )
        return 2
    out = Path(args.out)
    report = run_corpus(
        out, range(args.first, args.first + args.count), tiers, args.jobs, not args.no_pictures
    )
    for tier, s in report["summary"].items():
        print(
            f"  {tier}: {s['built']}/{s['specs']} built ({100 * s['rate']:.1f} %), "
            f"median {s['medianSeconds']:.1f} s, max {s['maxSeconds']:.1f} s; refusals {s['causes']}"
        )
    print(f"wrote {out / 'report.json'} and {out / 'index.html'}")
    return 0
