"""The page's document: what the browser receives, decoded here independently of the packing
(base64 of little-endian arrays) and checked against the loaded data it came from."""

from __future__ import annotations

import base64
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("trimesh")

from footfall.errors import InputError
from footfall.viz.view import build, load_view
from footfall.viz.view.payload import page_payload, trial_payload, trial_walk_payload

#: positions travel as float32 [m]
F32 = 1e-6


def _decode(s: str, dtype: str, cols: int) -> np.ndarray:
    return np.frombuffer(base64.b64decode(s), dtype=np.dtype(dtype)).reshape(-1, cols)


def _json_roundtrip(doc: dict[str, Any]) -> dict[str, Any]:
    # what the server sends: strict JSON (no NaN)
    out: dict[str, Any] = json.loads(json.dumps(doc, allow_nan=False))
    return out


def test_tubes_surround_their_segments_at_the_asked_radius() -> None:
    seg = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[0.0, 0.0, 0.0], [0.0, 0.0, 2.0]]])
    mesh = build.tube(build.Lines("/t", seg, (1, 2, 3)), 0.01)
    assert mesh.vertices.shape == (16, 3) and mesh.faces.shape == (16, 3)
    for k, (a, b) in enumerate(seg):
        d = (b - a) / np.linalg.norm(b - a)
        corners = mesh.vertices[8 * k : 8 * k + 8] - a
        along = corners @ d
        across = np.linalg.norm(corners - np.outer(along, d), axis=1)
        assert across == pytest.approx(np.full(8, 0.01 * np.sqrt(2)))
        assert sorted(np.round(along, 12)) == [0.0] * 4 + [np.linalg.norm(b - a)] * 4
    assert mesh.faces.min() == 0 and mesh.faces.max() == 15


def test_a_sphere_is_round() -> None:
    m = build.sphere("/s", 0.02, (0, 0, 0))
    assert np.linalg.norm(m.vertices, axis=1) == pytest.approx(np.full(len(m.vertices), 0.02))
    assert m.faces.max() < len(m.vertices)


def test_a_walk_document_carries_the_replay_and_the_scene(walk_dir: Path) -> None:
    data = load_view(walk_dir)
    doc = _json_roundtrip(page_payload(data, start=0.5))
    assert data.scene is not None and data.plan is not None and data.walk is not None
    motion = data.walk.motion
    assert motion is not None
    names = [m["name"] for m in doc["meshes"]]
    assert sum(n.startswith(build.REGIONS + "/") for n in names) == len(data.scene.terrain)
    assert sum(n.startswith(build.FOOTSTEPS + "/") for n in names) == data.plan.n_steps + 1
    robot = doc["robot"]
    frames, bodies = motion.pos.shape[:2]
    assert robot["bodies"] == list(motion.bodies)
    np.testing.assert_array_equal(_decode(robot["t"], "<f8", 1)[:, 0], motion.t)
    pos = _decode(robot["pos"], "<f4", 3).reshape(frames, bodies, 3)
    np.testing.assert_allclose(pos, motion.pos, atol=F32)
    wxyz = _decode(robot["wxyz"], "<f4", 4).reshape(frames, bodies, 4)
    np.testing.assert_allclose(wxyz, motion.wxyz, atol=F32)
    assert {m["body"] for m in robot["meshes"]} <= set(range(bodies))
    cop = next(m for m in robot["markers"] if m["name"] == "/walk/cop")
    at = _decode(cop["positions"], "<f4", 3)
    assert at.shape == (frames, 3)
    shown = np.isfinite(data.walk.cop[:frames]).all(axis=1)
    assert np.array_equal(np.isfinite(at).all(axis=1), shown)
    np.testing.assert_allclose(at[shown, :2], data.walk.cop[:frames][shown, :2], atol=F32)
    # a mesh's indices name its own vertices
    for m in doc["meshes"]:
        if m["kind"] == "mesh":
            idx = _decode(m["indices"], "<u4", 3)
            assert idx.max() < len(_decode(m["positions"], "<f4", 3)), m["name"]
    # the push: an arrow and a label shown around its time only
    pushes = [m for m in doc["meshes"] if m["name"].startswith("/walk/push/")]
    push = data.walk.pushes[0]
    assert pushes and all(
        m["shown"][0] < push.start < push.start + push.duration < m["shown"][1] for m in pushes
    )
    assert doc["start"] == 0.5 and doc["trials"] == []
    cam = doc["camera"]
    assert np.all(np.isfinite(cam["position"])) and 0 < cam["fov"] < np.pi


