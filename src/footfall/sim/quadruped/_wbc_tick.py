"""Compiled packing of the quadruped's whole-body QP (numba, beyond the documents).

:func:`feet_tick` interpolates the plan and decides each foot's part of the tick (a contact or
not, its point, its unload weight, the target of a stance foot off the ground); :func:`pack_tick`
writes one tick's contacts and tasks (:mod:`footfall.sim.quadruped.wbc`'s
module docstring) straight into the arrays of :class:`footfall.control.wbc.PackedProblem`, the
same numbers as building :class:`~footfall.control.wbc.Contact`, ``MotionTask`` and ``WrenchTask``
and packing them, without the ~40 small numpy operations and dataclasses per tick that cost more
than the QP itself at 250 Hz.

Everything compiled lives in this module (numba's on-disk cache, ``cache=True``, keys on it).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from footfall.control._wbc_kernel import assemble, rotation_error

#: columns of ``_Reference.table`` (see :class:`footfall.sim.quadruped.wbc._Reference`)
BODY, BODY_V, BODY_A, FEET, FEET_V, FEET_A, JOINTS, JOINTS_V, ZMP = 0, 3, 6, 9, 21, 33, 45, 57, 69
PITCH = 71
#: the planned joint accelerations (12) [rad/s^2], after the columns above
JOINTS_A = 72
#: entries of the gains vector of :func:`pack_tick`
(TRUNK_KP, TRUNK_KD, ROT_KP, ROT_KD, SWING_KP, SWING_KD, POSTURE_KP, POSTURE_KD) = range(8)
(TRUNK_W, ROT_W, SWING_W, POSTURE_W, COP_W) = range(8, 13)
(TOUCHDOWN_WINDOW, UNLOAD_TIME, UNLOAD_WEIGHT, REACH_DEPTH, REACH_SPEED) = range(13, 18)
LIFTOFF_DELAY = 18
REACH_GAIN = 19
#: rows of the tick's motion tasks that are not swing feet: trunk (3), orientation (3), joints (12)
FIXED_MOTION_ROWS = 18


@njit(cache=True)
def _matvec(a: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """``out = a @ x`` for ``a`` (r, n), ``x`` (n,), ``out`` (r,): BLAS's product, as numpy's
    ``@`` (a loop sums in another order; a walk then drifts from the dataclass path's by more
    than rounding, through the contact decisions)."""
    out[:] = np.dot(a, x)


@njit(cache=True)
def feet_tick(
    table: np.ndarray,
    planned_contact: np.ndarray,
    to_switch: np.ndarray,
    since_lift: np.ndarray,
    k: int,
    w: float,
    dt: float,
    geom: np.ndarray,
    dist: np.ndarray,
    foot_of_geom: np.ndarray,
    site_xpos: np.ndarray,
    foot_sites: np.ndarray,
    radius: float,
    gains: np.ndarray,
    row: np.ndarray,
    contact: np.ndarray,
    unload_w: np.ndarray,
    pts: np.ndarray,
    normal: np.ndarray,
) -> None:
    """The plan at this instant and each foot's part of the tick
    (:class:`~footfall.sim.quadruped.wbc.QuadrupedWbc`'s rules), written in place.

    Inputs: the plan ``table`` (T, 84) (``_Reference.table``'s columns), its ``planned_contact``
    (T, 4), ``to_switch`` (T, 4) [s] and ``since_lift`` (T, 4) [s] (from each leg's last
    planned lift-off to each sample, inf before the first); the sample ``k`` and weight ``w`` of this instant
    (``_Reference.at``) and the sample period ``dt`` [s]; MuJoCo's contacts ``geom`` (ncon, 2),
    ``dist`` (ncon,) [m] (a foot touches the ground when one of its contacts is not in the
    margin, ``dist <= 0``); ``foot_of_geom`` (ngeom,) each geom's leg or -1; ``site_xpos``
    (nsite, 3) [m] and the feet's ``foot_sites`` (4,); the feet's ``radius`` [m]; ``gains``
    (:func:`pack_tick`'s vector); ``normal`` (4, 3) the ground's normal under each foot.

    Outputs: ``row`` (84,) the interpolated plan, with the target of a planned stance foot off
    the ground descending from where it is; per leg ``contact`` (bool), ``unload_w`` (< 0:
    none) and ``pts`` (4, 3) [m] its contact point (the bottom of its sphere along the normal)
    or, not a contact, its centre.
    """
    for i in range(row.shape[0]):
        row[i] = (1.0 - w) * table[k, i] + w * table[k + 1, i]
    # the plan's contacts of the nearer sample (and the lift-off times counted from it)
    near = k if w < 0.5 else k + 1
    stance = planned_contact[near]
    touching = np.zeros(4, dtype=np.bool_)
    for i in range(geom.shape[0]):
        if dist[i] <= 0.0:  # within the margin: not yet
            for side in range(2):
                g = geom[i, side]
                if g >= 0 and foot_of_geom[g] >= 0:
                    touching[foot_of_geom[g]] = True
    window, unload = gains[TOUCHDOWN_WINDOW], gains[UNLOAD_TIME]
    delay = gains[LIFTOFF_DELAY]
    ahead = w * dt
    left = np.empty(4)
    lifted = np.empty(4)
    early = np.zeros(4, dtype=np.bool_)
    late = np.zeros(4, dtype=np.bool_)
    for leg in range(4):
        # time to this leg's next switch as seen from the nearer sample (from sample k, a
        # switch at k + 1 would still be the next one after the foot has switched)
        left[leg] = to_switch[near, leg] + (near - k) * dt - ahead
        early[leg] = touching[leg] and left[leg] <= window
        # a foot that lifted off less than liftoff_delay ago and still touches hands its load
        # over (its unload task ramps up to full weight over the delay)
        lifted[leg] = since_lift[near, leg] + ahead - (near - k) * dt
        late[leg] = (not stance[leg]) and touching[leg] and delay > 0 and lifted[leg] <= delay
        # a planned stance foot is a contact while it touches the ground; off it (the ground
        # lower than planned, or a foot that bounced) it reaches down instead of the QP
        # counting on a force that the ground cannot give
        contact[leg] = (stance[leg] and touching[leg]) or early[leg] or late[leg]
    n_contacts = np.sum(contact)
    for leg in range(4):
        is_contact = contact[leg]
        centre = site_xpos[foot_sites[leg]]
        # a planned stance foot off the ground outside its unload window (in it, it is let go
        # and lifts off a little early) descends from where it is along the normal at
        # reach_speed, to at most reach_depth below its foothold: no step in its target, so
        # it lands as gently as that speed
        if stance[leg] and not is_contact and left[leg] >= unload:
            depth = 0.0
            for i in range(3):
                depth += (centre[i] - row[FEET + 3 * leg + i]) * normal[leg, i]
            # faster the higher above its foothold (a foot the robot tipped off its ground)
            speed = gains[REACH_SPEED] + gains[REACH_GAIN] * max(depth, 0.0)
            depth = max(depth, -gains[REACH_DEPTH])
            for i in range(3):
                row[FEET + 3 * leg + i] += depth * normal[leg, i]
                row[FEET_V + 3 * leg + i] = -speed * normal[leg, i]
                row[FEET_A + 3 * leg + i] = 0.0
        unload_w[leg] = -1.0
        if is_contact:
            for i in range(3):
                pts[leg, i] = centre[i] - radius * normal[leg, i]
            # the load passes to the other feet only when three of them carry it (a foot
            # about to land that has not touched yet cannot take it: the leaving foot waits,
            # and lifts late through liftoff_delay)
            if n_contacts < 4:
                continue
            if stance[leg] and unload > 0 and left[leg] < unload:
                share = 1.0 - (0.0 if 0.0 > left[leg] else left[leg]) / unload
                unload_w[leg] = gains[UNLOAD_WEIGHT] * share
            elif late[leg] and not early[leg]:
                share = (0.0 if 0.0 > lifted[leg] else lifted[leg]) / delay
                unload_w[leg] = gains[UNLOAD_WEIGHT] * share
        else:
            pts[leg] = centre


@njit(cache=True)
def pack_tick(
    row: np.ndarray,
    trunk_xmat: np.ndarray,
    contact: np.ndarray,
    unload_w: np.ndarray,
    pts: np.ndarray,
    normal: np.ndarray,
    tangent: np.ndarray,
    foot_jac: np.ndarray,
    foot_jdot: np.ndarray,
    trunk_jac: np.ndarray,
    trunk_jdot: np.ndarray,
    trunk_pos: np.ndarray,
    qvel: np.ndarray,
    qpos: np.ndarray,
    joint_qpos: np.ndarray,
    joint_dofs: np.ndarray,
    gains: np.ndarray,
    c_jac: np.ndarray,
    c_drift: np.ndarray,
    c_origin: np.ndarray,
    c_points: np.ndarray,
    c_normal: np.ndarray,
    c_tangent: np.ndarray,
    m_jac: np.ndarray,
    m_rhs: np.ndarray,
    m_w: np.ndarray,
    w_rows: np.ndarray,
    w_about: np.ndarray,
    w_weight: np.ndarray,
    w_mask: np.ndarray,
    mass: np.ndarray,
    bias: np.ndarray,
    actuated: np.ndarray,
    unactuated: np.ndarray,
    torque_min: np.ndarray,
    torque_max: np.ndarray,
    n_points: np.ndarray,
    friction: np.ndarray,
    min_normal: np.ndarray,
    w_target: np.ndarray,
    eps: tuple[float, float, float],
) -> tuple[
    int,
    int,
    int,
    tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, np.ndarray, bool],
]:
    """Fill one tick's packed problem and assemble its QP: returns the numbers of contacts,
    motion rows and wrench rows (the arrays' leading parts that count) and
    :func:`~footfall.control._wbc_kernel.assemble`'s QP.

    Inputs: ``row`` (84,) the plan at this instant (``_Reference.table``'s columns);
    ``trunk_xmat`` (9,) the trunk's orientation (row-major); per leg (4): ``contact`` (bool) a contact this tick,
    ``unload_w`` the weight of its unload task (< 0: none), ``pts`` (4, 3) its contact point or
    (swing) its foot centre [m], ``normal`` and ``tangent`` (4, 3) its contact normal and friction
    pyramid orientation (zero: any), ``foot_jac`` and ``foot_jdot`` (4, 3, nv) the Jacobian of
    ``pts`` and its derivative; the trunk's ``trunk_jac``, ``trunk_jdot`` (6, nv) at its origin
    ``trunk_pos`` (3,) [m]; ``qpos`` (nq,), ``qvel`` (nv,); the planned joints' ``joint_qpos`` (12,)
    and ``joint_dofs`` (12,) addresses; ``gains`` (18,) (the indices above).

    Outputs (written in place, the constant parts set once by the caller: rows 3-5 of ``c_jac``
    and ``c_drift`` zero, one point per contact, the wrench targets zero): the contacts' ``c_jac``
    (4, 6, nv), ``c_drift`` (4, 6), ``c_origin`` (4, 3), ``c_points`` (4, 1, 3), ``c_normal``,
    ``c_tangent`` (4, 3); the motion rows ``m_jac`` (rm, nv), ``m_rhs``, ``m_w`` (rm,); the wrench
    rows ``w_rows`` (rw, 6), ``w_about`` (rw, 3), ``w_weight`` (rw,), ``w_mask`` (rw, 4).

    Then the rest of :class:`~footfall.control.wbc.PackedProblem`: ``mass`` (nv, nv), ``bias``
    (nv,), ``actuated``, ``unactuated``, ``torque_min``, ``torque_max``; per contact (4,)
    ``n_points`` (ones), ``friction``, ``min_normal``; ``w_target`` (6,) (zeros); and the
    controller's regularisation weights ``eps``.
    """
    nv = qvel.shape[0]
    # the planned orientation: nose-up pitch is a rotation about y by -pitch
    c, s = math.cos(-row[PITCH]), math.sin(-row[PITCH])
    plan_rot = np.zeros((3, 3))
    plan_rot[0, 0], plan_rot[0, 2], plan_rot[1, 1] = c, s, 1.0
    plan_rot[2, 0], plan_rot[2, 2] = -s, c
    err = rotation_error(plan_rot, trunk_xmat.reshape(3, 3))
    vel = np.empty(6)
    drift = np.empty(6)
    nc = 0
    rm = 0
    rw = 0
    height_sum = 0.0
    w_mask[:] = 0.0
    for leg in range(4):
        if contact[leg]:
            c_jac[nc, :3] = foot_jac[leg]
            _matvec(foot_jdot[leg], qvel, c_drift[nc, :3])
            c_origin[nc] = pts[leg]
            c_points[nc, 0] = pts[leg]
            c_normal[nc] = normal[leg]
            c_tangent[nc] = tangent[leg]
            height_sum += pts[leg, 2]
            if unload_w[leg] >= 0.0:
                w_rows[rw, :3] = normal[leg]
                w_rows[rw, 3:] = 0.0
                w_about[rw] = pts[leg]
                w_weight[rw] = unload_w[leg]
                w_mask[rw, nc] = 1.0
                rw += 1
            nc += 1
        else:
            _matvec(foot_jac[leg], qvel, vel[:3])
            _matvec(foot_jdot[leg], qvel, drift[:3])
            for i in range(3):
                acc = (
                    row[FEET_A + 3 * leg + i]
                    + gains[SWING_KP] * (row[FEET + 3 * leg + i] - pts[leg, i])
                    + gains[SWING_KD] * (row[FEET_V + 3 * leg + i] - vel[i])
                )
                m_jac[rm] = foot_jac[leg, i]
                m_rhs[rm] = acc - drift[i]
                m_w[rm] = gains[SWING_W]
                rm += 1
    _matvec(trunk_jac, qvel, vel)
    _matvec(trunk_jdot, qvel, drift)
    for i in range(3):
        acc = (
            row[BODY_A + i]
            + gains[TRUNK_KP] * (row[BODY + i] - trunk_pos[i])
            - gains[TRUNK_KD] * (vel[i] - row[BODY_V + i])
        )
        m_jac[rm + i] = trunk_jac[i]
        m_rhs[rm + i] = acc - drift[i]
        m_w[rm + i] = gains[TRUNK_W]
        acc = gains[ROT_KP] * err[i] - gains[ROT_KD] * vel[3 + i]
        m_jac[rm + 3 + i] = trunk_jac[3 + i]
        m_rhs[rm + 3 + i] = acc - drift[3 + i]
        m_w[rm + 3 + i] = gains[ROT_W]
    rm += 6
    for j in range(joint_dofs.shape[0]):
        dof = joint_dofs[j]
        # the plan's joint acceleration as feedforward: without it the task pulls against the
        # swing leg's planned motion (at lift-off ~100 rad/s^2 at a heavy leg's knee), and the
        # QP gives way by moving the trunk off its plan
        acc = (
            row[JOINTS_A + j]
            + gains[POSTURE_KP] * (row[JOINTS + j] - qpos[joint_qpos[j]])
            + gains[POSTURE_KD] * (row[JOINTS_V + j] - qvel[dof])
        )
        for a in range(nv):
            m_jac[rm, a] = 0.0
        m_jac[rm, dof] = 1.0
        m_rhs[rm] = acc - 0.0  # the posture task's zero drift
        m_w[rm] = gains[POSTURE_W]
        rm += 1
    if nc > 0 and gains[COP_W] > 0:
        # the horizontal moment (mx, my) about the planned ZMP at the stance points' mean height
        zp = height_sum / nc
        for i in range(2):
            w_rows[rw + i] = 0.0
            w_rows[rw + i, 3 + i] = 1.0
            w_about[rw + i, 0] = row[ZMP]
            w_about[rw + i, 1] = row[ZMP + 1]
            w_about[rw + i, 2] = zp
            w_weight[rw + i] = gains[COP_W]
            w_mask[rw + i, :nc] = 1.0
        rw += 2
    qp = assemble(
        mass,
        bias,
        actuated,
        unactuated,
        torque_min,
        torque_max,
        c_jac[:nc],
        c_drift[:nc],
        c_origin[:nc],
        c_points[:nc],
        n_points[:nc],
        c_normal[:nc],
        c_tangent[:nc],
        friction[:nc],
        min_normal[:nc],
        m_jac[:rm],
        m_rhs[:rm],
        m_w[:rm],
        w_rows[:rw],
        w_about[:rw],
        w_target[:rw],
        w_weight[:rw],
        w_mask[:rw, :nc],
        eps[0],
        eps[1],
        eps[2],
    )
    return nc, rm, rw, qp
