"""When a MuJoCo plant counts a fall: one definition, one set of thresholds per kind of robot.

A robot has fallen when its body (a humanoid's torso, a quadruped's trunk) tilts more than
``tilt`` from its reference attitude (upright, or the planned pitch), when it drops below
``height_share`` of its nominal height above the ground under it, or when the body touches the
terrain. Each plant checks these once per control tick and reports the first fall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from footfall._validate import positive


@dataclass(frozen=True)
class FallCriteria:
    """Fall thresholds.

    Attributes:
        tilt: largest tilt of the body from its reference attitude [rad].
        height_share: lowest body height above the ground, as a share of its nominal height.
    """

    tilt: float
    height_share: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "tilt", positive("fall.tilt", self.tilt))
        object.__setattr__(self, "height_share", positive("fall.height_share", self.height_share))

    def fallen(self, tilt: float, height: float, nominal_height: float) -> bool:
        """Whether a body tilted by ``tilt`` [rad] at ``height`` [m] above the ground (nominally
        ``nominal_height``) has fallen (a touch of the terrain is checked by the plant)."""
        return tilt > self.tilt or height < self.height_share * nominal_height


#: humanoids: the pelvis below 60 % of its standing height above the stance sole, or the torso
#: tilted more than 40 deg from upright
HUMANOID_FALL = FallCriteria(tilt=math.radians(40.0), height_share=0.6)
#: quadrupeds: the trunk below half its planned height above the ground, or pitched more than
#: 30 deg from its planned pitch
QUADRUPED_FALL = FallCriteria(tilt=math.radians(30.0), height_share=0.5)
