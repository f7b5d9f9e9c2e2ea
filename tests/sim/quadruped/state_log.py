"""The mujoco module with its stepping functions wrapped, for tests that check what the
quadruped's recorder measured against the states MuJoCo actually stepped from (kept outside the
recorder)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")


class StateLog:
    """Stands in for the mujoco module (``monkeypatch`` ``require_mujoco`` to return it): each
    physics step's start state ``(qpos, qvel)`` is kept by step number before MuJoCo steps."""

    def __init__(self) -> None:
        self.model: Any = None
        self.states: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self.timestep = 0.0

    def __getattr__(self, name: str) -> Any:
        return getattr(mujoco, name)

    def _keep(self, m: Any, d: Any) -> None:
        self.model, self.timestep = m, float(m.opt.timestep)
        self.states[round(d.time / self.timestep)] = (d.qpos.copy(), d.qvel.copy())

    def mj_step(self, m: Any, d: Any) -> None:
        self._keep(m, d)
        mujoco.mj_step(m, d)

    def mj_step1(self, m: Any, d: Any) -> None:
        self._keep(m, d)
        mujoco.mj_step1(m, d)


SETTLE = 0.5  # s, simulate's default


def logged_walk(
    monkeypatch: pytest.MonkeyPatch, controller: str, slope: float
) -> tuple[StateLog, Any]:
    """The document robot's one-cycle walk up ``slope`` [rad] (body at 2/3 of it) simulated with
    ``controller`` through a :class:`StateLog`: the log and the walk's result."""
    from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
    from footfall.sim.quadruped import sim as quad_sim

    log = StateLog()
    monkeypatch.setattr(quad_sim, "require_mujoco", lambda: log)
    plan = plan_gait(QuadrupedRobot(), GaitParams(slope=slope, body_pitch=slope * 2 / 3, cycles=1))
    return log, quad_sim.simulate(plan, controller=controller, settle_time=SETTLE)
