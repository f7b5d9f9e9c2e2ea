"""The quadruped robot of document 001 as one frozen parameter set.

Frames (document 001, sec. 1.1 and fig. 1):

* ``{B}``: body frame at the body's geometric centre, x forward, z up, y by the right-hand rule.
* ``{W}``: world (global reference) frame; z is vertical (against gravity). footfall places its
  origin on the slope surface under the initial body centre, x pointing up the slope's horizontal
  direction.
* ``{LF}``, ``{RF}``, ``{RH}``, ``{LH}``: one frame per leg at the hip (the point where the hip
  ab/adduction and hip pitch axes meet), axes parallel to ``{B}``.

Each leg has three joints: hip ab/adduction about the leg frame's x axis, hip pitch about y, knee
about y. At zero angles the leg hangs straight down along -z.

A robot loaded from its model (:mod:`footfall.robots.quadruped`) has the same three axes but
offsets between them: :class:`LegGeometry` holds one leg's joint points, axis signs, limits and
link inertias, as the model has them at zero joint angles; the document's robot is the special
case of no offsets (:meth:`QuadrupedRobot.leg_geometry`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from footfall._mjcf import rod_inertia
from footfall._typing import FloatArray
from footfall._validate import check_fields, finite_vector, positive
from footfall.errors import InputError


class Leg(str, Enum):
    """Legs, numbered 1-4 in the document's order LF, RF, RH, LH (sec. 1.1)."""

    LF = "LF"
    RF = "RF"
    RH = "RH"
    LH = "LH"

    @property
    def idx(self) -> int:
        """0-based position in the document's numbering (LF=0, RF=1, RH=2, LH=3)."""
        return LEGS.index(self)

    @property
    def is_front(self) -> bool:
        """True for the fore legs LF and RF."""
        return self in (Leg.LF, Leg.RF)

    @property
    def is_left(self) -> bool:
        """True for the left legs LF and LH."""
        return self in (Leg.LF, Leg.LH)


#: the document's leg numbering 1..4 (sec. 1.1)
LEGS: tuple[Leg, ...] = (Leg.LF, Leg.RF, Leg.RH, Leg.LH)

#: joint order inside one leg
JOINT_NAMES: tuple[str, ...] = ("hip_abad", "hip_pitch", "knee")
#: slice of one leg's joints inside the 12-vector of joint angles ordered by ``LEGS``
N_LEG_JOINTS = 3


@dataclass(frozen=True)
class JointLimits:
    """Lower and upper angle of the three leg joints [rad], in ``JOINT_NAMES`` order.

    The knee angle is positive when the knee points forward (see :mod:`kinematics`). The knee's
    lower limit keeps the leg from straightening into the singular (locked-knee) pose; it sets
    the usable leg length :attr:`QuadrupedRobot.max_leg_length`.
    """

    lower: tuple[float, float, float] = (-0.6, -1.8, 0.5)
    upper: tuple[float, float, float] = (0.6, 1.8, 2.7)

    def __post_init__(self) -> None:
        lo = finite_vector("joint_limits.lower", self.lower, 3)
        hi = finite_vector("joint_limits.upper", self.upper, 3)
        if np.any(lo >= hi):
            raise InputError("joint_limits", (self.lower, self.upper), "lower < upper per joint")
        object.__setattr__(self, "lower", tuple(float(v) for v in lo))
        object.__setattr__(self, "upper", tuple(float(v) for v in hi))


