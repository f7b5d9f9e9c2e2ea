"""Simulation of footstep plans.

``reduced``: the closed loop of document 000 section 5.4-5.5 on the reduced-order (ALIP) plant:
plan -> MPC footstep / ankle-torque adjuster (eq. 5.19) -> ALIP with a rectangular sole, pushes,
noise and model mismatch -> metrics (single-support ZMP offset, falls, goal error).
``compare``: the planner comparison of section 5.5 over seeded trials.
``quadruped_mjcf``, ``quadruped_sim``: the document-001 quadruped in MuJoCo (needs ``[sim]``).
"""

from footfall.sim.reduced import Push, SimMetrics, SimOptions, SimResult, simulate

__all__ = ["Push", "SimMetrics", "SimOptions", "SimResult", "simulate"]
