"""Region-aware footstep corrections in the reduced-order closed loop.

Document 000's MPC (eq. 5.19) moves the next footstep freely; with ``SimOptions.region_aware``
the reduced-order loop instead solves it with the footstep kept in its planned region inset by
the sole (``planned``), in the best region within reach (``nearby``), or in the region that the
short-horizon footstep MIQP chooses for it looking three footsteps ahead from the measured state
(``horizon``: :class:`footfall.control.horizon_regions.HorizonRegions`, re-solved at 50 Hz and at
a phase's first tick, warm-started from its last regions), through
:class:`footfall.control.region_mpc.RegionMPC`. Near the end of the plan, where fewer than three
footsteps are left, ``horizon`` keeps the planned region. The loop then runs in Python (the
compiled kernel has no region rows). The region metrics (footsteps landed off every region, region
changes) are computed for any run given the scene's regions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from footfall._typing import FloatArray
from footfall.control.adjusters import SWITCH_MARGIN
from footfall.control.horizon_regions import HORIZON_MODE, HorizonRegions
from footfall.control.mpc import MPC, MPCSolution
from footfall.control.region_mpc import RegionMPC, RegionRows, region_rows, regions_in_reach
from footfall.planning.plan import FootstepPlan
from footfall.terrain.region import Region
from footfall.terrain.terrain import region_of


@dataclass
class RegionFeet:
    """The region-aware MPC of one reduced-order run: candidates per phase and its choices.

    Attributes:
        plan: the plan walked.
        regions: the scene's regions.
        mode: ``planned``, ``nearby`` or ``horizon``.
        mpc: the loop's MPC (its counters and warm starts are shared).
        foot_length: sole length [m] of the inset.
        foot_width: sole width [m].
        choices: per phase, the region of the last solve.
    """

    plan: FootstepPlan
    regions: tuple[Region, ...]
    mode: str
    mpc: MPC
    foot_length: float
    foot_width: float
    choices: dict[int, str] = field(default_factory=dict)
    _nearby: dict[int, tuple[str, ...]] = field(default_factory=dict, repr=False)
    _rows: dict[tuple[int, str], RegionRows] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self.region_mpc = RegionMPC(self.mpc)
        self.by_name = {r.name: r for r in self.regions}
        # the inset uses the run's sole, which may differ from the plan robot's
        self._robot = replace(
            self.plan.robot, foot_length=self.foot_length, foot_width=self.foot_width
        )
        self._horizon = (
            HorizonRegions(self.plan, self.regions, self.mpc.model.control_dt)
            if self.mode == HORIZON_MODE
            else None
        )

    @property
    def horizon_solves(self) -> int:
        """``horizon`` mode: the short-horizon solves made (0 in the other modes)."""
        return 0 if self._horizon is None else self._horizon.solves

    def solve(
        self, i: int, k: int, theta: FloatArray, stance: FloatArray, p_ref: FloatArray
    ) -> MPCSolution:
        """Eq. (5.19) at tick ``k`` of phase ``i`` with the footstep in the region of choice."""
        plan = self.plan
        planned = plan.regions[i + 1]
        first = self.choices.get(i) or planned
        if self._horizon is not None:
            model = self.mpc.model
            foot = np.array([stance[0], stance[1], float(plan.footsteps[i][2])])
            time_left = (model.n_ticks - k) * model.control_dt
            first = self._horizon.choose(i, k, time_left, theta[:4], foot) or first
        names = [first]
        if self.mode == "nearby":
            if i not in self._nearby:
                self._nearby[i] = regions_in_reach(
                    self.regions, stance, float(plan.headings[i]), plan.sides[i], plan.robot
                )
            names += [n for n in self._nearby[i] if n != first]
        heading = float(plan.headings[i + 1])
        cands = []
        for n in names:
            if n in self.by_name:
                if (i, n) not in self._rows:  # the stance foot stays put for the phase
                    self._rows[i, n] = region_rows(self.by_name[n], stance, heading, self._robot)
                cands.append(self._rows[i, n])
        if not cands:
            return self.mpc.solve_theta(k, theta, stance, p_ref)
        reason = "planned" if cands[0].name == planned else "kept"
        rs = self.region_mpc.solve(k, theta, stance, p_ref, cands, SWITCH_MARGIN, reason)
        if rs.region:
            self.choices[i] = rs.region
            return rs.solution
        # no region fits the sole: the plan's footstep (the planner kept it inside)
        sol = rs.solution
        foot = np.array(p_ref, dtype=float)
        return MPCSolution(
            k_s=sol.k_s,
            torques=sol.torques,
            block_ticks=sol.block_ticks,
            next_footstep=foot,
            status=sol.status,
            fallback=sol.fallback,
            solve_time=sol.solve_time,
            iterations=sol.iterations,
            multipliers=sol.multipliers,
            message="no region fits the sole: the plan's footstep",
        )


def region_metrics(
    regions: Sequence[Region], plan: FootstepPlan, feet: FloatArray
) -> tuple[int, tuple[int, ...]]:
    """``(footsteps off every region, steps that changed region)`` of the landed ``feet``
    (n + 1, 3) [m] (row 0 is the start stance foot): a footstep is off when it stands on no region
    (:func:`footfall.terrain.terrain.region_of` in plan view: this plant has no heights); it
    changed region when the plan's region does not hold it."""
    by_name = {r.name: r for r in regions}
    off = 0
    changed = []
    for j in range(1, feet.shape[0]):
        off += not region_of(regions, feet[j, :2])  # plan view: no heights here
        own = by_name.get(plan.regions[j])
        if own is None or float(own.signed_distance(feet[j, :2])) > 0.0:
            changed.append(j)
    return off, tuple(changed)
