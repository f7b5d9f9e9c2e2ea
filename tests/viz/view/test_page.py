"""The page in a real browser: Playwright drives headless Chromium (software WebGL) against a
served walk. The counts come from the scene tree the page received (viser's client exposes it to
tests as ``window.__viserSceneTree``), the robot's pose from the page's three.js objects."""

from __future__ import annotations

import io
import re
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.viz.view.conftest import browser_or_skip

browser_or_skip()

from PIL import Image  # noqa: E402

from footfall.viz.view import build, load_view  # noqa: E402
from footfall.viz.view.browser import capture, chromium, open_page  # noqa: E402
from footfall.viz.view.page import ViewPage  # noqa: E402

#: a picture with less pixel spread than this is blank [grey levels]
BLANK_STD = 10.0
#: share of the picture that differs from the background when the scene fills it
FILLED_SHARE = 0.25
#: the pelvis must move this far [m] between the first and the last frame of a 0.6 m walk
MOVED = 0.3
#: grey levels by which a pixel of the robot differs after it moved
PIXEL_CHANGE = 30

_NODE_POS = "n => { const o = window.__viserMutable.nodeRefFromName[n]; return o ? o.position.toArray() : null; }"


_VERTICES = """n => { let count = 0;
  window.__viserMutable.nodeRefFromName[n].traverse(o => {
    if (o.isMesh) count += o.geometry.attributes.position.count; });
  return count; }"""


def _names(page: Any, prefix: str) -> list[str]:
    tree = page.evaluate("() => Object.keys(window.__viserSceneTree.getState())")
    return [n for n in tree if re.fullmatch(re.escape(prefix) + r"/\d+", n)]


def _pixels(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("L"), dtype=float)


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with chromium() as context:
        yield context


@pytest.fixture(scope="module")
def walk_page(walk_dir: Path, browser: Any) -> Iterator[tuple[ViewPage, Any]]:
    served = ViewPage(load_view(walk_dir), port=0)
    try:
        yield served, open_page(browser, served.url)
    finally:
        served.close()


def test_the_page_holds_every_region_and_footstep(walk_page: tuple[ViewPage, Any]) -> None:
    served, page = walk_page
    data = served.data
    assert data.scene is not None and data.plan is not None and data.walk is not None
    assert len(_names(page, build.REGIONS)) == len(data.scene.terrain)
    assert len(_names(page, build.FOOTSTEPS)) == data.plan.n_steps + 1
    # the plan's footsteps 1..N where they landed (the stop steps after them are not the plan's),
    # in one mesh of a sole's 8 corners each
    landed = np.all(np.isfinite(data.walk.landed[: data.plan.n_steps]), axis=1).sum()
    assert landed == data.plan.n_steps
    assert page.evaluate(_VERTICES, build.LANDED) == 8 * landed
    text = page.inner_text("body")
    assert "walk of short" in text and "frame 1 /" in text


def test_the_time_slider_moves_the_robot(walk_page: tuple[ViewPage, Any]) -> None:
    served, page = walk_page
    before_png = capture(page)
    before = page.evaluate(_NODE_POS, "/robot/pelvis")
    assert served.frame == 0 and before == pytest.approx(list(served.motion.pos[0, 0]), abs=1e-6)
    slider = page.get_by_role("slider")
    slider.focus()
    slider.press("End")  # the user drags the time to the end of the walk
    page.wait_for_function(
        "([n, x]) => { const o = window.__viserMutable.nodeRefFromName[n];"
        " return o && Math.abs(o.position.x - x) > 0.1; }",
        arg=["/robot/pelvis", before[0]],
    )
    last = len(served.t) - 1
    assert served.frame == last  # the server posed the last frame ...
    after = page.evaluate(_NODE_POS, "/robot/pelvis")
    # ... and the page shows the pelvis where the replay has it
    assert after == pytest.approx(list(served.motion.pos[last, 0]), abs=1e-5)
    assert after[0] - before[0] > MOVED
    changed = np.abs(_pixels(capture(page)) - _pixels(before_png)) > PIXEL_CHANGE
    assert changed.mean() > 0.002  # the robot's picture moved too
    assert f"frame {last + 1} /" in page.inner_text("body")