@dataclass(frozen=True)
class LegGeometry:
    """One leg as a chain of three joints (ab/ad about x, pitch about y, knee about y), at zero
    joint angles, in ``{B}`` axes [m, kg, rad].

    The foot in the leg frame (origin ``origin``, axes of ``{B}``) is

        p = R_x(t1) (hfe + R_y(t2) (knee + R_y(t3) foot)),    t = signs * q,

    where ``q`` are the model's joint angles (a joint turning about -x or -y has sign -1).

    Attributes:
        origin: leg-frame origin in ``{B}``: the point of the ab/ad axis level with the pitch axis
            (shape (3,)).
        hfe: the pitch axis' point from ``origin`` (its x is 0), shape (3,).
        knee: the knee axis' point from the pitch axis' point, shape (3,).
        foot: the foot centre from the knee axis' point, shape (3,).
        signs: +1 or -1 per joint: the model's angle is ``signs * t``, shape (3,).
        lower, upper: the model's joint limits [rad], shape (3,) each.
        branch: +1 or -1: which of the two knee bends the leg uses (the sign of ``t3`` minus the
            knee's straight-leg angle).
        masses: masses of the ab/ad link, the thigh and the shank with the foot [kg], shape (3,).
        coms: their centres of mass from ``origin``, the pitch point and the knee point, (3, 3).
        inertias: their inertia about their centre of mass in ``{B}`` axes (xx, yy, zz, xy, xz,
            yz) [kg m^2], shape (3, 6).
        torque: the joints' torque limits [N m], shape (3,) (None: the simulation's setting).
        joints: the model's joint names (empty for the document's robot).
    """

    origin: tuple[float, float, float]
    hfe: tuple[float, float, float]
    knee: tuple[float, float, float]
    foot: tuple[float, float, float]
    signs: tuple[float, float, float]
    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    branch: float
    masses: tuple[float, float, float]
    coms: tuple[tuple[float, float, float], ...]
    inertias: tuple[tuple[float, ...], ...]
    torque: tuple[float, float, float] | None = None
    joints: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name in ("origin", "hfe", "knee", "foot", "lower", "upper", "masses"):
            v = finite_vector(f"leg.{name}", getattr(self, name), 3)
            object.__setattr__(self, name, tuple(float(x) for x in v))
        if any(abs(s) != 1.0 for s in self.signs) or abs(self.branch) != 1.0:
            raise InputError("leg.signs", (self.signs, self.branch), "+1 or -1 each")
        if any(lo >= hi for lo, hi in zip(self.lower, self.upper, strict=True)):
            raise InputError("leg.limits", (self.lower, self.upper), "lower < upper per joint")
        if any(m <= 0.0 for m in self.masses):
            raise InputError("leg.masses", self.masses, "positive link masses [kg]")
        if abs(self.hfe[0]) > 1e-9:
            raise InputError("leg.hfe", self.hfe, "a pitch point level with the origin (x = 0)")
        coms = np.asarray(self.coms, dtype=float)
        ins = np.asarray(self.inertias, dtype=float)
        if (
            coms.shape != (3, 3)
            or ins.shape != (3, 6)
            or not (np.all(np.isfinite(coms)) and np.all(np.isfinite(ins)))
        ):
            raise InputError("leg.coms", coms.shape, "finite (3, 3) centres and (3, 6) inertias")
        object.__setattr__(self, "coms", tuple(tuple(float(x) for x in r) for r in coms))
        object.__setattr__(self, "inertias", tuple(tuple(float(x) for x in r) for r in ins))
        if self.torque is not None:
            tq = finite_vector("leg.torque", self.torque, 3)
            if np.any(tq <= 0.0):
                raise InputError("leg.torque", self.torque, "positive torque limits [N m]")
            object.__setattr__(self, "torque", tuple(float(x) for x in tq))

    @property
    def lateral(self) -> float:
        """Sideways offset of the foot from the ab/ad axis, at zero ab/ad angle [m]."""
        return self.hfe[1] + self.knee[1] + self.foot[1]

    @property
    def mass(self) -> float:
        """Mass of the leg [kg]."""
        return float(sum(self.masses))

    def sagittal_lengths(self, samples: int = 721) -> tuple[float, float]:
        """Shortest and longest pitch-point-to-foot distance in the leg's plane over the knee's
        limits [m] (sampled every ``(upper - lower) / (samples - 1)``)."""
        t3 = self.signs[2] * np.linspace(self.lower[2], self.upper[2], samples)
        k, f = np.asarray(self.knee)[[0, 2]], np.asarray(self.foot)[[0, 2]]
        c, s = np.cos(t3), np.sin(t3)
        x = k[0] + c * f[0] + s * f[1]
        z = k[1] - s * f[0] + c * f[1]
        r = np.hypot(x, z)
        return float(r.min()), float(r.max())


