"""A walk's trace sample ``k`` is the robot at the plan's time ``t[k]``: the measured trunk and
feet equal MuJoCo's kinematics of the state the physics had at that instant (recorded here at
every physics step, outside the recorder), not the state a physics step or a control period
later, for both controllers."""

from __future__ import annotations

import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall.quadruped.robot import LEGS  # noqa: E402
from footfall.sim.quadruped import names as nm  # noqa: E402
from tests.sim.quadruped.state_log import SETTLE, StateLog, logged_walk  # noqa: E402


def _kinematics(log: StateLog, step: int) -> tuple[np.ndarray, np.ndarray]:
    """Trunk centre and foot sites [m] of the state at the start of physics step ``step``."""
    m = log.model
    d = mujoco.MjData(m)
    d.qpos[:] = log.states[step][0]
    mujoco.mj_kinematics(m, d)
    trunk = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, nm.TRUNK_BODY)
    sites = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, nm.foot_site(leg)) for leg in LEGS]
    return d.xpos[trunk].copy(), d.site_xpos[sites].copy()


@pytest.mark.parametrize("controller", ["wbc", "servo"])
def test_sample_k_is_the_state_at_its_time(
    controller: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    log, res = logged_walk(monkeypatch, controller, math.radians(15.0))
    tr = res.trace
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
