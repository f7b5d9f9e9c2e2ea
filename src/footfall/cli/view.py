"""``footfall view``: the interactive 3-D page of what another command wrote."""

from __future__ import annotations

import math
import re
import time
from pathlib import Path
from typing import Any

import typer

from footfall.cli._common import app, console, refuse_inputs_as_outputs
from footfall.errors import InputError


def _size(text: str) -> tuple[int, int]:
    """``WIDTHxHEIGHT`` in pixels."""
    m = re.fullmatch(r"\s*(\d{2,5})\s*[xX]\s*(\d{2,5})\s*", text)
    if m is None or not (64 <= int(m[1]) <= 8192 and 64 <= int(m[2]) <= 8192):
        raise InputError("size", text, "WIDTHxHEIGHT in pixels, each 64..8192, e.g. 1280x720")
    return int(m[1]), int(m[2])


@app.command("view")
def view_command(
    path: Path = typer.Argument(
        ...,
        help="What to show: a scene .yaml, a plan.json, or a folder (or file) of `footfall "
        "walk`, `footfall quadruped` or `footfall study`.",
    ),
    scene: str | None = typer.Option(
        None, help="The terrain (built-in name or YAML file) when PATH's files do not hold it."
    ),
    host: str = typer.Option("127.0.0.1", help="Address to serve the page on."),
    port: int = typer.Option(8080, help="Port to serve the page on (0: any free port)."),
    screenshot: Path | None = typer.Option(
        None, help="Render the page headless into this PNG and exit (needs Chromium)."
    ),
    size: str = typer.Option("1280x720", help="Picture size of --screenshot, WIDTHxHEIGHT [px]."),
    at: float = typer.Option(
        0.0, "--time", help="Show the recorded motion at this time [s] (the slider's start)."
    ),
) -> None:
    """Serve an interactive 3-D page of a scene, plan, walk, quadruped walk or study:
    terrain coloured by height, footsteps with index and side, the CoM path, the robot replayed
    with a time slider, measured CoP against planned ZMP, pushes. With --screenshot, render it
    headless into a PNG and exit."""
    from footfall.viz.view.serve import start_server, stop_server

    width_height = _size(size)
    if not (math.isfinite(at) and at >= 0.0):
        raise InputError("time", at, "a finite time >= 0 [s]")
    if screenshot is not None and (screenshot.is_dir() or screenshot.suffix.lower() != ".png"):
        raise InputError("screenshot", str(screenshot), "a .png file path")
    if screenshot is not None and not screenshot.parent.is_dir():
        raise InputError("screenshot", str(screenshot), "a path in an existing folder")
    if not path.exists():  # before anything starts
        raise InputError("path", str(path), "an existing file or folder that footfall wrote")
    if screenshot is not None:
        refuse_inputs_as_outputs([path, scene], {"screenshot": [screenshot]})
    # serve first: a browser loads the page while the planner's modules are imported and the
    # files read and drawn into it
    server = start_server(host, 0 if screenshot is not None else port)
    try:
        from footfall.viz.view import load_view
        from footfall.viz.view.page import ViewPage

        page = ViewPage(None, host, server=server, trial_walker=_walk_trial_again)
    except BaseException:
        stop_server(server)
        raise
    try:
        data = load_view(path, scene)
        for note in data.notes:
            console.print(f"note: {note}")
        page.show(data, start=at)
        if screenshot is not None:
            from footfall.viz.view.browser import screenshot as take

            take(page.url, screenshot, width_height)
            console.print(f"wrote {screenshot}")
            return
        console.print(f"{data.title}: {page.url} (Ctrl-C to stop)")
        while True:
            time.sleep(1.0)
    finally:
        page.close()


def _walk_trial_again(folder: Path, trial: Any, scene: Any, out: Path) -> Any:
    """The study's own walker for the page's "walk this trial again" (imported when asked: the
    simulation is not needed to show a page)."""
    from footfall.experiments.study.rewalk import trial_walker

    return trial_walker(folder, trial, scene, out)
