"""The page in a real browser: Playwright drives headless Chromium (software WebGL) against a
served walk. Counts and poses come from the page's own state (``window.footfall``: the node names
it drew, the vertices of a node, a body's pose as drawn), pictures from the browser's screen."""

from __future__ import annotations

import io
import json
import re
import socket
import subprocess
import sys
import urllib.error
import urllib.request
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
#: positions travel as float32 [m]
F32 = 1e-5


def _names(page: Any, prefix: str) -> list[str]:
    names = page.evaluate("() => window.footfall.names")
    return [n for n in names if re.fullmatch(re.escape(prefix) + r"/\d+", n)]


def _body(page: Any, name: str) -> list[float]:
    return page.evaluate("n => window.footfall.bodyPosition(n)", name)


def _pixels(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("L"), dtype=float)


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with chromium() as context:
        yield context


@pytest.fixture(scope="module")
def served(walk_dir: Path) -> Iterator[ViewPage]:
    page = ViewPage(load_view(walk_dir), port=0)
    try:
        yield page
    finally:
        page.close()


@pytest.fixture
def walk_page(served: ViewPage, browser: Any) -> Iterator[tuple[ViewPage, Any]]:
    page = open_page(browser, served.url)
    try:
        yield served, page
    finally:
        page.close()


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
    assert page.evaluate("n => window.footfall.vertexCount(n)", build.LANDED) == 8 * landed
    text = page.inner_text("body")
    assert "walk of short" in text and "frame 1 /" in text
    assert page.evaluate("() => window.footfall.frames") == len(served.t)


def test_the_time_slider_moves_the_robot(walk_page: tuple[ViewPage, Any]) -> None:
    served, page = walk_page
    motion = served.motion
    assert motion is not None
    pelvis = motion.bodies.index("pelvis")
    before_png = capture(page)
    before = _body(page, "pelvis")
    assert before == pytest.approx(list(motion.pos[0, pelvis]), abs=F32)
    slider = page.get_by_role("slider")
    slider.focus()
    slider.press("End")  # the user drags the time to the end of the walk
    page.wait_for_function(
        "([n, x]) => Math.abs(window.footfall.bodyPosition(n)[0] - x) > 0.1",
        arg=["pelvis", before[0]],
    )
    last = len(served.t) - 1
    assert page.evaluate("() => window.footfall.frame") == last
    # the page shows the pelvis where the replay has it at the last frame
    after = _body(page, "pelvis")
    assert after == pytest.approx(list(motion.pos[last, pelvis]), abs=F32)
    assert after[0] - before[0] > MOVED
    changed = np.abs(_pixels(capture(page)) - _pixels(before_png)) > PIXEL_CHANGE
    assert changed.mean() > 0.002  # the robot's picture moved too
    assert f"frame {last + 1} /" in page.inner_text("body")


def test_between_frames_the_pose_is_interpolated(walk_page: tuple[ViewPage, Any]) -> None:
    served, page = walk_page
    motion = served.motion
    assert motion is not None
    pelvis = motion.bodies.index("pelvis")
    f = len(served.t) // 2
    t = 0.25 * served.t[f] + 0.75 * served.t[f + 1]
    page.evaluate("t => window.footfall.setTime(t)", float(t))
    expected = 0.25 * motion.pos[f, pelvis] + 0.75 * motion.pos[f + 1, pelvis]
    assert _body(page, "pelvis") == pytest.approx(list(expected), abs=F32)
    assert page.evaluate("() => window.footfall.frame") == f


def test_the_picture_is_not_blank_and_the_scene_fills_it(walk_page: tuple[ViewPage, Any]) -> None:
    _, page = walk_page
    px = _pixels(capture(page))
    assert px.std() > BLANK_STD
    background = np.median(px[:5, :])  # the top rows are sky
    assert (np.abs(px - background) > 8).mean() > FILLED_SHARE


def test_dragging_turns_the_view(walk_page: tuple[ViewPage, Any]) -> None:
    _, page = walk_page
    before = _pixels(capture(page))
    page.mouse.move(400, 400)
    page.mouse.down()
    page.mouse.move(520, 380, steps=5)
    page.mouse.up()
    after = _pixels(capture(page))
    assert (np.abs(after - before) > PIXEL_CHANGE).mean() > 0.02


def test_play_advances_frames_and_pause_stops(walk_page: tuple[ViewPage, Any]) -> None:
    _, page = walk_page
    page.get_by_text("play / pause").click()
    page.wait_for_function("() => window.footfall.frame >= 2")
    page.get_by_text("play / pause").click()
    state = page.evaluate("() => [window.footfall.playing, window.footfall.frame]")
    assert state[0] is False and state[1] >= 2
    assert re.search(r"frame (\d+) /", page.inner_text("body"))


def test_a_quadruped_page_shows_its_support_polygon(quadruped_dir: Path, browser: Any) -> None:
    served = ViewPage(load_view(quadruped_dir), port=0)
    try:
        page = open_page(browser, served.url)
        names = set(page.evaluate("() => window.footfall.names"))
        assert {"/quadruped/support", "/quadruped/cop", "/quadruped/zmp"} <= names
        assert page.evaluate("() => window.footfall.bodyPosition('trunk')") is not None
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
        assert not page.get_by_text("walk this trial again").is_visible()  # no walker given
        page.select_option("#trial", label=second.key)  # the user picks the second trial
        page.wait_for_function("() => /no plan in the cache/.test(document.body.innerText)")
        assert _names(page, build.FOOTSTEPS) == []  # this trial has no plan
        assert len(_names(page, build.REGIONS)) == 1  # the scene stays
        page.close()
    finally:
        served.close()


def test_a_study_trial_walks_again_in_the_page(mujoco_study_dir: Path, browser: Any) -> None:
    from footfall.experiments.study.rewalk import trial_walker

    served = ViewPage(load_view(mujoco_study_dir), port=0, trial_walker=trial_walker)
    try:
        page = open_page(browser, served.url)
        assert page.evaluate("() => window.footfall.frames") == 0  # a study row has no motion
        page.get_by_text("walk this trial again").click()  # the server walks it (seconds)
        page.wait_for_function("() => window.footfall.frames > 10", timeout=300_000)
        assert "walked again" in page.inner_text("body")
        assert page.evaluate("() => window.footfall.bodyPosition('pelvis')") is not None
        page.get_by_role("slider").press("End")
        assert page.evaluate("() => window.footfall.frame") == page.evaluate(
            "() => window.footfall.frames - 1"
        )
        page.close()
    finally:
        served.close()


def _get(url: str) -> tuple[int, Any]:
    try:
        with urllib.request.urlopen(url, timeout=10) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def test_the_server_answers_its_routes_only(served: ViewPage) -> None:
    status, body = _get(served.url + "data.json")
    assert status == 200 and json.loads(body)["title"] == served.data.title
    for path in ("etc/passwd", "../pyproject.toml", "static/viewer.js", "trial/0.json"):
        status, body = _get(served.url + path)
        assert status == 404 and "error" in json.loads(body), path  # a walk has no trials


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
