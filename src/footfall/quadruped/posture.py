"""Body posture and support points on a slope, document 001 sec. 2 (eq. 9, fig. 5-7).

Three postures are compared by the document:

* ``HORIZONTAL`` (fig. 5): body level, legs vertical; the fore legs get short and the hind legs
  long (eq. 9), which eats the leg workspace on steep slopes.
* ``PARALLEL`` (fig. 6): body parallel to the slope, legs normal to it; the workspace is the flat
  ground one but the CoM projection moves towards the rear of the support polygon.
* ``COMPROMISE`` (fig. 7): body pitched by ``beta_B`` between 0 and ``beta_S``, the main support
  legs vertical so the CoM projection stays on the support polygon's midline.

Heights ``h`` are vertical distances [m] from a hip (or the body centre) down to the foot-centre
plane, the slope plane raised by the foot radius along its normal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import finite, positive
from footfall.errors import InputError
from footfall.quadruped.kinematics import body_rotation
from footfall.quadruped.robot import LEGS, Leg, QuadrupedRobot

#: steepest slope footfall accepts at all; beyond it tan(beta_S) blows up the geometry
MAX_SLOPE = math.radians(60.0)


class BodyPosture(str, Enum):
    """The three slope postures of sec. 2."""

    HORIZONTAL = "horizontal"
    PARALLEL = "parallel"
    COMPROMISE = "compromise"


def leg_heights_horizontal(l_b: float, h_b: float, beta_s: float) -> tuple[float, float]:
    """Fore and hind leg heights of a level body on a slope, eq. (9).

    Implements eq. (9) of document 001: ``h_F = h_B - l_B tan(beta_S) / 2`` and
    ``h_H = h_B + l_B tan(beta_S) / 2``.

    Args:
        l_b: body length l_B (hip to hip) [m].
        h_b: height of the body centre above the ground h_B [m].
        beta_s: slope angle beta_S [rad].

    Returns:
        ``(h_F, h_H)`` [m].
    """
    half = 0.5 * positive("l_b", l_b) * math.tan(finite("beta_s", beta_s))
    h = positive("h_b", h_b)
    return h - half, h + half


def leg_heights(l_b: float, h_b: float, beta_s: float, beta_b: float) -> tuple[float, float]:
    """Vertical fore and hind leg heights of a body pitched by ``beta_B`` on a slope (fig. 7).

    With vertical legs the fore hip is ``(l_B/2) cos(beta_B)`` ahead of the body centre, where the
    ground is ``(l_B/2) cos(beta_B) tan(beta_S)`` higher, and ``(l_B/2) sin(beta_B)`` above it:
    ``h_F = h_B + (l_B/2)(sin beta_B - cos beta_B tan beta_S)``, ``h_H`` with the opposite sign.
    For ``beta_B = 0`` this is eq. (9); for ``beta_B = beta_S`` both equal ``h_B``.

    Returns:
        ``(h_F, h_H)`` [m].
    """
    half = 0.5 * positive("l_b", l_b)
    d = half * (math.sin(beta_b) - math.cos(beta_b) * math.tan(beta_s))
    return h_b + d, h_b - d


@dataclass(frozen=True)
class SlopePosture:
    """A body posture on a slope and the nominal (neutral) foot positions it implies.

    Attributes:
        slope: slope angle beta_S [rad], the ground rising along +x of ``{W}``.
        body_pitch: body angle beta_B to the horizontal [rad], in [0, beta_S].
        height: vertical height h_B of the body centre above the foot-centre plane [m].
        mode: which of the document's postures (sets the leg direction).
    """

    slope: float
    body_pitch: float
    height: float
    mode: BodyPosture = BodyPosture.COMPROMISE

    def __post_init__(self) -> None:
        slope = finite("slope", self.slope)
        if abs(slope) > MAX_SLOPE:
            raise InputError("slope", slope, f"within +-{MAX_SLOPE:.3f} rad (60 deg)")
        pitch = finite("body_pitch", self.body_pitch)
        lo, hi = min(0.0, slope), max(0.0, slope)
        if not lo - 1e-12 <= pitch <= hi + 1e-12:
            raise InputError(
                "body_pitch",
                round(pitch, 6),
                f"within [0, slope] = [{lo:.4f}, {hi:.4f}] rad "
                f"([{math.degrees(lo):.2f}, {math.degrees(hi):.2f}] deg; negative downhill)",
            )
        object.__setattr__(self, "slope", slope)
        object.__setattr__(self, "body_pitch", pitch)
        object.__setattr__(self, "height", positive("height", self.height))
        object.__setattr__(self, "mode", BodyPosture(self.mode))

    @classmethod
    def of(
        cls, mode: BodyPosture, slope: float, height: float, body_pitch: float | None = None
    ) -> SlopePosture:
        """The posture ``mode`` on ``slope``; ``body_pitch`` is only used by COMPROMISE."""
        if mode is BodyPosture.HORIZONTAL:
            return cls(slope, 0.0, height, mode)
        if mode is BodyPosture.PARALLEL:
            return cls(slope, slope, height, mode)
        return cls(slope, slope / 2.0 if body_pitch is None else body_pitch, height, mode)

    @property
    def beta_delta(self) -> float:
        """Body-to-slope angle beta_Delta = beta_S - beta_B [rad] (eq. 13)."""
        return self.slope - self.body_pitch

    @property
    def slope_direction(self) -> FloatArray:
        """Unit vector up the slope in ``{W}``, shape (3,)."""
        return np.array([math.cos(self.slope), 0.0, math.sin(self.slope)])

    @property
    def slope_normal(self) -> FloatArray:
        """Unit normal of the slope in ``{W}``, shape (3,)."""
        return np.array([-math.sin(self.slope), 0.0, math.cos(self.slope)])

    def leg_direction(self) -> FloatArray:
        """Direction of a nominal stance leg from hip to foot in ``{W}``, shape (3,)."""
        if self.mode is BodyPosture.PARALLEL:
            return -self.slope_normal
        return np.array([0.0, 0.0, -1.0])

    def plane_height(self, x: float) -> float:
        """Height of the foot-centre plane at horizontal position x [m] (0 under the start)."""
        return x * math.tan(self.slope)

    def body_position(self, x: float = 0.0, y: float = 0.0) -> FloatArray:
        """Body centre in ``{W}`` at horizontal position (x, y), h_B above the plane, shape (3,)."""
        return np.array([x, y, x * math.tan(self.slope) + self.height])

    def neutral_feet(
        self, robot: QuadrupedRobot, body_pos: FloatArray, lateral_share: float = 1.0
    ) -> FloatArray:
        """Nominal foot centres for the body at ``body_pos``: each hip's ray along
        :meth:`leg_direction` meets the foot-centre plane (the hip moved out by
        ``lateral_share`` of the leg's lateral offset, :meth:`QuadrupedRobot.stance_offset`).
        Shape (4, 3) [m], ``LEGS`` order.
        """
        rot = body_rotation(self.body_pitch)
        d = self.leg_direction()
        n = self.slope_normal
        feet = np.empty((4, 3))
        for i, leg in enumerate(LEGS):
            hip = body_pos + rot @ robot.stance_offset(leg, lateral_share)
            # plane through the origin with normal n: n.(hip + s d) = 0
            s = -float(n @ hip) / float(n @ d)
            feet[i] = hip + s * d
        return feet

    def hip_heights(self, robot: QuadrupedRobot) -> dict[Leg, float]:
        """Vertical hip heights above the foot-centre plane per leg [m] (fig. 5-7)."""
        body = self.body_position()
        rot = body_rotation(self.body_pitch)
        out = {}
        for leg in LEGS:
            hip = body + rot @ robot.hip_offset(leg)
            out[leg] = float(hip[2] - hip[0] * math.tan(self.slope))
        return out
