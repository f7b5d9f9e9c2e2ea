"""What the commands write: every file whole or not at all (an interrupted write leaves the
previous file, never a truncated one), no file of an earlier run beside a new one, and never an
output over one of the command's inputs."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from matplotlib.figure import Figure
from typer.testing import CliRunner

from footfall.cli import app
from tests.cli import error_line, footfall
from tests.planning.scenes import SHORT_FLAT

#: what an interrupted figure write leaves when written in place (the issue's walk.png)
TRUNCATED = 124


class Interrupted(BaseException):
    """Stands for SIGTERM arriving inside a write (footfall's handler raises a BaseException)."""


def _savefig_interrupted(self: Figure, target: Any, *args: Any, **kwargs: Any) -> None:
    """Write the first bytes of a PNG to ``target``, then be interrupted."""
    with open(target, "wb") as fh:
        fh.write(b"\x89PNG" + b"\0" * (TRUNCATED - 4))
    raise Interrupted


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".tmp" in p.name)


def test_an_interrupted_figure_leaves_the_previous_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from footfall.planning import make_plan
    from footfall.terrain import load_scene
    from footfall.viz.plan_plot import plot_plan

    sc = load_scene(SHORT_FLAT)
    plan = make_plan(sc, "kinematic", 3)
    path = plot_plan(plan, sc, tmp_path / "plan.png")
    good = path.read_bytes()
    monkeypatch.setattr(Figure, "savefig", _savefig_interrupted)
    with pytest.raises(Interrupted):
        plot_plan(plan, sc, path)
    assert path.read_bytes() == good
    assert _leftovers(tmp_path) == []


def test_a_writer_interrupted_in_atomic_path_leaves_the_previous_file(tmp_path: Path) -> None:
    from footfall._io import atomic_path, write_json

    path = write_json(tmp_path / "plan.json", {"status": "optimal"})
    with pytest.raises(Interrupted), atomic_path(path) as tmp:
        assert tmp.parent == path.parent and tmp.suffix == ".json" and tmp != path
        tmp.write_text('{"status": "ti')
        raise Interrupted
    assert json.loads(path.read_text()) == {"status": "optimal"}
    assert _leftovers(tmp_path) == []


