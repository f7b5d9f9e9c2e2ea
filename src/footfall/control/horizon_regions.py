"""The next footstep's region chosen by the short-horizon footstep MIQP, for either walker.

The region-aware MPC (:class:`footfall.control.region_mpc.RegionMPC`) keeps the next footstep in
one region. In ``horizon`` mode that region is not the plan's but the one
:class:`footfall.planning.HorizonPlanner` puts footstep i + 1 in, looking H = 3 footsteps ahead
from the measured ALIP state (document 000, eq. 5.11-5.18 over a short horizon). It is re-solved
at a phase's first tick and every ``HORIZON_PERIOD`` seconds, warm-started from its last regions
(shifted after a touchdown); between solves the last choice holds. Where fewer than H footsteps
are left, or the MIQP has no solution, the caller keeps its own region (the plan's, or the last
choice). Both the reduced-order loop and the MuJoCo walker use this one class.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.planning.plan import FootstepPlan
from footfall.terrain.region import Region
from footfall.terrain.terrain import Terrain

if TYPE_CHECKING:
    from footfall.planning.horizon import HorizonPlanner, HorizonSolution

#: the region mode that asks the short-horizon MIQP
HORIZON_MODE = "horizon"
#: time between two short-horizon solves within a single support [s] (50 Hz)
HORIZON_PERIOD = 0.02


@dataclass
class HorizonRegions:
    """Per phase, the region the short-horizon MIQP chooses for the next footstep.

    Attributes:
        plan: the plan walked (with ALIP states; the walker's plan includes its stopping steps).
        regions: the regions the footsteps may use.
        control_dt: the caller's control period [s]; solves are ``round(HORIZON_PERIOD /
            control_dt)`` ticks apart (at least 1).
        torque_limits: semi-axes ``(U_x, U_y)`` [N m] of the caller MPC's ankle-torque ellipse
            (:attr:`footfall.planning.horizon.HorizonOptions.torque_limits`), so the MIQP judges a
            region with the torque the MPC will use; None: the plan's ball ``U_max``.
        solves: short-horizon solves made so far.
        failures: solves that returned no solution (the caller's region held).
    """

    plan: FootstepPlan
    regions: Sequence[Region]
    control_dt: float
    torque_limits: tuple[float, float] | None = None
    solves: int = 0
    failures: int = 0
    #: control ticks between two solves
    every: int = field(init=False)
    _planner: HorizonPlanner = field(init=False, repr=False)
    _last: HorizonSolution | None = field(default=None, init=False, repr=False)
    _pick: dict[int, str] = field(default_factory=dict, init=False, repr=False)

    def __post_init__(self) -> None:
        from footfall.planning.horizon import HorizonOptions, HorizonPlanner

        if not (math.isfinite(self.control_dt) and self.control_dt > 0.0):
            raise InputError("control_dt", self.control_dt, "a period > 0 [s]")
        if self.plan.states is None or not self.plan.has_solution:
            raise InputError("plan", self.plan.planner, "a plan with footsteps and ALIP states")
        options = HorizonOptions(torque_limits=self.torque_limits)
        self._planner = HorizonPlanner(Terrain(tuple(self.regions)), self.plan.robot, options)
        self.every = max(1, round(HORIZON_PERIOD / self.control_dt))

    @property
    def horizon(self) -> int:
        """H, the footsteps the MIQP looks ahead."""
        return self._planner.h

    def choose(
        self, phase: int, tick: int, time_left: float, state: FloatArray, stance: FloatArray
    ) -> str | None:
        """The region of footstep ``phase + 1`` (None: no choice, keep the caller's).

        Args:
            phase: the single support i (standing on the plan's footstep i).
            tick: the control tick within that single support (0 at its start).
            time_left: time left in the single support [s].
            state: measured ALIP state (4,) relative to the stance foot (eq. 5.1).
            stance: the stance foot's contact point (3,) [m], world frame.

        A terrain of one region leaves nothing to choose: no solve, the caller's region holds
        (the same walk as ``planned``, at its speed).
        """
        h = self._planner.h
        if len(self.regions) == 1 or phase + h > self.plan.n_steps or time_left <= 0.0:
            return None
        if tick % self.every and phase in self._pick:
            return self._pick[phase]
        from footfall.planning.horizon import horizon_input

        inp = horizon_input(self.plan, phase, time_left, np.asarray(state[:4], dtype=float), h)
        inp = replace(inp, stance_foot=np.asarray(stance, dtype=float)[:3])
        last = self._last
        warm = None if last is None else last.next_regions(stepped=tick == 0)
        sol = self._planner.solve(inp, warm=warm)
        self.solves += 1
        self._last = sol if sol.has_solution else None
        if not sol.has_solution:
            self.failures += 1
            return self._pick.get(phase)
        self._pick[phase] = sol.regions[0]
        return sol.regions[0]
