"""Plants that walk footstep plans, and what they measure.

- ``reduced``: the closed loop of document 000, sections 5.4-5.5, on the reduced-order (ALIP) plant:
  plan -> MPC footstep / ankle-torque adjuster (eq. 5.19) -> ALIP with a rectangular sole, pushes,
  noise and model mismatch -> metrics (single-support ZMP offset, falls, goal error).
- ``biped``: the MuJoCo biped (ours or the Unitree G1) walking a plan with the same MPC.
- ``quadruped``: the document-001 quadruped walk gait in MuJoCo (needs ``[sim]``).
- :class:`Push`: the external force pulse all three take.
"""

from footfall.sim.pushes import Push
from footfall.sim.reduced import SimMetrics, SimOptions, SimResult, simulate

__all__ = ["Push", "SimMetrics", "SimOptions", "SimResult", "simulate"]