def test_the_quadruped_support_polygon_joins_the_stance_feet(quadruped_dir: Path) -> None:
    data = load_view(quadruped_dir)
    q = data.quadruped
    assert q is not None and q.motion is not None
    support = page_payload(data)["robot"]["support"]
    frames = len(q.motion.t)
    seg = _decode(support["positions"], "<f4", 3).reshape(frames, support["per"] // 2, 2, 3)
    for f in range(0, frames, 7):
        stance = q.feet[f][q.contact[f]]
        real = seg[f][np.linalg.norm(seg[f, :, 1] - seg[f, :, 0], axis=1) > 1e-9]
        if stance.shape[0] < 2:
            assert real.shape[0] == 0
            continue
        # every stance foot is a corner, every corner a stance foot (lifted to be seen)
        corners = real[:, 0] - np.array([0.0, 0.0, 2 * build.LIFT])
        assert real.shape[0] == stance.shape[0]
        d = np.linalg.norm(corners[:, None] - stance[None], axis=2)
        assert d.min(axis=1).max() < F32 * 10 and d.min(axis=0).max() < F32 * 10
        # a closed ring: each segment ends where another starts
        assert np.allclose(np.sort(real[:, 1], axis=0), np.sort(real[:, 0], axis=0))


def test_a_study_document_lists_trials_and_each_trial_draws_alone(study_dir: Path) -> None:
    data = load_view(study_dir)
    doc = page_payload(data)
    first, second = data.trials
    assert doc["trials"] == [first.key, second.key] and doc["robot"] is None
    assert first.plan is not None
    soles = [m for m in doc["meshes"] if m["name"].startswith(build.FOOTSTEPS + "/")]
    assert len(soles) == first.plan.n_steps + 1
    other = trial_payload(data, 1)
    assert "no plan in the cache" in other["outcome"]
    assert not any(m["name"].startswith(build.FOOTSTEPS) for m in other["meshes"])
    with pytest.raises(InputError, match="trial"):
        trial_payload(data, 2)


def test_a_start_time_must_be_a_time(walk_dir: Path) -> None:
    data = load_view(walk_dir)
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(InputError, match="time"):
            page_payload(data, start=bad)


def test_a_trial_walked_again_is_the_walk_its_row_records(
    mujoco_study_dir: Path, tmp_path: Path
) -> None:
    from footfall.experiments.study.rewalk import trial_walker
    from footfall.experiments.study.store import read_rows

    data = load_view(mujoco_study_dir)
    (trial,) = data.trials
    row = read_rows(mujoco_study_dir / "trials.parquet")[0]
    scene = next(s for s in data.scenes if s.name == trial.scene)
    outcome = trial_walker(mujoco_study_dir, trial, scene, tmp_path)
    # the simulator is deterministic: the same walk, number for number
    for name in ("success", "fell", "goal_error", "zmp_offset_mean", "steps_landed"):
        assert getattr(outcome, name) == row[name], name
    walked = load_view(tmp_path)  # a walk's folder, as footfall walk writes it
    assert walked.walk is not None and walked.walk.motion is not None
    assert len(walked.walk.motion.t) > 10 and walked.walk.pushes
    # and the page document of it carries the robot and says what the walk did
    doc = _json_roundtrip(trial_walk_payload(data, 0, trial_walker))
    assert doc["robot"] is not None
    assert doc["summaries"] == [
        f"walked again: success {outcome.success}, fell {outcome.fell}, goal error "
        f"{outcome.goal_error:.4g} m, ZMP offset mean {outcome.zmp_offset_mean:.4g} m"
    ]


def test_a_reduced_study_has_no_walk_to_show_again(study_dir: Path, tmp_path: Path) -> None:
    from footfall.experiments.study.design import StudyDesign

    design = StudyDesign(name="r", simulator="reduced", controller=None, scenes=("flat",))
    (study_dir / "study.json").write_text(
        json.dumps({"fingerprint": design.fingerprint(), "design": design.to_dict()})
    )
    from footfall.experiments.study.rewalk import trial_walker

    data = load_view(study_dir)
    with pytest.raises(InputError, match="MuJoCo study"):
        trial_walk_payload(data, 0, trial_walker)