@dataclass(frozen=True)
class QuadrupedRobot:
    """Geometric and inertial parameters of a 12-DoF quadruped (default: document 001 prototype).

    The default values follow sec. 4: body 1000 mm x 500 mm, about 100 kg in total, initial leg
    length 600 mm; the hip spacing 836 mm is the body length ``l_B`` used for fig. 8. Link
    lengths and masses are not given by the document; footfall chooses 0.45 m links so that the
    600 mm stance leaves room for a 400 mm step on 20 degree slopes.

    Attributes:
        body_length: body box length along x [m].
        body_width: body box width along y [m].
        body_height: body box height along z [m].
        hip_spacing_x: distance between fore and hind hips along x, ``l_B`` of eq. (9) [m].
        hip_spacing_y: distance between left and right hips along y [m].
        thigh_length: hip-pitch axis to knee axis [m].
        shank_length: knee axis to foot centre [m].
        foot_radius: radius of the spherical foot [m].
        body_mass: trunk mass (pumps, engine, batteries of the hydraulic prototype) [kg].
        thigh_mass: mass of one thigh [kg].
        shank_mass: mass of one shank including the foot [kg].
        hip_mass: mass of one hip ab/ad housing, lumped at the hip [kg].
        stance_height: initial leg length / body-centre height above the ground ``h_B`` [m].
        joint_limits: limits of the three leg joints (the knee's bound the usable leg length).
        legs: the four legs' geometry in ``LEGS`` order, for a robot loaded from its model (None:
            the document's legs, built from the fields above). The scalar leg fields are then
            only nominal (messages, scales): kinematics, masses and limits come from ``legs``.
        body_com: the trunk's centre of mass in ``{B}`` [m] (the body centre for the document's).
        body_inertia: the trunk's inertia about its centre of mass in ``{B}`` axes (xx, yy, zz,
            xy, xz, yz) [kg m^2] (None: a solid box of the body's size).
        name: the robot's name (``document``: document 001's prototype).
    """

    body_length: float = 1.0
    body_width: float = 0.5
    body_height: float = 0.2
    hip_spacing_x: float = 0.836
    hip_spacing_y: float = 0.5
    thigh_length: float = 0.45
    shank_length: float = 0.45
    foot_radius: float = 0.03
    body_mass: float = 80.0
    thigh_mass: float = 2.5
    shank_mass: float = 1.5
    hip_mass: float = 1.0
    stance_height: float = 0.6
    joint_limits: JointLimits = field(default_factory=JointLimits)
    legs: tuple[LegGeometry, ...] | None = None
    body_com: tuple[float, float, float] = (0.0, 0.0, 0.0)
    body_inertia: tuple[float, ...] | None = None
    name: str = "document"

    def __post_init__(self) -> None:
        if self.legs is not None:
            legs = tuple(self.legs)
            if len(legs) != len(LEGS) or not all(isinstance(g, LegGeometry) for g in legs):
                raise InputError(
                    "robot.legs", len(legs), "four LegGeometry in LF, RF, RH, LH order"
                )
            object.__setattr__(self, "legs", legs)
        com = finite_vector("robot.body_com", self.body_com, 3)
        object.__setattr__(self, "body_com", tuple(float(v) for v in com))
        if self.body_inertia is not None:
            bi = finite_vector("robot.body_inertia", self.body_inertia, 6)
            object.__setattr__(self, "body_inertia", tuple(float(v) for v in bi))
        check_fields(
            self,
            positive,
            (
                "body_length",
                "body_width",
                "body_height",
                "hip_spacing_x",
                "hip_spacing_y",
                "thigh_length",
                "shank_length",
                "foot_radius",
                "body_mass",
                "thigh_mass",
                "shank_mass",
                "hip_mass",
                "stance_height",
            ),
            prefix="robot.",
        )
        if self.stance_height >= self.max_leg_length:
            raise InputError(
                "robot.stance_height",
                self.stance_height,
                f"< usable leg length {self.max_leg_length:.3f} m",
            )
        if self.min_leg_length >= self.stance_height:
            raise InputError(
                "robot.stance_height",
                self.stance_height,
                f"> shortest leg length {self.min_leg_length:.3f} m (knee limit)",
            )

    @property
    def leg_mass(self) -> float:
        """Mass of one leg [kg] (the mean of the four for a robot loaded from its model)."""
        if self.legs is not None:
            return float(np.mean([g.mass for g in self.legs]))
        return self.hip_mass + self.thigh_mass + self.shank_mass

    @property
    def total_mass(self) -> float:
        """Whole-robot mass M [kg]."""
        return self.body_mass + 4.0 * self.leg_mass

    def _leg_length(self, knee: float) -> float:
        l1, l2 = self.thigh_length, self.shank_length
        return math.sqrt(l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * math.cos(knee))

    @property
    def max_leg_length(self) -> float:
        """Longest hip-to-foot distance, set by the knee's lower limit [m] (the shortest of the
        four legs' longest)."""
        if self.legs is not None:
            return min(g.sagittal_lengths()[1] for g in self.legs)
        return self._leg_length(max(0.0, self.joint_limits.lower[2]))

    @property
    def min_leg_length(self) -> float:
        """Shortest hip-to-foot distance, set by the knee's upper limit [m] (the longest of the
        four legs' shortest)."""
        if self.legs is not None:
            return max(g.sagittal_lengths()[0] for g in self.legs)
        return self._leg_length(self.joint_limits.upper[2])

    def leg_geometry(self, leg: Leg) -> LegGeometry:
        """The geometry of ``leg``: the model's, or the document's legs built from the fields."""
        if self.legs is not None:
            return self.legs[leg.idx]
        return _document_legs(self)[leg.idx]

    def hip_offset(self, leg: Leg) -> FloatArray:
        """Position of the leg frame origin in ``{B}``, shape (3,) [m]."""
        if self.legs is not None:
            return np.array(self.legs[leg.idx].origin)
        sx = 0.5 * self.hip_spacing_x * (1.0 if leg.is_front else -1.0)
        sy = 0.5 * self.hip_spacing_y * (1.0 if leg.is_left else -1.0)
        return np.array([sx, sy, 0.0])

    def stance_offset(self, leg: Leg, share: float = 1.0) -> FloatArray:
        """The point of ``{B}`` the neutral stance's foot lies under: the leg frame origin moved
        sideways by ``share`` of the leg's lateral offset (1: under a vertical leg), shape (3,)
        [m] (the hip itself for the document's robot, which has no offset)."""
        if self.legs is None:
            return self.hip_offset(leg)
        return self.hip_offset(leg) + np.array([0.0, share * self.legs[leg.idx].lateral, 0.0])

    def hip_offsets(self) -> FloatArray:
        """Hip positions of all legs in ``{B}`` in ``LEGS`` order, shape (4, 3) [m]."""
        return np.stack([self.hip_offset(leg) for leg in LEGS])


