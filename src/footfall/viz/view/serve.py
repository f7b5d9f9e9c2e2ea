"""The page's server: the standard library's threaded HTTP server, started before anything heavy
is imported, so a browser loads the page (two small static files) while the files are read.

Routes: ``/`` the page, ``/viewer.js`` its script, ``/data.json`` what it draws (503 until
:meth:`PageServer.publish` gives it; the page asks again), ``/trial/<i>.json`` a study trial's
drawing and ``/trial/<i>/walk.json`` its walk, walked again (each made when first asked).
Everything else is 404. It serves files of this package only:
nothing a request names is read from disk.

This module imports nothing of numpy, footfall's models, planning or terrain.
"""

from __future__ import annotations

import json
import re
import socket
import sys
import threading
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from typing import Any

from footfall.errors import FootfallError, InputError

#: the page's static files and their content types
_STATIC = {
    "/": ("index.html", "text/html; charset=utf-8"),
    "/index.html": ("index.html", "text/html; charset=utf-8"),
    "/viewer.js": ("viewer.js", "text/javascript; charset=utf-8"),
}
_TRIAL = re.compile(r"/trial/(\d{1,9})(\.json|/walk\.json)")


class _Server(ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request: Any, client_address: Any) -> None:
        """A browser that closed its tab mid-answer is not an error worth a traceback."""
        if not isinstance(sys.exc_info()[1], ConnectionError):
            super().handle_error(request, client_address)


def _static(name: str) -> bytes:
    return (resources.files("footfall.viz.view") / "static" / name).read_bytes()


def _json(obj: Any) -> bytes:
    return json.dumps(obj, separators=(",", ":"), allow_nan=False).encode()


class PageServer:
    """Serves the page on ``host:port`` (0: any free port) from a thread of its own."""

    def __init__(self, host: str, port: int) -> None:
        self._data: bytes | None = None
        self._routes: dict[str, Callable[[int], Any]] = {}
        self._made: dict[tuple[str, int], bytes] = {}
        self._lock = threading.Lock()
        self.files = {route: (_static(name), kind) for route, (name, kind) in _STATIC.items()}
        server = self

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                status, body, kind = server.respond(self.path.split("?", 1)[0])
                self.send_response(status)
                self.send_header("Content-Type", kind)
                self.send_header("Content-Length", str(len(body)))
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                self.wfile.write(body)

            def log_message(self, format: str, *args: Any) -> None:
                pass  # quiet: the command prints its own lines

        try:
            self.httpd = _Server((host, port), Handler)
        except OSError as e:
            raise InputError(
                "port", port, f"a free port on {host} ({e.strerror}); try --port 0"
            ) from None
        self._thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self._thread.start()

    def get_port(self) -> int:
        """The port it listens on."""
        return int(self.httpd.server_address[1])

    def publish(
        self,
        data: dict[str, Any],
        trial: Callable[[int], Any] | None = None,
        trial_walk: Callable[[int], Any] | None = None,
    ) -> None:
        """Serve ``data`` as ``data.json`` (encoded once), ``trial(i)`` as ``trial/<i>.json``
        and ``trial_walk(i)`` as ``trial/<i>/walk.json``."""
        body = _json(data)
        routes = {".json": trial, "/walk.json": trial_walk}
        with self._lock:
            self._routes = {k: v for k, v in routes.items() if v is not None}
            self._made = {}
            self._data = body

    def respond(self, path: str) -> tuple[int, bytes, str]:
        """Status, body and content type for a GET of ``path``."""
        if path in self.files:
            body, kind = self.files[path]
            return 200, body, kind
        kind = "application/json"
        if path == "/data.json":
            with self._lock:
                data = self._data
            return (
                (200, data, kind) if data is not None else (503, _json({"error": "loading"}), kind)
            )
        m = _TRIAL.fullmatch(path)
        make = self._routes.get(m.group(2)) if m is not None else None
        if m is not None and make is not None:
            key = (m.group(2), int(m.group(1)))
            with self._lock:
                cached = self._made.get(key)
            if cached is None:
                try:
                    cached = _json(make(key[1]))
                except FootfallError as e:
                    return 404, _json({"error": str(e)}), kind
                except Exception as e:  # the page shows it; the server goes on
                    return 500, _json({"error": f"{type(e).__name__}: {e}"}), kind
                with self._lock:
                    self._made[key] = cached
            return 200, cached, kind
        return 404, _json({"error": f"no such page: {path}"}), kind

    def stop(self) -> None:
        """Stop serving and close the port."""
        self.httpd.shutdown()
        self.httpd.server_close()
        self._thread.join(timeout=1.0)


def check_port(host: str, port: int) -> None:
    """Refuse a port out of range or one another program listens on."""
    if port == 0:
        return
    if not 0 < port < 65536:
        raise InputError("port", port, "a TCP port in 1..65535, or 0 for any free port")
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        try:
            s.bind((host, port))
        except OSError as e:
            raise InputError("port", port, f"a free port ({e.strerror}); try --port 0") from None


def start_server(host: str, port: int) -> PageServer:
    """A page server on ``host:port`` (0: any free port)."""
    check_port(host, port)
    return PageServer(host, port)


def stop_server(server: PageServer) -> None:
    """Stop ``server``."""
    server.stop()
