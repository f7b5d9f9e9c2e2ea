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

import math

import numpy as np
from numpy.typing import ArrayLike

from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.quadruped.robot import JOINT_NAMES, LEGS, Leg, LegGeometry, QuadrupedRobot

#: tolerance on the law-of-cosines argument before a target counts as out of reach
_REACH_TOL = 1e-9


def rot_y(angle: float) -> FloatArray:
    """Right-handed rotation matrix about y by ``angle`` [rad], shape (3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def body_rotation(pitch_up: float) -> FloatArray:
    """Rotation {B} -> {W} for a body pitched nose-up by ``pitch_up`` (beta_B) [rad], (3, 3)."""
    return rot_y(-pitch_up)


def _geometry(robot: QuadrupedRobot, leg: Leg | None) -> LegGeometry:
    """The geometry of ``leg``; the document's legs are all alike, so ``leg`` may be None."""
    if leg is None:
        if robot.legs is not None:
            raise ValueError("a robot loaded from its model needs the leg named")
        return robot.leg_geometry(Leg.LF)
    return robot.leg_geometry(leg)


def _rx(t: FloatArray, v: FloatArray) -> FloatArray:
    """Rotate vectors ``v`` (..., 3) about x by angles ``t`` (...)."""
    c, s = np.cos(t), np.sin(t)
    return np.stack([v[..., 0], c * v[..., 1] - s * v[..., 2], s * v[..., 1] + c * v[..., 2]], -1)


def _ry(t: FloatArray, v: FloatArray) -> FloatArray:
    """Rotate vectors ``v`` (..., 3) about y by angles ``t`` (...)."""
    c, s = np.cos(t), np.sin(t)
    return np.stack([c * v[..., 0] + s * v[..., 2], v[..., 1], -s * v[..., 0] + c * v[..., 2]], -1)


