"""State the MuJoCo biped's walking loop carries from one control tick to the next.

:class:`~footfall.sim.biped.walk.BipedWalk` keeps each concern in one small object: where the feet
are (:class:`FeetState`), the current single support and its swing path (:class:`SwingState`),
the ALIP reference (:class:`ReferenceState`, eq. 5.1, 5.5, 5.8-5.10), the actuators' modes and
last set points (:class:`ActuationState`); the measurements are a
:class:`~footfall.results.walk.WalkTrace`. Per tick,
:class:`Observation` is what the robot measured and :class:`Command` what the schedule asks of the
whole body.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.models.biped import Side
from footfall.sim.biped.references import SWING_SHARES

#: sole targets of the IK: position (3,) [m] and rotation (3, 3) per side
SolePoses = dict[Side, tuple[FloatArray, FloatArray]]


@dataclass
class FeetState:
    """Where each foot is (sole centre (3,) [m], measured at its last touchdown) and its sole
    rotation (3, 3) (the planned one, on its region's plane at its heading)."""

    pos: dict[Side, FloatArray]
    rot: dict[Side, FloatArray]


@dataclass
class SwingState:
    """The current single support: its phase index (-1 before the first), the stance side, and the
    swing sole's path: start pose, apex height [m] and the rise / descend shares of T_ss
    (:func:`~footfall.sim.biped.references.swing_reference`)."""

    stance: Side
    start: FloatArray
    rot0: FloatArray
    phase: int = -1
    apex: float = 0.0
    rise: float = SWING_SHARES[0]
    descend: float = 1.0 - SWING_SHARES[0]
    #: the target (3,) [m] the apex was set for
    apex_for: FloatArray = field(default_factory=lambda: np.zeros(3))
    #: the target (3,) [m] the swing path heads for (rate-limited toward the MPC's footstep)
    target: FloatArray = field(default_factory=lambda: np.zeros(3))
    #: the landing sole's rotation (3, 3): on the next footstep's plane, along its heading
    rot1: FloatArray = field(default_factory=lambda: np.eye(3))
    #: ``rot1`` pitched for the heel strike, the swing's end orientation (3, 3)
    rot1_strike: FloatArray = field(default_factory=lambda: np.eye(3))
    #: the swing path's progress share and the step time [s] (on the moved clock) when its
    #: touchdown last moved forward (the MPC's step timing; 0.0 and 0.0: never): from there
    #: the path runs to its end by T_ss on the moved clock
    tau0: float = 0.0
    tp0: float = 0.0


@dataclass
class ReferenceState:
    """The ALIP reference.

    Attributes:
        x: ALIP state (4,) relative to the current stance contact point (eq. 5.1).
        prev_stance: the stance sole centre (3,) [m] of the last single support.
        ds_aug: double-support state ``[x (4); d (3); w (3)]`` (eq. 5.8-5.10,
            :func:`~footfall.sim.biped.references.ds_propagator`).
        stop_from: measured CoM (2,) [m] when the stop begins.
        stop_vel: measured CoM velocity (2,) [m/s] when the stop begins.
    """

    prev_stance: FloatArray
    x: FloatArray = field(default_factory=lambda: np.zeros(4))
    ds_aug: FloatArray = field(default_factory=lambda: np.zeros(10))
    stop_from: FloatArray = field(default_factory=lambda: np.zeros(2))
    stop_vel: FloatArray = field(default_factory=lambda: np.zeros(2))


@dataclass
class ActuationState:
    """Actuators between ticks.

    Attributes:
        ankle_mode: per side, whether its ankle is torque-driven.
        ctrl_prev: last tick's actuator commands (12,) (set points [rad] or torques [N m]).
        pos_prev: which actuators were position servoed last tick (12,).
        ankle_u: the adjuster's ALIP ankle torque (2,) [N m] of the last single-support tick.
        landed_in: the single support in which the swing sole touched down early (-1: none).
    """

    ankle_mode: dict[Side, bool]
    ctrl_prev: FloatArray
    pos_prev: NDArray[np.bool_]
    ankle_u: FloatArray = field(default_factory=lambda: np.zeros(2))
    landed_in: int = -1


@dataclass(frozen=True)
class Observation:
    """What the robot measured at the start of a tick: CoM (3,) [m], its velocity (3,) [m/s], the
    angular momentum about it (3,), each foot's contact points and forces, a body-hit flag."""

    com: FloatArray
    vel: FloatArray
    l_g: FloatArray
    contacts: dict[Side, tuple[FloatArray, FloatArray]]
    body_hit: bool


@dataclass
class Command:
    """What the schedule asks of the whole body this tick.

    Attributes:
        com_ref: reference CoM (3,) [m].
        feet: sole targets per side.
        yaw: torso yaw [rad].
        walking: inside the stepping window (after the shift, before the stop).
        phase: the step index i while walking (-1 otherwise).
        tp: time since the start of step i [s] while walking.
        single: in single support (``walking`` and ``tp < T_ss``).
    """

    com_ref: FloatArray
    feet: SolePoses
    yaw: float
    walking: bool = False
    phase: int = -1
    tp: float = 0.0
    single: bool = False
