"""A walk's trace sample ``k`` is the robot at the plan's time ``t[k]``: the measured trunk and
feet equal MuJoCo's kinematics of the state the physics had at that instant (recorded here at
every physics step, outside the recorder), not the state a physics step or a control period
later, for both controllers."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait  # noqa: E402
from footfall.quadruped.robot import LEGS  # noqa: E402
from footfall.sim.quadruped import names as nm  # noqa: E402
from footfall.sim.quadruped import sim as quad_sim  # noqa: E402

SETTLE = 0.5  # s, simulate's default


class _StateLog:
    """The mujoco module with its stepping functions wrapped: each physics step's start state
    (time, qpos) is kept before MuJoCo steps."""

    def __init__(self) -> None:
        self.model: Any = None
        self.states: dict[int, np.ndarray] = {}
        self.timestep = 0.0

    def __getattr__(self, name: str) -> Any:
        return getattr(mujoco, name)

    def _keep(self, m: Any, d: Any) -> None:
        self.model, self.timestep = m, float(m.opt.timestep)
        self.states[round(d.time / self.timestep)] = d.qpos.copy()

    def mj_step(self, m: Any, d: Any) -> None:
        self._keep(m, d)
        mujoco.mj_step(m, d)

    def mj_step1(self, m: Any, d: Any) -> None:
        self._keep(m, d)
        mujoco.mj_step1(m, d)


def _kinematics(log: _StateLog, step: int) -> tuple[np.ndarray, np.ndarray]:
    """Trunk centre and foot sites [m] of the state at the start of physics step ``step``."""
    m = log.model
    d = mujoco.MjData(m)
    d.qpos[:] = log.states[step]
    mujoco.mj_kinematics(m, d)
    trunk = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, nm.TRUNK_BODY)
    sites = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, nm.foot_site(leg)) for leg in LEGS]
    return d.xpos[trunk].copy(), d.site_xpos[sites].copy()


@pytest.mark.parametrize("controller", ["wbc", "servo"])
def test_sample_k_is_the_state_at_its_time(
    controller: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    log = _StateLog()
    monkeypatch.setattr(quad_sim, "require_mujoco", lambda: log)
    slope = math.radians(15.0)
    plan = plan_gait(QuadrupedRobot(), GaitParams(slope=slope, body_pitch=slope * 2 / 3, cycles=1))
    tr = quad_sim.simulate(plan, controller=controller, settle_time=SETTLE).trace
    assert math.isnan(tr.fallen_at)
    n = tr.t.shape[0]
    per_sample = round(0.01 / log.timestep)
    assert per_sample > 1
    checked = 0
    for k in (0, 1, n // 3, n // 2, n - 1):
        step = round((SETTLE + float(tr.t[k])) / log.timestep)
        trunk, feet = _kinematics(log, step)
        np.testing.assert_allclose(tr.trunk_pos[k], trunk, rtol=0, atol=1e-12)
        np.testing.assert_allclose(tr.feet[k], feet, rtol=0, atol=1e-12)
        if k > 0:
            # a physics step later the robot is elsewhere: the check can tell the instants apart
            # (by far more than the match above)
            later, later_feet = _kinematics(log, step + 1)
            moved = max(
                np.abs(later - tr.trunk_pos[k]).max(), np.abs(later_feet - tr.feet[k]).max()
            )
            assert moved > 1e-10
            checked += 1
    assert checked == 4
