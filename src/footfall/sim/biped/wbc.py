"""Torque-level whole-body control of the MuJoCo biped (``WalkOptions.controller = "wbc"``).

Every tick :class:`BipedWbc` turns the walk's :class:`~footfall.sim.biped.state.Command` into a
:class:`~footfall.control.wbc.WbcProblem` from the MuJoCo state
(:class:`~footfall.sim.wbc_model.MujocoWbcModel`) and sends the QP's joint torques to the 12 leg
motors. The feet in contact are the schedule's (the stance foot in single support, both
otherwise); each touches at its four sole corners (the contact spheres' lowest points), so the
centre of pressure stays inside the sole by the friction pyramids' ``f . n >= 0``.

Tasks (:class:`WbcGains` holds the gains and weights):

- single support with a torque-driven stance (``WalkOptions.ankle_torque``): the moment of the
  stance foot's forces about its sole centre is the adjuster's ALIP torque ``u`` (eq. 5.3), so the
  planner's ankle torque is the commanded centre of pressure; the horizontal CoM is the pendulum's
  (no task) and the CoM height follows the reference;
- otherwise (standing, the shift, double support, the stop): the CoM tracks the reference in 3-D
  (PD with the reference's velocity);
- the centroidal angular momentum is damped (``dL_G/dt = -k L_G``), so the ground moment turns
  into CoM motion as the ALIP assumes;
- the swing sole tracks its reference pose (:func:`~footfall.sim.biped.references.swing_reference`)
  with feedforward velocity; the torso stays upright at the commanded yaw; a light posture task
  holds the joints near the nominal posture.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

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
from footfall.models.biped import Side
from footfall.robots import names as nm
from footfall.sim.biped.plant import BipedSim
from footfall.sim.biped.state import Command
from footfall.sim.wbc_model import MujocoWbcModel

#: a corner carrying at least this normal force [N] counts in the friction share
LOADED_CORNER = 1.0
#: a reference that moves more than this between two commands [m] restarts there (no velocity)
REFERENCE_JUMP = 0.05
#: rows of a wrench (force; moment) that select the force, the moment, the horizontal moment
FORCE_ROWS = np.hstack([np.eye(3), np.zeros((3, 3))])
MOMENT_ROWS = np.hstack([np.zeros((3, 3)), np.eye(3)])
HORIZONTAL_MOMENT_ROWS = MOMENT_ROWS[:2]


@dataclass(frozen=True)
class WbcGains:
    """Gains [1/s^2, 1/s] and weights of the biped's whole-body tasks.

    Weights multiply squared residuals in task units: CoM and frame accelerations [m/s^2,
    rad/s^2], the centre of pressure [m] (moment residual over the weight), the angular-momentum
    rate as a CoM acceleration [m/s^2] (over mass times CoM height).

    ``cop_weight`` trades the commanded CoP against the angular-momentum damping and the frame
    tasks. Measured on our biped (benchmarks/RESULTS.md, "Whole-body control"): at 1e5 the
    measured CoP follows the command one for one (regression slope 1.04 sagittal) but 4 N s
    pushes were walked 46 and 45 times of 50 on discrete_steps and stairs_slope_gap; at 3e4 the
    slope is 0.84 (the servo walker's: 0.85) and 49 of 50 on both; at 1e4 the slope falls to
    0.35 (the CoP no longer follows the planner) and at 3e3 the robot falls on every stairs walk.
    ``cop_share`` moves the QP's contact points toward the sole centre (a CoP margin; 0.85 walked
    fewer pushes than 1).
    """

    com_kp: float = 100.0
    com_kd: float = 20.0
    torso_kp: float = 200.0
    torso_kd: float = 28.0
    swing_kp: float = 900.0
    swing_kd: float = 60.0
    posture_kp: float = 100.0
    posture_kd: float = 20.0
    momentum_kd: float = 10.0
    com_weight: float = 10.0
    cop_weight: float = 3e4
    cop_share: float = 1.0
    momentum_weight: float = 10.0
    torso_weight: float = 5.0
    swing_weight: float = 10.0
    posture_weight: float = 0.05

    def __post_init__(self) -> None:
        check_fields(self, non_negative, tuple(self.__dataclass_fields__), prefix="wbc.")
        if not 0.0 < self.cop_share <= 1.0:
            raise InputError("wbc.cop_share", self.cop_share, "a share in (0, 1]")


@dataclass(frozen=True)
class CopTarget:
    """The horizontal moment ``moment`` (2,) [N m] (world x, y) that the ground forces on the
    feet ``sides`` exert about ``point`` (3,) [m]: document 000's ankle torque ``u`` (eq. 5.3)
    about the stance sole centre in single support; zero about the contact point moving from
    the old foot to the new one in double support (the model of the reset map, eq. 5.8)."""

    sides: tuple[Side, ...]
    point: FloatArray
    moment: FloatArray


def rotation_error(target: FloatArray, actual: FloatArray) -> FloatArray:
    """Rotation vector (3,) [rad], world axes, that turns ``actual`` (3, 3) into ``target``."""
    return rotation_log(target @ actual.T)


def yaw_rotation(yaw: float) -> FloatArray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass
class WbcTally:
    """What the whole-body QPs of a walk commanded, checked against their limits at every
    physics step: the largest torque as a share of its limit, the largest tangential force as a
    share of Coulomb's cone ``mu f_n`` over corners carrying at least ``LOADED_CORNER`` (the QP
    keeps it inside the inscribed pyramid: at most 1) and the largest ``|f_t| - mu f_n`` [N] over
    all corners (<= 0 up to the solver's tolerance), the smallest corner normal force [N] (>= 0:
    every centre of pressure inside its sole's corners), and the QPs solved and failed."""

    solves: int = 0
    failures: int = 0
    max_torque_share: float = 0.0
    max_friction_share: float = 0.0
    max_friction_excess: float = -math.inf
    min_corner_force: float = math.inf

    def add(self, sol: WbcSolution, problem: WbcProblem, torque_limit: FloatArray) -> None:
        """Count one solution of ``problem``; ``torque_limit`` (na,) [N m] > 0 (inf: none)."""
        self.solves += 1
        share = float(np.max(np.abs(sol.torque) / torque_limit, initial=0.0))
        self.max_torque_share = max(self.max_torque_share, share)
        for c in problem.contacts:
            f = sol.forces[c.name]
            fn = f @ c.normal
            ft = np.sqrt(np.maximum(np.einsum("ij,ij->i", f, f) - fn * fn, 0.0))
            mu_fn = c.friction * fn
            self.min_corner_force = min(self.min_corner_force, float(fn.min()))
            self.max_friction_excess = max(self.max_friction_excess, float((ft - mu_fn).max()))
            # tangential share of the cone on corners carrying at least LOADED_CORNER
            ratio = np.where(fn > LOADED_CORNER, ft / np.maximum(mu_fn, 1e-12), 0.0)
            self.max_friction_share = max(self.max_friction_share, float(ratio.max()))

    def to_dict(self) -> dict[str, float | int]:
        """JSON-ready numbers (walk.json's ``controller``)."""
        return {
            "qp_solves": self.solves,
            "qp_failures": self.failures,
            "max_torque_share": self.max_torque_share,
            "max_friction_share": self.max_friction_share,
            "max_friction_excess_N": self.max_friction_excess if self.solves else math.nan,
            "min_corner_force_N": self.min_corner_force if self.solves else math.nan,
        }


class BipedWbc:
    """Whole-body torque control of a :class:`BipedSim` (our biped or the G1).

    The walk sets the references of a control period with :meth:`command` and asks for torques
    at every physics step with :meth:`torques`; between two commands the CoM and sole position
    references move linearly from the last command's to this one's (as the servo set points
    ramp), with that motion's velocity as feedforward.
    """

    def __init__(self, sim: BipedSim, gains: WbcGains | None = None) -> None:
        self.sim = sim
        self.gains = gains if gains is not None else WbcGains()
        mj, m = sim.mujoco, sim.model
        self.model = MujocoWbcModel(mj, m, sim.data, sim.actuators)
        self.model.set_torque_mode()
        self.qp = WholeBodyController()
        obj = mj.mjtObj
        self.corner_geoms = {
            s: np.array(
                [int(mj.mj_name2id(m, obj.mjOBJ_GEOM, nm.corner_geom(s, k))) for k in range(4)]
            )
            for s in sim.sides
        }
        self.corner_radius = {s: np.array(m.geom_size[self.corner_geoms[s], 0]) for s in sim.sides}
        self.foot_body = {s: int(m.site_bodyid[sim.sole_sites[s]]) for s in sim.sides}
        self.friction = {
            s: float(np.min(m.geom_friction[self.corner_geoms[s], 0])) for s in sim.sides
        }
        self.q_nominal = np.array(sim.data.qpos[sim.joint_qpos])
        self.gravity = np.array(m.opt.gravity)
        nj = len(sim.joint_dof)
        self._posture_jac = np.zeros((nj, self.model.nv))
        self._posture_jac[np.arange(nj), sim.joint_dof] = 1.0
        self._posture_drift = np.zeros(nj)
        self._cmd: Command | None = None
        self._from: dict[str, FloatArray] = {}
        self._to: dict[str, FloatArray] = {}
        self._vel: dict[str, FloatArray] = {}
        self.last: WbcSolution | None = None
        self.last_problem: WbcProblem | None = None
        self.tally = WbcTally()
        #: wall time spent in the QP solver (pack, assemble, daqp) [s]
        self.qp_time = 0.0
        self._torque_limit = np.maximum(
            np.abs(self.model.torque_min), np.abs(self.model.torque_max)
        )

    # ------------------------------------------------------------------------ references
    def command(self, cmd: Command, dt: float) -> None:
        """The references of the next control period of ``dt`` [s]."""
        refs = {"com": np.asarray(cmd.com_ref, dtype=float)}
        for side in self.sim.sides:
            refs[side.value] = np.asarray(cmd.feet[side][0], dtype=float)
        for key, value in refs.items():
            prev = self._to.get(key)
            # a reference that jumps (a new phase restarts it) is not moved along
            if prev is None or float(np.linalg.norm(value - prev)) > REFERENCE_JUMP:
                prev = value
            self._from[key], self._to[key] = prev, value
            self._vel[key] = (value - prev) / dt
        self._cmd = cmd

    def _ref(self, key: str, share: float) -> tuple[FloatArray, FloatArray]:
        """Reference position and velocity ``share`` in (0, 1] through the control period."""
        a, b = self._from[key], self._to[key]
        return a + share * (b - a), self._vel[key]

    # ------------------------------------------------------------------------------ pieces
    def _contact(self, side: Side) -> Contact:
        """The ``side`` sole touching at the lowest points of its corner spheres."""
        d = self.sim.data
        sid = self.sim.sole_sites[side]
        pos = np.array(d.site_xpos[sid])
        normal = np.array(d.site_xmat[sid][2::3])  # the sole's z axis
        ids = self.corner_geoms[side]
        corners = np.array(d.geom_xpos[ids]) - self.corner_radius[side][:, None] * normal
        # the QP's points are the corners moved toward the sole centre: CoP margin
        points = pos + self.gains.cop_share * (corners - pos)
        return self.model.contact(
            side.value, self.foot_body[side], pos, points, normal, self.friction[side]
        )

    # ------------------------------------------------------------------------------ tick
    def torques(
        self,
        share: float,
        contact_sides: tuple[Side, ...],
        cop: CopTarget | None,
        com: FloatArray,
        vel: FloatArray,
        l_g: FloatArray,
    ) -> FloatArray:
        """Joint torques (12,) [N m] at ``share`` in (0, 1] of the commanded control period.

        Args:
            share: how far through the control period this physics step ends.
            contact_sides: feet in contact (constraints).
            cop: the ground moment to command (the centre of pressure), which leaves the
                horizontal CoM to the pendulum; None: the CoM tracks its reference in 3-D.
            com, vel, l_g: measured CoM (3,) [m], its velocity (3,) [m/s] and the angular
                momentum about it (3,) [kg m^2/s].

        Raises:
            SolverError: when the QP has no solution.
        """
        cmd = self._cmd
        if cmd is None:
            raise InputError("command", None, "BipedWbc.command() before torques()")
        g, sim = self.gains, self.sim
        d = sim.data
        mass = sim.mass
        contacts = tuple(self._contact(s) for s in contact_sides)
        m_mat, h = self.model.dynamics()
        wrench: list[WrenchTask] = []
        motion: list[MotionTask] = []
        # --- CoM: the total contact force is m (cdd - g) (Newton)
        c_ref, v_ref = self._ref("com", share)
        a_com = g.com_kp * (c_ref - com) + g.com_kd * (v_ref - vel)
        com_w = np.full(3, g.com_weight / mass**2)
        if cop is not None:
            com_w[:2] = 0.0  # the pendulum moves the CoM horizontally
            wrench.append(
                WrenchTask(
                    "cop",
                    np.asarray(cop.point, dtype=float),
                    HORIZONTAL_MOMENT_ROWS,
                    np.asarray(cop.moment, dtype=float),
                    g.cop_weight / (mass * -self.gravity[2]) ** 2,
                    contacts=tuple(s.value for s in cop.sides),
                )
            )
        if contacts:
            wrench.append(WrenchTask("com", com, FORCE_ROWS, mass * (a_com - self.gravity), com_w))
            z = max(0.3, float(com[2] - min(float(c.points[:, 2].min()) for c in contacts)))
            wrench.append(
                WrenchTask(
                    "momentum",
                    com,
                    MOMENT_ROWS,
                    -g.momentum_kd * l_g,
                    g.momentum_weight / (mass * z) ** 2,
                )
            )
        # --- torso upright at the commanded yaw
        jac, drift = self.model.frame(sim.torso, d.xpos[sim.torso])
        rot = np.array(d.xmat[sim.torso]).reshape(3, 3)
        omega = jac[3:] @ d.qvel
        a_torso = g.torso_kp * rotation_error(yaw_rotation(cmd.yaw), rot) - g.torso_kd * omega
        motion.append(MotionTask("torso", jac[3:], drift[3:], a_torso, g.torso_weight))
        # --- swing soles
        for side in sim.sides:
            if side not in contact_sides:
                motion.append(self._swing_task(side, cmd.feet[side][1], share))
        # --- posture
        q = d.qpos[sim.joint_qpos]
        qd = d.qvel[sim.joint_dof]
        a_post = g.posture_kp * (self.q_nominal - q) - g.posture_kd * qd
        motion.append(
            MotionTask("posture", self._posture_jac, self._posture_drift, a_post, g.posture_weight)
        )
        problem = WbcProblem(
            mass_matrix=m_mat,
            bias=h,
            actuated=self.model.actuated,
            torque_min=self.model.torque_min,
            torque_max=self.model.torque_max,
            contacts=contacts,
            motion_tasks=tuple(motion),
            wrench_tasks=tuple(wrench),
        )
        # the arrays are built here from the model, so the shape checks are skipped
        t0 = time.perf_counter()
        try:
            self.last = sol = self.qp.solve(problem, check=False)
        except SolverError:
            self.tally.failures += 1
            raise
        finally:
            self.qp_time += time.perf_counter() - t0
        self.last_problem = problem
        self.tally.add(sol, problem, self._torque_limit)
        return sol.torque

    def _swing_task(self, side: Side, rot_ref: FloatArray, share: float) -> MotionTask:
        """The ``side`` sole tracks its target pose (PD, feedforward reference velocity)."""
        g, sim = self.gains, self.sim
        pos_ref, v_ref = self._ref(side.value, share)
        pos, rot = sim.sole(side)
        jac, drift = self.model.frame(self.foot_body[side], pos)
        v = jac @ sim.data.qvel
        a = np.concatenate(
            [
                g.swing_kp * (pos_ref - pos) + g.swing_kd * (v_ref - v[:3]),
                g.swing_kp * rotation_error(rot_ref, rot) - g.swing_kd * v[3:],
            ]
        )
        return MotionTask(f"swing_{side.value}", jac, drift, a, g.swing_weight)
