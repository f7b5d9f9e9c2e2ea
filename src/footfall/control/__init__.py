"""Feedback control on top of a footstep plan: the MPC footstep / ankle-torque adjuster (eq. 5.19)."""

from footfall.control.mpc import (
    MPC,
    CondensedMPC,
    MPCSolution,
    MPCStatus,
    MPCWeights,
    build_mpc,
    solve_ball_qp,
)

__all__ = [
    "MPC",
    "CondensedMPC",
    "MPCSolution",
    "MPCStatus",
    "MPCWeights",
    "build_mpc",
    "solve_ball_qp",
]
