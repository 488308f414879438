"""A tiny static HTTP server for web_lab/ and the built packages it runs (mounted at ``/out/``).

ES modules and import maps only work over HTTP with a JavaScript MIME type, and the system
``mimetypes`` table differs between machines (``.js`` is sometimes ``application/javascript``,
``.mjs`` is often missing), so the types are pinned here instead of guessed.

``GET /packages.json`` lists the packages of the ``out`` mount (one entry per folder holding a
``build-report.json``): the index page (web_lab/index.html, served at ``/``) is built from it.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import http.server
import json
import os
import posixpath
import sys
import threading
import urllib.parse
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ..resources import lab_modules, web_lab_dir

#: Pinned so that a module script is never refused for a wrong type, whatever the host's tables say.
MIME_TYPES: dict[str, str] = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".mjs": "text/javascript; charset=utf-8",
    ".json": "application/json",
    ".map": "application/json",
    ".wasm": "application/wasm",
    ".css": "text/css; charset=utf-8",
    ".txt": "text/plain; charset=utf-8",
    ".md": "text/markdown; charset=utf-8",
    ".wgsl": "text/plain; charset=utf-8",
    ".glb": "model/gltf-binary",
    ".gltf": "model/gltf+json",
    ".bin": "application/octet-stream",
    ".png": "image/png",
    ".svg": "image/svg+xml",
    ".ico": "image/x-icon",
}

#: The lab app: static pages shipped inside the package (resources.py), three from resources.lab_modules.
WEB_LAB = web_lab_dir()
DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8765
#: The listing of the built packages that the index page reads (see package_listing).
LISTING_PATH = "/packages.json"
#: Pages per package kind: the demo (public API only, for a person) and the lab page (the test harness's).
PAGES: dict[str, dict[str, str]] = {
    "creature": {"demo": "demo-creature.html", "lab": "creature.html"},
    "frost": {"demo": "demo-frost.html", "lab": "frost.html"},
}


def _gates_passed(gates: Any) -> str | None:
    """``"passed/total"`` over a build report's gates (creature: ``passed``; frost: ``status``)."""
    if not isinstance(gates, list) or not gates:
        return None
    ok = sum(
        1 for g in gates if isinstance(g, dict) and (g.get("passed") is True or g.get("status") == "pass")
    )
    return f"{ok}/{len(gates)}"


def _section(report: dict[str, Any], key: str) -> dict[str, Any]:
    value = report.get(key)
    return value if isinstance(value, dict) else {}


def _key_figures(kind: str, report: dict[str, Any], folder: Path) -> tuple[str | None, dict[str, Any]]:
    """The tier and a few figures a person compares packages by, from one build report."""
    figures: dict[str, Any] = {}
    tier: Any = None
    if kind == "creature":
        workload = _section(report, "workload")
        tier = report.get("tier") or workload.get("tier")
        with contextlib.suppress(OSError, ValueError, KeyError, TypeError):
            spec = json.loads((folder / "assets" / "spec.json").read_text(encoding="utf-8"))
            figures["locomotion"] = spec["locomotion"]["type"]
        for key in ("vertices", "triangles", "slots"):
            if key in workload:
                figures[key] = workload[key]
    elif kind == "frost":
        history = _section(report, "historyFormat")
        memory = _section(report, "memory")
        params = _section(report, "params")
        tier = history.get("name")
        for label, value in (
            ("history format", history.get("historyFormat")),
            ("history scale", params.get("historyScale")),
            ("update policy", params.get("policy")),
            ("history bytes at 1920x1080", memory.get("historyBytes")),
            ("structure file bytes", memory.get("structureFileBytes")),
        ):
            if value is not None:
                figures[label] = value
    gates = _gates_passed(report.get("gates"))
    if gates is not None:
        figures["gates passed"] = gates
    return (str(tier) if tier is not None else None), figures


def package_listing(out: Path) -> list[dict[str, Any]]:
    """One entry per built package under ``out`` (a folder with a ``build-report.json``), sorted by folder.

    Links are site paths: the package's demo and lab pages (``?pkg=<folder>``) and its README under
    ``/out/``. A folder that resolves outside ``out`` (a symlink) is left out, as the server refuses its
    files; an unreadable report is listed with its ``error`` so the index says why it has no links.
    """
    root = Path(out).resolve()
    if not root.is_dir():
        return []
    entries: list[dict[str, Any]] = []
    for report_path in sorted(root.glob("*/build-report.json")):
        folder = report_path.parent
        if not folder.resolve().is_relative_to(root) or not report_path.resolve().is_relative_to(root):
            continue
        slug = folder.name
        quoted = urllib.parse.quote(slug)
        entry: dict[str, Any] = {"slug": slug, "readme": f"/out/{quoted}/README.md"}
        try:
            report = json.loads(report_path.read_text(encoding="utf-8"))
            if not isinstance(report, dict):
                raise ValueError("not a JSON object")
        except (OSError, ValueError) as exc:
            entry.update(kind=None, name=slug, error=f"unreadable build-report.json: {exc}")
            entries.append(entry)
            continue
        kind = str(report.get("kind") or "")
        tier, figures = _key_figures(kind, report, folder)
        entry.update(
            kind=kind or None,
            name=report.get("name") or slug,
            package=report.get("package") or slug,
            version=report.get("compilerVersion"),
            tier=tier,
            figures=figures,
        )
        pages = PAGES.get(kind)
        if pages is None:
            entry["error"] = f"unknown package kind {kind!r}: no demo or lab page"
        else:
            entry.update(
                {role: f"/{page}?pkg={urllib.parse.quote(slug, safe='')}" for role, page in pages.items()}
            )
        entries.append(entry)
    return entries


