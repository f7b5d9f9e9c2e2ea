"""Reference motions of the MuJoCo biped's walk: swing paths and the CoM height (000 section 5.5).

The swing sole rises above every region it passes over before it moves (:func:`swing_reference`,
:func:`terrain_height_along`, :func:`swing_shares`) and bows around the stance foot
(:func:`swing_bow`); the CoM height lies on the 3-D LIPM constraint planes through z_H above
consecutive footsteps (:class:`CoMHeight`), on which the horizontal motion is exactly the ALIP's
(eq. 5.1); :func:`ds_propagator` advances the double-support ALIP exactly (eq. 5.8-5.10).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import expm

from footfall._geometry import rotation_exp, rotation_log
from footfall._typing import FloatArray
from footfall.models.alip import ALIP
from footfall.terrain.region import Region

#: the horizontal swing motion runs between these shares of the swing
SWING_MOVE = (0.1, 0.9)
#: shortest and longest share of the swing for the rise (and for the descent)
SWING_SHARES = (0.35, 0.5)
#: peak vertical acceleration of the swing sole the shares aim at [m/s^2] (a 0.05 m rise in
#: 0.35 x 0.4 s needs 15)
SWING_ACC_MAX = 15.0
#: peak acceleration of the quintic smoothstep over a unit distance and duration
QUINTIC_PEAK_ACC = 10.0 / math.sqrt(3.0)


def smoothstep(s: float) -> float:
    """Quintic 0 -> 1 on [0, 1] with zero velocity and acceleration at both ends."""
    s = min(1.0, max(0.0, s))
    return s * s * s * (10.0 + s * (-15.0 + 6.0 * s))


def foot_rotation(normal: ArrayLike, heading: float) -> FloatArray:
    """Rotation (3, 3) of a sole lying on a plane with ``normal`` and pointing along ``heading``.

    Columns: the heading direction projected onto the plane, the lateral axis, the normal.
    """
    n = np.asarray(normal, dtype=float)
    h = np.array([math.cos(heading), math.sin(heading), 0.0])
    x = h - (h @ n) * n
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(n, x), n])


def swing_reference(
    tau: float,
    start: FloatArray,
    target: FloatArray,
    apex: float,
    rise: float = 0.35,
    descend: float = 0.65,
    stance: FloatArray | None = None,
    side_clearance: float = 0.0,
) -> tuple[FloatArray, float]:
    """Swing sole position (3,) [m] at phase share ``tau`` and the horizontal progress in [0, 1].

    The sole rises to ``apex`` in the first ``rise`` share of the swing, moves horizontally during
    ``SWING_MOVE`` and descends from the ``descend`` share on, so it crosses every step edge at
    the apex height; every profile is a quintic smoothstep (zero velocity at lift-off and
    touchdown). With the ``stance`` sole centre (3,) [m] the horizontal path bows sideways, away
    from it, so that it passes the stance sole centre at least ``side_clearance`` [m] apart
    (:func:`swing_bow`; beyond the document).
    """
    s_h = smoothstep((tau - SWING_MOVE[0]) / (SWING_MOVE[1] - SWING_MOVE[0]))
    xy = start[:2] + (target[:2] - start[:2]) * s_h
    if stance is not None and side_clearance > 0.0:
        bow, s_pass = swing_bow(start, target, stance, side_clearance)
        if s_h <= s_pass:
            w = math.sin(0.5 * math.pi * s_h / s_pass) if s_pass > 0.0 else 1.0
        else:
            w = math.sin(0.5 * math.pi * (1.0 - s_h) / (1.0 - s_pass)) if s_pass < 1.0 else 1.0
        xy = xy + bow * w
    if tau < rise:
        z = start[2] + (apex - start[2]) * smoothstep(tau / rise)
    elif tau < descend:
        z = apex
    else:
        z = apex + (target[2] - apex) * smoothstep((tau - descend) / (1.0 - descend))
    return np.array([xy[0], xy[1], z]), s_h


def swing_bow(
    start: FloatArray, target: FloatArray, stance: FloatArray, clearance: float
) -> tuple[FloatArray, float]:
    """Sideways bow of a swing path that passes the stance sole centre too closely.

    The straight horizontal path ``start -> target`` passes ``stance`` (all (2,) or (3,) [m],
    horizontal parts used) at the share ``s`` in [0, 1] of its length where ``stance`` projects
    onto it, at the distance ``d``. When ``s`` is strictly inside the path and ``d <
    clearance``, the path must move ``clearance - d`` further from ``stance`` there, along the
    path's normal pointing away from it (the swing foot's side of the path when ``stance`` lies
    on it, the left of the path).
    :func:`swing_reference` adds ``bow * w(s_h)`` with ``w`` a quarter sine rising from 0 at the
    start to 1 at ``s`` and falling back to 0 at the target, so lift-off and touchdown points are
    unchanged.

    Returns:
        ``(bow (2,) [m], s)``: the bow at its peak (zero when none is needed) and where it peaks.
    """
    p0, p1, c = (np.asarray(v, dtype=float)[:2] for v in (start, target, stance))
    e = p1 - p0
    length = float(np.linalg.norm(e))
    if length < 1e-9:
        return np.zeros(2), 0.5
    u = e / length
    s = float((c - p0) @ u) / length
    if not 0.0 < s < 1.0:
        return np.zeros(2), min(max(s, 0.0), 1.0)
    normal = np.array([-u[1], u[0]])  # left of the path
    side = float((p0 - c) @ normal)
    d = abs(side)
    if d >= clearance:
        return np.zeros(2), s
    away = normal if side >= 0.0 else -normal
    return away * (clearance - d), s


def swing_shares(rise_height: float, fall_height: float, t_ss: float) -> tuple[float, float]:
    """Rise-until and descend-from shares of a swing that lifts the sole by ``rise_height`` and
    lowers it by ``fall_height`` [m] in ``t_ss`` [s].

    Each vertical motion takes at least ``SWING_SHARES[0]`` of the swing (the sole must clear the
    ground before it moves, else it scuffs) and longer when its quintic profile's peak
    acceleration ``5.77 h / T^2`` would exceed ``SWING_ACC_MAX``, up to half the swing (a swing
    leg lifted fast unloads the stance foot).
    """
    lo, hi = SWING_SHARES

    def share(h: float) -> float:
        need = math.sqrt(QUINTIC_PEAK_ACC * max(h, 0.0) / SWING_ACC_MAX) / t_ss
        return min(max(need, lo), hi)

    return share(rise_height), 1.0 - share(fall_height)


def terrain_height_along(
    regions: tuple[Region, ...],
    start: FloatArray,
    target: FloatArray,
    half_length: float,
    half_width: float,
) -> float:
    """Highest region surface under the sole swept from ``start`` to ``target`` [m].

    The swept area is approximated by the segment start -> target extended by ``half_length``
    at both ends (heel behind the start, toe beyond the target) and widened by ``half_width``
    on both sides: a region counts when a sample of the extended segment lies within
    ``half_width`` of it. (Widening by the half length as well would count blocks the toe never
    reaches, and a needlessly high swing's acceleration lifts the stance foot.)
    """
    d = target[:2] - start[:2]
    length = float(np.linalg.norm(d))
    u = d / length if length > 1e-9 else np.zeros(2)
    n_samples = max(16, math.ceil((length + 2.0 * half_length) / 0.01) + 1)
    pts = start[:2] + np.outer(np.linspace(-half_length, length + half_length, n_samples), u)
    best = max(float(start[2]), float(target[2]))
    for r in regions:
        near = np.asarray(r.signed_distance(pts)) <= half_width
        if np.any(near):
            best = max(best, float(np.max(r.height_at(pts[near]))))
    return best


class CoMHeight:
    """CoM height reference over the footsteps: the 3-D linear inverted pendulum's constraint planes.

    The CoM moves on the planes through the points ``P_j + (0, 0, z_H)`` above consecutive
    footsteps: between footsteps ``j`` and ``j + 1`` the plane rises with gradient
    ``g_j = (z_{j+1} - z_j) d_j / |d_j|^2`` (``d_j`` the horizontal step), level across it. Every
    plane used while standing on ``P_j`` (the one from the previous step behind the foot, the one
    to the next step ahead of it) passes through ``z_j + z_H`` above the stance foot, so the
    horizontal CoM motion is exactly the pendulum of height ``z_H`` of eq. (5.1) (Kajita et al.,
    2001: on such a plane the leg force along foot -> CoM adds no horizontal acceleration the ALIP
    does not have), and consecutive supports share the plane between their feet, so the height is
    continuous through double support. The kink above each footstep is rounded over
    ``+-kink`` [m] of progress, where the CoM is nearly above the foot and the vertical
    acceleration of the rounding hardly pushes it horizontally.

    A height that rises in *time* (from one mid single support to the next) pushes the CoM forward
    whenever it rises ahead of the stance foot, and the walk speeds up at every step-up.
    """

    def __init__(self, footsteps: FloatArray, z_h: float, kink: float = 0.05) -> None:
        p = np.asarray(footsteps, dtype=float)
        self.points = p
        self.z_h = float(z_h)
        self.kink = float(kink)
        n = p.shape[0]
        self.grad = np.zeros((n + 1, 2))  # grad[j + 1]: plane from footstep j to j + 1
        for j in range(n - 1):
            d = p[j + 1, :2] - p[j, :2]
            d2 = float(d @ d)
            if d2 > 1e-6:
                self.grad[j + 1] = (p[j + 1, 2] - p[j, 2]) * d / d2
        self.ahead = np.zeros((n, 2))  # walking direction through each footstep
        for j in range(n):
            d = p[min(j + 1, n - 1), :2] - p[max(j - 1, 0), :2]
            norm = float(np.linalg.norm(d))
            self.ahead[j] = d / norm if norm > 1e-6 else 0.0

    def __call__(self, support: int, c_xy: ArrayLike) -> float:
        """Reference CoM height [m] while standing on footstep ``support`` (0..N; in double
        support the footstep being stepped onto) with the horizontal CoM at ``c_xy`` (2,) [m]."""
        j = min(max(support, 0), self.points.shape[0] - 1)
        r = np.asarray(c_xy, dtype=float)[:2] - self.points[j, :2]
        w = smoothstep((float(r @ self.ahead[j]) + self.kink) / (2.0 * self.kink))
        slope = (1.0 - w) * self.grad[j] + w * self.grad[j + 1]
        return float(self.points[j, 2]) + self.z_h + float(slope @ r)


def ds_propagator(alip: ALIP, dt: float) -> FloatArray:
    """Exact one-tick map of [x (4); d (3); w (3)] for the double-support ALIP (eq. 5.8-5.10).

    The contact point moves by ``d`` (its displacement from the old foot) at constant velocity
    ``w``; measured from the old foot this is the single-support ALIP driven by ``E d``.
    """
    m = np.zeros((10, 10))
    m[:4, :4] = alip.A
    m[:4, 4:7] = alip.E
    m[4:7, 7:10] = np.eye(3)
    return np.asarray(expm(m * dt))


def pitch_about_y(angle: float) -> FloatArray:
    """Rotation (3, 3) by ``angle`` [rad] about the y axis (in a sole frame: toe down for > 0)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def blend_rot(r0: FloatArray, r1: FloatArray, s: float) -> FloatArray:
    """Rotation between ``r0`` (s = 0) and ``r1`` (s = 1) along the geodesic:
    ``r0 exp(s log(r0^T r1))``."""
    if s <= 0.0:
        return r0
    if s >= 1.0:
        return r1
    return np.asarray(r0 @ rotation_exp(s * rotation_log(r0.T @ r1)))
