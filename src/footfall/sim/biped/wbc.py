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

Every physics step packs these tasks straight into the QP's arrays and assembles it in one compiled
call (:mod:`._wbc_tick`), the same numbers as building the dataclasses of
:mod:`footfall.control.wbc` (:attr:`BipedWbc.last_problem` rebuilds them when asked).
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
    PackedProblem,
    WbcProblem,
    WbcSolution,
    WholeBodyController,
    WrenchTask,
)
from footfall.errors import InputError, SolverError
from footfall.models.biped import Side
from footfall.robots import names as nm
from footfall.sim.biped import _wbc_tick as tick
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


class _Buffers:
    """One physics step's packed problem (:func:`._wbc_tick.pack_tick`'s outputs: the arrays of
    a :class:`PackedProblem` with room for two soles, 3 + 6 + nj motion rows and 2 + 3 + 3 wrench
    rows), its ``M`` and ``h``, and the solution; the problem and the solution as dataclasses
    are rebuilt from them when asked (:meth:`problem`, :meth:`solution`).

    Args:
        model: the robot's model terms.
        n_joints: joints of the posture task.
    """

    def __init__(self, model: MujocoWbcModel, n_joints: int) -> None:
        nv = model.nv
        self.nv = nv
        self.mass, self.bias = np.zeros((nv, nv)), np.zeros(nv)
        rm, rw = 3 + 6 + n_joints, 8
        #: pack_tick's outputs after ``bias``, in its argument order
        self.outputs = (
            *(np.zeros((2, 6, nv)), np.zeros((2, 6)), np.zeros((2, 3)), np.zeros((2, 4, 3))),
            *(np.zeros((2, 3)), np.zeros(2)),
            *(np.zeros((rm, nv)), np.zeros(rm), np.zeros(rm)),
            *(np.zeros((rw, 6)), np.zeros((rw, 3)), np.zeros(rw), np.zeros(rw), np.zeros((rw, 2))),
        )
        act = np.asarray(model.actuated, dtype=np.int64)
        free = np.ones(nv, dtype=bool)
        free[act] = False
        #: the constant arrays: actuated and other dofs, torque limits [N m], per contact its
        #: four points, no pyramid orientation, no minimum normal force
        self.constant = (
            act,
            np.flatnonzero(free).astype(np.int64),
            np.asarray(model.torque_min, dtype=float),
            np.asarray(model.torque_max, dtype=float),
            np.full(2, 4, dtype=np.int64),
            np.zeros((2, 3)),
            np.zeros(2),
        )
        #: the last packed problem: its contacts, whether it has a CoP task, its motion tasks
        #: (name, rows) and its sizes (contacts, motion rows, wrench rows)
        self.contacts: tuple[Side, ...] = ()
        self.cop_sides: tuple[Side, ...] | None = None
        self.motion: list[tuple[str, int]] = []
        self.sizes = (0, 0, 0)
        #: the solution: x = (qdd, forces), joint torques [N m], solver iterations
        self.x, self.torque, self.iterations = np.zeros(0), np.zeros(0), 0

    def packed(self) -> PackedProblem:
        """The last packed problem (``sizes``)."""
        nc, rm, rw = self.sizes
        c_jac, c_drift, c_origin, c_points, c_normal, c_friction, *motion_wrench = self.outputs
        m_jac, m_rhs, m_w, w_rows, w_about, w_target, w_weight, w_mask = motion_wrench
        act, unact, lo, hi, n_points, tangent, min_normal = self.constant
        return PackedProblem(
            self.mass,
            self.bias,
            act,
            unact,
            lo,
            hi,
            c_jac[:nc],
            c_drift[:nc],
            c_origin[:nc],
            c_points[:nc],
            n_points[:nc],
            c_normal[:nc],
            tangent[:nc],
            c_friction[:nc],
            min_normal[:nc],
            m_jac[:rm],
            m_rhs[:rm],
            m_w[:rm],
            w_rows[:rw],
            w_about[:rw],
            w_target[:rw],
            w_weight[:rw],
            w_mask[:rw, :nc],
        )

    def problem(self) -> WbcProblem:
        """The packed problem as dataclasses (copies). A motion task's drift is folded into its
        acceleration (zero drift, acceleration ``a* - Jdot qd``): the same rows of the QP."""
        p = self.packed()
        contacts = tuple(
            Contact(
                side.value,
                p.jac[i].copy(),
                p.drift[i].copy(),
                p.origin[i].copy(),
                p.points[i].copy(),
                p.normal[i].copy(),
                float(p.friction[i]),
            )
            for i, side in enumerate(self.contacts)
        )
        tasks, r = [], 0
        for name, n in self.motion:
            sel = slice(r, r + n)
            tasks.append(
                MotionTask(
                    name,
                    p.motion_jac[sel].copy(),
                    np.zeros(n),
                    p.motion_rhs[sel].copy(),
                    p.motion_w[sel].copy(),
                )
            )
            r += n
        groups: list[tuple[str, int, tuple[str, ...] | None]] = [("com", 3, None)]
        groups.append(("momentum", 3, None))
        if self.cop_sides is not None:
            groups.insert(0, ("cop", 2, tuple(s.value for s in self.cop_sides)))
        wrench, r = [], 0
        for name, n, sides in groups:
            if r + n > p.wrench_w.shape[0]:
                break  # no contacts: only the CoP task
            sel = slice(r, r + n)
            wrench.append(
                WrenchTask(
                    name,
                    p.wrench_about[r].copy(),
                    p.wrench_rows[sel].copy(),
                    p.wrench_target[sel].copy(),
                    p.wrench_w[sel].copy(),
                    sides,
                )
            )
            r += n
        return WbcProblem(
            mass_matrix=p.mass.copy(),
            bias=p.bias.copy(),
            actuated=p.actuated.astype(float),
            torque_min=p.torque_min.copy(),
            torque_max=p.torque_max.copy(),
            contacts=contacts,
            motion_tasks=tuple(tasks),
            wrench_tasks=tuple(wrench),
        )

    def solution(self) -> WbcSolution:
        """The solution of :meth:`problem`."""
        nv, x = self.nv, self.x
        forces = {
            side.value: x[nv + 12 * i : nv + 12 * (i + 1)].reshape(4, 3).copy()
            for i, side in enumerate(self.contacts)
        }
        return WbcSolution(x[:nv].copy(), self.torque, forces, self.iterations)


