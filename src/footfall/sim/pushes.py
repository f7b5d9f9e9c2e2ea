"""External pushes, one type for every plant: a constant force pulse.

The reduced-order plant applies a push at the CoM (its horizontal part changes the angular
momentum about the contact point like the torque ``z_H (-F_y, F_x)``); the MuJoCo walker applies
it to the torso. Both use :class:`Push`, so a study can hand the same disturbance to either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import finite, finite_vector, non_negative, positive


@dataclass(frozen=True)
class Push:
    """A constant force pulse on the robot.

    Attributes:
        start: start time since the beginning of the walk [s], >= 0.
        duration: pulse length [s], > 0.
        force: world-frame force (3,) [N] during the pulse (read-only).
    """

    start: float
    duration: float
    force: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", non_negative("push.start", self.start))
        object.__setattr__(self, "duration", positive("push.duration", self.duration))
        f = finite_vector("push.force", self.force, 3)
        f.setflags(write=False)
        object.__setattr__(self, "force", f)

    @classmethod
    def horizontal(
        cls, start: float, impulse: float, direction: float = 0.0, duration: float = 0.1
    ) -> Push:
        """A horizontal push of ``impulse`` [N s] (>= 0) over ``duration`` [s], in the world
        direction ``direction`` [rad] (0 = +x): force ``impulse / duration`` along it."""
        impulse = non_negative("push.impulse", impulse)
        direction = finite("push.direction", direction)
        duration = positive("push.duration", duration)
        f = impulse / duration
        return cls(
            start, duration, np.array([f * math.cos(direction), f * math.sin(direction), 0.0])
        )

    @property
    def impulse(self) -> float:
        """Magnitude of the horizontal impulse [N s]."""
        return float(np.hypot(self.force[0], self.force[1])) * self.duration

    @property
    def end(self) -> float:
        """End time [s]."""
        return self.start + self.duration

    def to_dict(self) -> dict[str, object]:
        """Plain JSON data: start and duration [s], force [N], impulse [N s]."""
        return {
            "start": self.start,
            "duration": self.duration,
            "force": self.force.tolist(),
            "impulse": self.impulse,
        }

    def active(self, t: float) -> bool:
        """Whether the push acts at time ``t`` [s]."""
        return self.start <= t < self.start + self.duration
