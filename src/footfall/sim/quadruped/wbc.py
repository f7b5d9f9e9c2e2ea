"""Whole-body torque control of the quadruped (beyond document 001): the contact forces put the
centre of pressure on the planned ZMP.

Document 001 plans the body motion so that the ZMP (eq. 5) lies at the optimal stability point of
the support triangle, and walks it with joint position servos; measured, the centre of pressure
then strays far from the plan. Here every joint is torque-driven by the whole-body QP of
:mod:`footfall.control.wbc` (the biped's controller, with point feet):

- contacts: the planned stance feet, each a point force at the bottom of its sphere with a
  friction pyramid (the model's friction) and zero acceleration of that point;
- the centre of pressure: the moment of the contact forces about the planned ZMP (on the
  horizontal plane through the stance contacts, as eq. 5 defines it) has no horizontal part;
- the trunk: position and orientation (the posture's pitch, eq. 9) with PD feedback and the plan's
  acceleration as feedforward; the swing feet: the zero-impact trajectories (eq. 10-13) the same
  way; the joints: a weak posture task toward the planned angles.

The QP runs at every physics step from the state of that step (``mj_step1`` / ``mj_step2``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from footfall._geometry import rotation_log
from footfall._typing import FloatArray
from footfall._validate import check_fields, non_negative
from footfall.control.wbc import (
    Contact,
    MotionTask,
    WbcProblem,
    WbcSolution,
    WholeBodyController,
    WrenchTask,
)
from footfall.errors import InputError, SolverError
from footfall.quadruped.gait import GaitTrajectory
from footfall.quadruped.ground import PlaneGround, QuadrupedGround
from footfall.sim.wbc_model import MujocoWbcModel

#: moment rows (mx, my) of the contact wrench: the horizontal moment about the ZMP
_HORIZONTAL_MOMENT = np.array([[0, 0, 0, 1.0, 0, 0], [0, 0, 0, 0, 1.0, 0]])


@dataclass(frozen=True)
class QuadrupedWbcGains:
    """Gains [1/s^2, 1/s] and weights of the quadruped's whole-body tasks.

    Attributes:
        trunk_kp, trunk_kd: trunk position PD.
        rot_kp, rot_kd: trunk orientation PD.
        swing_kp, swing_kd: swing foot PD.
        posture_kp, posture_kd: joint posture PD.
        trunk_weight, rot_weight, swing_weight, posture_weight: task weights (residuals in
            m/s^2 or rad/s^2).
        cop_weight: weight of the horizontal moment about the planned ZMP [1/(N m)^2].
        unload_time: a stance foot's normal force is driven to zero over this time before its
            planned lift-off [s] (the plan's ZMP already lies in the other three feet's triangle),
            so it leaves the ground unloaded instead of kicking the centre of pressure.
        unload_weight: weight of that task at lift-off [1/N^2] (ramping up from 0).
        touchdown_window: a swing foot that touches the ground this close [s] before its planned
            touchdown becomes a contact at once (the QP then chooses its force).
        qp_every: physics steps per QP solve (the torques are held in between).
    """

    trunk_kp: float = 400.0
    trunk_kd: float = 40.0
    rot_kp: float = 400.0
    rot_kd: float = 40.0
    swing_kp: float = 900.0
    swing_kd: float = 60.0
    posture_kp: float = 100.0
    posture_kd: float = 20.0
    trunk_weight: float = 1.0
    rot_weight: float = 1.0
    swing_weight: float = 10.0
    posture_weight: float = 1e-3
    cop_weight: float = 1e-4
    unload_time: float = 0.05
    unload_weight: float = 1e-5
    touchdown_window: float = 0.05
    qp_every: int = 2

    def __post_init__(self) -> None:
        check_fields(
            self,
            non_negative,
            [f.name for f in fields(self) if f.name != "qp_every"],
            prefix="wbc_gains.",
        )
        q = self.qp_every
        if isinstance(q, bool) or not isinstance(q, int) or q < 1:
            raise InputError("wbc_gains.qp_every", q, "an integer >= 1")


@dataclass(frozen=True)
class _Sample:
    """The plan at one instant (:meth:`_Reference.sample`).

    Attributes:
        k, w: sample index and weight of the instant (:meth:`_Reference.at`).
        body, body_v, body_a: trunk position (3,) [m], velocity [m/s], acceleration [m/s^2].
        feet, feet_v, feet_a: foot centres (4, 3) [m], velocities, accelerations.
        joints, joints_v: joint angles (12,) [rad] and rates [rad/s].
        zmp: planned ZMP (2,) [m].
        rot: planned trunk orientation (3, 3) (its pitch follows the ground's local plane).
    """

    k: int
    w: float
    body: FloatArray
    body_v: FloatArray
    body_a: FloatArray
    feet: FloatArray
    feet_v: FloatArray
    feet_a: FloatArray
    joints: FloatArray
    joints_v: FloatArray
    zmp: FloatArray
    rot: FloatArray


class _Reference:
    """The sampled plan with velocities and accelerations, interpolated linearly in time."""

    def __init__(self, ref: GaitTrajectory) -> None:
        self.t = ref.t
        dt = float(ref.t[1] - ref.t[0]) if ref.t.size > 1 else 1.0
        self.dt = dt
        body_v = np.gradient(ref.body_pos, dt, axis=0)
        feet_v = np.gradient(ref.feet, dt, axis=0)
        n = ref.t.size
        # the interpolated quantities side by side (in _Sample's order), so that one
        # interpolation per tick gives them all
        columns = [
            ref.body_pos,
            body_v,
            np.gradient(body_v, dt, axis=0),
            ref.feet.reshape(n, -1),
            feet_v.reshape(n, -1),
            np.gradient(feet_v, dt, axis=0).reshape(n, -1),
            ref.joints,
            np.gradient(ref.joints, dt, axis=0),
            ref.zmp,
            ref.body_pitch[:, None],
        ]
        #: (T, 72) the columns above
        self.table = np.hstack(columns)
        ends = np.cumsum([c.shape[1] for c in columns]).tolist()
        self._slices = [slice(a, b) for a, b in zip([0, *ends[:-1]], ends, strict=True)]
        self.contact = ref.contact
        #: (T, 4) time from each sample to the next change of each leg's planned contact [s]
        self.to_switch = np.full(ref.contact.shape, np.inf)
        nxt = np.full(4, np.inf)
        for k in range(ref.t.size - 2, -1, -1):
            changed = ref.contact[k + 1] != ref.contact[k]
            nxt = np.where(changed, ref.t[k + 1], nxt)
            self.to_switch[k] = nxt - ref.t[k]

    def at(self, t: float) -> tuple[int, float]:
        """Sample index k and weight w of time ``t``: value = (1 - w) x[k] + w x[k + 1]."""
        u = (t - self.t[0]) / self.dt
        k = int(min(max(math.floor(u), 0), self.t.size - 2))
        return k, float(min(max(u - k, 0.0), 1.0))

    def sample(self, t: float) -> _Sample:
        """The plan at time ``t`` [s]."""
        k, w = self.at(t)
        row = (1.0 - w) * self.table[k] + w * self.table[k + 1]
        body, body_v, body_a, feet, feet_v, feet_a, joints, joints_v, zmp, pitch = (
            row[s] for s in self._slices
        )
        c, s = math.cos(-pitch[0]), math.sin(-pitch[0])
        return _Sample(
            k,
            w,
            body,
            body_v,
            body_a,
            feet.reshape(4, 3),
            feet_v.reshape(4, 3),
            feet_a.reshape(4, 3),
            joints,
            joints_v,
            zmp,
            # nose-up pitch is a rotation about y by -pitch
            np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]),
        )


class QuadrupedWbc:
    """Torques of the quadruped's joints from the whole-body QP, one physics step at a time.

    Args:
        sim: the :class:`~footfall.sim.quadruped.sim.QuadrupedSim` (its actuators become motors).
        ref: the sampled gait plan.
        ground: the ground walked (its normal at each contact).
        gains: task gains and weights.
    """

    def __init__(
        self, sim: Any, ref: GaitTrajectory, ground: QuadrupedGround, gains: QuadrupedWbcGains
    ) -> None:
        mj, m = sim.mujoco, sim.model
        self.sim = sim
        self.model = MujocoWbcModel(mj, m, sim.data, sim.actuators)
        self.model.set_torque_mode()
        self.ctrl = WholeBodyController()
        self.ref = _Reference(ref)
        self.gains = gains
        self.ground = ground
        #: one normal and pyramid orientation for the whole walk on a plane (the common case)
        self._plane = _surface(ground.normal(0.0, 0.0)) if isinstance(ground, PlaneGround) else None
        self.friction = float(m.geom_friction[sim.foot_geoms[0], 0])
        self.radius = float(m.geom_size[sim.foot_geoms[0], 0])
        self.foot_bodies = [int(m.site_bodyid[s]) for s in sim.foot_sites]
        #: generalised-velocity index of each planned joint angle (LEGS x JOINT_NAMES order)
        self.joint_dofs = np.array(
            [int(m.jnt_dofadr[int(m.actuator_trnid[a, 0])]) for a in sim.actuators]
        )
        #: constant task arrays: the joints' rows of qdd, their zero drift, a normal-force row
        self._select = np.zeros((self.joint_dofs.size, self.model.nv))
        self._select[np.arange(self.joint_dofs.size), self.joint_dofs] = 1.0
        self._no_drift = np.zeros(self.joint_dofs.size)
        self.failures = 0
        self.last_tau = np.zeros(len(sim.actuators))
        #: the last solved problem and its solution (None before the first solve)
        self.last_problem: WbcProblem | None = None
        self.last: WbcSolution | None = None

    def retarget(self, ref: GaitTrajectory) -> None:
        """Track ``ref`` from now on (same sample times; the slip guard's held reference)."""
        self.ref = _Reference(ref)

    def _touching(self) -> list[bool]:
        """Which feet touch the ground now (from the contacts of the last collision check)."""
        con = self.sim.data.contact
        geoms = np.asarray(con.geom)[np.asarray(con.dist) <= 0.0]  # within the margin: not yet
        hit = set(geoms.ravel().tolist())
        return [g in hit for g in self.sim.foot_geoms]

    def torques(self, t: float) -> FloatArray:
        """Joint torques (12,) [N m] at gait time ``t`` from the current state (positions and
        velocities; ``mj_step1`` has run)."""
        sim, d, g, ref = self.sim, self.sim.data, self.gains, self.ref
        plan = ref.sample(t)
        k, w = plan.k, plan.w
        qvel = d.qvel
        mass, bias = self.model.dynamics()
        stance = ref.contact[k] if w < 0.5 else ref.contact[k + 1]
        to_switch = ref.to_switch[k] - w * ref.dt
        touching = self._touching()
        centres = d.site_xpos[sim.foot_sites]
        contacts, tasks, wrench = [], [], []
        heights = []
        for leg in range(4):
            centre = centres[leg]
            early = touching[leg] and to_switch[leg] <= g.touchdown_window
            if stance[leg] or early:
                normal, tangent, normal_force = self._plane or _surface(
                    self.ground.normal(float(centre[0]), float(centre[1]))
                )
                pt = centre - self.radius * normal
                jac, drift = self.model.frame(self.foot_bodies[leg], pt, angular=False)
                name = f"foot{leg}"
                contacts.append(
                    Contact.point(name, jac, drift, pt, normal, self.friction, 0.0, tangent)
                )
                heights.append(pt[2])
                if stance[leg] and g.unload_time > 0 and to_switch[leg] < g.unload_time:
                    share = 1.0 - max(to_switch[leg], 0.0) / g.unload_time
                    wrench.append(
                        WrenchTask(
                            f"unload{leg}",
                            pt,
                            normal_force,
                            np.zeros(1),
                            g.unload_weight * share,
                            (name,),
                        )
                    )
            else:
                jac, drift = self.model.frame(self.foot_bodies[leg], centre, angular=False)
                vel = jac @ qvel
                acc = (
                    plan.feet_a[leg]
                    + g.swing_kp * (plan.feet[leg] - centre)
                    + g.swing_kd * (plan.feet_v[leg] - vel)
                )
                tasks.append(MotionTask(f"swing{leg}", jac, drift, acc, g.swing_weight))
        # trunk position and orientation
        jac, drift = self.model.frame(sim.trunk, d.xpos[sim.trunk])
        vel = jac @ qvel
        acc_lin = (
            plan.body_a
            + g.trunk_kp * (plan.body - d.xpos[sim.trunk])
            - g.trunk_kd * (vel[:3] - plan.body_v)
        )
        rot = d.xmat[sim.trunk].reshape(3, 3)
        err = rotation_log(plan.rot @ rot.T)
        acc_ang = g.rot_kp * err - g.rot_kd * vel[3:]
        tasks.append(MotionTask("trunk", jac[:3], drift[:3], acc_lin, g.trunk_weight))
        tasks.append(MotionTask("trunk_rot", jac[3:], drift[3:], acc_ang, g.rot_weight))
        # joint posture
        q = d.qpos[sim.qpos_adr]
        qd = qvel[self.joint_dofs]
        acc_q = g.posture_kp * (plan.joints - q) + g.posture_kd * (plan.joints_v - qd)
        tasks.append(MotionTask("posture", self._select, self._no_drift, acc_q, g.posture_weight))
        if heights and g.cop_weight > 0:
            zp = sum(heights) / len(heights)  # the stance points' mean height
            z = plan.zmp
            wrench.append(
                WrenchTask(
                    "cop", np.array([z[0], z[1], zp]), _HORIZONTAL_MOMENT, np.zeros(2), g.cop_weight
                )
            )
        problem = WbcProblem(
            mass_matrix=mass,
            bias=bias,
            actuated=self.model.actuated,
            torque_min=self.model.torque_min,
            torque_max=self.model.torque_max,
            contacts=tuple(contacts),
            motion_tasks=tuple(tasks),
            wrench_tasks=tuple(wrench),
        )
        try:
            sol = self.ctrl.solve(problem, check=False)
        except SolverError:  # counted in the metrics; the last torques are held for one step
            self.failures += 1
            return self.last_tau
        self.last_tau = sol.torque
        self.last_problem, self.last = problem, sol
        return np.asarray(sol.torque)


def _surface(normal: FloatArray) -> tuple[FloatArray, FloatArray | None, FloatArray]:
    """Contact normal (3,), friction pyramid orientation and the normal-force wrench row (1, 6).

    Gravity's pull along a slope points at an edge of the friction pyramid (where it reaches
    Coulomb's cone, mu) rather than at a face (mu / sqrt(2)): the first face direction is the
    downhill direction turned 45 degrees about the normal (None on level ground: no preferred
    direction).
    """
    n = np.asarray(normal, dtype=float)
    down = np.array([0.0, 0.0, -1.0]) - n * (-n[2])
    tangent = None
    if np.linalg.norm(down) > 1e-9:
        down /= np.linalg.norm(down)
        tangent = (down + np.cross(n, down)) / math.sqrt(2.0)
    return n, tangent, np.concatenate([n, np.zeros(3)]).reshape(1, 6)


def check_gains(gains: object) -> QuadrupedWbcGains:
    """``gains`` if it is a :class:`QuadrupedWbcGains` (an error naming the field otherwise)."""
    if not isinstance(gains, QuadrupedWbcGains):
        raise InputError("wbc_gains", type(gains).__name__, "a QuadrupedWbcGains")
    return gains


__all__ = ["QuadrupedWbc", "QuadrupedWbcGains", "check_gains"]
