"""A tiny static HTTP server for web_lab/ (and, later, built packages).

ES modules and import maps only work over HTTP with a JavaScript MIME type, and the system
``mimetypes`` table differs between machines (``.js`` is sometimes ``application/javascript``,
``.mjs`` is often missing), so the types are pinned here instead of guessed.
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
    print(f"    {base}smoke.html  WebGPU smoke page")
    print(f"    {base}frost.html?pkg=<slug>  a built frost package, e.g. after `make build EXAMPLE=...`")
    print(f"    {base}creature.html?pkg=<slug>  a built creature package")
    for report in sorted(Path(args.out).glob("*/build-report.json")):
        kind = json.loads(report.read_text()).get("kind")
        page = {"frost": "frost.html", "creature": "creature.html"}.get(str(kind))
        if page:
            print(f"    {base}{page}?pkg={report.parent.name}")
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
