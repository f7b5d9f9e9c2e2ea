"""Plants that walk footstep plans, and what they measure.

One trial pipeline (:mod:`footfall.sim.trial`): every plant takes a scene, a plan and a
:class:`Disturbance` and returns a :class:`~footfall.results.outcome.Outcome`
(:func:`run_trial`); :func:`make_plant` makes one by its registry name.

- ``reduced``: the closed loop of document 000, sections 5.4-5.5, on the reduced-order (ALIP) plant:
  plan -> MPC footstep / ankle-torque adjuster (eq. 5.19) -> ALIP with a rectangular sole, pushes,
  noise and model mismatch -> metrics (single-support ZMP offset, falls, goal error).
- ``biped``: the MuJoCo biped (ours or the Unitree G1) walking a plan with the same MPC (the
  ``mujoco`` plant).
- ``quadruped``: the document-001 quadruped walk gait in MuJoCo (needs ``[sim]``).
- :class:`Disturbance` (a push in N s or as a velocity change, at a step and phase of single
  support) and :class:`Push`, the force pulse a plant applies.
"""

from footfall.sim.disturbance import Disturbance, Push
from footfall.sim.reduced import SimMetrics, SimOptions, SimResult, simulate
from footfall.sim.trial import PLANTS, make_plant, run_trial

__all__ = [
    "PLANTS",
    "Disturbance",
    "Push",
    "SimMetrics",
    "SimOptions",
    "SimResult",
    "make_plant",
    "run_trial",
    "simulate",
]
