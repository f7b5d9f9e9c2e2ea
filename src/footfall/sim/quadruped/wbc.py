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
  way; the joints: a weak posture task toward the planned angles, also with the plan's
  acceleration as feedforward;
- the hand-overs: a foot about to lift is unloaded before it lifts, and a foot that has just lifted
  but still touches stays a contact for ``liftoff_delay`` while its load passes to the others (the
  gait lifts a front foot at the instant the hind foot on its side touches down); a foot hands its
  load over only onto three other contacts;
- the dynamics: MuJoCo's ``M`` and bias with the implicit integrator's damping term
  (:class:`~footfall.sim.wbc_model.MujocoWbcModel`'s ``implicit_damping``).

The QP runs at every ``qp_every``-th physics step, and at every step near a planned touchdown
(``landing_window``), from the state of that step (``mj_step1`` / ``mj_step2``); the tick packs
it straight into arrays (:mod:`._wbc_tick`), the dataclasses are rebuilt only when asked
(``last_problem``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._geometry import cross3
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
from footfall.quadruped.gait import GaitTrajectory
from footfall.quadruped.ground import PlaneGround, QuadrupedGround
from footfall.sim.quadruped._wbc_tick import FIXED_MOTION_ROWS, feet_tick, pack_tick
from footfall.sim.wbc_model import MujocoWbcModel


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
        cop_weight: weight of the horizontal moment about the planned ZMP divided by the
            robot's weight, i.e. of the centre of pressure's distance from the planned ZMP
            [1/m^2] (the QP's weight per (N m)^2 is this over the weight squared, so one value
            serves robots of any size).
        unload_time: a stance foot's normal force is driven to zero over this time before its
            planned lift-off [s] (the plan's ZMP already lies in the other three feet's triangle),
            so it leaves the ground unloaded instead of kicking the centre of pressure.
        unload_weight: weight of that task at lift-off per (normal force / robot weight)^2
            [1] (ramping up from 0).
        touchdown_window: a swing foot that touches the ground this close [s] before its planned
            touchdown becomes a contact at once (the QP then chooses its force).
        liftoff_delay: a foot still touching the ground this long [s] after its planned
            lift-off stays a contact, its unload task ramping up to full weight over the delay:
            where the document's gait lifts one foot at the instant another touches down (a hind
            foot's touchdown and the front foot's lift-off on its side), the load passes from
            one to the other instead of the two carrying nothing at that instant (the swing's
            time law starts with zero velocity and acceleration, eq. 10-13: in 0.02 s of a 0.5 s
            swing it rises 0.06 % of its height).
        reach_depth, reach_speed, reach_gain: a planned stance foot that does not touch the
            ground (the ground lower than planned, a foot that bounced off or is a few
            milliseconds late, a foot the robot tipped off the ground) is not a contact: it
            descends from where it is along the normal at ``reach_speed`` [m/s] plus
            ``reach_gain`` [1/s] times its height above its foothold, to at most
            ``reach_depth`` [m] below the foothold, until it touches (in its unload window
            before lift-off it is let go instead). Its target has no step, so a foot a fraction
            of a millimetre late lands at about ``reach_speed`` (a target a centimetre below,
            as before, put the ~0.1 m/s impact of a late foot in the centre of pressure), and a
            foot tipped a centimetre up comes back at ~0.3 m/s (``reach_speed`` alone let
            ANYmal C and Go2 fall after lateral pushes they had survived).
        qp_every: physics steps per QP solve (the torques are held in between), except
            within ``landing_window`` [s] of a planned touchdown, where the QP runs at every
            step: torques held over two steps leave the swing foot a few tenths of a millimetre
            off its plan, and in the last millimetre of the zero-impact swing (eq. 10-13) that
            decides whether the foot lands early, with an impact.
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
    cop_weight: float = 300.0
    unload_time: float = 0.05
    unload_weight: float = 10.0
    touchdown_window: float = 0.05
    reach_depth: float = 0.01
    reach_speed: float = 0.02
    liftoff_delay: float = 0.02
    reach_gain: float = 30.0
    landing_window: float = 0.1
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


class _Reference:
    """The sampled plan with velocities and accelerations, interpolated linearly in time."""

    def __init__(self, ref: GaitTrajectory) -> None:
        self.t = ref.t
        dt = float(ref.t[1] - ref.t[0]) if ref.t.size > 1 else 1.0
        self.dt = dt
        body_v = np.gradient(ref.body_pos, dt, axis=0)
        feet_v = np.gradient(ref.feet, dt, axis=0)
        joints_v = np.gradient(ref.joints, dt, axis=0)
        n = ref.t.size
        # the interpolated quantities side by side (the columns of _wbc_tick.BODY...), so that
        # one interpolation per tick gives them all
        columns = [
            ref.body_pos,
            body_v,
            np.gradient(body_v, dt, axis=0),
            ref.feet.reshape(n, -1),
            feet_v.reshape(n, -1),
            np.gradient(feet_v, dt, axis=0).reshape(n, -1),
            ref.joints,
            joints_v,
            ref.zmp,
            ref.body_pitch[:, None],
            np.gradient(joints_v, dt, axis=0),
        ]
        #: (T, 84) the columns above: body position (3) [m], velocity, acceleration, feet
        #: (4 x 3) [m], velocities, accelerations, joints (12) [rad], rates, ZMP (2) [m], pitch,
        #: joint accelerations (12) [rad/s^2]
        self.table = np.hstack(columns)
        self.contact = ref.contact
        #: (T, 4) time from each sample to the next change of each leg's planned contact [s]
        self.to_switch = np.full(ref.contact.shape, np.inf)
        nxt = np.full(4, np.inf)
        for k in range(ref.t.size - 2, -1, -1):
            changed = ref.contact[k + 1] != ref.contact[k]
            nxt = np.where(changed, ref.t[k + 1], nxt)
            self.to_switch[k] = nxt - ref.t[k]
        #: (T, 4) time from each leg's last planned lift-off to each sample [s] (inf: none yet)
        self.since_lift = np.full(ref.contact.shape, np.inf)
        last = np.full(4, -np.inf)
        for k in range(1, ref.t.size):
            lifted = (ref.contact[k] == 0) & (ref.contact[k - 1] != 0)
            last = np.where(lifted, ref.t[k], last)
            self.since_lift[k] = ref.t[k] - last

    def at(self, t: float) -> tuple[int, float]:
        """Sample index k and weight w of time ``t``: value = (1 - w) x[k] + w x[k + 1]."""
        u = (t - self.t[0]) / self.dt
        k = int(min(max(math.floor(u), 0), self.t.size - 2))
        return k, float(min(max(u - k, 0.0), 1.0))


class _Buffers:
    """One tick's arrays: the inputs of :func:`pack_tick` that the tick fills, its outputs (the
    arrays of a :class:`PackedProblem` with room for 4 contacts, 12 + 18 motion rows and 4 + 2
    wrench rows) and the solution; the problem and the solution as dataclasses are rebuilt from
    them when asked (:meth:`problem`, :meth:`solution`).

    Args:
        model: the robot's model terms.
        friction: the feet's friction coefficient.
        plane: ``_surface`` of a plane ground (its normal and pyramid orientation are set once),
            None on other grounds (set per foot by each tick).
    """

    def __init__(
        self,
        model: MujocoWbcModel,
        friction: float,
        plane: tuple[FloatArray, FloatArray | None] | None,
    ) -> None:
        nv = model.nv
        self.nv = nv
        #: inputs: M (nv, nv), h (nv,), per leg a contact flag, unload weight (< 0: none), point
        #: [m], normal, pyramid orientation (zero: any), Jacobian of the point and derivative
        self.mass, self.bias = np.zeros((nv, nv)), np.zeros(nv)
        self.contact = np.zeros(4, dtype=bool)
        self.unload_w = np.full(4, -1.0)
        self.pts, self.normal, self.tangent = np.zeros((4, 3)), np.zeros((4, 3)), np.zeros((4, 3))
        if plane is not None:
            self.normal[:] = plane[0]
            if plane[1] is not None:
                self.tangent[:] = plane[1]
        self.foot_jac, self.foot_jdot = np.zeros((4, 3, nv)), np.zeros((4, 3, nv))
        self.trunk_jac, self.trunk_jdot = np.zeros((6, nv)), np.zeros((6, nv))
        rm, rw = 12 + FIXED_MOTION_ROWS, 6
        #: pack_tick's outputs, in its argument order (the contacts' angular rows stay zero)
        self.outputs = (
            *(np.zeros((4, 6, nv)), np.zeros((4, 6)), np.zeros((4, 3)), np.zeros((4, 1, 3))),
            *(np.zeros((4, 3)), np.zeros((4, 3))),
            *(np.zeros((rm, nv)), np.zeros(rm), np.zeros(rm)),
            *(np.zeros((rw, 6)), np.zeros((rw, 3)), np.zeros(rw), np.zeros((rw, 4))),
        )
        act = np.asarray(model.actuated, dtype=np.int64)
        free = np.ones(nv, dtype=bool)
        free[act] = False
        #: the constant arrays: actuated and other dofs, torque limits [N m], per contact one
        #: point, the friction, no minimum normal force; the wrench targets (zero)
        self.constant = (
            act,
            np.flatnonzero(free).astype(np.int64),
            np.asarray(model.torque_min, dtype=float),
            np.asarray(model.torque_max, dtype=float),
        )
        self.n_points, self.friction = np.ones(4, dtype=np.int64), np.full(4, friction)
        self.min_normal, self.w_target = np.zeros(4), np.zeros(rw)
        #: the sizes (contacts, motion rows, wrench rows) of the last packed problem
        self.sizes = (0, 0, 0)
        #: the solution: x = (qdd, forces), joint torques [N m], solver iterations
        self.x, self.torque, self.iterations = np.zeros(0), np.zeros(0), 0

    def packed(self) -> PackedProblem:
        """The last packed problem (``sizes``)."""
        nc, rm, rw = self.sizes
        c_jac, c_drift, c_origin, c_points, c_normal, c_tangent, *motion_wrench = self.outputs
        m_jac, m_rhs, m_w, w_rows, w_about, w_weight, w_mask = motion_wrench
        act, unact, lo, hi = self.constant
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
            self.n_points[:nc],
            c_normal[:nc],
            c_tangent[:nc],
            self.friction[:nc],
            self.min_normal[:nc],
            m_jac[:rm],
            m_rhs[:rm],
            m_w[:rm],
            w_rows[:rw],
            w_about[:rw],
            self.w_target[:rw],
            w_weight[:rw],
            w_mask[:rw, :nc],
        )

    def _names(self) -> list[str]:
        return [f"foot{leg}" for leg in range(4) if self.contact[leg]]

    def problem(self) -> WbcProblem:
        """The packed problem as dataclasses (copies). A motion task's drift is folded into its
        acceleration (zero drift, acceleration ``a* - Jdot qd``): the same rows of the QP."""
        p = self.packed()
        contacts = tuple(
            Contact.point(
                name,
                p.jac[i, :3].copy(),
                p.drift[i, :3].copy(),
                p.origin[i].copy(),
                p.normal[i].copy(),
                float(p.friction[i]),
                float(p.min_normal[i]),
                p.tangent[i].copy() if p.tangent[i].any() else None,
            )
            for i, name in enumerate(self._names())
        )
        groups = [(f"swing{leg}", 3) for leg in range(4) if not self.contact[leg]]
        tasks, r = [], 0
        for name, n in [*groups, ("trunk", 3), ("trunk_rot", 3), ("posture", 12)]:
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
        # the unload rows (one per unloading contact, in leg order), then the CoP's two rows
        wrench, r = [], 0
        for c in contacts:
            if self.unload_w[int(c.name[-1])] >= 0.0:
                about, rows = p.wrench_about[r].copy(), p.wrench_rows[r : r + 1].copy()
                weight = float(p.wrench_w[r])
                wrench.append(
                    WrenchTask(f"unload{c.name[-1]}", about, rows, np.zeros(1), weight, (c.name,))
                )
                r += 1
        if r < p.wrench_w.shape[0]:
            about, rows = p.wrench_about[r].copy(), p.wrench_rows[r : r + 2].copy()
            wrench.append(WrenchTask("cop", about, rows, np.zeros(2), float(p.wrench_w[r])))
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
            name: x[nv + 3 * i : nv + 3 * i + 3].reshape(1, 3).copy()
            for i, name in enumerate(self._names())
        }
        return WbcSolution(x[:nv].copy(), self.torque, forces, self.iterations)


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
        self.model = MujocoWbcModel(mj, m, sim.data, sim.actuators, implicit_damping=True)
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
        self._foot_sites = np.asarray(sim.foot_sites, dtype=np.int64)
        self._joint_qpos = np.asarray(sim.qpos_adr, dtype=np.int64)
        #: generalised-velocity index of each planned joint angle (LEGS x JOINT_NAMES order)
        self.joint_dofs = np.array(
            [int(m.jnt_dofadr[int(m.actuator_trnid[a, 0])]) for a in sim.actuators]
        )
        g = gains
        #: the gains in the order of pack_tick's and feet_tick's vector
        # the CoP's and the unload's weights are per (m)^2 and per (share of the weight)^2: in
        # the QP, per (N m)^2 and per N^2 of this robot's weight
        weight = float(np.sum(m.body_mass)) * -float(m.opt.gravity[2])
        g = dataclasses.replace(
            g, cop_weight=g.cop_weight / weight**2, unload_weight=g.unload_weight / weight**2
        )
        self._gains = np.array(
            [
                *(g.trunk_kp, g.trunk_kd, g.rot_kp, g.rot_kd, g.swing_kp, g.swing_kd),
                *(g.posture_kp, g.posture_kd, g.trunk_weight, g.rot_weight, g.swing_weight),
                *(g.posture_weight, g.cop_weight, g.touchdown_window, g.unload_time),
                *(g.unload_weight, g.reach_depth, g.reach_speed),
                g.liftoff_delay,
                g.reach_gain,
            ]
        )
        #: the plan at the tick's instant (the columns of ``_Reference.table``), filled per tick
        self._row = np.empty(self.ref.table.shape[1])
        # two sets of arrays: a tick fills the one that does not hold the last solved problem
        self._buffers = (
            _Buffers(self.model, self.friction, self._plane),
            _Buffers(self.model, self.friction, self._plane),
        )
        self._last: _Buffers | None = None
        self.failures = 0
        self._fine = self._near_touchdown()
        self.last_tau = np.zeros(len(sim.actuators))

    def retarget(self, ref: GaitTrajectory) -> None:
        """Track ``ref`` from now on (same sample times; the slip guard's held reference)."""
        self.ref = _Reference(ref)
        self._fine = self._near_touchdown()

    def _near_touchdown(self) -> NDArray[np.bool_]:
        """Per plan sample (T,): a swing foot lands within ``landing_window`` (and one sample)
        of it, where the QP runs at every physics step (:meth:`due`)."""
        ref = self.ref
        swing = np.asarray(ref.contact, dtype=bool) == 0
        window = self.gains.landing_window + ref.dt
        return np.asarray(np.any(swing & (ref.to_switch <= window), axis=1))

    @property
    def last_problem(self) -> WbcProblem | None:
        """The last solved problem as dataclasses (rebuilt from its packed arrays when asked;
        None before the first solve)."""
        return None if self._last is None else self._last.problem()

    @property
    def last(self) -> WbcSolution | None:
        """The last solution (None before the first solve)."""
        return None if self._last is None else self._last.solution()

    def _feet(self, buf: _Buffers, k: int, w: float) -> None:
        """The plan at sample ``k``, weight ``w``, into ``_row`` and each foot's part of the tick
        into ``buf`` (:func:`feet_tick`): a contact or not, its contact normal, unload weight,
        point and that point's Jacobians."""
        sim, d, ref = self.sim, self.sim.data, self.ref
        if self._plane is None:  # the ground's normal and pyramid orientation under each foot
            for leg, site in enumerate(sim.foot_sites):
                centre = d.site_xpos[site]
                normal, tangent = _surface(self.ground.normal(float(centre[0]), float(centre[1])))
                buf.normal[leg] = normal
                buf.tangent[leg] = 0.0 if tangent is None else tangent
        con = d.contact
        feet_tick(
            ref.table,
            ref.contact,
            ref.to_switch,
            ref.since_lift,
            k,
            w,
            ref.dt,
            con.geom,
            con.dist,
            sim.foot_of_geom,
            d.site_xpos,
            self._foot_sites,
            self.radius,
            self._gains,
            self._row,
            buf.contact,
            buf.unload_w,
            buf.pts,
            buf.normal,
        )
        for leg in range(4):
            self.model.jacobians(
                self.foot_bodies[leg], buf.pts[leg], buf.foot_jac[leg], buf.foot_jdot[leg]
            )

    def due(self, step: int, t: float) -> bool:
        """Whether the QP runs at physics step ``step`` (gait time ``t`` [s]): at every
        ``qp_every``-th step, and at every step near a planned touchdown."""
        if step % self.gains.qp_every == 0:
            return True
        k, _ = self.ref.at(t)
        return bool(self._fine[k] or self._fine[k + 1])

    def torques(self, t: float) -> FloatArray:
        """Joint torques (12,) [N m] at gait time ``t`` from the current state (positions and
        velocities; ``mj_step1`` has run)."""
        sim, d, ref = self.sim, self.sim.data, self.ref
        k, w = ref.at(t)
        # fill the buffers that do not hold the last solved problem
        buf = self._buffers[1] if self._last is self._buffers[0] else self._buffers[0]
        self._feet(buf, k, w)
        trunk_pos = d.xpos[sim.trunk]
        self.model.jacobians(sim.trunk, trunk_pos, buf.trunk_jac, buf.trunk_jdot)
        self.model.mass_matrix(buf.mass)
        np.subtract(d.qfrc_bias, d.qfrc_passive, out=buf.bias)
        nc, rm, rw, qp = pack_tick(
            self._row,
            d.xmat[sim.trunk],
            buf.contact,
            buf.unload_w,
            buf.pts,
            buf.normal,
            buf.tangent,
            buf.foot_jac,
            buf.foot_jdot,
            buf.trunk_jac,
            buf.trunk_jdot,
            trunk_pos,
            d.qvel,
            d.qpos,
            self._joint_qpos,
            self.joint_dofs,
            self._gains,
            *buf.outputs,
            buf.mass,
            buf.bias,
            *buf.constant,
            buf.n_points,
            buf.friction,
            buf.min_normal,
            buf.w_target,
            self.ctrl.eps,
        )
        buf.sizes = (nc, rm, rw)
        try:
            buf.x, buf.torque, buf.iterations = self.ctrl.solve_assembled(qp)
        except SolverError:  # counted in the metrics; the last torques are held for one step
            self.failures += 1
            return self.last_tau
        self._last = buf
        self.last_tau = buf.torque
        return buf.torque


def _surface(normal: FloatArray) -> tuple[FloatArray, FloatArray | None]:
    """Contact normal (3,) and friction pyramid orientation (3,) (or None).

    Gravity's pull along a slope points at an edge of the friction pyramid (where it reaches
    Coulomb's cone, mu) rather than at a face (mu / sqrt(2)): the first face direction is the
    downhill direction turned 45 degrees about the normal (None on level ground: no preferred
    direction).
    """
    n = np.asarray(normal, dtype=float)
    down = np.array([0.0, 0.0, -1.0]) - n * (-n[2])
    tangent = None
    length = np.linalg.norm(down)
    if length > 1e-9:
        down /= length
        # cross3: np.cross's ~15 us would be paid per contact and tick on a curved ground
        tangent = (down + cross3(n, down)) / math.sqrt(2.0)
    return n, tangent


def check_gains(gains: object) -> QuadrupedWbcGains:
    """``gains`` if it is a :class:`QuadrupedWbcGains` (an error naming the field otherwise)."""
    if not isinstance(gains, QuadrupedWbcGains):
        raise InputError("wbc_gains", type(gains).__name__, "a QuadrupedWbcGains")
    return gains


__all__ = ["QuadrupedWbc", "QuadrupedWbcGains", "check_gains"]
