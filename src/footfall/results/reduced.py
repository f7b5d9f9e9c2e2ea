"""What a closed-loop run of the reduced-order plant measured
(:func:`footfall.sim.reduced.closed_loop.simulate`, document 000 sections 5.4-5.5): the summary
:class:`SimMetrics` and the :class:`SimResult` with the trajectories. Declared once here, below both
the simulation and the figures."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray


@dataclass(frozen=True)
class SimMetrics:
    """Outcome of one closed-loop run (definitions in :mod:`footfall.sim.reduced.closed_loop`).

    Attributes:
        fell: the capture point left the viable region (or the state blew up).
        fall_time: time of the fall [s] (nan if none).
        stopped: after the last footstep the capture point is inside the two final soles.
        success: ``not fell and stopped``.
        zmp_offset_mean: mean single-support CoP distance from the stance foot centre [m].
        zmp_offset_rms: its RMS [m].
        zmp_offset_max: its maximum [m].
        zmp_offset_phase_mean: per single-support phase [m].
        zmp_offset_phase_max: per single-support phase [m].
        saturated_time: single-support time with the CoP clipped at the sole edge [s].
        saturated_fraction: that time over the simulated single-support time.
        footstep_dev_mean: mean horizontal distance of the landed footsteps from the plan [m].
        footstep_dev_max: maximum of it [m].
        goal_error: horizontal distance of the final CoM from the goal [m] (nan after a fall).
        steps_taken: footsteps landed.
        mpc_solves: MPC solves.
        mpc_fallbacks: failed MPC solves replaced by the last good solution.
        mpc_time_median: median MPC solve time [s].
        mpc_time_p99: 99th percentile of the MPC solve time [s].
        mpc_time_max: maximum MPC solve time [s].
        sim_time: simulated time [s].
        wall_time: wall time of the run [s].
        engine: the engine that ran the loop, ``python`` or ``compiled`` (solve times of the
            compiled engine are those of the compiled solve, read inside the kernel).
        footsteps_off_regions: landed footsteps whose centre lies outside every region in plan
            view (None without the scene's regions).
        region_changes: indices of the landed footsteps outside their planned region.
    """

    fell: bool
    fall_time: float
    stopped: bool
    success: bool
    zmp_offset_mean: float
    zmp_offset_rms: float
    zmp_offset_max: float
    zmp_offset_phase_mean: tuple[float, ...]
    zmp_offset_phase_max: tuple[float, ...]
    saturated_time: float
    saturated_fraction: float
    footstep_dev_mean: float
    footstep_dev_max: float
    goal_error: float
    steps_taken: int
    mpc_solves: int
    mpc_fallbacks: int
    mpc_time_median: float
    mpc_time_p99: float
    mpc_time_max: float
    sim_time: float
    wall_time: float
    engine: str
    footsteps_off_regions: int | None = None
    region_changes: tuple[int, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (NaN becomes None)."""
        out: dict[str, Any] = {}
        for k, v in asdict(self).items():
            if k == "region_changes":
                out[k] = list(v)
            elif isinstance(v, tuple):
                out[k] = [None if not math.isfinite(x) else float(x) for x in v]
            elif isinstance(v, float) and not math.isfinite(v):
                out[k] = None
            else:
                out[k] = v
        return out


@dataclass(frozen=True, eq=False)
class SimResult:
    """Trajectories and metrics of one run; arrays have one row per plant sample (control tick).

    Attributes:
        metrics: :class:`SimMetrics`.
        t: sample times [s], shape (T,).
        stance: index of the stance footstep, shape (T,) (during double support: the old foot).
        single: True in single support, shape (T,).
        com: world CoM horizontal position [m], shape (T, 2).
        cop: realised world CoP [m], shape (T, 2).
        cop_offset: realised CoP minus the stance foot centre, in the foot frame [m], shape (T, 2).
        torque_cmd: MPC torque command [N m], shape (T, 2) (zero in double support).
        torque: applied (clipped) ankle torque [N m], shape (T, 2).
        saturated: CoP clipped at the sole edge, shape (T,).
        footsteps: landed footsteps [m], shape (n + 1, 3).
        plan_footsteps: planned footsteps [m], shape (N + 1, 3).
        headings: footstep headings [rad], shape (n + 1,).
        goal: goal position (2,) [m].
        u_max: torque bound U_max [N m].
        foot_length: sole length [m].
        foot_width: sole width [m].
        planner: name of the planner of the plan.
    """

    metrics: SimMetrics
    t: FloatArray
    stance: NDArray[np.int64]
    single: NDArray[np.bool_]
    com: FloatArray
    cop: FloatArray
    cop_offset: FloatArray
    torque_cmd: FloatArray
    torque: FloatArray
    saturated: NDArray[np.bool_]
    footsteps: FloatArray
    plan_footsteps: FloatArray
    headings: FloatArray
    goal: FloatArray
    u_max: float
    foot_length: float
    foot_width: float
    planner: str