def test_a_run_stopped_while_writing_leaves_no_file_of_the_earlierfootfall(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`plan` interrupted between plan.json and plan.png: the new plan.json is there, the old
    plan.png is gone (not left beside it, not truncated)."""
    scene_file = tmp_path / "flat.yaml"
    scene_file.write_text(SHORT_FLAT)
    out = tmp_path / "out"
    args = ["plan", str(scene_file), "--planner", "kinematic", "--steps", "3", "--out", str(out)]
    assert CliRunner().invoke(app, args).exit_code == 0
    assert (out / "plan.png").stat().st_size > 10_000
    monkeypatch.setattr(Figure, "savefig", _savefig_interrupted)
    with pytest.raises(Interrupted):
        CliRunner().invoke(app, [*args[:4], "--steps", "4", "--out", str(out)])
    assert len(json.loads((out / "plan.json").read_text())["footsteps"]) == 5  # this run's
    assert not (out / "plan.png").exists()
    assert _leftovers(out) == []


def _refused(r: subprocess.CompletedProcess[str], field: str) -> None:
    assert "not an input" in error_line(r, f"{field}:")


def test_a_figure_never_replaces_the_height_map_it_is_made_from(tmp_path: Path) -> None:
    from PIL import Image

    counts = np.full((20, 30), 1000, dtype=np.uint16)
    Image.fromarray(counts).save(tmp_path / "m.png")
    before = (tmp_path / "m.png").read_bytes()
    r = footfall("terrain", "from-heightmap", str(tmp_path / "m.png"), "--resolution", "0.02",
             "--height-scale", "0.001", "--out", str(tmp_path / "m.yaml"))  # fmt: skip
    _refused(r, "out")
    assert (tmp_path / "m.png").read_bytes() == before
    assert not (tmp_path / "m.yaml").exists()


def test_check_never_writes_over_the_plan_it_checks(tmp_path: Path) -> None:
    from footfall._io import write_json
    from footfall.planning import make_plan
    from footfall.terrain import load_scene

    sc = load_scene(SHORT_FLAT)
    plan_file = write_json(tmp_path / "check.json", make_plan(sc, "kinematic", 3).to_dict(sc.name))
    before = plan_file.read_bytes()
    scene_file = tmp_path / "flat.yaml"
    scene_file.write_text(SHORT_FLAT)
    _refused(footfall("check", str(plan_file), str(scene_file), "--out", str(tmp_path)), "out")
    assert plan_file.read_bytes() == before


@pytest.mark.parametrize("target", ["scene", "link"])
def test_the_progress_log_never_replaces_the_scene(tmp_path: Path, target: str) -> None:
    scene_file = tmp_path / "flat.yaml"
    scene_file.write_text(SHORT_FLAT)
    log = scene_file
    if target == "link":  # another name for the same file
        log = tmp_path / "log.jsonl"
        log.symlink_to(scene_file)
    r = footfall("plan", str(scene_file), "--steps", "3", "--log-json", str(log),
             "--out", str(tmp_path / "out"))  # fmt: skip
    _refused(r, "log_json")
    assert scene_file.read_text() == SHORT_FLAT


def test_a_log_that_cannot_be_written_is_refused_before_planning(tmp_path: Path) -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full here")
    r = footfall("plan", "--scene", "flat", "--steps", "8", "--log-json", "/dev/full",
                 "--out", str(tmp_path))  # fmt: skip
    error_line(r, "log_json:")
    assert not (tmp_path / "plan.json").exists()


def test_an_interrupted_replay_leaves_the_previous_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """replay.npz (what `footfall view` replays) is written whole or not at all, like the rest."""
    from footfall.sim.replay import REPLAY_FILE, ReplayRecorder

    class _Data:
        qpos = np.zeros(3)

    rec = ReplayRecorder("biped")
    rec.begin("<mujoco/>")
    rec.sample(0.0, _Data())
    path = rec.write(tmp_path / REPLAY_FILE)
    good = path.read_bytes()

    def savez_interrupted(fh: Any, **arrays: Any) -> None:
        fh.write(b"PK\x03\x04" + b"\0" * 60)  # the start of a zip, then the signal
        raise Interrupted

    monkeypatch.setattr(np, "savez_compressed", savez_interrupted)
    with pytest.raises(Interrupted):
        rec.write(path)
    assert path.read_bytes() == good
    assert _leftovers(tmp_path) == []


def test_an_interrupted_video_leaves_the_previous_one(tmp_path: Path) -> None:
    """The MuJoCo plants' video (sim/_video.Video) is put in place only when the walk completes."""
    pytest.importorskip("imageio_ffmpeg")
    from footfall.sim._video import Video

    class _Renderer:
        def __init__(self, model: Any, height: int, width: int) -> None:
            self.shape = (height, width, 3)

        def update_scene(self, data: Any, camera: str) -> None:
            pass

        def render(self) -> Any:
            return np.zeros(self.shape, dtype=np.uint8)

        def close(self) -> None:
            pass

    class _Mujoco:
        Renderer = _Renderer

    path = tmp_path / "walk.mp4"

    def record(complete: bool) -> Path | None:
        video = Video(_Mujoco, None, path, (64, 48), 1 / 30, "track")
        for k in range(3):
            assert video.frame(k, None)
        return video.close(complete)

    assert record(True) == path
    good = path.read_bytes()
    assert record(False) is None
    assert path.read_bytes() == good
    assert _leftovers(tmp_path) == []


@pytest.mark.parametrize("given_as", ["MODEL", "--config"])
def test_robot_inspect_never_writes_over_the_robot_file_it_reads(
    tmp_path: Path, given_as: str
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    robot_file = out / "robot.yaml"
    robot_file.write_text("name: mine\nmodel: mine.urdf\n")
    before = robot_file.read_bytes()
    model = robot_file if given_as == "MODEL" else tmp_path / "mine.urdf"
    config = ["--config", str(robot_file)] if given_as == "--config" else []
    _refused(footfall("robot", "inspect", str(model), *config, "--out", str(out)), "out")
    assert robot_file.read_bytes() == before


def test_view_never_writes_its_screenshot_over_what_it_shows(tmp_path: Path) -> None:
    shown = tmp_path / "shot.png"
    shown.write_bytes(b"\x89PNG earlier picture")
    _refused(footfall("view", str(shown), "--screenshot", str(shown)), "screenshot")
    assert shown.read_bytes() == b"\x89PNG earlier picture"
