"""Loading what footfall wrote into the page's data: one loader per kind, old folders, bad files."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("trimesh")

from footfall.errors import InputError
from footfall.models.biped import Side
from footfall.planning import load_plan
from footfall.terrain import builtin_scene, load_scene
from footfall.terrain.scene import scene_to_yaml
from footfall.viz.view import load_view
from footfall.viz.view.load import sole_points
from footfall.viz.view.replay import read_replay

#: exact arithmetic of a rotation and a sum
EXACT_TOL = 1e-12
#: positions stored as float32
FLOAT32_TOL = 1e-5


def test_a_walk_folder_holds_its_scene_plan_robot_and_sole_traces(walk_dir: Path) -> None:
    data = load_view(walk_dir)
    assert data.kind == "walk" and data.notes == ()
    saved = load_scene(walk_dir.parent / "short.yaml")
    assert data.scene is not None and len(data.scene.terrain) == len(saved.terrain)
    assert data.plan is not None and data.plan.n_steps == 4
    w = data.walk
    assert w is not None and w.motion is not None
    assert w.planned.shape == (4, 3) and np.all(np.isfinite(w.landed))
    # the measured CoP lies on a sole: within half the sole's diagonal of a foot's centre, at its
    # height (flat ground)
    known = np.all(np.isfinite(w.cop), axis=1)
    assert known.sum() > 10
    half = math.hypot(data.plan.robot.foot_length, data.plan.robot.foot_width) / 2
    feet = read_replay(walk_dir / "replay.npz").traces["feet"][known]
    gaps = np.linalg.norm(w.cop[known, None, :] - feet, axis=2).min(axis=1)
    assert np.all(gaps <= half + FLOAT32_TOL)
    # the push is where the CoM was when it came
    (push,) = w.pushes
    assert push.at is not None and push.at[2] > 0.3
    assert np.linalg.norm(push.force) == pytest.approx(40.0, rel=1e-6)


def test_a_folder_written_before_replays_still_opens(walk_dir: Path, tmp_path: Path) -> None:
    old = tmp_path / "old"
    shutil.copytree(walk_dir, old)
    (old / "replay.npz").unlink()
    data = load_view(old, scene=str(walk_dir.parent / "short.yaml"))
    assert data.walk is not None and data.walk.motion is None
    assert any("replay.npz" in n for n in data.notes)
    assert data.plan is not None and data.scene is not None
    # without the scene file, a scene that is not built in is a note, not an error
    data = load_view(old / "walk.json")
    assert data.scene is None and any("--scene" in n for n in data.notes)


def test_sole_points_turn_offsets_by_the_stance_heading(walk_dir: Path) -> None:
    plan = load_plan(walk_dir / "plan.json")
    i = 1
    side = 0 if plan.sides[i] is Side.LEFT else 1
    feet = np.zeros((3, 2, 3))
    feet[:, side] = [1.0, 2.0, 0.5]
    offset = np.array([[0.02, 0.0], [0.0, 0.01], [np.nan, np.nan]])
    phase = np.array([i, i, i])
    got = sole_points(offset, phase, feet, plan)
    th = plan.headings[i]
    assert np.allclose(
        got[0], [1 + 0.02 * math.cos(th), 2 + 0.02 * math.sin(th), 0.5], atol=EXACT_TOL
    )
    assert np.allclose(
        got[1], [1 - 0.01 * math.sin(th), 2 + 0.01 * math.cos(th), 0.5], atol=EXACT_TOL
    )
    assert np.all(np.isnan(got[2]))
    assert np.all(np.isnan(sole_points(offset[:1], np.array([-1]), feet[:1], plan)))


def test_scene_and_plan_files_open_alone(walk_dir: Path, tmp_path: Path) -> None:
    scene = builtin_scene("discrete_steps")
    path = tmp_path / "scene.yaml"
    path.write_text(scene_to_yaml(scene))
    for p in (path, tmp_path):  # the file, or the folder `footfall scenes --show` wrote
        data = load_view(p)
        assert data.kind == "scene" and data.scene is not None
        assert len(data.scene.terrain) == len(scene.terrain)
    data = load_view(walk_dir / "plan.json", scene=str(walk_dir.parent / "short.yaml"))
    assert data.kind == "plan" and data.plan is not None and data.scene is not None


def test_a_quadruped_folder_holds_feet_contacts_cop_and_zmp(quadruped_dir: Path) -> None:
    data = load_view(quadruped_dir)
    q = data.quadruped
    assert data.kind == "quadruped" and q is not None and q.motion is not None
    n = len(q.motion.t)
    assert q.feet.shape == (n, 4, 3) and q.contact.shape == (n, 4)
    # a walk gait: three or four feet down at every instant
    assert np.all(q.contact.sum(axis=1) >= 3)
    assert np.all(np.isfinite(q.zmp))
    report = json.loads((quadruped_dir / "quadruped.json").read_text())
    assert data.title == f"quadruped walk of {report['robot']['name']}"
    assert q.summary == (
        f"distance up the slope {report['distance_up_slope_m']:.2f} m, fell {report['fell']}"
    )


def test_a_study_folder_lists_its_trials_with_their_plans(study_dir: Path) -> None:
    data = load_view(study_dir)
    first, second = data.trials
    assert data.kind == "study" and first.plan is not None and first.plan.n_steps == 4
    assert second.plan is None and any("no plan" in n for n in data.notes)
    assert first.push is not None
    # 10 N s over the pulse, along +y (pi / 2)
    assert first.push.force[1] * first.push.duration == pytest.approx(10.0)
    assert abs(first.push.force[0]) < 1e-9
    assert [s.name for s in data.scenes] == ["flat"]


@pytest.mark.parametrize("name", ["missing", "notes.txt", "folder"])
def test_what_footfall_did_not_write_is_an_input_error(name: str, tmp_path: Path) -> None:
    path = tmp_path / name
    if name == "notes.txt":
        path.write_text("hello")
    elif name == "folder":
        path.mkdir()
    with pytest.raises(InputError) as err:
        load_view(path)
    assert err.value.field == "path"


def test_a_truncated_walk_file_names_itself(walk_dir: Path, tmp_path: Path) -> None:
    bad = tmp_path / "bad"
    shutil.copytree(walk_dir, bad)
    text = (bad / "walk.json").read_text()
    (bad / "walk.json").write_text(text[: len(text) // 2])
    with pytest.raises(InputError, match=r"walk\.json"):
        load_view(bad)
