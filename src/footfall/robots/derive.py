"""What footfall derives from a walker model's kinematics and inertia (needs ``footfall[sim]``).

Everything here is measured on the compiled walker model (:mod:`footfall.robots.build`) by
MuJoCo's forward kinematics and inverse kinematics by least squares inside the joint ranges:

- :func:`nominal_posture`: the standing posture: pelvis upright at the pelvis height above two flat
  soles ``stance_width`` apart, the whole-body CoM above the soles' midpoint.
- :func:`stance_feasible`: whether the legs hold a double-support stance (front sole at (dx, dy, dz)
  from the rear one, both flat and parallel, pelvis upright at the pelvis height above their mean
  height, the CoM between them) with every leg joint ``JOINT_MARGIN`` inside its range.
- :func:`derive_reach`: the step height h and the reach trapezoid (the planner's eq. 5.12f) whose
  corners are feasible at h up, level and h down, so that the planner's footsteps stay where the
  legs can put them whatever the step's height (the planner bounds length and height separately).
  Long steps and high steps trade against each other (a step down bends the rear ankle); h is the
  largest height (at most ``STEP_HEIGHT_CAP``) at which the legs still step ``MIN_STEP_SHARE`` of
  their length forward, and the reach is also capped at ``REACH_SHARE`` of the leg length (longer
  steps are a matter of the swing's dynamics, which the single-support time is sized for).
- :func:`best_pelvis_height`: the pelvis height whose worst double-support joint margin over a set
  of stances is largest (a low pelvis bends the rear ankle past its range on long steps, a high
  one cannot reach down).
- :func:`measure_leg`: the swing leg's inertia about its hip, the hip's height and torque limit.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from footfall._mjcf import require_mujoco
from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.models.biped import Side
from footfall.robots import names as nm

#: a leg joint must stay this far inside its range in a stance counted feasible [rad]
JOINT_MARGIN = 0.05
#: an IK solution is exact below this residual [m, rad]
IK_TOL = 1e-5
#: the highest step up and down derived [m] (the planner's default bound)
STEP_HEIGHT_CAP = 0.25
#: lateral gap kept between the soles' edges in the narrowest stance [m]
SOLE_GAP = 0.02
#: the derived step height still lets the legs step this share of their length forward
MIN_STEP_SHARE = 0.25
#: the reach goes at most this share of the leg length forward, back and out (footfall's biped:
#: 0.35 m forward on 0.74 m legs)
REACH_SHARE = 0.45
#: the stances (step length [m], step height [m]) :func:`best_pelvis_height` checks
PELVIS_STANCES = ((0.2, 0.0), (0.3, 0.0), (0.2, 0.1), (0.3, 0.1), (0.2, -0.1), (0.3, -0.1))


class Kinematics:
    """A compiled walker model with the handles inverse kinematics needs.

    Args:
        xml: the walker model's MJCF (:func:`footfall.robots.build.walker_xml`), no terrain.
    """

    def __init__(self, xml: str) -> None:
        mujoco = require_mujoco()
        self.mj = mujoco
        self.model = m = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(m)
        obj = mujoco.mjtObj
        sides = (Side.LEFT, Side.RIGHT)
        self.jid = [
            mujoco.mj_name2id(m, obj.mjOBJ_JOINT, nm.joint(s, j))
            for s in sides
            for j in nm.LEG_JOINTS
        ]
        self.adr = np.array([m.jnt_qposadr[j] for j in self.jid])
        self.range = np.array(m.jnt_range[self.jid], dtype=float)
        self.sites = [mujoco.mj_name2id(m, obj.mjOBJ_SITE, nm.sole_site(s)) for s in sides]
        self.pelvis = mujoco.mj_name2id(m, obj.mjOBJ_BODY, nm.PELVIS_BODY)
        root = mujoco.mj_name2id(m, obj.mjOBJ_JOINT, nm.ROOT_JOINT)
        self.root = int(m.jnt_qposadr[root])

    def pose(self, q: FloatArray, base: FloatArray) -> None:
        """Leg joints ``q`` (12,) [rad], the pelvis upright at ``base`` (3,) [m]."""
        d = self.data
        d.qpos[:] = 0.0
        d.qpos[self.root : self.root + 3] = base
        d.qpos[self.root + 3] = 1.0
        d.qpos[self.adr] = q
        self.mj.mj_kinematics(self.model, d)
        self.mj.mj_comPos(self.model, d)

    def soles(self) -> list[tuple[FloatArray, FloatArray]]:
        """Position (3,) and rotation (3, 3) of the left and right sole sites."""
        d = self.data
        return [(d.site_xpos[s].copy(), d.site_xmat[s].reshape(3, 3).copy()) for s in self.sites]

    def com(self) -> FloatArray:
        """Whole-body CoM (3,) [m]."""
        return np.array(self.data.subtree_com[self.pelvis])

    def solve(
        self,
        targets: Sequence[FloatArray],
        height: float,
        q0: FloatArray,
        margin: float = JOINT_MARGIN,
    ) -> tuple[FloatArray, FloatArray, float]:
        """Joints (12,) and the pelvis position (3,) [m] with both soles flat and facing +x at
        ``targets`` (left, right; (3,) [m]), the pelvis upright ``height`` above their mean
        height and the CoM above their midpoint, every joint ``margin`` inside its range:
        ``(q, pelvis, residual)``.
        """
        from scipy.optimize import least_squares

        mid = 0.5 * (targets[0] + targets[1])
        z = float(mid[2] + height)

        def residual(u: FloatArray) -> FloatArray:
            self.pose(u[:12], np.array([u[12], u[13], z]))
            r: list[float] = []
            for (pos, rot), target in zip(self.soles(), targets, strict=True):
                r += [*(pos - target), rot[2, 0], rot[2, 1], rot[1, 0]]
            c = self.com()
            r += [c[0] - mid[0], c[1] - mid[1]]
            return np.array(r)

        lo = np.r_[self.range[:, 0] + margin, mid[0] - 1.0, mid[1] - 1.0]
        hi = np.r_[self.range[:, 1] - margin, mid[0] + 1.0, mid[1] + 1.0]
        if np.any(lo[:12] >= hi[:12]):
            raise InputError(
                "joint ranges", self.range.tolist(), f"ranges wider than {2 * margin} rad"
            )
        u0 = np.clip(np.r_[q0, mid[0], mid[1]], lo, hi)
        sol = least_squares(residual, u0, bounds=(lo, hi), xtol=1e-12, ftol=1e-12, gtol=1e-12)
        res = float(np.max(np.abs(residual(sol.x))))
        return sol.x[:12], np.array([sol.x[12], sol.x[13], z]), res


def nominal_posture(kin: Kinematics, height: float, stance_width: float) -> FloatArray:
    """Leg joints (12,) [rad] of the standing posture (module docstring), left then right leg in
    ``LEG_JOINTS`` order.

    Raises:
        InputError: no such posture within the joint ranges.
    """
    targets = [np.array([0.0, s.sign * stance_width / 2, 0.0]) for s in (Side.LEFT, Side.RIGHT)]
    q0 = _bent_knees(kin)
    q, _, res = kin.solve(targets, height, q0, margin=0.0)
    if res > IK_TOL:
        raise InputError(
            "pelvis_height / stance_width",
            (height, stance_width),
            f"a posture the legs reach with flat soles (residual {res:.2g})",
        )
    return q


def _bent_knees(kin: Kinematics) -> FloatArray:
    """A start for the solver: knees bent forward, hips and ankles compensating."""
    q = np.zeros(12)
    for leg in (0, 6):
        q[leg + 2], q[leg + 3], q[leg + 4] = -0.3, 0.6, -0.3
    return np.clip(q, kin.range[:, 0], kin.range[:, 1])


def stance_feasible(
    kin: Kinematics, dx: float, dy: float, dz: float, height: float, q0: FloatArray
) -> bool:
    """Whether the double support with the left sole at (dx, dy, dz) [m] from the right one is
    held within the joint ranges (module docstring)."""
    targets = [np.array([dx / 2, dy / 2, dz / 2]), np.array([-dx / 2, -dy / 2, -dz / 2])]
    _, _, res = kin.solve(targets, height, q0)
    return res <= IK_TOL


@dataclass(frozen=True)
class Reach:
    """Derived step limits.

    Attributes:
        vertices: the reach trapezoid (4, 2) [m] for a right stance foot (the planner's
            ``ReachTrapezoid``): inner edge at ``y_in``, outer edge at ``y_out``.
        step_height_max: the largest step up and down [m].
    """

    vertices: tuple[tuple[float, float], ...]
    step_height_max: float


def _feasible_all(
    kin: Kinematics, dx: float, dy: float, heights: Sequence[float], height: float, q0: FloatArray
) -> bool:
    return all(stance_feasible(kin, dx, dy, dz, height, q0) for dz in heights)


def _edge(
    kin: Kinematics,
    dy: float,
    heights: Sequence[float],
    height: float,
    q0: FloatArray,
    sign: float,
    limit: float,
) -> float:
    """The farthest dx in direction ``sign`` (up to ``limit``) feasible at every height: from 0
    outward in 2 cm steps, refined by bisection."""
    step, x = 0.02, 0.0
    while abs(x) + step <= limit and _feasible_all(kin, x + sign * step, dy, heights, height, q0):
        x += sign * step
    lo, hi = x, x + sign * step
    for _ in range(4):
        mid = 0.5 * (lo + hi)
        if abs(mid) <= limit and _feasible_all(kin, mid, dy, heights, height, q0):
            lo = mid
        else:
            hi = mid
    return lo


def derive_reach(
    kin: Kinematics, height: float, stance_width: float, sole_width: float, leg_length: float
) -> Reach:
    """The step height and reach trapezoid of the module docstring.

    ``leg_length``: the pelvis's height above the soles with straight legs [m].

    Raises:
        InputError: not even the nominal stance is held h = 0 (the model cannot stand).
    """
    q0 = nominal_posture(kin, height, stance_width)
    if not stance_feasible(kin, 0.0, stance_width, 0.0, height, q0):
        raise InputError("stance_width", stance_width, "a stance the legs hold with joint margins")
    # the largest step height at which a step of MIN_STEP_SHARE of the leg is held up and down
    step = MIN_STEP_SHARE * leg_length

    def holds(h: float) -> bool:
        return _feasible_all(kin, step, stance_width, (h, 0.0, -h), height, q0)

    if not holds(0.0):
        raise InputError(
            "pelvis_height", height, f"a posture from which the legs step {step:.2f} m forward"
        )
    lo, hi = 0.0, STEP_HEIGHT_CAP
    if holds(hi):
        lo = hi
    else:
        for _ in range(7):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if holds(mid) else (lo, mid)
    h = math.floor(lo * 100.0) / 100.0  # whole centimetres, rounded down
    heights = (h, 0.0, -h) if h > 0 else (0.0,)
    limit = REACH_SHARE * leg_length
    y_in = max(sole_width + SOLE_GAP, min(stance_width, 0.12))
    # the outer edge: the widest stance held straight beside the stance foot, up to the cap
    y_out = stance_width
    while y_out + 0.02 <= limit and _feasible_all(kin, 0.0, y_out + 0.02, heights, height, q0):
        y_out += 0.02
    y_out = max(y_out, stance_width + 0.02)
    corners = []
    for y in (y_in, y_out):
        corners.append(
            (
                _edge(kin, y, heights, height, q0, -1.0, limit),
                _edge(kin, y, heights, height, q0, 1.0, limit),
            )
        )
    (b_in, f_in), (b_out, f_out) = corners
    vertices = ((b_in, y_in), (f_in, y_in), (f_out, y_out), (b_out, y_out))
    return Reach(tuple((round(x, 3), round(y, 3)) for x, y in vertices), h)


def best_pelvis_height(
    xml_at: Any,
    heights: Sequence[float],
    stance_width: float,
    stances: Sequence[tuple[float, float]] = PELVIS_STANCES,
) -> float:
    """Of ``heights`` [m], the pelvis height whose worst joint margin over ``stances`` (step
    length, step height) is largest; ``xml_at(height)`` is the walker model's MJCF.

    Raises:
        InputError: no height holds every stance.
    """
    best, best_margin = math.nan, -math.inf
    kin = Kinematics(xml_at(heights[0]))
    for h in heights:
        try:
            q0 = nominal_posture(kin, h, stance_width)
        except InputError:
            continue
        worst = math.inf
        for length, dz in stances:
            targets = [
                np.array([length / 2, stance_width / 2, dz / 2]),
                np.array([-length / 2, -stance_width / 2, -dz / 2]),
            ]
            q, _, res = kin.solve(targets, h, q0, margin=-1.0)  # solve past the ranges ...
            if res > IK_TOL:
                worst = -math.inf
                break
            # ... and measure how far inside (or outside) them the legs are
            margin = float(np.min(np.minimum(q - kin.range[:, 0], kin.range[:, 1] - q)))
            worst = min(worst, margin)
        if worst > best_margin:
            best, best_margin = h, worst
    if not math.isfinite(best):
        raise InputError(
            "pelvis_height", list(heights), "a height at which the legs hold the stances"
        )
    return float(best)


@dataclass(frozen=True)
class LegInfo:
    """The swing leg at the nominal posture, measured by MuJoCo.

    Attributes:
        inertia: the leg's inertia about its hip pitch axis with the pelvis held [kg m^2] (the
            hip pitch entry of the joint-space inertia matrix).
        hip_height: hip pitch axis above the sole [m].
        hip_torque: the hip pitch actuator's torque limit [N m] (inf: none).
        mass: the leg's mass [kg].
        ankle_torque: the ankle (pitch, roll) actuators' torque limits [N m] (inf: none).
    """

    inertia: float
    hip_height: float
    hip_torque: float
    mass: float
    ankle_torque: tuple[float, float]


def measure_leg(kin: Kinematics, q: FloatArray, pelvis_height: float) -> LegInfo:
    """The left leg's :class:`LegInfo` with the joints at ``q`` (12,) and the pelvis upright
    ``pelvis_height`` above the soles."""
    mj, m, d = kin.mj, kin.model, kin.data
    kin.pose(q, np.array([0.0, 0.0, pelvis_height]))
    mj.mj_forward(m, d)
    mass_matrix = np.zeros((m.nv, m.nv))
    mj.mj_fullM(m, d, mass_matrix)
    hip = kin.jid[nm.LEG_JOINTS.index("hip_pitch")]
    dof = int(m.jnt_dofadr[hip])
    sole = kin.sites[0]

    def limit(joint: str) -> float:
        a = mj.mj_name2id(m, mj.mjtObj.mjOBJ_ACTUATOR, nm.actuator(Side.LEFT, joint))
        return float(m.actuator_forcerange[a, 1]) if m.actuator_forcelimited[a] else math.inf

    b = int(m.site_bodyid[sole])
    while int(m.body_parentid[b]) != kin.pelvis:
        b = int(m.body_parentid[b])
    return LegInfo(
        inertia=float(mass_matrix[dof, dof]),
        hip_height=float(d.xanchor[hip][2] - d.site_xpos[sole][2]),
        hip_torque=limit("hip_pitch"),
        mass=float(m.body_subtreemass[b]),
        ankle_torque=(limit("ankle_pitch"), limit("ankle_roll")),
    )
