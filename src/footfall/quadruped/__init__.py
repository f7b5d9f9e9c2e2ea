"""Quadruped walk gait on slopes from ZMP theory (document 001).

Robot model and closed-form leg kinematics, the ZMP stability criterion (eq. 1-8), ZMP planning
with the optimal stability point in the suboptimal support triangle (sec. 1.3), slope postures
(sec. 2, eq. 9), the zero-impact swing trajectory (eq. 10-13) and the gait sequencer.
"""

from footfall.quadruped.gait import (
    GaitParams,
    GaitPhase,
    GaitPlan,
    GaitTrajectory,
    PhaseKind,
    check_reachability,
    plan_gait,
)
from footfall.quadruped.kinematics import leg_fk, leg_ik, whole_body_com, whole_body_ik
from footfall.quadruped.posture import (
    BodyPosture,
    SlopePosture,
    leg_heights,
    leg_heights_horizontal,
)
from footfall.quadruped.robot import LEGS, JointLimits, Leg, QuadrupedRobot
from footfall.quadruped.stability import (
    centre_of_pressure,
    incentre,
    stability_margin,
    support_polygon,
    zmp_from_com,
    zmp_from_momentum,
)
from footfall.quadruped.swing import SwingProfile, swing_in_leg_frame
from footfall.quadruped.zmp_planning import (
    ZmpStrategy,
    optimal_stability_point,
    suboptimal_triangle,
    swing_order,
)

__all__ = [
    "LEGS",
    "BodyPosture",
    "GaitParams",
    "GaitPhase",
    "GaitPlan",
    "GaitTrajectory",
    "JointLimits",
    "Leg",
    "PhaseKind",
    "QuadrupedRobot",
    "SlopePosture",
    "SwingProfile",
    "ZmpStrategy",
    "centre_of_pressure",
    "check_reachability",
    "incentre",
    "leg_fk",
    "leg_heights",
    "leg_heights_horizontal",
    "leg_ik",
    "optimal_stability_point",
    "plan_gait",
    "stability_margin",
    "suboptimal_triangle",
    "support_polygon",
    "swing_in_leg_frame",
    "swing_order",
    "whole_body_com",
    "whole_body_ik",
    "zmp_from_com",
    "zmp_from_momentum",
]
