"""The per-stance slip integrates the feet's sliding at every physics step: each control period's
``slip_disp`` equals the sum over its physics steps of the sliding velocity times the step,
recomputed here from the states MuJoCo started each step from (kept outside the recorder, then
re-run through ``mj_forward`` on a fresh ``MjData``), MuJoCo's contact list read here. And the
per-stance slips are sums of it."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall.quadruped.robot import LEGS  # noqa: E402
from footfall.sim.quadruped import names as nm  # noqa: E402
from tests.sim.quadruped.state_log import SETTLE, StateLog, logged_walk  # noqa: E402


def _sliding(log: StateLog, d: Any, step: int, stance: np.ndarray) -> np.ndarray:
    """(4, 3) [m/s]: each foot's contact point velocity minus its part along the ground's normal
    (the plane of the document's slope) at the start of physics step ``step``; the centre's, along the ground, for a foot planned
    down (``stance``) that touches nothing; zero for a swing foot in the air."""
    m = log.model
    d.qpos[:], d.qvel[:] = log.states[step]
    mujoco.mj_forward(m, d)
    geom = mujoco.mjtObj.mjOBJ_GEOM
    feet = [mujoco.mj_name2id(m, geom, nm.foot_geom(leg)) for leg in LEGS]
    floor = mujoco.mj_name2id(m, geom, nm.FLOOR_GEOM)
    out = np.zeros((4, 3))
    touched = [False] * 4
    vel = np.zeros(6)
    for c in d.contact[: d.ncon]:
        pair = {int(c.geom1), int(c.geom2)}
        if floor not in pair:
            continue
        for leg, g in enumerate(feet):
            if g in pair:
                mujoco.mj_objectVelocity(m, d, geom, g, vel, 0)
                point_vel = vel[3:] + np.cross(vel[:3], c.pos - d.geom_xpos[g])
                normal = NORMAL
                out[leg] = point_vel - (point_vel @ normal) * normal
                touched[leg] = True
    for leg, g in enumerate(feet):
        if stance[leg] and not touched[leg]:
            mujoco.mj_objectVelocity(m, d, geom, g, vel, 0)
            out[leg] = vel[3:] - (vel[3:] @ NORMAL) * NORMAL
    return out


SLOPE = math.radians(15.0)
#: the slope's upward normal (up the slope is +x)
NORMAL = np.array([-math.sin(SLOPE), 0.0, math.cos(SLOPE)])


@pytest.mark.parametrize("controller", ["wbc", "servo"])
def test_each_period_integrates_every_physics_step(
    controller: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    log, res = logged_walk(monkeypatch, controller, SLOPE)
    tr = res.trace
    assert math.isnan(tr.fallen_at)
    h = log.timestep
    per_period = round(0.01 / h)
    assert per_period > 1
    d = mujoco.MjData(log.model)
    n = tr.t.shape[0]
    reference = np.zeros((n, 4, 3))
    for k in range(n):
        first = round((SETTLE + float(tr.t[k])) / h)
        for s in range(per_period):
            reference[k] += _sliding(log, d, first + s, tr.planned.contact[k]) * h
    np.testing.assert_allclose(tr.slip_disp, reference, rtol=0, atol=1e-12)
    # the control-rate sum (one sample for its whole period) is a different number: the check
    # tells them apart, by far more than the match above
    assert np.abs(tr.slip_vel * 0.01 - reference).max() > 1e-6
    # each planned stance's slip is the length of the sum of its periods (stances found here
    # from the planned contact flags: runs of samples with the foot down)
    expected = []
    for leg in range(4):
        down = np.concatenate([[False], tr.planned.contact[:, leg], [False]]).astype(int)
        starts, ends = np.flatnonzero(np.diff(down) == 1), np.flatnonzero(np.diff(down) == -1)
        for a, b in zip(starts, ends, strict=True):
            expected.append((LEGS[leg].value, float(np.linalg.norm(reference[a:b, leg].sum(0)))))
    got = [(st.leg, st.slip_m) for st in res.metrics.stance_slips]
    assert sorted(x[0] for x in got) == sorted(x[0] for x in expected)
    for leg in LEGS:
        mine = [v for name, v in expected if name == leg.value]
        theirs = [v for name, v in got if name == leg.value]
        np.testing.assert_allclose(theirs, mine, rtol=0, atol=1e-12)
