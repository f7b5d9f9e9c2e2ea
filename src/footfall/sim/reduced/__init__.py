"""The reduced-order (ALIP) plant in closed loop with the MPC (document 000, sections 5.4-5.5).

:func:`simulate` runs a footstep plan through the MPC of eq. (5.19) and the ALIP with a real sole,
pushes, noise and model mismatch (:mod:`footfall.sim.reduced.closed_loop`); the same loop compiled
with numba is :mod:`footfall.sim.reduced._kernel`.
"""

from footfall.sim.reduced.closed_loop import SimMetrics, SimOptions, SimResult, simulate

__all__ = ["SimMetrics", "SimOptions", "SimResult", "simulate"]
