"""Whole-body differential inverse kinematics of the MuJoCo biped with ``mink`` (000 section 5.5).

One QP per iteration (solved by ``daqp``) tracks the CoM, both sole poses and an upright torso,
with a light posture task; the resulting joint angles are the set points of the joint servos.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.models.biped import Side
from footfall.robots import names as nm
from footfall.sim.biped.plant import BipedSim

#: sole-pose and CoM costs of the inverse kinematics: the feet must be where they are (the stance
#: foot cannot move), the CoM is the ALIP's; torso and posture are secondary
FOOT_POSITION_COST = 10.0
FOOT_ORIENTATION_COST = 5.0
COM_COST = 10.0
TORSO_ORIENTATION_COST = 2.0
POSTURE_COST = 0.05
#: cost of keeping a joint that is not position servoed at its measured angle
HOLD_COST = 100.0
#: Levenberg-Marquardt style damping of the IK QP
IK_DAMPING = 1e-3


class WholeBodyIK:
    """mink differential IK on a kinematic copy of the model (its own MjData)."""

    def __init__(self, sim: BipedSim) -> None:
        import mink

        self.mink = mink
        self.sim = sim
        self.config = mink.Configuration(sim.model)
        self.config.update(sim.data.qpos.copy())
        self.feet = {
            s: mink.FrameTask(
                nm.sole_site(s),
                "site",
                position_cost=FOOT_POSITION_COST,
                orientation_cost=FOOT_ORIENTATION_COST,
            )
            for s in sim.sides
        }
        self.com = mink.ComTask(cost=COM_COST)
        self.torso = mink.FrameTask(
            nm.TORSO_BODY, "body", position_cost=0.0, orientation_cost=TORSO_ORIENTATION_COST
        )
        self.posture = mink.PostureTask(sim.model, cost=POSTURE_COST)
        self.posture.set_target(sim.data.qpos.copy())
        self.hold = mink.PostureTask(sim.model, cost=0.0)
        self.hold.set_target(sim.data.qpos.copy())
        self.tasks = [*self.feet.values(), self.com, self.torso, self.posture, self.hold]
        self.limits = [mink.ConfigurationLimit(sim.model)]
        self.failures = 0

    def solve(
        self,
        feet: dict[Side, tuple[FloatArray, FloatArray]],
        com: FloatArray,
        torso_yaw: float,
        dt: float,
        iterations: int,
        q_meas: FloatArray | None = None,
        com_axes: tuple[bool, bool, bool] = (True, True, True),
        hold: NDArray[np.int_] | None = None,
    ) -> FloatArray:
        """Joint set points (12,) [rad] for sole poses, CoM (3,) [m] and torso yaw [rad].

        Args:
            q_meas: measured configuration (nq,); given, the IK starts from it every tick, so
                torso orientation and swing-foot pose are fed back (closed loop); None: the IK
                integrates its own kinematic copy (open loop).
            com_axes: which CoM coordinates are tasks (a torque-driven stance ankle leaves the
                horizontal CoM to the pendulum).
            hold: joint indices into ``BipedSim.joint_qpos`` kept at their measured angles
                (joints that are not position servoed, such as a torque-driven ankle).
        """
        mink = self.mink
        if q_meas is not None:
            self.config.update(q_meas)
            self.hold.set_target(q_meas)
        cost = np.zeros(self.sim.model.nv)
        if hold is not None and q_meas is not None:
            cost[self.sim.joint_dof[hold]] = HOLD_COST
        self.hold.set_cost(cost)
        self.com.set_cost(COM_COST * np.asarray(com_axes, dtype=float))
        for s, (pos, rot) in feet.items():
            self.feet[s].set_target(
                mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(rot), pos)
            )
        self.com.set_target(com)
        c, s_ = math.cos(torso_yaw / 2), math.sin(torso_yaw / 2)
        self.torso.set_target(
            mink.SE3.from_rotation_and_translation(
                mink.SO3(np.array([c, 0.0, 0.0, s_])), np.zeros(3)
            )
        )
        for _ in range(iterations):
            try:
                vel = mink.solve_ik(
                    self.config,
                    self.tasks,
                    dt,
                    solver="daqp",
                    damping=IK_DAMPING,
                    limits=self.limits,
                )
            except mink.NoSolutionFound:
                # infeasible limits (e.g. after a fall): keep the last set points
                self.failures += 1
                break
            self.config.integrate_inplace(vel, dt)
        return np.array(self.config.q[self.sim.joint_qpos])
