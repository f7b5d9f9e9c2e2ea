"""The replay a walk records (footfall.sim.replay) and its reader (footfall.viz.view.replay)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("trimesh")

from footfall.errors import InputError  # noqa: E402
from footfall.models.biped import Side  # noqa: E402
from footfall.planning import load_plan  # noqa: E402
from footfall.robots import names as nm  # noqa: E402
from footfall.sim.replay import DISPLAY_RATE, REPLAY_FILE, ReplayRecorder, at_frames  # noqa: E402
from footfall.viz.view.replay import read_replay, robot_motion  # noqa: E402

#: float32 storage of positions of order 1 m
FLOAT32_TOL = 1e-5
#: the walk measures its soles from MuJoCo's site positions of the last mj_step, computed before
#: that step integrated qpos: one physics step (2 ms) behind the replay. A standing sole barely
#: moves in it; a swinging one (up to ~3 m/s) moves millimetres
STANCE_LAG_TOL, SWING_LAG_TOL = 2e-4, 0.01
#: a replay's bytes per second of walk (30 frames of 19 joint positions and traces, compressed)
BYTES_PER_SECOND = 15_000


class _Data:
    def __init__(self, nq: int) -> None:
        self.qpos = np.zeros(nq)


def test_the_recorder_keeps_one_frame_per_display_instant(tmp_path: Path) -> None:
    rec = ReplayRecorder("biped")
    rec.begin("<mujoco/>")
    data = _Data(3)
    dt = 0.002  # a control tick far finer than the display
    for k in range(1001):
        data.qpos[:] = k
        rec.sample(k * dt, data)
    t = rec.times
    assert t[0] == 0.0
    assert len(t) == round(2.0 * DISPLAY_RATE) + 1
    # frames lie on the display grid (to a tick) and never drift
    assert np.all(np.abs(t * DISPLAY_RATE - np.round(t * DISPLAY_RATE)) <= dt * DISPLAY_RATE)
    path = rec.write(tmp_path / REPLAY_FILE, {"x": t * 2})
    with np.load(path, allow_pickle=False) as f:
        assert f["qpos"].dtype == np.float32 and f["qpos"].shape == (len(t), 3)
        assert np.allclose(f["qpos"][:, 0], np.round(t / dt), atol=1e-3)
        assert np.allclose(f["trace/x"], 2 * t, atol=FLOAT32_TOL)
    with pytest.raises(InputError):
        rec.write(tmp_path / "bad.npz", {"x": np.zeros(3)})  # not one row a frame
    assert not list(tmp_path.glob(".*tmp*"))  # the atomic write left nothing behind


def test_at_frames_holds_the_last_measurement() -> None:
    t = np.array([0.0, 0.1, 0.2, 0.3])
    v = np.array([[0.0], [1.0], [2.0], [3.0]])
    got = at_frames(t, v, np.array([0.0, 0.15, 0.2, 0.29, 1.0]))
    assert got[:, 0].tolist() == [0.0, 1.0, 2.0, 2.0, 3.0]


def test_a_walk_records_a_compact_replay_at_the_display_rate(walk_dir: Path) -> None:
    path = walk_dir / REPLAY_FILE
    replay = read_replay(path)
    duration = float(replay.t[-1] - replay.t[0])
    assert replay.kind == "biped"
    assert np.allclose(np.diff(replay.t), 1.0 / DISPLAY_RATE, atol=0.011)  # within a tick
    assert path.stat().st_size < BYTES_PER_SECOND * duration
    with np.load(path, allow_pickle=False) as f:
        assert f["qpos"].dtype == np.float32
    assert {"phase", "feet", "com", "cop_offset", "zmp_offset"} <= set(replay.traces)


def test_recorded_joint_positions_reproduce_the_measured_soles(walk_dir: Path) -> None:
    # forward kinematics of the recorded qpos put the sole sites where the walk measured them
    replay = read_replay(walk_dir / REPLAY_FILE)
    model = mujoco.MjModel.from_xml_string(replay.model_xml)
    data = mujoco.MjData(model)
    sites = [
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, nm.sole_site(s))
        for s in (Side.LEFT, Side.RIGHT)
    ]
    feet, phase = replay.traces["feet"], replay.traces["phase"]
    plan_sides = [s.value for s in load_plan(walk_dir / "plan.json").sides]
    stance_checked = 0
    for f in range(len(replay.t)):
        data.qpos[:] = replay.qpos[f]
        mujoco.mj_kinematics(model, data)
        assert np.allclose(data.site_xpos[sites], feet[f], atol=SWING_LAG_TOL)
        if 0 <= phase[f] < len(plan_sides):  # single support: the stance sole stands still
            k = 0 if plan_sides[phase[f]] == "left" else 1
            assert np.allclose(data.site_xpos[sites[k]], feet[f, k], atol=STANCE_LAG_TOL)
            stance_checked += 1
    assert stance_checked > 10
    # and the robot walked: the soles moved forward by the walk's length
    assert feet[-1, :, 0].mean() - feet[0, :, 0].mean() > 0.4


def test_robot_motion_meshes_every_moving_body(walk_dir: Path) -> None:
    motion = robot_motion(read_replay(walk_dir / REPLAY_FILE))
    carried = {g.body for g in motion.geoms if g.body >= 0}
    assert carried == set(range(len(motion.bodies)))
    assert "pelvis" in motion.bodies and "torso" in motion.bodies
    for g in motion.geoms:
        assert g.mesh.faces.max() < g.mesh.vertices.shape[0]
    # unit quaternions, finite positions
    assert np.allclose(np.linalg.norm(motion.wxyz, axis=2), 1.0, atol=1e-9)
    assert np.all(np.isfinite(motion.pos))


def test_a_damaged_or_foreign_replay_is_an_input_error(walk_dir: Path, tmp_path: Path) -> None:
    good = (walk_dir / REPLAY_FILE).read_bytes()
    cut = tmp_path / "cut.npz"
    cut.write_bytes(good[: len(good) // 2])
    with pytest.raises(InputError, match="replay"):
        read_replay(cut)
    # an object array would need pickle: refused, never unpickled
    evil = tmp_path / "evil.npz"
    np.savez(evil, format=np.array("footfall-replay-1"), kind=np.array("biped"),
             t=np.zeros(1), qpos=np.array([{"a": 1}], dtype=object), model_xml=np.array(""))  # fmt: skip
    with pytest.raises(InputError):
        read_replay(evil)
    other = tmp_path / "other.npz"
    np.savez(other, x=np.zeros(3))
    with pytest.raises(InputError, match="footfall replay"):
        read_replay(other)