def _chain(geo: LegGeometry, q: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Angles t = signs * q (..., 3) and the broadcast shape helpers."""
    qa = np.asarray(q, dtype=float)
    t = qa * np.asarray(geo.signs)
    return t[..., 0], t[..., 1], t[..., 2]


def leg_fk(robot: QuadrupedRobot, q: ArrayLike, leg: Leg | None = None) -> FloatArray:
    """Foot-centre position in the leg frame from joint angles (closed form, eq. of
    :class:`~footfall.quadruped.robot.LegGeometry`).

    Args:
        robot: robot parameters (link lengths or the model's leg geometry).
        q: joint angles ``(q1, q2, q3)`` [rad], shape (3,) or (N, 3).
        leg: which leg (needed for a robot loaded from its model).

    Returns:
        Foot position(s) in the leg frame, shape (3,) or (N, 3) [m].
    """
    return leg_link_points(robot, q, leg)[..., 2, :]


def leg_link_points(robot: QuadrupedRobot, q: ArrayLike, leg: Leg | None = None) -> FloatArray:
    """Pitch-axis point, knee and foot positions in the leg frame, shape (..., 3, 3) rows =
    (hip, knee, foot) [m] (the hip is the leg-frame origin for the document's robot)."""
    geo = _geometry(robot, leg)
    t1, t2, t3 = _chain(geo, q)
    shape = np.shape(t1)
    hfe = np.broadcast_to(np.asarray(geo.hfe), (*shape, 3))
    knee_v = np.broadcast_to(np.asarray(geo.knee), (*shape, 3))
    foot_v = np.broadcast_to(np.asarray(geo.foot), (*shape, 3))
    knee_pitch = _ry(t2, knee_v)
    foot_pitch = _ry(t2, knee_v + _ry(t3, foot_v))
    return np.stack([_rx(t1, hfe), _rx(t1, hfe + knee_pitch), _rx(t1, hfe + foot_pitch)], axis=-2)


def leg_ik(robot: QuadrupedRobot, foot: ArrayLike, leg: Leg | None = None) -> FloatArray:
    """Closed-form inverse kinematics of one leg (the leg's knee branch), vectorised.

    Inverts :func:`leg_fk`. The ab/ad angle turns the leg's plane so that the foot's sideways
    offset from the ab/ad axis is the leg's :attr:`~LegGeometry.lateral`; in that plane the knee
    angle follows from the law of cosines on the pitch-point-to-foot distance (branch
    :attr:`~LegGeometry.branch`) and the pitch angle from the direction to the foot. The foot is
    taken to be below the pitch axis (as it is in every stance and swing).

    Args:
        robot: robot parameters.
        foot: foot-centre position(s) in the leg frame, shape (3,) or (N, 3) [m].
        leg: which leg (names it in errors; needed for a robot loaded from its model).

    Returns:
        Joint angles ``(q1, q2, q3)`` [rad] (the model's), shape (3,) or (N, 3).

    Raises:
        InputError: a target out of the leg's reach or violating a joint limit; the message
            names the first offending target and limit.
    """
    geo = _geometry(robot, leg)
    p = np.asarray(foot, dtype=float)
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    name = f"foot[{leg.value}]" if leg is not None else "foot"
    hfe, kv, fv = np.asarray(geo.hfe), np.asarray(geo.knee), np.asarray(geo.foot)
    lat = geo.lateral
    # sagittal vectors (x, z) of the thigh and shank, and their lengths
    a, b = kv[[0, 2]], fv[[0, 2]]
    l1, l2 = float(np.hypot(*a)), float(np.hypot(*b))
    rho2 = y * y + z * z - lat * lat
    zs = -np.sqrt(np.maximum(rho2, 0.0))  # sagittal z of the foot, below the ab/ad axis
    u_z = zs - hfe[2]
    u2 = x * x + u_z * u_z
    # |a + R_y(t3) b|^2 = l1^2 + l2^2 + 2 (A cos t3 + B sin t3)
    big_a = a[0] * b[0] + a[1] * b[1]
    big_b = a[0] * b[1] - a[1] * b[0]
    psi = math.atan2(big_b, big_a)
    c3 = (u2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    out_of_reach = (np.abs(c3) > 1.0 + _REACH_TOL) | (rho2 < -_REACH_TOL)
    if np.any(out_of_reach):
        k = int(np.flatnonzero(np.atleast_1d(out_of_reach))[0])
        bad_p = p.reshape(-1, 3)[k]
        raise InputError(
            name, tuple(round(float(v), 4) for v in bad_p), f"within leg reach {l1 + l2:.3f} m"
        )
    t3 = psi + geo.branch * np.arccos(np.clip(c3, -1.0, 1.0))
    t1 = np.arctan2(z, y) - np.arctan2(zs, lat)
    # the pitch turns w = a + R_y(t3) b onto (x, u_z): angles measured as atan2(x, z)
    c, s = np.cos(t3), np.sin(t3)
    w_x = a[0] + c * b[0] + s * b[1]
    w_z = a[1] - s * b[0] + c * b[1]
    t2 = np.arctan2(x, u_z) - np.arctan2(w_x, w_z)
    t = np.stack([t1, t2, t3], axis=-1)
    t = (t + np.pi) % (2.0 * np.pi) - np.pi
    q = t * np.asarray(geo.signs)
    lo = np.asarray(geo.lower)
    hi = np.asarray(geo.upper)
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


def leg_points(robot: QuadrupedRobot, q: ArrayLike, leg: Leg | None = None) -> FloatArray:
    """Knee and foot positions in the leg frame, vectorised: shape (..., 2, 3) [m]."""
    return leg_link_points(robot, q, leg)[..., 1:, :]


def leg_mass_points(robot: QuadrupedRobot, q: ArrayLike, leg: Leg) -> FloatArray:
    """Centres of mass of the ab/ad link, thigh and shank in the leg frame, vectorised: shape
    (..., 3, 3) [m] (the hip and the link midpoints for the document's robot)."""
    geo = robot.leg_geometry(leg)
    t1, t2, t3 = _chain(geo, q)
    shape = np.shape(t1)
    hfe, kv = np.asarray(geo.hfe), np.asarray(geo.knee)
    c = [np.broadcast_to(np.asarray(v), (*shape, 3)) for v in geo.coms]
    hip = _rx(t1, c[0])
    thigh = _rx(t1, hfe + _ry(t2, c[1]))
    shank = _rx(t1, hfe + _ry(t2, np.broadcast_to(kv, (*shape, 3)) + _ry(t3, c[2])))
    return np.stack([hip, thigh, shank], axis=-2)


def whole_body_com(
    robot: QuadrupedRobot, body_pos: ArrayLike, pitch_up: float, q: ArrayLike
) -> FloatArray:
    """Whole-robot centre of mass in ``{W}`` with point masses at the trunk's and each leg
    link's centre of mass (:func:`leg_mass_points`).

    Args:
        robot: robot parameters (masses).
        body_pos: body centre in ``{W}``, shape (3,) [m].
        pitch_up: body pitch beta_B [rad].
        q: joint angles in ``LEGS`` order, shape (12,) [rad].

    Returns:
        CoM position p_c in ``{W}``, shape (3,) [m].
    """
    qa = np.asarray(q, dtype=float).reshape(4, 3)
    acc = robot.body_mass * np.asarray(robot.body_com)
    for i, leg in enumerate(LEGS):
        geo = robot.leg_geometry(leg)
        pts = leg_mass_points(robot, qa[i], leg) + robot.hip_offset(leg)
        acc = acc + np.asarray(geo.masses) @ pts
    return np.asarray(body_pos, dtype=float) + body_rotation(pitch_up) @ acc / robot.total_mass