def test_the_picture_is_not_blank_and_the_scene_fills_it(walk_page: tuple[ViewPage, Any]) -> None:
    _, page = walk_page
    px = _pixels(capture(page))
    assert px.std() > BLANK_STD
    background = np.median(px[:5, :])  # the top rows are sky
    assert (np.abs(px - background) > 8).mean() > FILLED_SHARE


def test_play_advances_frames(walk_page: tuple[ViewPage, Any]) -> None:
    served, page = walk_page
    served.set_frame(0)
    page.get_by_text("play / pause").click()
    page.wait_for_function("() => /frame ([2-9]|\\d\\d+) \\//.test(document.body.innerText)")
    page.get_by_text("play / pause").click()
    assert served.frame > 0


def test_a_quadruped_page_shows_its_support_polygon(quadruped_dir: Path, browser: Any) -> None:
    served = ViewPage(load_view(quadruped_dir), port=0)
    try:
        page = open_page(browser, served.url)
        tree = page.evaluate("() => Object.keys(window.__viserSceneTree.getState())")
        assert {"/quadruped/support", "/quadruped/cop", "/quadruped/zmp", "/robot/trunk"} <= set(
            tree
        )
        page.close()
    finally:
        served.close()


def test_a_study_page_shows_the_picked_trial(study_dir: Path, browser: Any) -> None:
    served = ViewPage(load_view(study_dir), port=0)
    try:
        page = open_page(browser, served.url)
        first, second = served.data.trials
        assert first.plan is not None
        assert len(_names(page, build.FOOTSTEPS)) == first.plan.n_steps + 1
        served.show_trial(second.key)  # what the trial picker does; this trial has no plan
        page.wait_for_function(  # the soles are gone (their parent groups may stay, empty)
            "() => !Object.keys(window.__viserSceneTree.getState())"
            ".some(n => /^\\/plan\\/footsteps\\/\\d+$/.test(n))"
        )
        assert len(_names(page, build.REGIONS)) == 1  # the scene stays
        assert "no plan in the cache" in page.inner_text("body")
        page.close()
    finally:
        served.close()


def _cli(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str
) -> tuple[int, str]:
    """Run ``footfall view ARGS`` through the console script's entry point (its exit codes and
    its one-line errors); the exit code and what it printed on stderr."""
    from footfall.cli import main

    monkeypatch.setattr(sys, "argv", ["footfall", "view", *args])
    capsys.readouterr()
    with pytest.raises(SystemExit) as done:
        main()
    code = done.value.code
    return (0 if code is None else int(code)), capsys.readouterr().err


def test_screenshot_writes_a_picture_and_exits(walk_dir: Path, tmp_path: Path) -> None:
    # a process of its own: the command starts its own Playwright (one a thread may run)
    out = tmp_path / "walk.png"
    args = [str(walk_dir), "--screenshot", str(out), "--size", "800x450"]
    r = subprocess.run(
        [sys.executable, "-m", "footfall", "view", *args],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert r.returncode == 0, r.stderr
    img = Image.open(out)
    assert img.size == (800, 450)
    assert np.asarray(img.convert("L"), dtype=float).std() > BLANK_STD


def test_bad_inputs_exit_2_with_one_clear_line(
    walk_dir: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    cut = tmp_path / "cut"
    cut.mkdir()
    for name in ("walk.json", "plan.json"):
        (cut / name).write_bytes((walk_dir / name).read_bytes())
    good = (walk_dir / "replay.npz").read_bytes()
    (cut / "replay.npz").write_bytes(good[: len(good) // 3])
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        cases = {
            "path:": [str(tmp_path / "nowhere")],
            "replay": [str(cut)],
            "port": [str(walk_dir), "--port", str(port)],
            "screenshot": [str(walk_dir), "--screenshot", str(tmp_path / "x.jpg")],
            "size": [str(walk_dir), "--size", "huge"],
        }
        for word, args in cases.items():
            code, err = _cli(monkeypatch, capsys, *args)
            assert code == 2, (args, err)
            assert word in err and "Traceback" not in err, err
            assert len([ln for ln in err.splitlines() if ln.strip()]) == 1, err
