"""The outcome of one trial (a plant walking a plan under a disturbance), the same record for every
plant, and its row in a table.

Adding a metric is one field of :class:`Outcome`, one line of ``OUTCOME_COLUMNS`` and the plants
that measure it; a plant that does not measure it leaves NaN (a count: None).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

#: the outcome's columns in a trial table, in order, with their Arrow types
OUTCOME_COLUMNS: tuple[tuple[str, str], ...] = (
    ("success", "bool"),
    ("fell", "bool"),
    ("fall_time", "float64"),
    ("zmp_offset_mean", "float64"),
    ("zmp_offset_max", "float64"),
    ("cop_error_mean", "float64"),
    ("cop_error_max", "float64"),
    ("footstep_error_mean", "float64"),
    ("goal_error", "float64"),
    ("steps_landed", "int64"),
    ("footsteps_off_terrain", "int64"),
    ("sim_time", "float64"),
    ("wall_time", "float64"),
)


@dataclass(frozen=True)
class Outcome:
    """How one walk went, measured by its plant (NaN: not measured by this plant).

    Attributes:
        plant: the plant's registry name (:data:`footfall.sim.trial.PLANTS`).
        success: the walk reached its goal without a fall (each plant's test: the reduced
            plant comes to rest over its final feet, the MuJoCo biped lands every planned
            footstep and stops within ``GOAL_TOL`` of the goal, the quadruped ends near its
            planned final body position).
        fell: a fall was detected.
        fall_time: when [s] (NaN without a fall).
        zmp_offset_mean: mean single-support distance of the stance foot's centre of pressure
            from its sole centre [m] (document 000, section 5.5; bipeds).
        zmp_offset_max: its largest value [m].
        cop_error_mean: mean distance of the measured centre of pressure from the planned ZMP
            [m] (document 001, eq. 5; the quadruped).
        cop_error_max: its largest value [m].
        footstep_error_mean: mean horizontal distance of the landed footsteps from the plan [m].
        goal_error: horizontal distance of the robot's final position from its goal [m].
        steps_landed: footsteps landed (None: not counted by this plant).
        footsteps_off_terrain: landed footsteps on no region of the scene
            (:func:`footfall.terrain.terrain.region_of`; None: not counted).
        sim_time: simulated time [s].
        wall_time: wall-clock time of the whole trial [s] (:func:`footfall.sim.trial.run_trial`).
        detail: the plant's own full result (:mod:`footfall.results`), not part of the row.
    """

    plant: str
    success: bool
    fell: bool
    fall_time: float = math.nan
    zmp_offset_mean: float = math.nan
    zmp_offset_max: float = math.nan
    cop_error_mean: float = math.nan
    cop_error_max: float = math.nan
    footstep_error_mean: float = math.nan
    goal_error: float = math.nan
    steps_landed: int | None = None
    footsteps_off_terrain: int | None = None
    sim_time: float = math.nan
    wall_time: float = math.nan
    detail: Any = field(default=None, compare=False, repr=False)

    def row(self) -> dict[str, Any]:
        """The outcome's columns of a trial table (``OUTCOME_COLUMNS``) by name."""
        return {name: getattr(self, name) for name, _ in OUTCOME_COLUMNS}