class LabRequestHandler(http.server.SimpleHTTPRequestHandler):
    """Static files with pinned MIME types, no caching and no per-request log lines.

    ``mounts`` maps a first URL segment to another folder: the lab serves built packages from
    ``/out/<slug>/`` while its own files and node_modules stay in web_lab/.
    """

    def __init__(self, *args: Any, mounts: dict[str, Path] | None = None, **kwargs: Any) -> None:
        self.mounts = mounts or {}
        super().__init__(*args, **kwargs)

    def translate_path(self, path: str) -> str:
        clean = posixpath.normpath(path.split("?", 1)[0].split("#", 1)[0])
        parts = [p for p in clean.split("/") if p]
        if parts and parts[0] in self.mounts:
            root = self.mounts[parts[0]].resolve()
            target = root.joinpath(*parts[1:]).resolve()
            # normpath already removed "..", but a symlink could still point outside: refuse that too.
            return str(target) if target.is_relative_to(root) else str(root / "__outside__")
        return super().translate_path(path)

    def _listing(self) -> bytes | None:
        """The body of ``GET /packages.json`` (the ``out`` mount's packages), or None for any other path."""
        if self.path.split("?", 1)[0].split("#", 1)[0] != LISTING_PATH:
            return None
        out = self.mounts.get("out")
        listing = {"packages": package_listing(out) if out is not None else []}
        return json.dumps(listing, indent=1).encode("utf-8")

    def _send_listing(self, body: bytes, *, head: bool) -> None:
        self.send_response(http.HTTPStatus.OK)
        self.send_header("Content-Type", MIME_TYPES[".json"])
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        if not head:
            self.wfile.write(body)

    def do_GET(self) -> None:
        body = self._listing()
        if body is None:
            super().do_GET()
        else:
            self._send_listing(body, head=False)

    def do_HEAD(self) -> None:
        body = self._listing()
        if body is None:
            super().do_HEAD()
        else:
            self._send_listing(body, head=True)

    def guess_type(self, path: str | os.PathLike[str]) -> str:
        ext = posixpath.splitext(os.fspath(path))[1].lower()
        return MIME_TYPES.get(ext) or super().guess_type(path)

    def end_headers(self) -> None:
        # A rebuilt package must be picked up by the next page load, never served from cache.
        self.send_header("Cache-Control", "no-store")
        super().end_headers()

    def log_message(self, format: str, *args: Any) -> None:
        # Test output should show the page's console, not one line per module fetch.
        return


class _QuietThreadingServer(http.server.ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request: Any, client_address: Any) -> None:
        # Chromium drops connections when a page closes mid-fetch; that is not a server failure.
        exc = sys.exc_info()[1]
        if isinstance(exc, ConnectionError):
            return
        super().handle_error(request, client_address)


def make_server(
    root: Path, host: str = DEFAULT_HOST, port: int = 0, mounts: dict[str, Path] | None = None
) -> http.server.ThreadingHTTPServer:
    """Bind (port 0 picks a free one) without serving yet, so callers learn the real port first."""
    root = Path(root).resolve()
    if not root.is_dir():
        raise FileNotFoundError(f"lab server root {root} is not a directory")
    mounted = dict(mounts or {})
    if root == WEB_LAB.resolve() and "node_modules" not in mounted:
        # The pages import /node_modules/three: a checkout's own, or the one an installed tool fetched.
        modules = lab_modules(install=True)
        if modules is not None:
            mounted["node_modules"] = modules
    handler = functools.partial(LabRequestHandler, directory=str(root), mounts=mounted)
    return _QuietThreadingServer((host, port), handler)


@contextlib.contextmanager
def serve(
    root: Path, port: int = 0, host: str = DEFAULT_HOST, mounts: dict[str, Path] | None = None
) -> Iterator[str]:
    """Serve ``root`` on a background thread for the duration of a with-block; yields the base URL."""
    server = make_server(root, host, port, mounts)
    thread = threading.Thread(target=server.serve_forever, name="creaturegen-lab-http", daemon=True)
    thread.start()
    try:
        bound_host, bound_port = server.server_address[:2]
        host_text = bound_host.decode() if isinstance(bound_host, bytes) else bound_host
        yield f"http://{host_text}:{bound_port}/"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=5)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``make lab``: serve web_lab/ in the foreground until Ctrl-C."""
    parser = argparse.ArgumentParser(prog="python -m creaturegen.lab.server", description=__doc__)
    parser.add_argument(
        "--root", type=Path, default=WEB_LAB, help="folder to serve (default: the shipped web_lab)"
    )
    parser.add_argument("--host", default=DEFAULT_HOST, help=f"bind address (default: {DEFAULT_HOST})")
    parser.add_argument("--port", type=int, default=DEFAULT_PORT, help=f"port (default: {DEFAULT_PORT})")
    parser.add_argument("--out", type=Path, default=Path("out"), help="built packages, served at /out/")
    args = parser.parse_args(argv)
    server = make_server(args.root, args.host, args.port, {"out": args.out})
    base = f"http://{args.host}:{server.server_address[1]}/"
    print(f"==> serving {Path(args.root).resolve()} at {base}; packages: {Path(args.out).resolve()} at /out/")
    print(f"    {base}  index: every built package with its demo, lab page and README")
    print(f"    {base}smoke.html  WebGPU smoke page")
    listing = package_listing(args.out)
    if not listing:
        print(f"    no built packages in {args.out} yet: `make build EXAMPLE=...`, then reload the index")
    for entry in listing:
        for role in ("demo", "lab"):
            if role in entry:
                print(f"    {base}{entry[role].lstrip('/')}  {entry['kind']} {role}")
    print("    Ctrl-C stops the server", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