class BipedWbc:
    """Whole-body torque control of a :class:`BipedSim` (our biped, the G1, Talos).

    The walk sets the references of a control period with :meth:`command` and asks for torques
    at every physics step with :meth:`torques`; between two commands the CoM and sole position
    references move linearly from the last command's to this one's (as the servo set points
    ramp), with that motion's velocity as feedforward.

    Every physics step packs its QP straight into arrays (:mod:`._wbc_tick`, one compiled call
    with the assembly); the problem and the solution as dataclasses are rebuilt only when asked
    (:attr:`last_problem`, :attr:`last`).
    """

    def __init__(self, sim: BipedSim, gains: WbcGains | None = None) -> None:
        self.sim = sim
        self.gains = g = gains if gains is not None else WbcGains()
        mj, m, d = sim.mujoco, sim.model, sim.data
        self.model = MujocoWbcModel(mj, m, d, sim.actuators)
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
        self.q_nominal = np.array(d.qpos[sim.joint_qpos])
        self.gravity = np.array(m.opt.gravity)
        nv, nj = self.model.nv, len(sim.joint_dof)
        self._cmd: Command | None = None
        self._from: dict[str, FloatArray] = {}
        self._to: dict[str, FloatArray] = {}
        self._vel: dict[str, FloatArray] = {}
        self._tally = WbcTally()
        #: the tally's largest torque share, friction share, friction excess, smallest corner force
        self._stats = np.array([0.0, 0.0, -math.inf, math.inf])
        #: wall time spent in the QP solver (pack, assemble, daqp) [s]
        self.qp_time = 0.0
        self._torque_limit = np.maximum(
            np.abs(self.model.torque_min), np.abs(self.model.torque_max)
        )
        # --- the compiled tick's inputs
        mass = sim.mass
        #: the gains in the order of pack_tick's vector (the weights in task units as the
        #: dataclass path computes them)
        self._gains = np.zeros(tick.N_GAINS)
        gv = self._gains
        gv[tick.COM_KP], gv[tick.COM_KD] = g.com_kp, g.com_kd
        gv[tick.TORSO_KP], gv[tick.TORSO_KD] = g.torso_kp, g.torso_kd
        gv[tick.SWING_KP], gv[tick.SWING_KD] = g.swing_kp, g.swing_kd
        gv[tick.POSTURE_KP], gv[tick.POSTURE_KD] = g.posture_kp, g.posture_kd
        gv[tick.MOMENTUM_KD], gv[tick.COP_SHARE], gv[tick.MASS] = g.momentum_kd, g.cop_share, mass
        gv[tick.COM_W] = g.com_weight / mass**2
        gv[tick.COP_W] = g.cop_weight / (mass * -self.gravity[2]) ** 2
        gv[tick.MOMENTUM_W], gv[tick.TORSO_W] = g.momentum_weight, g.torso_weight
        gv[tick.SWING_W], gv[tick.POSTURE_W] = g.swing_weight, g.posture_weight
        gv[tick.SQUARE] = 2.0
        self._side_index = {s: i for i, s in enumerate(sim.sides)}
        self._contact_sides = {
            sides: np.array([self._side_index[s] for s in sides], dtype=np.int64)
            for sides in [(), *((s,) for s in sim.sides), tuple(sim.sides)]
        }
        self._step = np.zeros(tick.N_STEP)
        self._cop_sides = np.zeros(2)
        self._refs = np.zeros((3, 3, 3))
        self._yaw_rot = np.eye(3)
        self._rot_ref = np.zeros((2, 3, 3))
        self._model_arrays = (
            np.array([sim.sole_sites[s] for s in sim.sides], dtype=np.int64),
            np.array([self.corner_geoms[s] for s in sim.sides], dtype=np.int64),
            np.array([self.corner_radius[s] for s in sim.sides], dtype=float),
            np.array([self.friction[s] for s in sim.sides]),
            int(sim.torso),
            np.asarray(sim.joint_qpos, dtype=np.int64),
            np.asarray(sim.joint_dof, dtype=np.int64),
        )
        # MuJoCo's arrays (views of MjData's memory, fixed for its lifetime)
        self._state = (
            d.qpos,
            d.qvel,
            d.qfrc_bias,
            d.qfrc_passive,
            d.site_xpos,
            d.site_xmat,
            d.geom_xpos,
            d.xmat,
        )
        #: the Jacobians of each sole centre and of the torso origin and their derivatives
        self._foot_jac, self._foot_jdot = np.zeros((2, 6, nv)), np.zeros((2, 6, nv))
        self._torso_jac, self._torso_jdot = np.zeros((6, nv)), np.zeros((6, nv))
        frames = [
            (
                self.foot_body[s],
                d.site_xpos[sim.sole_sites[s]],
                self._foot_jac[i],
                self._foot_jdot[i],
            )
            for i, s in enumerate(sim.sides)
        ]
        frames.append((int(sim.torso), d.xpos[sim.torso], self._torso_jac, self._torso_jdot))
        #: mj_jac / mj_jacDot arguments: body, point (a view: read at the call), row blocks
        self._frames = [
            (body, point, jac[:3], jac[3:], jdot[:3], jdot[3:]) for body, point, jac, jdot in frames
        ]
        # two sets of arrays: a step fills the one that does not hold the last solved problem
        self._buffers = (_Buffers(self.model, nj), _Buffers(self.model, nj))
        self._last: _Buffers | None = None

    @property
    def tally(self) -> WbcTally:
        """What the QPs of the walk commanded so far (:class:`WbcTally`)."""
        t, s = self._tally, self._stats
        t.max_torque_share, t.max_friction_share = float(s[0]), float(s[1])
        t.max_friction_excess, t.min_corner_force = float(s[2]), float(s[3])
        return t

    @property
    def last_problem(self) -> WbcProblem | None:
        """The last solved problem as dataclasses (rebuilt from its packed arrays when asked;
        None before the first solve)."""
        return None if self._last is None else self._last.problem()

    @property
    def last(self) -> WbcSolution | None:
        """The last solution (None before the first solve)."""
        return None if self._last is None else self._last.solution()

    # ------------------------------------------------------------------------ references
    def command(self, cmd: Command, dt: float) -> None:
        """The references of the next control period of ``dt`` [s]."""
        refs = {"com": np.asarray(cmd.com_ref, dtype=float)}
        for side in self.sim.sides:
            refs[side.value] = np.asarray(cmd.feet[side][0], dtype=float)
        for i, (key, value) in enumerate(refs.items()):
            prev = self._to.get(key)
            # a reference that jumps (a new phase restarts it) is not moved along
            if prev is None or float(np.linalg.norm(value - prev)) > REFERENCE_JUMP:
                prev = value
            self._from[key], self._to[key] = prev, value
            self._vel[key] = (value - prev) / dt
            self._refs[i] = (prev, value, self._vel[key])
        self._yaw_rot[:] = yaw_rotation(cmd.yaw)
        for i, side in enumerate(self.sim.sides):
            self._rot_ref[i] = cmd.feet[side][1]
        self._cmd = cmd

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
        if self._cmd is None:
            raise InputError("command", None, "BipedWbc.command() before torques()")
        mj, m, d = self.model.mj, self.model.m, self.model.d
        buf = self._buffers[1] if self._last is self._buffers[0] else self._buffers[0]
        self.model.mass_matrix(buf.mass)
        for body, point, jacp, jacr, jdotp, jdotr in self._frames:
            mj.mj_jac(m, d, jacp, jacr, point, body)
            mj.mj_jacDot(m, d, jdotp, jdotr, point, body)
        step = self._step
        step[tick.SHARE] = share
        step[tick.COM : tick.COM + 3] = com
        step[tick.VEL : tick.VEL + 3] = vel
        step[tick.L_G : tick.L_G + 3] = l_g
        cop_sides = self._cop_sides
        if cop is None:
            step[tick.HAS_COP] = 0.0
        else:
            step[tick.HAS_COP] = 1.0
            step[tick.COP_POINT : tick.COP_POINT + 3] = cop.point
            step[tick.COP_MOMENT : tick.COP_MOMENT + 2] = cop.moment
            cop_sides[:] = 0.0
            for s in cop.sides:
                cop_sides[self._side_index[s]] = 1.0
        sides = self._contact_sides.get(contact_sides)
        if sides is None:
            sides = np.array([self._side_index[s] for s in contact_sides], dtype=np.int64)
        t0 = time.perf_counter()
        try:
            nc, rm, rw, qp = tick.pack_tick(
                step,
                sides,
                cop_sides,
                self._gains,
                self.gravity,
                self._refs,
                self._yaw_rot,
                self._rot_ref,
                self.q_nominal,
                *self._model_arrays,
                *self._state,
                self._foot_jac,
                self._foot_jdot,
                self._torso_jac,
                self._torso_jdot,
                buf.mass,
                buf.bias,
                *buf.outputs,
                *buf.constant,
                self.qp.eps,
            )
            buf.x, buf.torque, buf.iterations = self.qp.solve_assembled(qp)
        except SolverError:
            self._tally.failures += 1
            raise
        finally:
            self.qp_time += time.perf_counter() - t0
        buf.sizes = (nc, rm, rw)
        buf.contacts = tuple(contact_sides)
        buf.cop_sides = None if cop is None else tuple(cop.sides)
        buf.motion = [("torso", 3)]
        buf.motion += [(f"swing_{s.value}", 6) for s in self.sim.sides if s not in contact_sides]
        buf.motion.append(("posture", rm - 3 - 6 * (len(buf.motion) - 1)))
        self._last = buf
        self._tally.solves += 1
        c_normal, c_friction = buf.outputs[4], buf.outputs[5]
        tick.tally_step(
            buf.x,
            buf.torque,
            self._torque_limit,
            self.model.nv,
            c_normal[:nc],
            c_friction[:nc],
            self._stats,
        )
        return buf.torque
