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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

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

    def __post_init__(self) -> None:
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
        """Mass of one leg [kg]."""
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
        """Longest hip-to-foot distance, set by the knee's lower limit [m]."""
        return self._leg_length(max(0.0, self.joint_limits.lower[2]))

    @property
    def min_leg_length(self) -> float:
        """Shortest hip-to-foot distance, set by the knee's upper limit [m]."""
        return self._leg_length(self.joint_limits.upper[2])

    def hip_offset(self, leg: Leg) -> FloatArray:
        """Position of the leg frame origin in ``{B}``, shape (3,) [m]."""
        sx = 0.5 * self.hip_spacing_x * (1.0 if leg.is_front else -1.0)
        sy = 0.5 * self.hip_spacing_y * (1.0 if leg.is_left else -1.0)
        return np.array([sx, sy, 0.0])

    def hip_offsets(self) -> FloatArray:
        """Hip positions of all legs in ``{B}`` in ``LEGS`` order, shape (4, 3) [m]."""
        return np.stack([self.hip_offset(leg) for leg in LEGS])
