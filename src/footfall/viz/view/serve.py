"""Start the page's server before anything heavy is imported: a browser can load the page (its
client is a large script) while the files are read and drawn into it.

This module imports viser and nothing of footfall's models, planning or terrain.
"""

from __future__ import annotations

import contextlib
import io
import socket
from typing import Any

from footfall.errors import InputError

#: the node the page gets last (see :func:`footfall.viz.view.browser.wait_loaded`)
READY_NODE = "/footfall_ready"


def _viser() -> Any:
    try:
        import viser
    except ImportError:
        raise InputError("viser", "not installed", "pip install 'footfall[view]'") from None
    return viser


def check_port(host: str, port: int) -> None:
    """Refuse a port another program listens on (viser would silently take the next one)."""
    if port == 0:
        return
    if not 0 < port < 65536:
        raise InputError("port", port, "a TCP port in 1..65535, or 0 for any free port")
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        try:
            s.bind((host, port))
        except OSError as e:
            raise InputError("port", port, f"a free port ({e.strerror}); try --port 0") from None


def start_server(host: str, port: int) -> Any:
    """A viser server on ``host:port`` (0: any free port), lit for software WebGL."""
    viser = _viser()
    check_port(host, port)
    with contextlib.redirect_stdout(io.StringIO()):  # viser prints a banner regardless
        server = viser.ViserServer(host=host, port=port, label="footfall", verbose=False)
    if port and server.get_port() != port:  # taken between the check and the bind
        stop_server(server)
        raise InputError("port", port, "a free port; try --port 0")
    # software WebGL: no environment map (its prefiltering stalls the first frame for seconds)
    # and no shadows
    server.scene.configure_environment_map(None)
    server.scene.configure_default_lights(True, cast_shadow=False)
    server.scene.set_up_direction("+z")
    return server


def stop_server(server: Any) -> None:
    """Stop ``server`` without its "Server stopped" line."""
    with contextlib.redirect_stdout(io.StringIO()):
        server.stop()
