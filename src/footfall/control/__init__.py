"""Feedback control on top of a footstep plan: the MPC (eq. 5.19) and the footstep / ankle-torque
adjusters a walking controller asks every tick (:mod:`footfall.control.adjusters`)."""

from footfall.control.adjusters import (
    FootstepAdjuster,
    MPCAdjuster,
    PlanFollower,
    RegionChoice,
    extend_plan,
    sole_torque_limits,
)
from footfall.control.ball_qp import solve_ball_qp
from footfall.control.horizon_regions import HorizonRegions
from footfall.control.mpc import (
    MPC,
    CondensedMPC,
    MPCSolution,
    MPCStatus,
    MPCWeights,
    build_mpc,
)
from footfall.control.region_mpc import RegionMPC, RegionRows, RegionSolution, sole_inset_offsets

__all__ = [
    "MPC",
    "CondensedMPC",
    "FootstepAdjuster",
    "HorizonRegions",
    "MPCAdjuster",
    "MPCSolution",
    "MPCStatus",
    "MPCWeights",
    "PlanFollower",
    "RegionChoice",
    "RegionMPC",
    "RegionRows",
    "RegionSolution",
    "build_mpc",
    "extend_plan",
    "sole_inset_offsets",
    "sole_torque_limits",
    "solve_ball_qp",
]
