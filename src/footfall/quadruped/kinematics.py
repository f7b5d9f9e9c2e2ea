"""Closed-form kinematics of one 3-DoF leg and the frame changes {W} <-> {B} <-> {leg}.

Leg model (document 001, fig. 1): joint angles ``q = (q1, q2, q3)`` = (hip ab/ad about x, hip pitch
about y, knee about y). With ``l1`` the thigh and ``l2`` the shank length, the foot in the leg frame
is

    x = -l1 sin q2 - l2 sin(q2 + q3)
    r =  l1 cos q2 + l2 cos(q2 + q3)         (length of the leg in its sagittal plane)
    y =  r sin q1,    z = -r cos q1.

Positive hip pitch swings the foot backwards (a positive rotation about y turns -z towards -x);
positive knee angles bend the knee forwards, the configuration footfall uses for all four legs.

Body orientation: footfall's gaits only pitch the body. ``pitch_up`` is the document's body angle
``beta_B`` (nose up positive); the rotation {B} -> {W} is ``R_y(-pitch_up)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.quadruped.robot import JOINT_NAMES, LEGS, Leg, QuadrupedRobot

#: tolerance on the law-of-cosines argument before a target counts as out of reach
_REACH_TOL = 1e-9


def rot_y(angle: float) -> FloatArray:
    """Right-handed rotation matrix about y by ``angle`` [rad], shape (3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def body_rotation(pitch_up: float) -> FloatArray:
    """Rotation {B} -> {W} for a body pitched nose-up by ``pitch_up`` (beta_B) [rad], (3, 3)."""
    return rot_y(-pitch_up)


def leg_fk(robot: QuadrupedRobot, q: ArrayLike) -> FloatArray:
    """Foot-centre position in the leg frame from joint angles (closed form).

    Args:
        robot: robot parameters (link lengths).
        q: joint angles ``(q1, q2, q3)`` [rad], shape (3,) or (N, 3).

    Returns:
        Foot position(s) in the leg frame, shape (3,) or (N, 3) [m].
    """
    qa = np.asarray(q, dtype=float)
    q1, q2, q3 = qa[..., 0], qa[..., 1], qa[..., 2]
    l1, l2 = robot.thigh_length, robot.shank_length
    x = -l1 * np.sin(q2) - l2 * np.sin(q2 + q3)
    r = l1 * np.cos(q2) + l2 * np.cos(q2 + q3)
    return np.stack([x, r * np.sin(q1), -r * np.cos(q1)], axis=-1)


def leg_link_points(robot: QuadrupedRobot, q: ArrayLike) -> FloatArray:
    """Hip, knee and foot positions in the leg frame, shape (3, 3) rows = (hip, knee, foot) [m]."""
    q1, q2, _ = np.asarray(q, dtype=float)
    l1 = robot.thigh_length
    knee_sag = np.array([-l1 * np.sin(q2), l1 * np.cos(q2)])
    knee = np.array([knee_sag[0], knee_sag[1] * np.sin(q1), -knee_sag[1] * np.cos(q1)])
    return np.stack([np.zeros(3), knee, leg_fk(robot, q)])


def leg_ik(robot: QuadrupedRobot, foot: ArrayLike, leg: Leg | None = None) -> FloatArray:
    """Closed-form inverse kinematics of one leg (knee-forward branch), vectorised.

    Inverts :func:`leg_fk`: ``q1 = atan2(y, -z)``, the sagittal length ``r = sqrt(y^2 + z^2)``, the
    knee from the law of cosines and the hip pitch from the triangle hip-knee-foot. The foot is
    taken to be below the hip in the leg's plane (``r > 0``), as it is in every stance and swing.

    Args:
        robot: robot parameters.
        foot: foot-centre position(s) in the leg frame, shape (3,) or (N, 3) [m].
        leg: which leg (only used to name it in errors).

    Returns:
        Joint angles ``(q1, q2, q3)`` [rad], shape (3,) or (N, 3).

    Raises:
        InputError: a target is farther than ``thigh + shank`` or violates a joint limit; the
            message names the first offending target and limit.
    """
    p = np.asarray(foot, dtype=float)
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    name = f"foot[{leg.value}]" if leg is not None else "foot"
    l1, l2 = robot.thigh_length, robot.shank_length
    q1 = np.arctan2(y, -z)
    r = np.hypot(y, z)
    c3 = (x * x + r * r - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    out_of_reach = np.abs(c3) > 1.0 + _REACH_TOL
    if np.any(out_of_reach):
        k = int(np.flatnonzero(np.atleast_1d(out_of_reach))[0])
        bad_p = p.reshape(-1, 3)[k]
        raise InputError(
            name, tuple(round(float(v), 4) for v in bad_p), f"within leg reach {l1 + l2:.3f} m"
        )
    q3 = np.arccos(np.clip(c3, -1.0, 1.0))
    q2 = np.arctan2(-x, r) - np.arctan2(l2 * np.sin(q3), l1 + l2 * np.cos(q3))
    q = np.stack([q1, q2, q3], axis=-1)
    lo = np.asarray(robot.joint_limits.lower)
    hi = np.asarray(robot.joint_limits.upper)
    bad = (q < lo - _REACH_TOL) | (q > hi + _REACH_TOL)
    if np.any(bad):
        flat = bad.reshape(-1, 3)
        k = int(np.flatnonzero(flat.any(axis=1))[0])
        j = int(np.flatnonzero(flat[k])[0])
        qk = q.reshape(-1, 3)[k]
        raise InputError(
            name,
            tuple(round(float(v), 4) for v in p.reshape(-1, 3)[k]),
            f"{JOINT_NAMES[j]} angle {qk[j]:.3f} rad within its limits [{lo[j]:.3f}, {hi[j]:.3f}]",
        )
    return q


def foot_in_leg_frame(
    robot: QuadrupedRobot,
    leg: Leg,
    body_pos: ArrayLike,
    pitch_up: float,
    foot_world: ArrayLike,
) -> FloatArray:
    """World foot position in the leg frame: ``R^T (p - p_B) - hip_offset``, shape (3,) [m]."""
    rot = body_rotation(pitch_up)
    rel = np.asarray(foot_world, dtype=float) - np.asarray(body_pos, dtype=float)
    return rot.T @ rel - robot.hip_offset(leg)


def foot_in_world(
    robot: QuadrupedRobot,
    leg: Leg,
    body_pos: ArrayLike,
    pitch_up: float,
    foot_leg: ArrayLike,
) -> FloatArray:
    """Express a leg-frame foot position in ``{W}``, shape (3,) [m]."""
    rot = body_rotation(pitch_up)
    return np.asarray(body_pos, dtype=float) + rot @ (
        robot.hip_offset(leg) + np.asarray(foot_leg, dtype=float)
    )


def whole_body_ik(
    robot: QuadrupedRobot, body_pos: ArrayLike, pitch_up: float, feet_world: ArrayLike
) -> FloatArray:
    """Joint angles of all four legs putting the feet at ``feet_world``.

    Args:
        robot: robot parameters.
        body_pos: body centre in ``{W}``, shape (3,) [m].
        pitch_up: body pitch beta_B [rad].
        feet_world: foot centres in ``LEGS`` order, shape (4, 3) [m].

    Returns:
        Joint angles in ``LEGS`` order, shape (12,) [rad].
    """
    feet = np.asarray(feet_world, dtype=float)
    out = np.empty(12)
    for i, leg in enumerate(LEGS):
        p = foot_in_leg_frame(robot, leg, body_pos, pitch_up, feet[i])
        out[3 * i : 3 * i + 3] = leg_ik(robot, p, leg)
    return out


def leg_points(robot: QuadrupedRobot, q: ArrayLike) -> FloatArray:
    """Knee and foot positions in the leg frame, vectorised: shape (..., 2, 3) [m]."""
    qa = np.asarray(q, dtype=float)
    q1, q2 = qa[..., 0], qa[..., 1]
    r1 = robot.thigh_length * np.cos(q2)
    knee = np.stack([-robot.thigh_length * np.sin(q2), r1 * np.sin(q1), -r1 * np.cos(q1)], axis=-1)
    return np.stack([knee, leg_fk(robot, qa)], axis=-2)


def whole_body_com(
    robot: QuadrupedRobot, body_pos: ArrayLike, pitch_up: float, q: ArrayLike
) -> FloatArray:
    """Whole-robot centre of mass in ``{W}`` with point masses at the hips and link midpoints.

    Args:
        robot: robot parameters (masses).
        body_pos: body centre in ``{W}`` (the trunk's CoM), shape (3,) [m].
        pitch_up: body pitch beta_B [rad].
        q: joint angles in ``LEGS`` order, shape (12,) [rad].

    Returns:
        CoM position p_c in ``{W}``, shape (3,) [m].
    """
    pts = leg_points(robot, np.asarray(q, dtype=float).reshape(4, 3))  # (4, 2, 3)
    knee, foot = pts[:, 0], pts[:, 1]
    # hip at the leg-frame origin; thigh mass at the thigh midpoint, shank at the shank midpoint
    local = 0.5 * robot.thigh_mass * knee + 0.5 * robot.shank_mass * (knee + foot)
    acc = robot.leg_mass * robot.hip_offsets().sum(axis=0) + local.sum(axis=0)
    return np.asarray(body_pos, dtype=float) + body_rotation(pitch_up) @ acc / robot.total_mass
