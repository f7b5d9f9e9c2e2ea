"""Headless Chromium through Playwright: open the page, wait for it, take its picture.

Playwright drives the system's Chromium (Debian's ``chromium`` package, or ``$FOOTFALL_CHROMIUM``)
with software WebGL (SwiftShader): no display and no GPU needed, no browser download.
"""

from __future__ import annotations

import base64
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from footfall.errors import FootfallError, InputError

#: a browser the environment names, then the usual names of a system Chromium
BROWSER_ENV = "FOOTFALL_CHROMIUM"
BROWSER_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
#: headless, software WebGL, nothing that reaches out to the network
CHROMIUM_ARGS = (
    "--headless=new",
    "--no-sandbox",
    "--disable-gpu",
    "--use-gl=angle",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-default-apps",
    "--no-first-run",
    "--mute-audio",
)
#: how long the page may take to receive the scene [ms]
LOAD_TIMEOUT_MS = 60_000


def chromium_path() -> str:
    """The Chromium executable to drive; an :class:`InputError` says how to install one."""
    given = os.environ.get(BROWSER_ENV)
    if given:
        if not (Path(given).is_file() and os.access(given, os.X_OK)):
            raise InputError(BROWSER_ENV, given, "the path of a Chromium executable")
        return given
    for name in BROWSER_NAMES:
        found = shutil.which(name)
        if found:
            return found
    raise InputError(
        "browser", "no Chromium found", f"apt-get install chromium (or set {BROWSER_ENV})"
    )


@contextmanager
def chromium() -> Iterator[Any]:
    """A headless Chromium (a Playwright ``Browser``) with a fresh profile, closed on exit."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        raise InputError("playwright", "not installed", "pip install 'footfall[view]'") from None
    exe = chromium_path()
    with tempfile.TemporaryDirectory(prefix="footfall-chromium-") as profile:
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(
                profile,
                executable_path=exe,
                args=list(CHROMIUM_ARGS),
                headless=True,
                viewport={"width": 1280, "height": 720},
            )
            try:
                yield context
            finally:
                context.close()


def wait_loaded(page: Any, timeout_ms: int = LOAD_TIMEOUT_MS) -> None:
    """Wait until the page holds the whole scene and has drawn it (``window.footfall.ready``),
    then two animation frames more; a page that failed raises its message."""
    page.wait_for_function(
        "() => !!(window.footfall && (window.footfall.ready || window.footfall.error))",
        timeout=timeout_ms,
        polling=20,
    )
    error = page.evaluate("() => window.footfall.error")
    if error:
        raise FootfallError(f"the page could not draw: {error}")
    page.evaluate(
        "() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => r(0))))"
    )


def open_page(context: Any, url: str, size: tuple[int, int] = (1280, 720)) -> Any:
    """A new tab of ``context`` showing ``url`` at ``size`` (width, height) [px], loaded."""
    page = context.new_page()
    page.set_viewport_size({"width": size[0], "height": size[1]})
    page.goto(url)
    wait_loaded(page)
    return page


def capture(page: Any) -> bytes:
    """The page as PNG bytes (through the DevTools protocol: Playwright's own screenshot waits
    for web fonts the page cannot fetch offline)."""
    page.evaluate(
        "() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => r(0))))"
    )
    cdp = page.context.new_cdp_session(page)
    try:
        shot = cdp.send("Page.captureScreenshot", {"format": "png"})
    finally:
        cdp.detach()
    return base64.b64decode(shot["data"])


def write_atomic(path: Path, content: bytes) -> Path:
    """Write ``content`` to ``path`` whole or not at all (:func:`footfall._io.atomic_open`: a
    temporary file beside it, flushed to disk and renamed over it)."""
    from footfall._io import atomic_open

    with atomic_open(path, "wb") as fh:
        fh.write(content)
    return path


def screenshot(url: str, out: Path, size: tuple[int, int] = (1280, 720)) -> Path:
    """Open ``url`` headless, wait for its scene and write its picture to ``out`` (PNG)."""
    with chromium() as context:
        page = open_page(context, url, size)
        return write_atomic(out, capture(page))