#: link radii of the document robot's MuJoCo model [m]: hip sphere, thigh and shank rods
DOCUMENT_LINK_RADII = (0.06, 0.035, 0.028)


@functools.lru_cache(maxsize=32)
def _document_legs(robot: QuadrupedRobot) -> tuple[LegGeometry, ...]:
    """The document robot's legs: no offsets, masses at the hip and the link midpoints."""
    l1, l2 = robot.thigh_length, robot.shank_length
    hip_i = 0.4 * robot.hip_mass * DOCUMENT_LINK_RADII[0] ** 2
    out = []
    for leg in LEGS:
        origin = robot.hip_offset(leg)
        out.append(
            LegGeometry(
                origin=(float(origin[0]), float(origin[1]), float(origin[2])),
                hfe=(0.0, 0.0, 0.0),
                knee=(0.0, 0.0, -l1),
                foot=(0.0, 0.0, -l2),
                signs=(1.0, 1.0, 1.0),
                lower=robot.joint_limits.lower,
                upper=robot.joint_limits.upper,
                branch=1.0,
                masses=(robot.hip_mass, robot.thigh_mass, robot.shank_mass),
                coms=((0.0, 0.0, 0.0), (0.0, 0.0, -l1 / 2), (0.0, 0.0, -l2 / 2)),
                inertias=(
                    (hip_i, hip_i, hip_i, 0.0, 0.0, 0.0),
                    (*rod_inertia(robot.thigh_mass, l1, DOCUMENT_LINK_RADII[1]), 0.0, 0.0, 0.0),
                    (*rod_inertia(robot.shank_mass, l2, DOCUMENT_LINK_RADII[2]), 0.0, 0.0, 0.0),
                ),
            )
        )
    return tuple(out)
